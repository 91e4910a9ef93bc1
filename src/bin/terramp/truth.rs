//! `terramp truth`: the ground truth of one view (`terramp::truth`), written as a folder.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use terramp::dataset::Dataset;
use terramp::gpu::Gpu;
use terramp::truth::{DEFAULT_REACH_M, TruthOptions, files, render_truth};

use super::ViewArgs;

#[derive(Args)]
pub struct TruthArgs {
    #[command(flatten)]
    view: ViewArgs,
    /// Samples per pixel along each axis (box-filtered).
    #[arg(long, default_value_t = 4)]
    supersample: u32,
    /// Seeds grow out to this distance from the camera, metres.
    #[arg(long, default_value_t = DEFAULT_REACH_M)]
    reach_m: f64,
    /// Impostor folder whose meshes the seeds are drawn with (default: `draw_seeds.impostors`).
    #[arg(long)]
    impostors: Option<PathBuf>,
    /// Folder written: truth.png, seed_ids.u32, depth.f32, seeds.csv, truth.json.
    #[arg(long)]
    out: PathBuf,
}

impl TruthArgs {
    pub fn run(self) -> Result<()> {
        let (settings, camera) = self.view.load()?;
        let dataset = Dataset::open(&self.view.dataset)?;
        let gpu = Gpu::new(settings.gpu.adapter)?;
        eprintln!("terramp: adapter {}", gpu.describe());
        let options = TruthOptions {
            supersample: self.supersample,
            reach_m: self.reach_m,
            impostors: self.impostors.unwrap_or_default(),
        };
        let start = Instant::now();
        let truth = render_truth(gpu, dataset, &settings, &camera, &options)?;
        truth.write(&self.out).with_context(|| format!("writing {}", self.out.display()))?;
        let visible = truth.samples.iter().filter(|&&n| n > 0).count();
        println!(
            "{}: {}×{} px at {}² samples, {} seeds drawn ({} candidates within {:.0} m), {visible} visible, {:.1} s",
            self.out.join(files::IMAGE_FILE).display(),
            truth.size_px[0],
            truth.size_px[1],
            truth.supersample,
            truth.seeds.len(),
            truth.counts.candidates,
            self.reach_m,
            start.elapsed().as_secs_f64()
        );
        Ok(())
    }
}
