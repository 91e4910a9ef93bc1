//! How it works: one viewing session: the renderer, the screen, the flight and the overlay, and
//! what happens each redraw (`frame`): move, render, show, then do what the overlay and the keys
//! asked. A resize is taken by the surface at once and by the renderer once the size has held
//! still for `RESIZE_SETTLE`, the old frame stretched over the window meanwhile.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use glam::DVec3;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::ActiveEventLoop;
use winit::keyboard::PhysicalKey;

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::config::knobs::{Apply, KNOBS};
use terramp::dataset::Dataset;
use terramp::frame::{FrameReport, Renderer};
use terramp::gpu::Gpu;
use terramp::path::CameraPath;
use terramp::profile::stats;

use super::ViewArgs;
use super::capture::{self, Recording};
use super::flight::{Action, Flight};
use super::overlay::{Overlay, Request, Shown};
use super::screen::Screen;

/// How long a new window size must hold before the renderer is remade at it.
const RESIZE_SETTLE: Duration = Duration::from_millis(300);

/// What a session starts from, known before the window opens.
pub struct Start {
    pub settings: Settings,
    pub dataset: Dataset,
    pub dataset_dir: PathBuf,
    pub path: Option<CameraPath>,
}

/// `--path` being flown: frame `next` of `frames`.
struct Autopilot {
    path: CameraPath,
    next: u32,
    frames: u32,
}

pub struct Viewer {
    pub screen: Screen,
    renderer: Renderer,
    adapter: String,
    dataset_dir: PathBuf,
    preset: String,
    flight: Flight,
    overlay: Overlay,
    /// R's overview, then the views Tab steps through.
    views: Vec<Camera>,
    view_index: usize,
    report: FrameReport,
    autopilot: Option<Autopilot>,
    recording: Option<Recording>,
    /// Along `--path`, per frame: wall time, the screen pass's GPU time (frame shown and
    /// overlay), the overlay's CPU time, ms.
    path_frame_ms: Vec<[f64; 3]>,
    started: Instant,
    /// The scene's time of the frames drawn now (wind, clouds), seconds.
    time_s: f64,
    last_frame: Instant,
    resize_since: Option<Instant>,
    drag_from: Option<(f64, f64)>,
    cursor: (f64, f64),
    message: String,
    presented_any: bool,
}

/// The dataset's overview: from beyond its south edge, high enough to see it all, looking north.
fn overview(dataset: &Dataset, settings: &Settings) -> Camera {
    let m = &dataset.manifest;
    let [w, h] = m.extent_m();
    let corner = m.corner_m();
    let span = w.max(h);
    Camera {
        position_m: DVec3::new(
            corner[0] + 0.5 * w,
            corner[1] - 0.25 * h,
            f64::from(m.height.max_m) + 0.45 * span,
        ),
        yaw_deg: 0.0,
        pitch_deg: -35.0,
        roll_deg: 0.0,
        fov_deg: settings.render.fov_deg,
        near_m: settings.render.near_m,
    }
}

impl Viewer {
    /// Opens the window, the GPU that presents to it and the renderer at its size.
    pub fn open(event_loop: &ActiveEventLoop, args: &ViewArgs, start: Start) -> Result<Self> {
        let attributes = winit::window::Window::default_attributes()
            .with_title(format!("terramp — {}", start.dataset_dir.display()))
            .with_inner_size(winit::dpi::LogicalSize::new(args.width, args.height));
        let window = Arc::new(event_loop.create_window(attributes).context("opening the window")?);
        let display = Box::new(event_loop.owned_display_handle());
        let (gpu, surface) = Gpu::for_surface(start.settings.gpu.adapter, display, Arc::clone(&window))?;
        let adapter = gpu.describe();
        eprintln!("terramp: adapter {adapter}");
        let mut settings = start.settings;
        let size = window.inner_size();
        (settings.render.width, settings.render.height) = (size.width.max(1), size.height.max(1));
        let renderer = Renderer::new(gpu.clone(), start.dataset, settings)?;
        crate::say_undrawn(&renderer);
        let screen = Screen::new(window, surface, &gpu, &renderer, !args.no_vsync)?;
        let home = overview(&renderer.dataset, &renderer.settings);
        let mut views = vec![home];
        if let Ok((path, _)) = terramp::profile::default_path(&renderer.dataset) {
            let r = &renderer.settings.render;
            let n = path.keys.len().max(2);
            views.extend((0..n).map(|i| path.camera_at(i as f64 / (n - 1) as f64, r.fov_deg, r.near_m)));
        }
        let [w, h] = renderer.dataset.manifest.extent_m();
        let mut overlay = Overlay::new();
        overlay.visible = !args.no_overlay;
        let now = Instant::now();
        Ok(Self {
            screen,
            adapter,
            dataset_dir: start.dataset_dir,
            preset: args.preset.clone(),
            flight: Flight::new(home, w.max(h)),
            overlay,
            views,
            view_index: 0,
            report: FrameReport::default(),
            autopilot: start.path.map(|path| Autopilot { path, next: 0, frames: args.path_frames.max(2) }),
            recording: None,
            path_frame_ms: Vec::new(),
            started: now,
            time_s: 0.0,
            last_frame: now,
            resize_since: None,
            drag_from: None,
            cursor: (0.0, 0.0),
            message: String::new(),
            presented_any: false,
            renderer,
        })
    }

