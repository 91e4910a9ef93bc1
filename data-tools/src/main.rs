//! `terramp-data`: builds terramp datasets from GeoTIFF (`build`), synthesizes stress datasets
//! (`synth`), bakes impostors from glTF models (`bake`), generates trees as glTF (`tree`), draws
//! models side by side (`preview`) and lays pictures out for the docs' figures (`compose`). GDAL does the reading and
//! reprojection here, and only here: the runtime crate reads nothing but its own packs. Baking
//! lives in the library (`terramp::bake`, which the demo also uses): `bake` only parses its
//! arguments.

mod build;
mod compose;
mod models;
mod plan;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::{Parser, Subcommand};
use terramp::dataset::ImageryFormat;

#[derive(Parser)]
#[command(name = "terramp-data", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build a dataset from a DEM GeoTIFF, with optional imagery and land cover; or, with --plan
    /// and --partition, one partition of a planned build.
    Build(build::BuildArgs),
    /// Plan a partitioned build: split it into jobs that any scheduler runs (`build --plan P
    /// --partition I`, e.g. scripts/dask_build.py), then `merge`.
    Plan(plan::PlanArgs),
    /// Assemble a planned build's partitions into the dataset (atomically), once all are built.
    Merge {
        /// The plan file (`terramp-data plan`).
        #[arg(long)]
        plan: PathBuf,
        /// The output dataset folder (replaced atomically if it holds a dataset).
        #[arg(long)]
        out: PathBuf,
    },
    /// Synthesize a stress dataset: fractal DEM, classes, imagery; any size, tile by tile.
    Synth {
        /// DEM samples per side (imagery is 4× finer per axis: 8192 gives giga-pixel imagery).
        #[arg(long, default_value_t = terramp::synth::SynthParams::default().size)]
        size: u32,
        /// The output dataset folder (replaced atomically if it holds a dataset).
        #[arg(long)]
        out: PathBuf,
        /// Random seed: the same seed gives the same dataset, bit for bit.
        #[arg(long, default_value_t = terramp::synth::SynthParams::default().seed)]
        seed: u64,
        /// How the imagery is stored: rgba8, or bc7 / bc1 blocks (4× / 8× smaller, lossy).
        #[arg(long, default_value = "rgba8", value_parser = parse_imagery_format)]
        imagery_format: ImageryFormat,
    },
    /// Bake impostors (billboard clouds at 3 LODs, atlases with mips, the mesh) from glTF models,
    /// and with --classes the forest samples (texcells) of a class table's dense classes.
    Bake(BakeArgs),
    /// Generate a tree (Weber & Penn, with the Virtual Forest's health) as a glTF binary.
    Tree(models::TreeArgs),
    /// Draw glTF models side by side on one scale, as the baker sees them, into a PNG.
    Preview(models::PreviewArgs),
    /// Lay pictures out on a grid (cropped, scaled, over a checkerboard), for the figures in docs/.
    Compose(compose::ComposeArgs),
}

#[derive(clap::Args)]
struct BakeArgs {
    /// A glTF model (.glb) to bake; repeat for several. The impostor is named after the file.
    #[arg(long = "model", required_unless_present = "classes")]
    models: Vec<PathBuf>,
    /// A class table (nc, nlcd, or a TOML file): bake a forest sample (texcells) for each class it
    /// marks `texcells = true`, from its species' models in --models, into OUT/texcells/CODE.
    #[arg(long, requires = "models_dir")]
    classes: Option<String>,
    /// The folder of the glTF models the class table names (`<model>.glb`).
    #[arg(long = "models")]
    models_dir: Option<PathBuf>,
    /// The output folder: one sub-folder per model (replaced atomically).
    #[arg(long)]
    out: PathBuf,
    /// Planes of each LOD's billboard cloud, finest first.
    #[arg(long, value_delimiter = ',', default_values_t = terramp::bake::BakeOptions::default().planes)]
    planes: Vec<usize>,
    /// Width and height of each LOD's atlas in texels (a power of two, 64 to 8192).
    #[arg(long, default_value_t = terramp::bake::BakeOptions::default().texels)]
    texels: u32,
    /// Also slice each crown (Jakulin's slicings): ORIENTATIONSxSLICES, e.g. `6x5` (the paper's),
    /// on an atlas of --texels; the trunk and limbs (bark materials) stay the mesh.
    #[arg(long, value_parser = parse_slicing)]
    slicings: Option<terramp::bake::SlicingOptions>,
    /// Skip the models already baked into --out in this build's format (resumes a bake; a folder
    /// of an older format is baked again).
    #[arg(long)]
    missing: bool,
}

