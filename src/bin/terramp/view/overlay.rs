//! How it works: the viewer's overlay, drawn with egui over the 3D frame. One panel shows what
//! the renderer did: the latest GPU timings per pass as a table like the paper's Table 1, each
//! with a rolling graph of its last seconds; frames per second and frame time; seeds checked,
//! selected and drawn; tiles resident, in flight and uploaded per cache; the adapter; the camera
//! in the dataset's CRS with a button that copies the `terramp render` line of this view. A
//! second panel holds the preset and the knobs (`config::knobs`): live ones change the running
//! renderer at once, the others say they remake it and do so when let go. The overlay never
//! touches the renderer: it returns what was asked (`Request`) and the viewer does it.

use std::collections::{BTreeMap, VecDeque};

use egui::{Color32, RichText};

use terramp::camera::Camera;
use terramp::config::PRESETS;
use terramp::config::Settings;
use terramp::config::knobs::{Apply, KNOBS};
use terramp::frame::FrameReport;
use terramp::gpu::{PassTiming, TimeSource};
use terramp::streaming::CacheStats;

/// Samples each rolling graph keeps (frames).
const HISTORY: usize = 120;
/// Width and height of a pass's rolling graph, points.
const GRAPH_SIZE: [f32; 2] = [120.0, 16.0];

/// What the overlay asks the viewer to do.
#[derive(Debug, Clone, PartialEq)]
pub enum Request {
    /// Make the renderer again with this preset.
    Preset(String),
    /// Set knob `KNOBS[index]` to `value` (a live knob now; the others remake).
    Knob { index: usize, value: f64 },
    /// Copy the `terramp render` line of this view to the clipboard.
    CopyRenderLine,
    /// Switch ground-follow.
    Follow,
    /// Switch the speed's scaling with the height above the ground.
    ByHeight,
    /// Go to a pose written as `--camera` takes one (CRS, or `lonlat:` / `lonlat-ground:`).
    GoTo(String),
}

/// What the viewer shows in the overlay this frame.
pub struct Shown<'a> {
    pub report: &'a FrameReport,
    pub timings: &'a [PassTiming],
    pub adapter: &'a str,
    pub camera: &'a Camera,
    pub speed_m_s: f64,
    pub follow_m: Option<f64>,
    /// The speed scales with the height above the ground.
    pub by_height: bool,
    pub settings: &'a Settings,
    pub preset: &'a str,
    /// Keyframes recorded so far, while recording.
    pub recording: Option<usize>,
    /// A line for the person (saved files, a remake, an error), if any.
    pub message: &'a str,
    /// A remake is pending or running.
    pub busy: bool,
}

/// The overlay's state between frames: the rolling histories.
#[derive(Default)]
pub struct Overlay {
    pub visible: bool,
    frame_ms: VecDeque<f32>,
    passes: BTreeMap<String, VecDeque<f32>>,
    /// The knob values being dragged (a remake knob waits for the drag to end).
    dragging: BTreeMap<usize, f64>,
    /// The pose being typed for "go to".
    go_to: String,
}

fn push(history: &mut VecDeque<f32>, value: f32) {
    if history.len() == HISTORY {
        history.pop_front();
    }
    history.push_back(value);
}

/// A small line graph of `values` scaled to their maximum.
fn sparkline(ui: &mut egui::Ui, values: &VecDeque<f32>) {
    let (rect, _) = ui.allocate_exact_size(GRAPH_SIZE.into(), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_black_alpha(60));
    let top = values.iter().copied().fold(f32::EPSILON, f32::max);
    let step = rect.width() / (HISTORY - 1) as f32;
    let points: Vec<egui::Pos2> = values
        .iter()
        .enumerate()
        .map(|(i, v)| egui::pos2(rect.left() + i as f32 * step, rect.bottom() - rect.height() * v / top))
        .collect();
    painter.add(egui::Shape::line(points, egui::Stroke::new(1.0, Color32::LIGHT_GREEN)));
}