    /// Handles a window event; `Ok(false)` closes the viewer.
    pub fn event(&mut self, event: &WindowEvent, args: &ViewArgs) -> Result<bool> {
        let taken = self.screen.input.on_window_event(&self.screen.window, event).consumed;
        match event {
            WindowEvent::CloseRequested => return Ok(false),
            WindowEvent::RedrawRequested => return self.frame(args),
            WindowEvent::Resized(_) | WindowEvent::ScaleFactorChanged { .. } => {
                self.screen.resized(&self.renderer.gpu);
                self.resize_since = Some(Instant::now());
            }
            WindowEvent::Focused(false) => self.flight.release_all(),
            WindowEvent::KeyboardInput { event, .. } if !taken || event.state == ElementState::Released => {
                if let PhysicalKey::Code(code) = event.physical_key
                    && !event.repeat
                    && let Some(action) = self.flight.key(code, event.state == ElementState::Pressed)
                {
                    return self.act(action, args);
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !taken => self.flight.scroll(match delta {
                MouseScrollDelta::LineDelta(_, y) => f64::from(*y),
                MouseScrollDelta::PixelDelta(p) => p.y / 40.0,
            }),
            WindowEvent::MouseInput { state, button: MouseButton::Left, .. } => {
                let over_overlay = self.screen.egui.is_pointer_over_egui();
                self.drag_from = (*state == ElementState::Pressed && !over_overlay).then_some(self.cursor);
            }
            WindowEvent::CursorMoved { position, .. } => {
                self.cursor = (position.x, position.y);
                if let Some((x, y)) = self.drag_from.replace(self.cursor) {
                    self.flight.drag(position.x - x, position.y - y);
                }
            }
            _ => {}
        }
        Ok(true)
    }

    /// One frame: move, render, show; then what was asked of the overlay.
    fn frame(&mut self, args: &ViewArgs) -> Result<bool> {
        let now = Instant::now();
        let dt_s = (now - self.last_frame).as_secs_f64();
        self.last_frame = now;
        self.resize_if_settled()?;
        let dataset = Arc::clone(&self.renderer.dataset);
        let origin = dataset.manifest.origin_m;
        let mut flying_path = false;
        if let Some(auto) = self.autopilot.as_mut() {
            let r = &self.renderer.settings.render;
            let t = f64::from(auto.next) / f64::from(auto.frames - 1);
            self.flight.camera = auto.path.camera_at(t, r.fov_deg, r.near_m);
            // The path's frames show the wind and clouds of `fly`'s and `profile`'s same frames.
            self.time_s = self.renderer.settings.wind.time_of_frame_s(auto.next as usize);
            auto.next += 1;
            flying_path = true;
        } else {
            let ground = |x: f64, y: f64| dataset.height_at(x - origin[0], y - origin[1], 0).ok();
            self.flight.step(dt_s, ground);
            self.time_s = self.started.elapsed().as_secs_f64();
        }
        self.renderer.set_time_s(self.time_s);
        if let Some(rec) = self.recording.as_mut() {
            rec.advance(dt_s, &self.flight.camera);
        }
        self.report = self.renderer.render(&self.flight.camera)?;
        self.flight.lifted(self.report.camera_lifted_m);
        self.overlay.record(dt_s * 1000.0, self.renderer.last_timings());
        if flying_path {
            let s = &self.screen;
            self.path_frame_ms.push([dt_s * 1000.0, s.pass_gpu_ms.unwrap_or(f64::NAN), s.overlay_cpu_ms]);
        }
        let shown = Shown {
            report: &self.report,
            timings: self.renderer.last_timings(),
            adapter: &self.adapter,
            camera: &self.flight.camera,
            speed_m_s: self.flight.moving_speed_m_s(),
            follow_m: self.flight.follow_m,
            by_height: self.flight.by_height,
            settings: &self.renderer.settings,
            preset: &self.preset,
            recording: self.recording.as_ref().map(Recording::len),
            message: &self.message,
            busy: self.resize_since.is_some(),
        };
        let overlay = &mut self.overlay;
        let presented = self.screen.present(&self.renderer.gpu, |ctx| overlay.ui(ctx, &shown))?;
        if presented.is_some() && !self.presented_any {
            self.presented_any = true;
            eprintln!("terramp: the window shows its first frame");
        }
        for request in presented.unwrap_or_default() {
            self.request(request, args)?;
        }
        if let Some(auto) = &self.autopilot
            && auto.next >= auto.frames
        {
            self.autopilot = None;
            if args.quit_after_path {
                return Ok(false);
            }
            // Said on stderr too, so a script can wait for it (scripts/docs_images.sh).
            eprintln!("terramp: path flown");
            self.message = "path flown: the controls are yours".into();
        }
        Ok(true)
    }

    /// The path's frame times, once a `--path` has been flown: one line.
    pub fn summary(&self) -> Option<String> {
        // The first frames compile shaders and fill the caches.
        let skip = (self.path_frame_ms.len() / 10).max(1);
        let flown = self.path_frame_ms.get(skip..).filter(|f| !f.is_empty())?;
        let column = |i: usize| flown.iter().map(|f| f[i]).collect::<Vec<f64>>();
        let median = |i: usize| stats::median(&column(i)).unwrap_or(f64::NAN);
        Some(format!(
            "view: {} frames along the path after {skip} warm-up, {}×{} px, overlay {}: median {:.1} ms, 95th \
             percentile {:.1} ms per frame; the screen's pass {:.2} ms on the GPU, the overlay {:.2} ms on the CPU",
            flown.len(),
            self.renderer.settings.render.width,
            self.renderer.settings.render.height,
            if self.overlay.visible { "shown" } else { "hidden" },
            median(0),
            stats::percentile(&column(0), 95.0).unwrap_or(f64::NAN),
            median(1),
            median(2),
        ))
    }

    fn resize_if_settled(&mut self) -> Result<()> {
        let Some(since) = self.resize_since else { return Ok(()) };
        if since.elapsed() < RESIZE_SETTLE {
            return Ok(());
        }
        self.resize_since = None;
        let [w, h] = self.screen.size_px();
        let r = &self.renderer.settings.render;
        if [r.width, r.height] != [w, h] {
            let start = Instant::now();
            match self.renderer.resize(w, h) {
                Ok(()) => {
                    self.screen.rebind(&self.renderer.gpu, &self.renderer);
                    self.message = format!("resized to {w}×{h} px in {:.2} s", start.elapsed().as_secs_f64());
                }
                Err(error) => self.message = format!("{w}×{h} px: {error}"),
            }
        }
        Ok(())
    }

    /// Remakes the renderer with `settings`, keeping the camera; a refusal is shown, not fatal.
    fn remake(&mut self, settings: Settings, what: &str) -> Result<()> {
        let start = Instant::now();
        match self.renderer.remake(settings) {
            Ok(()) => {
                self.screen.rebind(&self.renderer.gpu, &self.renderer);
                self.message =
                    format!("remade the renderer for {what} in {:.1} s", start.elapsed().as_secs_f64());
            }
            Err(error) => self.message = format!("{what}: {error}"),
        }
        Ok(())
    }

    fn request(&mut self, request: Request, args: &ViewArgs) -> Result<()> {
        match request {
            Request::CopyRenderLine => {
                let line = capture::render_line(
                    &self.dataset_dir,
                    &self.preset,
                    args.settings.as_deref(),
                    &self.flight.camera,
                    self.time_s,
                    &args.out.join("view.png"),
                );
                println!("{line}");
                self.screen.egui.copy_text(line);
                self.message = "render line copied (and printed)".into();
            }
            Request::ByHeight => self.flight.by_height = !self.flight.by_height,
            Request::GoTo(text) => {
                let r = &self.renderer.settings.render;
                match self.renderer.dataset.camera_from(&text, r.fov_deg, r.near_m) {
                    Ok(camera) => {
                        // The pose as written: ground-follow would move it to its own height.
                        self.flight.camera = camera;
                        self.flight.follow_m = None;
                        self.message = format!("went to {text}");
                    }
                    Err(error) => self.message = error.to_string(),
                }
            }
            Request::Follow => {
                let p = self.flight.camera.position_m;
                let origin = self.renderer.dataset.manifest.origin_m;
                let ground = self.renderer.dataset.height_at(p.x - origin[0], p.y - origin[1], 0).ok();
                self.flight.toggle_follow(ground);
            }
            Request::Preset(name) => {
                let mut settings = Settings::load(&name, args.settings.as_deref())?;
                let r = &self.renderer.settings;
                settings.render.width = r.render.width;
                settings.render.height = r.render.height;
                settings.draw_seeds.impostors.clone_from(&r.draw_seeds.impostors);
                settings.seeds.class_table.clone_from(&r.seeds.class_table);
                self.remake(settings, &format!("preset {name}"))?;
                self.preset = name;
            }
            Request::Knob { index, value } => {
                let knob = &KNOBS[index];
                let mut settings = self.renderer.settings.clone();
                (knob.set)(&mut settings, value);
                // A time of day over a dataset that does not say where on the Earth it lies is
                // refused here, with the reason, rather than by the next frame.
                let sun = terramp::sun::check(&settings.render, &self.renderer.dataset.manifest);
                if let Err(error) = settings.validate() {
                    self.message = error.to_string();
                } else if let Err(error) = sun {
                    self.message = error.to_string();
                } else if knob.apply == Apply::Live {
                    self.renderer.settings = settings;
                } else {
                    self.remake(settings, knob.label)?;
                }
            }
        }
        Ok(())
    }

    fn act(&mut self, action: Action, args: &ViewArgs) -> Result<bool> {
        match action {
            Action::Quit => return Ok(false),
            Action::Overlay => self.overlay.visible = !self.overlay.visible,
            Action::Reset => {
                self.autopilot = None;
                self.view_index = 0;
                self.flight.camera = self.views[0];
            }
            Action::NextView => {
                self.autopilot = None;
                self.view_index = (self.view_index + 1) % self.views.len();
                self.flight.camera = self.views[self.view_index];
            }
            Action::Screenshot => self.screenshot(args)?,
            Action::Record => match self.recording.take() {
                None => {
                    self.recording = Some(Recording::default());
                    self.message = "recording the path (P stops)".into();
                }
                Some(rec) => {
                    self.message = match rec.finish(&args.out, &self.flight.camera)? {
                        Some(file) => format!("path written: {}", file.display()),
                        None => "nothing flown: no path written".into(),
                    };
                }
            },
        }
        Ok(true)
    }

    /// F12: the view settled (every tile it needs resident), saved with its settings.
    fn screenshot(&mut self, args: &ViewArgs) -> Result<()> {
        self.renderer.render_resolved(&self.flight.camera)?;
        let image = self.renderer.read_colour()?;
        let shot = capture::Shot {
            dataset: &self.dataset_dir,
            preset: &self.preset,
            user_settings: args.settings.as_deref(),
            settings: &self.renderer.settings,
            camera: &self.flight.camera,
            time_s: self.time_s,
        };
        let (png, line) = capture::screenshot(&args.out, &image, &shot)?;
        println!("terramp: screenshot {}; the same view headless: {line}", png.display());
        self.message = format!("saved {}", png.display());
        Ok(())
    }
}
