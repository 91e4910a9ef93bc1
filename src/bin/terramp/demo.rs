//! How it works: `terramp demo`, the main job on the embedded default. The default dataset is
//! synthesized when missing (or of a format this build no longer reads); its seeds grow from the
//! built-in table of generated trees for its scheme (`nc-generated`), unless the settings name a
//! class table (`seeds.class_table = "nc"` for the shared models), and the models that table names
//! are baked into impostors the first time (generated trees by the generator, others from
//! `--models`), so seeds are drawn on a clone with nothing beside it; then a straight flight
//! across the dataset is rendered through a profiling session: a few warm-up frames at its start,
//! then every frame written as PNG and timed, and the profile table (per pass: median and 95th
//! percentile) printed and written beside the frames (`profile.txt`, `profile.json`). Without models the flight still runs, its seeds
//! selected but not drawn, and says so.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail};
use glam::DVec3;

use terramp::camera::Camera;
use terramp::classes::ClassTable;
use terramp::config::Settings;
use terramp::dataset::{Dataset, DatasetError, PackError};
use terramp::frame::Renderer;
use terramp::gpu::Gpu;
use terramp::profile::{Meta, Session, Summary};

pub struct DemoArgs {
    pub dataset: PathBuf,
    pub out: PathBuf,
    pub frames: u32,
    pub warmup: u32,
    pub impostors: PathBuf,
    pub models: PathBuf,
    pub preset: String,
    pub settings_file: Option<PathBuf>,
}

pub fn run(args: &DemoArgs) -> Result<()> {
    if args.frames == 0 {
        bail!("--frames must be at least 1");
    }
    let (settings, dataset) = prepare(&Prepare {
        dataset: &args.dataset,
        impostors: &args.impostors,
        models: &args.models,
        preset: &args.preset,
        settings_file: args.settings_file.as_deref(),
    })?;
    let gpu = Gpu::new(settings.gpu.adapter)?;
    let adapter = gpu.describe();
    eprintln!("terramp: adapter {adapter}");
    let mut renderer = Renderer::new(gpu, dataset, settings)?;
    crate::say_undrawn(&renderer);
    std::fs::create_dir_all(&args.out).with_context(|| format!("creating {}", args.out.display()))?;
    let path = DemoPath::over(&renderer.dataset);
    let cameras: Vec<Camera> = (0..args.frames)
        .map(|i| path.camera(&renderer, f64::from(i) / f64::from(args.frames.max(2) - 1)))
        .collect::<Result<_>>()?;
    let (timing, timing_note) = terramp::profile::timing_of(&renderer);

    let mut session = Session::new(&mut renderer, args.warmup);
    for _ in 0..args.warmup {
        session.frame(&cameras[0])?;
    }
    let mut frame_ms = Vec::new();
    for (i, camera) in cameras.iter().enumerate() {
        let start = Instant::now();
        let report = session.frame(camera)?;
        let image = session.renderer().read_colour()?;
        let file = args.out.join(format!("frame_{i:04}.png"));
        image.save(&file).with_context(|| format!("writing {}", file.display()))?;
        frame_ms.push(start.elapsed().as_secs_f64() * 1000.0);
        let seeds = report.seeds.as_ref().map_or(0, |s| s.counters.selected);
        println!(
            "frame {i:>3}: {:>4} nodes, uploaded {:>3} height / {:>3} imagery tiles, {seeds:>7} seeds, {:>7.1} ms",
            report.nodes_drawn,
            report.height.uploaded,
            report.imagery.uploaded,
            frame_ms.last().copied().unwrap_or_default()
        );
    }
    let recording = session.finish()?;
    let s = &renderer.settings;
    let meta = Meta {
        adapter,
        timing,
        timing_note,
        resolution: [s.render.width, s.render.height],
        preset: args.preset.clone(),
        settings: args.settings_file.as_ref().map(|f| f.display().to_string()),
        dataset: args.dataset.display().to_string(),
        path: "demo: a straight flight across the dataset, 120 m up".into(),
        warmup: args.warmup,
    };
    let summary = Summary::new(&recording, meta);
    let table = terramp::profile::table::render(&summary);
    print!("{table}");
    for (name, text) in [("profile.txt", table), ("profile.json", summary.to_json())] {
        let file = args.out.join(name);
        std::fs::write(&file, text).with_context(|| format!("writing {}", file.display()))?;
    }
    frame_ms.sort_by(f64::total_cmp);
    println!(
        "{} frames in {}: median {:.1} ms per frame (render + readback + PNG); profile.txt, profile.json",
        args.frames,
        args.out.display(),
        frame_ms[frame_ms.len() / 2]
    );
    Ok(())
}

/// Where the embedded default lives and is baked from, and the settings asked for.
pub struct Prepare<'a> {
    pub dataset: &'a Path,
    pub impostors: &'a Path,
    pub models: &'a Path,
    pub preset: &'a str,
    pub settings_file: Option<&'a Path>,
}

