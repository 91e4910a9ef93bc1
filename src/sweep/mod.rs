//! How it works: `terramp sweep` measures the speed trade (DESIGN.md, "Accuracy, and the speed
//! trade"). Its points are presets, optionally crossed with knob values (`knobs`). Every point
//! flies the same camera path (`--path`, or the dataset's default as `terramp profile` chooses it)
//! in fresh renderers, timed by the profiling session (`profile::Session`) in interleaved rounds:
//! each round flies every point in turn (warm-up frames, then its consecutive share of the timed
//! frames, as far apart along the path as in one block), odd rounds in reverse order, so that
//! the host's load drifting over the sweep (even steadily, from the first point to the last)
//! falls on all points alike; the rounds' frames pool
//! (`Recording::append`) into per-pass GPU medians and the frame's median wall time
//! (`profile::Summary`). Then, at a few sample poses spread along the same path, it settles the view
//! (`render_resolved`: everything the view asked for is resident) and measures it (`measure`)
//! against two references, neither of them the thing measured:
//! - the **ground truth** (`truth`, through `truths`) of the point's own seeded world (every seed
//!   grown, as meshes, supersampled): its kept seeds against the any-part oracle (recall,
//!   precision, pixel-weighted recall, and why the missed pixels are missed); its frame by PSNR,
//!   SSIM and FLIP, whole and per distance band (`truth::compare`); its ground (the frame without
//!   seeds) against the truth's ground (PSNR);
//! - the **exact summit oracle** (`reference::oracle`): the distance of each kept seed's ground
//!   height from the f64 drawn ground (`reference::accuracy`), and recall and precision against pass 3's
//!   own rule, done exactly.
//!
//! Each sample pose's frame is also measured against its photograph frame (the same settings with
//! nothing grown, `photo`): CIEDE2000 of 5 × 5 block means, pooled over the poses.
//!
//! Popping is measured along a short flight of consecutive frames at a steady speed
//! (`popping_frames` frames `popping_step_m` apart, from the middle sample pose on): the largest
//! 4 × 4 block change between frames, against the reference world's truth along the same flight
//! (`reference::frame_change`).
//!
//! Seed counts add up over the sample poses (recall is over all their seeds); image errors pool
//! the poses' pixels (as one image). `report` writes `trade.csv`, `trade.json` (schema
//! `terramp-trade/3`), `tables` `trade.md` and the terminal table; `plot` draws `trade.png`.
//! Progress goes to a callback, one step per frame rendered, pose settled and truth rendered.

pub mod knobs;
mod measure;
pub mod plot;
pub mod report;
pub mod tables;
mod truths;

use std::path::{Path, PathBuf};

use thiserror::Error;

use crate::camera::Camera;
use crate::config::{Settings, SettingsError};
use crate::dataset::{Dataset, DatasetError};
use crate::profile::ProfileError;
use crate::truth::TruthOptions;
pub use knobs::{Knob, Point, points};
pub use report::{PoppingFlight, SCHEMA, Trade, TradePoint};

