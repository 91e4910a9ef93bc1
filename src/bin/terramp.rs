//! The `terramp` command line: render a frame of a dataset, fly the demo or a path, profile the
//! passes, measure the speed trade, render the ground truth, measure a view against its
//! photograph, describe a dataset.

// Under `terramp/`, not beside this file: every `src/bin/*.rs` is a binary of its own.
#[path = "terramp/demo.rs"]
mod demo;

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::{Gpu, PassTiming};
use terramp::profile::{Meta, Summary};

// Crate roots look for modules beside themselves: this one keeps its own in src/bin/terramp/.
#[path = "terramp/info.rs"]
mod info;
#[path = "terramp/photo.rs"]
mod photo;
#[path = "terramp/sweep.rs"]
mod sweep;
#[path = "terramp/truth.rs"]
mod truth;
#[cfg(feature = "viewer")]
#[path = "terramp/view/mod.rs"]
mod view;

#[derive(Parser)]
#[command(
    name = "terramp",
    version,
    about = "GPU terrain amplification: stream a DEM with imagery and render it"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Args)]
struct SettingsArgs {
    /// Preset: fast, balanced or accurate.
    #[arg(long, default_value = "balanced")]
    preset: String,
    /// A TOML file overriding settings (see config/default.toml for every key).
    #[arg(long)]
    settings: Option<PathBuf>,
    /// The date and time the sun stands at over the place under the camera (`render.sun_time`):
    /// RFC 3339, e.g. 2026-06-21T17:30Z. Needs a dataset that records where it lies on the Earth.
    #[arg(long)]
    time: Option<String>,
}

impl SettingsArgs {
    fn load(&self) -> Result<Settings> {
        let mut settings = Settings::load(&self.preset, self.settings.as_deref())?;
        if let Some(time) = &self.time {
            settings.render.sun_time.clone_from(time);
        }
        Ok(settings)
    }
}

/// One view of a dataset: which, from where, through what viewport, with what settings.
#[derive(Args)]
struct ViewArgs {
    #[arg(long)]
    dataset: PathBuf,
    /// X,Y,Z,YAW,PITCH[,ROLL]: position in the dataset CRS (metres; Z above the datum), compass
    /// heading from the grid's north, pitch above the horizon and roll (right side down; 0 if
    /// left out) (degrees). E.g. `--camera 636000,214000,900,0,-20`. Or on the Earth (datasets whose manifest records where they
    /// lie): `lonlat:LON,LAT,H,HEADING,PITCH` (WGS 84 degrees, H metres above its ellipsoid,
    /// heading from true north), `lonlat-ground:LON,LAT,H,HEADING,PITCH` (H above the ground).
    #[arg(long, allow_hyphen_values = true)]
    camera: String,
    /// Vertical field of view, degrees.
    #[arg(long)]
    fov: Option<f64>,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// The scene's time, seconds: where the wind's sway and the clouds are (`terramp view`'s
    /// screenshots give theirs).
    #[arg(long, default_value_t = 0.0)]
    time_s: f64,
    #[command(flatten)]
    settings: SettingsArgs,
}

impl ViewArgs {
    /// The settings with the view's overrides, and the camera.
    fn load(&self) -> Result<(Settings, Camera)> {
        let mut settings = self.settings.load()?;
        let r = &mut settings.render;
        r.fov_deg = self.fov.unwrap_or(r.fov_deg);
        r.width = self.width.unwrap_or(r.width);
        r.height = self.height.unwrap_or(r.height);
        let camera = Dataset::open(&self.dataset)?.camera_from(&self.camera, r.fov_deg, r.near_m)?;
        Ok((settings, camera))
    }
}