fn bake(args: BakeArgs) -> Result<()> {
    let started = Instant::now();
    let stale = |model: &PathBuf| {
        let name = model.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        !(args.missing && terramp::impostor::is_current(&args.out, &name))
    };
    let models: Vec<PathBuf> = args.models.iter().filter(|m| stale(m)).cloned().collect();
    if args.missing && models.len() < args.models.len() {
        println!("{} models already baked in {}", args.models.len() - models.len(), args.out.display());
    }
    if !models.is_empty() {
        let options =
            terramp::bake::BakeOptions { planes: args.planes, texels: args.texels, slicing: args.slicings };
        let reports = terramp::bake::bake_models(None, &models, &args.out, &options, true)?;
        println!(
            "baked {} models into {} in {:.1} s",
            reports.len(),
            args.out.display(),
            started.elapsed().as_secs_f64()
        );
    }
    if let (Some(classes), Some(models)) = (&args.classes, &args.models_dir) {
        let table = terramp::classes::ClassTable::load(classes)?;
        let options = terramp::bake::forest::ForestOptions::default();
        let reports =
            terramp::bake::forest::bake_forests(None, &table, models, &args.out, &options, &mut |r| {
                println!(
                    "forest sample of class {} ({}): {} trees in {:.1} s, {}",
                    r.class_code,
                    r.class_name,
                    r.trees,
                    r.seconds,
                    r.dir.display()
                )
            })?;
        if reports.is_empty() {
            println!("class table {classes} marks no class `texcells = true`: no forest sample to bake");
        }
    }
    Ok(())
}

fn main() -> Result<()> {
    // SAFETY: first thing in main, before any thread starts.
    unsafe { terramp::gpu::skip_device_select_layer() };
    match Cli::parse().command {
        Command::Build(args) => match (&args.plan, args.partition) {
            (Some(plan), Some(part)) => plan::build_partition(plan, part),
            _ => build::run(&args),
        },
        Command::Plan(args) => plan::plan(&args),
        Command::Merge { plan, out } => plan::merge(&plan, &out),
        Command::Bake(args) => bake(args),
        Command::Tree(args) => models::tree(&args),
        Command::Preview(args) => models::preview(&args),
        Command::Compose(args) => compose::compose(&args),
        Command::Synth { size, out, seed, imagery_format } => {
            let params = terramp::synth::SynthParams { size, seed, imagery_format, ..Default::default() };
            let dir = terramp::synth::synthesize(&out, &params, true)?;
            println!("wrote {}", dir.display());
            Ok(())
        }
    }
}

/// `--imagery-format`: `rgba8`, `bc1` or `bc7`.
pub(crate) fn parse_imagery_format(text: &str) -> Result<ImageryFormat, String> {
    ImageryFormat::ALL.into_iter().find(|f| f.short_name() == text).ok_or_else(|| {
        let names: Vec<&str> = ImageryFormat::ALL.iter().map(|f| f.short_name()).collect();
        format!("`{text}`: expected one of {}", names.join(", "))
    })
}

/// `--slicings ORIENTATIONSxSLICES`, e.g. `6x5`.
fn parse_slicing(text: &str) -> Result<terramp::bake::SlicingOptions, String> {
    let numbers =
        text.split_once(['x', 'X']).and_then(|(o, s)| Some((o.trim().parse().ok()?, s.trim().parse().ok()?)));
    match numbers {
        Some((orientations, slices)) => Ok(terramp::bake::SlicingOptions { orientations, slices }),
        None => Err(format!("`{text}`: expected ORIENTATIONSxSLICES, e.g. 6x5")),
    }
}
