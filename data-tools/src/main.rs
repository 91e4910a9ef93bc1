//! `terramp-data`: builds terramp datasets from GeoTIFF (`build`), synthesizes stress datasets
//! (`synth`) and bakes impostors from glTF models (`bake`). GDAL does the reading and
//! reprojection here, and only here: the runtime crate reads nothing but its own packs.

mod bake;
mod build;

use std::path::PathBuf;

use anyhow::Result;
use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(name = "terramp-data", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Build a dataset from a DEM GeoTIFF, with optional imagery and land cover.
    Build(build::BuildArgs),
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
    },
    /// Bake impostors (billboard clouds at 3 LODs, atlases with mips, the mesh) from glTF models.
    Bake(bake::BakeArgs),
}

fn main() -> Result<()> {
    match Cli::parse().command {
        Command::Build(args) => build::run(&args),
        Command::Bake(args) => bake::run(&args),
        Command::Synth { size, out, seed } => {
            let params = terramp::synth::SynthParams { size, seed, ..Default::default() };
            let dir = terramp::synth::synthesize(&out, &params, true)?;
            println!("wrote {}", dir.display());
            Ok(())
        }
    }
}