#[derive(Subcommand)]
enum Command {
    /// Fly over a dataset in a window, with a live per-pass profiler and the speed knobs (without
    /// --dataset: the embedded default). Controls: mouse drag to look, WASD/arrows to move, E/Q
    /// or Space/Ctrl up/down, scroll or +/- for speed, Shift to boost, R overview, Tab next
    /// view, F12 screenshot, P record the path, H overlay, Esc quit.
    #[cfg(feature = "viewer")]
    View(view::ViewArgs),
    /// Render one frame of a dataset to a PNG.
    Render {
        #[command(flatten)]
        view: ViewArgs,
        #[arg(long)]
        out: PathBuf,
    },
    /// The main job on the embedded default: synthesize the default dataset and bake the
    /// species' impostors if missing, then fly over it with seeds drawn, write the frames and
    /// the profile table (`profile.txt`, `profile.json`).
    Demo {
        /// Where the default dataset lives (created when missing).
        #[arg(long, default_value = "data/default")]
        dataset: PathBuf,
        /// Folder for the frames and the profile.
        #[arg(long, default_value = "out/demo")]
        out: PathBuf,
        #[arg(long, default_value_t = 24)]
        frames: u32,
        /// Frames rendered first at the start, neither written nor profiled.
        #[arg(long, default_value_t = 4)]
        warmup: u32,
        /// Impostor folder (baked there when a species' model is missing: generated trees by the
        /// generator, others from --models), unless the settings name one (`draw_seeds.impostors`).
        #[arg(long, default_value = "data/impostors")]
        impostors: PathBuf,
        /// The glTF models (.glb) the class table's species name, unless generated trees: the
        /// demo's default table (`nc-generated`) needs none; `seeds.class_table = "nc"` in a
        /// settings file draws the shared models instead.
        #[arg(long, default_value = "../shared/data/models")]
        models: PathBuf,
        #[command(flatten)]
        settings: SettingsArgs,
    },
    /// The ground truth of one view: every seed the land cover grows, as its full mesh, every
    /// tile at its finest level, supersampled, with a per-sample seed id and depth.
    Truth(truth::TruthArgs),
    /// One view's amplified frame against its photograph frame (the same settings with nothing
    /// grown: the imagery on the terrain alone): CIEDE2000 of mean colours per imagery texel
    /// footprint and per 5 × 5 block, detail, the share of wooded pixels changed.
    Photo(photo::PhotoArgs),
    /// Fly a camera path (config/paths/*.toml) and write the frames and a log: one JSON object per
    /// frame in `log.jsonl` (tiles needed, resident, uploaded, evicted, failed, bytes uploaded;
    /// seeds checked, selected, culled by class, rule, distance, frustum and occlusion, overflow;
    /// pass timings, process memory).
    Fly {
        #[arg(long)]
        dataset: PathBuf,
        #[arg(long)]
        path: PathBuf,
        #[arg(long, default_value_t = 120)]
        frames: u32,
        #[arg(long)]
        out: PathBuf,
        /// Write every Nth frame as PNG (0: none; the log always has every frame).
        #[arg(long, default_value_t = 1)]
        save_every: u32,
        #[arg(long)]
        width: Option<u32>,
        #[arg(long)]
        height: Option<u32>,
        #[command(flatten)]
        settings: SettingsArgs,
    },
    /// Time every pass along a camera path: after warm-up frames, the median and 95th percentile
    /// of each GPU pass (timestamp queries) and of the CPU work, seeds checked and selected per
    /// frame, frames per second; printed as a table like the paper's Table 1, optionally as JSON
    /// and as a Chrome trace (chrome://tracing, Perfetto).
    Profile {
        #[arg(long)]
        dataset: PathBuf,
        /// Camera path (config/paths/*.toml). Default: config/paths/default.toml on a synthetic
        /// dataset that holds all its keyframes (the default one), else an orbit around the centre.
        #[arg(long)]
        path: Option<PathBuf>,
        /// Profiled frames, spread evenly along the path.
        #[arg(long, default_value_t = 240)]
        frames: u32,
        /// Frames rendered first, unprofiled, at the path's start (caches fill, shaders compile).
        #[arg(long, default_value_t = 30)]
        warmup: u32,
        #[arg(long)]
        width: Option<u32>,
        #[arg(long)]
        height: Option<u32>,
        /// Write the figures as JSON (schema in the `terramp::profile::summary` docs).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Write a Chrome trace (Trace Event Format JSON) of the profiled frames.
        #[arg(long)]
        trace: Option<PathBuf>,
        /// Write one JSON object per frame (warm-up included), as `fly` does in `log.jsonl`.
        #[arg(long)]
        log: Option<PathBuf>,
        #[command(flatten)]
        settings: SettingsArgs,
    },
    /// Measure the speed trade: fly the same path with every preset (and knob value), timing each
    /// pass in interleaved rounds, then at sample poses judge each against the ground truth of its
    /// own world (any-part recall, precision and pixel-weighted recall; frame PSNR, SSIM, FLIP and
    /// forest cover, whole and per distance band; popping) and the exact summit oracle (recall,
    /// precision, height error). Writes trade.csv, trade.json, trade.png and trade.md (Markdown
    /// tables) into --out and prints a table.
    Sweep(sweep::SweepArgs),
    /// Describe a dataset: frame, extent, layers.
    Info {
        #[arg(long)]
        dataset: PathBuf,
    },
}

