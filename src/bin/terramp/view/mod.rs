//! How it works: `terramp view`, a window over a dataset. winit runs the event loop; on its first
//! `resumed` the window opens, the GPU is chosen among the adapters that can present to it, and
//! the renderer is made at the window's size. Every redraw: the flight (or `--path`) moves the
//! camera by the time elapsed, the renderer draws a frame as headless commands do, and the screen
//! shows it under the overlay. Input goes to egui first; what it does not take flies the camera.
//! Knobs that need new GPU resources and a new preset remake the renderer on the same device,
//! keeping the camera; a new window size resizes it (`Renderer::resize`: its tiles stay), once
//! the size has held still a moment.
//! Every failure is one line and a non-zero exit: no display, no adapter, a dataset that does not
//! open, a frame that fails. What the window needs (an adapter, then the display) is checked
//! before the embedded default is synthesized and its trees baked, which takes minutes.

mod capture;
mod flight;
mod overlay;
mod screen;
mod viewer;

use std::path::PathBuf;

use anyhow::{Context, Result, anyhow};
use clap::Args;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::WindowId;

use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::gpu::Gpu;

use crate::demo;

/// `terramp view`'s options.
#[derive(Args)]
pub struct ViewArgs {
    /// The dataset. Without it: the embedded default (synthesized and its impostors baked when
    /// missing, as `terramp demo` does).
    #[arg(long)]
    dataset: Option<PathBuf>,
    /// Preset: fast, balanced or accurate (switchable in the overlay).
    #[arg(long, default_value = "balanced")]
    preset: String,
    /// A TOML file overriding settings (see config/default.toml).
    #[arg(long)]
    settings: Option<PathBuf>,
    /// Fly this camera path (config/paths/*.toml) first, then hand the controls over.
    #[arg(long)]
    path: Option<PathBuf>,
    /// Frames the path is flown in (as `fly --frames` and `profile --frames`).
    #[arg(long, default_value_t = 600)]
    path_frames: u32,
    /// Close when the path ends, printing the frame times (for measurements).
    #[arg(long, requires = "path")]
    quit_after_path: bool,
    /// Start with the overlay hidden (H or F1 shows it).
    #[arg(long)]
    no_overlay: bool,
    /// Present as fast as frames come rather than at the display's refresh.
    #[arg(long)]
    no_vsync: bool,
    /// The window's size at the start, logical pixels.
    #[arg(long, default_value_t = 1280)]
    width: u32,
    #[arg(long, default_value_t = 720)]
    height: u32,
    /// Where screenshots (F12) and recorded paths (P) go.
    #[arg(long, default_value = "out/view")]
    out: PathBuf,
    /// For the embedded default only: its folder, and where its impostors are baked from and to.
    #[arg(long, default_value = "data/default")]
    default_dataset: PathBuf,
    #[arg(long, default_value = "data/impostors")]
    impostors: PathBuf,
    #[arg(long, default_value = "../shared/data/models")]
    models: PathBuf,
}

/// Opens the window and flies until it is closed.
pub fn run(args: ViewArgs) -> Result<()> {
    let settings = Settings::load(&args.preset, args.settings.as_deref())?;
    let given = match &args.dataset {
        Some(dir) => {
            let dataset =
                Dataset::open(dir).with_context(|| format!("cannot open the dataset {}", dir.display()))?;
            Some((dataset, dir.clone()))
        }
        None => None,
    };
    // Keyframes on the Earth are placed in the dataset given (the embedded default does not say
    // where it lies: they are refused there).
    let path = match (args.path.as_deref(), &given) {
        (Some(file), Some((dataset, _))) => Some(terramp::profile::load_path(dataset, file)?),
        (Some(file), None) => Some(terramp::path::CameraPath::load(file)?),
        (None, _) => None,
    };
    // The window's needs first: the embedded default is minutes of work, no use without them.
    Gpu::probe(settings.gpu.adapter).context("terramp view needs a GPU adapter")?;
    let event_loop = EventLoop::new().map_err(|e| {
        let unset = ["DISPLAY", "WAYLAND_DISPLAY"].iter().all(|v| std::env::var_os(v).is_none());
        let why = if unset { "neither DISPLAY nor WAYLAND_DISPLAY is set".to_owned() } else { e.to_string() };
        anyhow!(
            "no display to open a window on ({why}): terramp view needs X11 or Wayland; headless, use \
             terramp render, fly or profile"
        )
    })?;
    let (settings, dataset, dataset_dir) = match given {
        Some((dataset, dir)) => (settings, dataset, dir),
        None => {
            let prepared = demo::prepare(&demo::Prepare {
                dataset: &args.default_dataset,
                impostors: &args.impostors,
                models: &args.models,
                preset: &args.preset,
                settings_file: args.settings.as_deref(),
            })?;
            (prepared.0, prepared.1, args.default_dataset.clone())
        }
    };
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        args,
        start: Some(viewer::Start { settings, dataset, dataset_dir, path }),
        viewer: None,
        error: None,
    };
    event_loop.run_app(&mut app).context("the window's event loop failed")?;
    match app.error {
        Some(error) => Err(error),
        None => Ok(()),
    }
}

struct App {
    args: ViewArgs,
    /// What the viewer starts from, until the window opens.
    start: Option<viewer::Start>,
    viewer: Option<viewer::Viewer>,
    error: Option<anyhow::Error>,
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.error.get_or_insert(error);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(start) = self.start.take() else { return };
        match viewer::Viewer::open(event_loop, &self.args, start) {
            Ok(viewer) => self.viewer = Some(viewer),
            Err(error) => self.fail(event_loop, error),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(viewer) = self.viewer.as_mut() else { return };
        match viewer.event(&event, &self.args) {
            Ok(true) => {}
            Ok(false) => {
                if let Some(summary) = viewer.summary() {
                    println!("{summary}");
                }
                event_loop.exit();
            }
            Err(error) => self.fail(event_loop, error),
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(viewer) = &self.viewer {
            viewer.screen.window.request_redraw();
        }
    }
}
