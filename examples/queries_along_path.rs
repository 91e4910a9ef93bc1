//! A headless host: the ground and the plants along a straight walk across a dataset, asked of
//! terramp on the CPU, with no frame drawn and no window.
//!
//! How it works: a renderer is made on a headless device (`Gpu::new`), which is what holds the
//! dataset, the settings and the seeded world; the queries themselves read the dataset's packs
//! and never touch the GPU. At each point of the walk it asks the finest ground's height and
//! normal (`ground_at`), the land-cover class (`land_cover_at`) and every plant grown within a
//! radius, seen or not (`plants_near` with `Plants::Grown`: what a walker would collide with),
//! from a walker's eye 1.7 m above the ground looking along the walk, and prints one CSV row (the position as f64 writes it, to read back exactly).
//!
//! ```text
//! cargo run --example queries_along_path -- [DATASET] [--points N] [--radius M]
//! ```
//!
//! Without a dataset it synthesises a small one into the system's temporary directory first.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use terramp::host::glam::{DVec2, DVec3};
use terramp::host::{
    AdapterChoice, Camera, Dataset, Gpu, Plants, Renderer, Settings, SynthParams, synthesize,
};

/// A walker's eye above the ground, metres.
const EYE_M: f64 = 1.7;

struct Args {
    dataset: Option<PathBuf>,
    points: usize,
    radius_m: f64,
}

fn parse_args() -> Result<Args> {
    let mut args = Args { dataset: None, points: 20, radius_m: 20.0 };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().with_context(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--points" => args.points = value("--points")?.parse().context("--points: a whole number")?,
            "--radius" => args.radius_m = value("--radius")?.parse().context("--radius: metres")?,
            flag if flag.starts_with("--") => bail!("unknown option {flag}"),
            path => args.dataset = Some(PathBuf::from(path)),
        }
    }
    if args.points < 2 {
        bail!("--points: at least 2 (the walk's ends)");
    }
    if !(args.radius_m.is_finite() && args.radius_m > 0.0) {
        bail!("--radius: a positive number of metres");
    }
    Ok(args)
}

fn main() -> Result<()> {
    let args = parse_args()?;
    let Some(dir) = args.dataset else {
        let dir = std::env::temp_dir().join(format!("terramp-example-{}", std::process::id()));
        eprintln!("no dataset given: synthesising one into {}", dir.display());
        synthesize(&dir, &SynthParams { size: 256, ..Default::default() }, false)?;
        let walked = walk(&dir, args.points, args.radius_m);
        std::fs::remove_dir_all(&dir).with_context(|| format!("removing {}", dir.display()))?;
        return walked;
    };
    walk(&dir, args.points, args.radius_m)
}

/// Prints the walk's rows over the dataset in `dir`.
fn walk(dir: &Path, points: usize, radius_m: f64) -> Result<()> {
    let dataset = Dataset::open(dir).with_context(|| format!("opening {}", dir.display()))?;
    let gpu = Gpu::new(AdapterChoice::Auto)?;
    let renderer = Renderer::new(gpu, dataset, Settings::default())?;
    let manifest = &renderer.dataset.manifest;
    let origin = DVec2::from(manifest.origin_m);
    let extent = DVec2::from(manifest.extent_m());
    // South-west to north-east, a tenth of the dataset in from each corner.
    let (from, to) = (0.1 * extent, 0.9 * extent);
    let step = (to - from) / (points - 1) as f64;
    let heading_deg = step.x.atan2(step.y).to_degrees();
    let names: Vec<String> = renderer
        .class_table()
        .map(|t| t.species.iter().map(|s| s.name.clone()).collect())
        .unwrap_or_default();

    println!("distance_m,x_m,y_m,height_m,slope_deg,class,plants,nearest_m,nearest_species");
    for i in 0..points {
        let grid = from + step * i as f64;
        let ground = renderer.ground_at(grid.x, grid.y)?;
        let class = renderer.land_cover_at(grid.x, grid.y)?;
        let walker = Camera {
            position_m: (origin + grid).extend(ground.height_m + EYE_M),
            yaw_deg: heading_deg,
            pitch_deg: 0.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
            near_m: 0.5,
        };
        let plants =
            renderer.plants_near(&walker, grid.to_array(), radius_m, Plants::Grown)?.unwrap_or_default();
        let nearest = plants
            .iter()
            .map(|p| (p.position_grid_m.truncate().distance(grid), p.species))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let slope_deg = ground.normal.angle_between(DVec3::Z).to_degrees();
        let (nearest_m, species) = match nearest {
            Some((d, s)) => {
                (format!("{d:.2}"), names.get(s as usize).cloned().unwrap_or_else(|| s.to_string()))
            }
            None => (String::new(), String::new()),
        };
        println!(
            "{:.1},{},{},{:.3},{:.2},{},{},{},{}",
            (grid - from).length(),
            origin.x + grid.x,
            origin.y + grid.y,
            ground.height_m,
            slope_deg,
            class.map(|c| c.to_string()).unwrap_or_default(),
            plants.len(),
            nearest_m,
            species,
        );
    }
    Ok(())
}