fn cache_row(ui: &mut egui::Ui, name: &str, s: &CacheStats) {
    ui.label(name);
    ui.label(s.resident.to_string());
    ui.label(s.in_flight.to_string());
    ui.label(s.uploaded.to_string());
    ui.label(format!("{}/{}", s.needed_resident, s.needed));
    ui.end_row();
}

/// A speed in the unit that reads best.
pub fn speed_text(m_s: f64) -> String {
    if m_s >= 1000.0 { format!("{:.1} km/s", m_s / 1000.0) } else { format!("{m_s:.0} m/s") }
}

impl Overlay {
    /// A shown overlay with empty histories.
    pub fn new() -> Self {
        Self { visible: true, ..Default::default() }
    }

    /// Takes a frame's wall time and the latest pass timings into the histories.
    pub fn record(&mut self, frame_ms: f64, timings: &[PassTiming]) {
        push(&mut self.frame_ms, frame_ms as f32);
        for t in timings {
            match self.passes.get_mut(&t.label) {
                Some(history) => push(history, t.ms as f32),
                None => {
                    self.passes.insert(t.label.clone(), VecDeque::from([t.ms as f32]));
                }
            }
        }
    }

    /// Median frame time over the history, ms.
    pub fn median_frame_ms(&self) -> f64 {
        let ms: Vec<f64> = self.frame_ms.iter().copied().map(f64::from).collect();
        terramp::profile::stats::median(&ms).unwrap_or(0.0)
    }