fn main() -> Result<()> {
    // SAFETY: first thing in main, before any thread starts.
    unsafe { terramp::gpu::skip_device_select_layer() };
    match Cli::parse().command {
        Command::Render { view, out } => {
            let (settings, camera) = view.load()?;
            render_one(&view.dataset, settings, &camera, view.time_s, &out)
        }
        Command::Demo { dataset, out, frames, warmup, impostors, models, settings } => {
            demo::run(&demo::DemoArgs {
                dataset,
                out,
                frames,
                warmup,
                impostors,
                models,
                preset: settings.preset,
                settings_file: settings.settings,
            })
        }
        Command::Fly { dataset, path, frames, out, save_every, width, height, settings } => {
            let mut settings = settings.load()?;
            settings.render.width = width.unwrap_or(settings.render.width);
            settings.render.height = height.unwrap_or(settings.render.height);
            fly(&dataset, &path, frames, &out, save_every, settings)
        }
        Command::Profile { dataset, path, frames, warmup, width, height, json, trace, log, settings } => {
            let outputs = ProfileOutputs { json, trace, log };
            profile(&dataset, path.as_deref(), frames, warmup, (width, height), &settings, &outputs)
        }
        #[cfg(feature = "viewer")]
        Command::View(args) => view::run(args),
        Command::Sweep(args) => args.run(),
        Command::Truth(args) => args.run(),
        Command::Photo(args) => args.run(),
        Command::Info { dataset } => info::run(&dataset),
    }
}

struct ProfileOutputs {
    json: Option<PathBuf>,
    trace: Option<PathBuf>,
    log: Option<PathBuf>,
}

fn profile(
    dataset_dir: &Path,
    path: Option<&Path>,
    frames: u32,
    warmup: u32,
    (width, height): (Option<u32>, Option<u32>),
    settings_args: &SettingsArgs,
    outputs: &ProfileOutputs,
) -> Result<()> {
    if frames == 0 {
        bail!("--frames must be at least 1");
    }
    let mut settings = settings_args.load()?;
    settings.render.width = width.unwrap_or(settings.render.width);
    settings.render.height = height.unwrap_or(settings.render.height);
    let dataset = Dataset::open(dataset_dir)?;
    let (path, path_name) = match path {
        Some(file) => (terramp::profile::load_path(&dataset, file)?, file.display().to_string()),
        None => terramp::profile::default_path(&dataset)?,
    };
    let gpu = Gpu::new(settings.gpu.adapter)?;
    let adapter = gpu.describe();
    eprintln!("terramp: adapter {adapter}");
    let mut renderer = Renderer::new(gpu, dataset, settings)?;
    say_undrawn(&renderer);
    let (timing, timing_note) = terramp::profile::timing_of(&renderer);
    let mut log = match &outputs.log {
        Some(file) => Some(std::io::BufWriter::new(
            std::fs::File::create(file).with_context(|| format!("creating {}", file.display()))?,
        )),
        None => None,
    };
    eprintln!("terramp: {warmup} warm-up frames, then {frames} profiled frames along {path_name}");
    let log_writer = log.as_mut().map(|w| w as &mut dyn std::io::Write);
    let recording = terramp::profile::fly(&mut renderer, &path, warmup, frames, log_writer)?;
    if let Some(log) = log.as_mut() {
        std::io::Write::flush(log)?;
    }
    let s = &renderer.settings.render;
    let meta = Meta {
        adapter,
        timing,
        timing_note,
        resolution: [s.width, s.height],
        preset: settings_args.preset.clone(),
        settings: settings_args.settings.as_ref().map(|f| f.display().to_string()),
        dataset: dataset_dir.display().to_string(),
        path: path_name,
        warmup,
    };
    let summary = Summary::new(&recording, meta);
    print!("{}", terramp::profile::table::render(&summary));
    if let Some(file) = &outputs.json {
        std::fs::write(file, summary.to_json()).with_context(|| format!("writing {}", file.display()))?;
    }
    if let Some(file) = &outputs.trace {
        terramp::profile::trace::write(file, &recording, &summary.meta)?;
    }
    Ok(())
}

/// Says which seeds `renderer` selects but cannot draw, if any: a frame shows no sign of them.
fn say_undrawn(renderer: &Renderer) {
    if let Some(undrawn) = renderer.undrawn_seeds() {
        eprintln!("terramp: {undrawn}");
    }
}

fn open_renderer(dataset_dir: &Path, settings: Settings) -> Result<Renderer> {
    let dataset = Dataset::open(dataset_dir)?;
    let gpu = Gpu::new(settings.gpu.adapter)?;
    eprintln!("terramp: adapter {}", gpu.describe());
    let renderer = Renderer::new(gpu, dataset, settings)?;
    say_undrawn(&renderer);
    let unbaked = renderer.texcell_classes_unbaked();
    if !unbaked.is_empty() {
        eprintln!(
            "terramp: dense classes {unbaked:?} have no forest sample in draw_seeds.impostors: no texcells there \
             (terramp-data bake --classes SCHEME --models DIR --out IMPOSTORS)"
        );
    }
    Ok(renderer)
}

