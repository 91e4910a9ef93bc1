//! `terramp truth`: the ground truth of one view (`terramp::truth`), written as a folder.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use clap::Args;
use terramp::camera::Camera;
use terramp::dataset::Dataset;
use terramp::gpu::Gpu;
use terramp::truth::{DEFAULT_REACH_M, TruthOptions, files, render_truth};

use super::SettingsArgs;

#[derive(Args)]
pub struct TruthArgs {
    #[arg(long)]
    dataset: PathBuf,
    /// X,Y,Z,YAW,PITCH as for `render`.
    #[arg(long, allow_hyphen_values = true)]
    camera: String,
    /// Vertical field of view, degrees.
    #[arg(long)]
    fov: Option<f64>,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
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
    #[command(flatten)]
    settings: SettingsArgs,
}

impl TruthArgs {
    pub fn run(self) -> Result<()> {
        let mut settings = self.settings.load()?;
        settings.render.fov_deg = self.fov.unwrap_or(settings.render.fov_deg);
        settings.render.width = self.width.unwrap_or(settings.render.width);
        settings.render.height = self.height.unwrap_or(settings.render.height);
        let camera = Camera::parse_pose(&self.camera, settings.render.fov_deg, settings.render.near_m)?;
        let dataset = Dataset::open(&self.dataset)?;
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