/// Why a sweep, or writing its outputs, failed.
#[derive(Debug, Error)]
pub enum SweepError {
    /// A point's settings (preset, settings file or knob value) do not load or check.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// The dataset's folder or manifest could not be opened.
    #[error(transparent)]
    Dataset(#[from] DatasetError),
    /// A point's timed flight failed.
    #[error(transparent)]
    Profile(#[from] ProfileError),
    /// A renderer could not be made, or a settled or reference frame failed.
    #[error(transparent)]
    Render(#[from] crate::frame::RenderError),
    /// No adapter, or the GPU failed outside a frame.
    #[error(transparent)]
    Gpu(#[from] crate::gpu::GpuError),
    /// A height tile could not be read for the default path or the seeds' height error.
    #[error(transparent)]
    Pack(#[from] crate::dataset::PackError),
    /// A frame could not be measured against its photograph.
    #[error(transparent)]
    Photo(#[from] crate::photo::PhotoError),
    /// A ground truth could not be rendered.
    #[error(transparent)]
    Truth(#[from] crate::truth::TruthError),
    /// The exact oracle could not list the visible seeds of a sample pose.
    #[error(transparent)]
    Oracle(#[from] crate::reference::oracle::OracleError),
    /// A frame and its reference cannot be compared: different sizes, or too small for SSIM.
    #[error(transparent)]
    Image(#[from] crate::reference::image_metrics::ImageMetricError),
    /// The camera path file (`--path`) does not load or parse.
    #[error(transparent)]
    Path(#[from] crate::path::PathError),
    /// Reading the settings file, or creating or writing an output, failed.
    #[error("{what}: {source}")]
    Io {
        /// What was being done, naming the file (`writing out/trade.csv`).
        what: String,
        /// What the file system said.
        source: std::io::Error,
    },
    /// Drawing or saving `trade.png` failed.
    #[error("plotting {path}: {message}")]
    Plot {
        /// The image being drawn.
        path: String,
        /// What the plotting library said.
        message: String,
    },
    /// The options ask for nothing to measure: no frames, no samples or no presets.
    #[error("sweep: {0}")]
    Options(String),
}

/// What to sweep, and how.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// The dataset's folder; every point and the reference open it afresh.
    pub dataset: PathBuf,
    /// Camera path file; `None` takes `profile::default_path`.
    pub path: Option<PathBuf>,
    /// Presets to measure (`fast`, `balanced`, `accurate`), each crossed with every knob value.
    pub presets: Vec<String>,
    /// Settings keys to vary, one `--knob` each; the points are their cartesian product, or with
    /// `series` one knob at a time (`knobs::series`).
    pub knobs: Vec<Knob>,
    /// Vary one knob at a time from each preset instead of crossing them all.
    pub series: bool,
    /// With `series`, the presets the knobs are varied from (empty: every one of `presets`).
    pub series_from: Vec<String>,
    /// A settings file laid over every point's preset and over the reference (before the knobs).
    pub settings: Option<PathBuf>,
    /// Timed frames per point, spread evenly along the path, after `warmup` frames at its start.
    pub frames: u32,
    /// Untimed frames per point and round at the path's start, so caches fill and shaders
    /// compile first.
    pub warmup: u32,
    /// Rounds the timed frames are split into: every round times each point in turn (a fresh
    /// renderer, `warmup` frames, then its consecutive share of the timed frames), so a slow drift
    /// of the machine's load falls on every point alike instead of on whichever was timed then.
    pub timing_rounds: u32,
    /// Poses along the path where accuracy is measured, at t = (i + ½) / samples.
    pub samples: u32,
    /// Override of `render.width` for every point and the reference, pixels.
    pub width: Option<u32>,
    /// Override of `render.height` for every point and the reference, pixels.
    pub height: Option<u32>,
    /// Frames of the popping flight (0: popping is not measured).
    pub popping_frames: u32,
    /// Metres the camera moves between the popping flight's frames (0.25 m: 15 m/s at 60 frames
    /// per second; slow, so that motion alone changes few blocks much and artefacts stand out).
    pub popping_step_m: f64,
    /// How the ground truths are rendered (supersampling, reach; impostors: the reference
    /// settings' `draw_seeds.impostors` when empty; without any, the truths grow no seeds).
    pub truth: TruthOptions,
}

/// A sweep's progress, for a progress bar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Progress<'a> {
    /// The number of steps the whole sweep takes.
    Total(u64),
    /// One more step done; what is being done now.
    Step(&'a str),
}

/// File `write_outputs` puts the table in, as CSV, one row per point.
pub const CSV_FILE: &str = "trade.csv";
/// File `write_outputs` puts the whole `Trade` in, as JSON (schema `terramp-trade/3`).
pub const JSON_FILE: &str = "trade.json";
/// File `write_outputs` draws the speed/accuracy plot in.
pub const PLOT_FILE: &str = "trade.png";
/// File `write_outputs` puts the tables in, as Markdown.
pub const MARKDOWN_FILE: &str = "trade.md";

/// Runs the sweep: the reference, then every point. Fails before rendering anything when a point's
/// settings are invalid.
pub fn run(options: &SweepOptions, progress: &mut dyn FnMut(Progress)) -> Result<Trade, SweepError> {
    if options.frames == 0 || options.samples == 0 || options.presets.is_empty() {
        return Err(SweepError::Options("--frames, --samples and --presets need at least one".into()));
    }
    if options.timing_rounds == 0 || options.timing_rounds > options.frames {
        return Err(SweepError::Options(format!(
            "--timing-rounds {} must be between 1 and --frames ({})",
            options.timing_rounds, options.frames
        )));
    }
    let user = match &options.settings {
        Some(file) => {
            let text = std::fs::read_to_string(file)
                .map_err(|source| SweepError::Io { what: format!("reading {}", file.display()), source })?;
            Some((file.display().to_string(), text))
        }
        None => None,
    };
    let resize = |mut s: Settings| {
        s.render.width = options.width.unwrap_or(s.render.width);
        s.render.height = options.height.unwrap_or(s.render.height);
        s
    };
    let points = match options.series {
        true => knobs::series(&options.presets, &options.series_from, &options.knobs),
        false => points(&options.presets, &options.knobs),
    };
    let settings: Vec<Settings> =
        points.iter().map(|p| p.settings(user.as_ref()).map(resize)).collect::<Result<_, _>>()?;
    let reference_point = Point { preset: "accurate".into(), knobs: Vec::new() };
    let reference_settings = resize(reference_point.settings(user.as_ref())?);

    let dataset = Dataset::open(&options.dataset)?;
    let (path, path_name) = match &options.path {
        Some(file) => (crate::profile::load_path(&dataset, file)?, file.display().to_string()),
        None => crate::profile::default_path(&dataset)?,
    };
    let r = &reference_settings.render;
    let poses: Vec<(f64, Camera)> = (0..options.samples)
        .map(|i| {
            let t = (f64::from(i) + 0.5) / f64::from(options.samples);
            (t, path.camera_at(t, r.fov_deg, r.near_m))
        })
        .collect();
    drop(dataset);
    // The popping flight starts at the middle sample pose (settled there, then flown).
    let (popping_t, popping_start) = poses[poses.len() / 2];
    let popping: Vec<Camera> = match options.popping_frames {
        0 => Vec::new(),
        n => {
            let walk = path.walk(popping_t, options.popping_step_m, n as usize, r.fov_deg, r.near_m);
            if walk.len() < 2 {
                let at = popping_start.position_m;
                return Err(SweepError::Options(format!(
                    "the popping flight from t = {popping_t:.2} ({:.0}, {:.0}) does not move: the path \
                     ends there, or --popping-step-m is not positive",
                    at.x, at.y
                )));
            }
            walk.into_iter().map(|(_, camera)| camera).collect()
        }
    };

    let per_point = |s: &Settings| {
        let grounds = if s.draw_seeds.impostors.is_empty() { 0 } else { 1 };
        u64::from(options.warmup * options.timing_rounds + options.frames)
            + u64::from(options.samples) * (1 + grounds)
            + popping.len() as u64
    };
    let mut truth = options.truth.clone();
    if truth.impostors.as_os_str().is_empty() {
        truth.impostors = PathBuf::from(&reference_settings.draw_seeds.impostors);
    }
    if truth.impostors.as_os_str().is_empty() {
        // No mesh to draw seeds with: the truths are the ground alone.
        truth.reach_m = 0.0;
    }
    let worlds = match truth.reach_m > 0.0 {
        true => truths::world_count(&reference_settings, &settings),
        false => 1,
    };
    let truth_steps = u64::from(options.samples) * worlds as u64 + popping.len() as u64;
    progress(Progress::Total(truth_steps + settings.iter().map(per_point).sum::<u64>()));

    let flight = measure::Flight {
        dataset_dir: &options.dataset,
        path: &path,
        poses: &poses,
        popping: &popping,
        warmup: options.warmup,
        frames: options.frames,
    };
    let mut truths = truths::Truths::new(&flight, &reference_settings, truth.clone(), progress)?;
    // Timing first, round-robin over the points, then each point's accuracy.
    let mut timed: Vec<Option<measure::Timed>> = points.iter().map(|_| None).collect();
    for round in 0..options.timing_rounds {
        for index in round_order(points.len(), round) {
            let this = flight.time_round(
                &points[index].label(),
                &settings[index],
                (round, options.timing_rounds),
                progress,
            )?;
            match &mut timed[index] {
                Some(pooled) => pooled.append(this),
                None => timed[index] = Some(this),
            }
        }
    }
    let mut measured = Vec::with_capacity(points.len());
    for ((point, settings), timed) in points.iter().zip(settings).zip(timed) {
        let timed = timed.ok_or_else(|| SweepError::Options("a point was never timed".into()))?;
        measured.push(flight.measure(point, settings, timed, &mut truths, progress)?);
    }
    let first = measured.first();
    Ok(Trade {
        schema: SCHEMA,
        adapter: first.map(|m| m.adapter.clone()).unwrap_or_default(),
        timing: first.map(|m| m.timing_note.clone()).unwrap_or_default(),
        dataset: options.dataset.display().to_string(),
        path: path_name,
        resolution: [reference_settings.render.width, reference_settings.render.height],
        warmup: options.warmup,
        frames: options.frames,
        timing_rounds: options.timing_rounds,
        sample_t: poses.iter().map(|(t, _)| *t).collect(),
        popping_flight: (!popping.is_empty()).then_some(PoppingFlight {
            frames: popping.len() as u32,
            step_m: options.popping_step_m,
            from_t: popping_t,
        }),
        reference: format!(
            "ground truth of each point's own world (its seed patterns), every seed within {:.0} m as its \
             full mesh{}, every tile at its finest level, {}² samples per pixel",
            truth.reach_m,
            if truth.reach_m > 0.0 { "" } else { " (none: no impostors)" },
            truth.supersample
        ),
        settings: options.settings.as_ref().map(|f| f.display().to_string()),
        points: measured.into_iter().map(|m| m.point).collect(),
    })
}

/// The order round `round` times the points in: forward in even rounds, backward in odd ones, so
/// that a load that rises or falls steadily over the sweep gives every point the same mean load
/// over two rounds (in one direction only, the last points would always fly latest).
fn round_order(points: usize, round: u32) -> impl Iterator<Item = usize> {
    let backward = round % 2 == 1;
    (0..points).map(move |i| if backward { points - 1 - i } else { i })
}

/// Writes `trade.csv`, `trade.json`, `trade.png` and `trade.md` (the tables in Markdown) into `dir`
/// (created if missing).
pub fn write_outputs(trade: &Trade, dir: &Path) -> Result<(), SweepError> {
    let io = |what: String| move |source| SweepError::Io { what, source };
    std::fs::create_dir_all(dir).map_err(io(format!("creating {}", dir.display())))?;
    let csv = dir.join(CSV_FILE);
    std::fs::write(&csv, report::csv(trade)).map_err(io(format!("writing {}", csv.display())))?;
    let json = dir.join(JSON_FILE);
    std::fs::write(&json, report::json(trade)).map_err(io(format!("writing {}", json.display())))?;
    let markdown = dir.join(MARKDOWN_FILE);
    std::fs::write(&markdown, tables::markdown(trade))
        .map_err(io(format!("writing {}", markdown.display())))?;
    plot::write(trade, &dir.join(PLOT_FILE))
}

#[cfg(test)]
mod tests {
    use super::round_order;

    #[test]
    fn rounds_alternate_direction_so_a_steady_drift_averages_out() {
        let order = |round| round_order(4, round).collect::<Vec<_>>();
        assert_eq!(order(0), [0, 1, 2, 3]);
        assert_eq!(order(1), [3, 2, 1, 0]);
        assert_eq!(order(2), [0, 1, 2, 3]);
        // A load rising one unit per slot: over two rounds every point's summed slot is the same.
        let mut slot_sum = [0usize; 4];
        for round in 0..2 {
            for (slot, point) in round_order(4, round).enumerate() {
                slot_sum[point] += slot + 4 * round as usize;
            }
        }
        assert!(slot_sum.iter().all(|&s| s == slot_sum[0]), "{slot_sum:?}");
        assert_eq!(round_order(0, 1).count(), 0);
    }
}