fn render_one(
    dataset_dir: &Path,
    settings: Settings,
    camera: &Camera,
    time_s: f64,
    out: &Path,
) -> Result<()> {
    let mut renderer = open_renderer(dataset_dir, settings)?;
    renderer.set_time_s(time_s);
    let start = Instant::now();
    // One finished picture: keep rendering while tiles stream in.
    let (report, frames) = renderer.render_resolved(camera)?;
    let image = renderer.read_colour()?;
    let elapsed = start.elapsed();
    save_png(&image, out)?;
    let drained = renderer.profiler.drain(&renderer.gpu)?;
    println!(
        "{}: {} nodes, {} TLM cells visible, {} height + {} imagery tiles resident, resolved in {frames} frames, {:.0} ms (shaders compiled on first use)",
        out.display(),
        report.nodes_drawn,
        report.tlm_visible_cells,
        report.height.needed_resident,
        report.imagery.needed_resident,
        elapsed.as_secs_f64() * 1000.0
    );
    print_timings(drained.last().map(Vec::as_slice).unwrap_or(renderer.last_timings()));
    Ok(())
}

fn save_png(image: &image::RgbaImage, out: &Path) -> Result<()> {
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent).with_context(|| format!("creating {}", parent.display()))?;
    }
    image.save(out).with_context(|| format!("writing {}", out.display()))
}

fn print_timings(timings: &[PassTiming]) {
    for t in timings {
        println!("  {:<16} {:>8.2} ms  ({:?})", t.label, t.ms, t.source);
    }
}

fn fly(
    dataset_dir: &Path,
    path_file: &Path,
    frames: u32,
    out: &Path,
    save_every: u32,
    settings: Settings,
) -> Result<()> {
    if frames == 0 {
        bail!("--frames must be at least 1");
    }
    let mut renderer = open_renderer(dataset_dir, settings)?;
    let path = terramp::profile::load_path(&renderer.dataset, path_file)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let log_path = out.join("log.jsonl");
    let mut log = std::io::BufWriter::new(
        std::fs::File::create(&log_path).with_context(|| format!("creating {}", log_path.display()))?,
    );
    let mut frame_ms = Vec::with_capacity(frames as usize);
    for i in 0..frames {
        let r = &renderer.settings.render;
        let camera = path.camera_at(f64::from(i) / f64::from(frames.max(2) - 1), r.fov_deg, r.near_m);
        let time_s = renderer.settings.wind.time_of_frame_s(i as usize);
        renderer.set_time_s(time_s);
        let start = Instant::now();
        let report = match renderer.render(&camera) {
            Ok(report) => report,
            Err(error) => {
                // A failed frame (a lost device, say) stops the flight with what it logged kept.
                std::io::Write::flush(&mut log)?;
                let logged = format!("{i} frames logged in {}", log_path.display());
                return Err(anyhow::Error::new(error).context(format!("frame {i} of the flight ({logged})")));
            }
        };
        let save = save_every != 0 && i % save_every == 0;
        if save {
            save_png(&renderer.read_colour()?, &out.join(format!("frame_{i:04}.png")))?;
        }
        let ms = start.elapsed().as_secs_f64() * 1000.0;
        frame_ms.push(ms);
        let record = serde_json::json!({
            "frame": i,
            "camera": { "x_m": camera.position_m.x, "y_m": camera.position_m.y, "z_m": camera.position_m.z,
                        "yaw_deg": camera.yaw_deg, "pitch_deg": camera.pitch_deg },
            "report": report,
            "wall_ms": ms,
            "saved_png": save,
            // GPU timings arrive a few frames late: these are the latest complete ones.
            "passes": renderer.last_timings(),
            "resident_kib": status_kib("VmRSS:"),
            "anonymous_kib": status_kib("RssAnon:"),
        });
        serde_json::to_writer(&mut log, &record)?;
        std::io::Write::write_all(&mut log, b"\n")?;
    }
    std::io::Write::flush(&mut log)?;
    frame_ms.sort_by(f64::total_cmp);
    println!(
        "{frames} frames, log in {}: median {:.1} ms, 95th percentile {:.1} ms per frame (render{})",
        log_path.display(),
        frame_ms[frame_ms.len() / 2],
        frame_ms[(frame_ms.len() * 95 / 100).min(frame_ms.len() - 1)],
        if save_every > 0 { " + PNG of saved frames" } else { "" }
    );
    Ok(())
}

/// A figure of the process's memory from Linux's `/proc/self/status` (`VmRSS:`, `RssAnon:`), KiB.
fn status_kib(key: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(key))?;
    line.split_whitespace().nth(1)?.parse().ok()
}