    /// Draws the overlay; returns what the person asked for.
    pub fn ui(&mut self, ctx: &egui::Context, shown: &Shown) -> Vec<Request> {
        let mut requests = Vec::new();
        if !self.visible {
            return requests;
        }
        egui::Window::new("terramp").default_pos([8.0, 8.0]).resizable(false).show(ctx, |ui| {
            self.stats(ui, shown, &mut requests);
        });
        egui::Window::new("knobs")
            .anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0])
            .default_open(false)
            .show(ctx, |ui| self.knobs(ui, shown, &mut requests));
        requests
    }

    fn stats(&mut self, ui: &mut egui::Ui, shown: &Shown, requests: &mut Vec<Request>) {
        let median = self.median_frame_ms();
        let fps = if median > 0.0 { 1000.0 / median } else { 0.0 };
        ui.label(RichText::new(format!("{fps:.1} fps · {median:.1} ms per frame")).strong());
        ui.label(RichText::new(shown.adapter).small());
        egui::Grid::new("passes").num_columns(3).striped(true).show(ui, |ui| {
            ui.label("pass");
            ui.label("ms");
            ui.label("last seconds");
            ui.end_row();
            for t in shown.timings {
                // The CPU's steps are marked: the others are the GPU's timestamps.
                let cpu = t.source == TimeSource::Cpu;
                ui.label(if cpu { format!("{} (CPU)", t.label) } else { t.label.clone() });
                ui.label(format!("{:>7.2}", t.ms));
                if let Some(history) = self.passes.get(&t.label) {
                    sparkline(ui, history);
                }
                ui.end_row();
            }
            ui.label(RichText::new("frame").strong());
            ui.label(format!("{:>7.2}", self.frame_ms.back().copied().unwrap_or_default()));
            sparkline(ui, &self.frame_ms);
            ui.end_row();
        });
        ui.separator();
        let r = shown.report;
        match &r.seeds {
            Some(s) => ui.label(format!(
                "seeds: {} checked, {} selected, {} drawn{}",
                s.counters.checked,
                s.counters.selected,
                s.counters.selected.saturating_sub(s.counters.overflow),
                if s.counters.overflow > 0 {
                    format!(" ({} overflowed)", s.counters.overflow)
                } else {
                    String::new()
                }
            )),
            None => ui.label("seeds: none (no land cover)"),
        };
        egui::Grid::new("caches").num_columns(5).show(ui, |ui| {
            for head in ["tiles", "resident", "in flight", "uploaded", "needed in"] {
                ui.label(head);
            }
            ui.end_row();
            cache_row(ui, "height", &r.height);
            cache_row(ui, "imagery", &r.imagery);
            cache_row(ui, "land cover", &r.landcover);
        });
        ui.separator();
        let c = shown.camera;
        let p = c.position_m;
        ui.label(format!(
            "camera {:.1}, {:.1}, {:.1} m · heading {:.1}° pitch {:.1}°",
            p.x, p.y, p.z, c.yaw_deg, c.pitch_deg
        ));
        ui.horizontal(|ui| {
            if ui.button("copy render line").clicked() {
                requests.push(Request::CopyRenderLine);
            }
            let follow = match shown.follow_m {
                Some(m) => format!("ground-follow {m:.0} m"),
                None => "ground-follow off".into(),
            };
            if ui.button(follow).clicked() {
                requests.push(Request::Follow);
            }
            let pace = if shown.by_height { "speed by height (V): on" } else { "speed by height (V): off" };
            if ui.button(pace).clicked() {
                requests.push(Request::ByHeight);
            }
        });
        ui.horizontal(|ui| {
            let hint = "lonlat-ground:LON,LAT,H,HEADING,PITCH or X,Y,Z,YAW,PITCH";
            let field =
                ui.add(egui::TextEdit::singleline(&mut self.go_to).hint_text(hint).desired_width(280.0));
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if (ui.button("go to").clicked() || entered) && !self.go_to.trim().is_empty() {
                requests.push(Request::GoTo(self.go_to.trim().to_owned()));
            }
        });
        let pace = if shown.by_height { " at this height" } else { "" };
        ui.label(format!("speed {}{pace} (scroll, +/−; Shift ×10)", speed_text(shown.speed_m_s)));
        if let Some(keys) = shown.recording {
            ui.label(
                RichText::new(format!("● recording the path: {keys} keyframes (P stops)"))
                    .color(Color32::RED),
            );
        }
        if !shown.message.is_empty() {
            ui.label(RichText::new(shown.message).small());
        }
    }

    fn knobs(&mut self, ui: &mut egui::Ui, shown: &Shown, requests: &mut Vec<Request>) {
        ui.add_enabled_ui(!shown.busy, |ui| {
            ui.horizontal(|ui| {
                ui.label("preset");
                for (name, _) in PRESETS {
                    if ui.selectable_label(shown.preset == *name, *name).clicked() && shown.preset != *name {
                        requests.push(Request::Preset((*name).to_owned()));
                    }
                }
            });
            ui.label(RichText::new("● remakes the renderer when let go").small());
            egui::Grid::new("knobs").num_columns(2).show(ui, |ui| {
                for (index, knob) in KNOBS.iter().enumerate() {
                    let remake = knob.apply == Apply::Remake;
                    ui.label(if remake { format!("● {}", knob.label) } else { knob.label.to_owned() });
                    let current = (knob.get)(shown.settings);
                    let mut value = self.dragging.get(&index).copied().unwrap_or(current);
                    let slider = egui::Slider::new(&mut value, knob.range.clone())
                        .logarithmic(knob.logarithmic)
                        .integer_if(knob.integer)
                        .suffix(format!(" {}", knob.unit));
                    let response = ui.horizontal(|ui| {
                        let response = ui.add(slider);
                        if let Some(note) = (knob.note)(shown.settings) {
                            ui.label(RichText::new(note).small());
                        }
                        response
                    });
                    let response = response.inner;
                    if response.dragged() && remake {
                        self.dragging.insert(index, value);
                    } else if response.changed() || response.drag_stopped() {
                        self.dragging.remove(&index);
                        if value != current {
                            requests.push(Request::Knob { index, value });
                        }
                    }
                    ui.end_row();
                }
            });
        });
    }
}

/// `Slider::integer` when `integer`.
trait IntegerIf {
    fn integer_if(self, integer: bool) -> Self;
}

impl IntegerIf for egui::Slider<'_> {
    fn integer_if(self, integer: bool) -> Self {
        if integer { self.integer() } else { self }
    }
}