/// The embedded default ready to fly: the dataset (synthesized if missing), and the settings with
/// its generated trees' class table and the impostor folder (baked if missing), unless the
/// settings name others.
pub fn prepare(p: &Prepare) -> Result<(Settings, Dataset)> {
    let mut settings = Settings::load(p.preset, p.settings_file)?;
    ensure_dataset(p.dataset)?;
    let dataset = Dataset::open(p.dataset)?;
    let scheme = dataset.manifest.landcover.as_ref().map(|l| l.scheme.as_str());
    if let (true, Some(table)) =
        (settings.seeds.class_table.is_empty(), scheme.and_then(ClassTable::generated_for))
    {
        eprintln!("terramp: seeds grow from the class table {table} (generated trees)");
        settings.seeds.class_table = table.to_string();
    }
    if settings.draw_seeds.impostors.is_empty() {
        let baked = ensure_impostors(&dataset, &settings, p.impostors, p.models)?;
        settings.draw_seeds.impostors = baked.map(|d| d.display().to_string()).unwrap_or_default();
    }
    Ok((settings, dataset))
}

/// The default dataset is ours to make: synthesized when missing, or when made by a build whose
/// format this one no longer reads.
fn ensure_dataset(dir: &Path) -> Result<()> {
    match Dataset::open(dir) {
        Ok(_) => Ok(()),
        Err(
            error @ (DatasetError::NotADataset { .. }
            | DatasetError::Version { .. }
            | DatasetError::Pack(PackError::Version { .. })),
        ) => {
            eprintln!("terramp: {error}; synthesizing the default dataset at {}", dir.display());
            let start = Instant::now();
            terramp::synth::synthesize(dir, &terramp::synth::SynthParams::default(), true)?;
            eprintln!("terramp: synthesized in {:.1} s", start.elapsed().as_secs_f64());
            Ok(())
        }
        Err(error) => Err(error.into()),
    }
}

/// The impostor folder holding every model the dataset's class table names, baking the missing
/// ones from `models`; `None` (seeds not drawn) when the dataset has no land cover or no model
/// can be found.
fn ensure_impostors(
    dataset: &Dataset,
    settings: &Settings,
    dir: &Path,
    models: &Path,
) -> Result<Option<PathBuf>> {
    let Some(landcover) = &dataset.manifest.landcover else { return Ok(None) };
    let name = match settings.seeds.class_table.as_str() {
        "" => landcover.scheme.as_str(),
        name => name,
    };
    let table = ClassTable::load(name)?;
    let wanted: Vec<&str> = table.species.iter().map(|s| s.model.as_str()).collect();
    if wanted.iter().all(|m| terramp::impostor::is_current(dir, m)) {
        return Ok(Some(dir.to_path_buf()));
    }
    eprintln!("terramp: baking the missing impostors into {} (once)", dir.display());
    let start = Instant::now();
    let options = terramp::bake::BakeOptions::default();
    let missing = terramp::bake::bake_missing(None, models, &wanted, dir, &options, true)?;
    for path in &missing.absent {
        eprintln!("terramp: no model {} (--models): its species are selected but not drawn", path.display());
    }
    eprintln!("terramp: baked {} in {:.1} s", missing.baked.len(), start.elapsed().as_secs_f64());
    let any = wanted.iter().any(|m| terramp::impostor::is_current(dir, m));
    Ok(any.then(|| dir.to_path_buf()))
}

/// A straight flight across the dataset's middle, 120 m above the highest ground near the line,
/// looking ahead and down.
struct DemoPath {
    start_m: DVec3,
    end_m: DVec3,
}

impl DemoPath {
    fn over(dataset: &Dataset) -> Self {
        let m = &dataset.manifest;
        let [w, h] = m.extent_m();
        let corner = m.corner_m();
        let at = |fx: f64, fy: f64| DVec3::new(corner[0] + fx * w, corner[1] + fy * h, 0.0);
        Self { start_m: at(0.15, 0.2), end_m: at(0.75, 0.7) }
    }

    fn camera(&self, renderer: &Renderer, t: f64) -> Result<Camera> {
        let m = &renderer.dataset.manifest;
        let position = self.start_m.lerp(self.end_m, t);
        let ahead = (self.end_m - self.start_m).normalize();
        // Clearance over the ground below and a little ahead, so the camera never dives into a hill.
        let mut ground_m = f64::MIN;
        for step in 0..8 {
            let probe = position + ahead * f64::from(step) * 40.0;
            let grid = [probe.x - m.origin_m[0], probe.y - m.origin_m[1]];
            ground_m = ground_m.max(renderer.dataset.height_at(grid[0], grid[1], 0)?);
        }
        let yaw_deg = ahead.x.atan2(ahead.y).to_degrees();
        let r = &renderer.settings.render;
        Ok(Camera {
            position_m: DVec3::new(position.x, position.y, ground_m + 120.0),
            yaw_deg,
            pitch_deg: -12.0,
            roll_deg: 0.0,
            fov_deg: r.fov_deg,
            near_m: r.near_m,
        })
    }
}
