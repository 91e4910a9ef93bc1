//! `terramp photo`: one view's amplified frame against its photograph frame (`terramp::photo`),
//! written as a folder and printed as a table.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result};
use clap::Args;
use terramp::dataset::Dataset;
use terramp::gpu::Gpu;
use terramp::photo::{PhotoReport, measure_view, side_by_side, table};

use super::ViewArgs;

/// The photograph frame (nothing grown), as a PNG in the output folder.
const PHOTOGRAPH_FILE: &str = "photograph.png";
/// The amplified frame (the settings as given).
const AMPLIFIED_FILE: &str = "amplified.png";
/// The two side by side: photograph | amplified.
const SIDE_BY_SIDE_FILE: &str = "side_by_side.png";
/// The figures (`PhotoReport`) as JSON.
const REPORT_FILE: &str = "photo.json";

#[derive(Args)]
pub struct PhotoArgs {
    #[command(flatten)]
    view: ViewArgs,
    /// Folder written: photograph.png, amplified.png, side_by_side.png, photo.json.
    #[arg(long)]
    out: PathBuf,
    /// Measure this PNG as the amplified frame instead of rendering it: a frame of the same view
    /// and size rendered elsewhere (another build's `terramp render`, say).
    #[arg(long)]
    amplified: Option<PathBuf>,
}

impl PhotoArgs {
    pub fn run(self) -> Result<()> {
        let (settings, camera) = self.view.load()?;
        let dataset = Arc::new(Dataset::open(&self.view.dataset)?);
        let gpu = Gpu::new(settings.gpu.adapter)?;
        let adapter = gpu.describe();
        eprintln!("terramp: adapter {adapter}");
        let given = match &self.amplified {
            Some(path) => {
                let image = image::open(path).with_context(|| format!("reading {}", path.display()))?;
                Some(image.to_rgba8())
            }
            None => None,
        };
        let view = measure_view(&gpu, dataset, &settings, &camera, self.view.time_s, given)?;
        let out = &self.out;
        std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
        let save = |image: &image::RgbaImage, name: &str| {
            let path = out.join(name);
            image.save(&path).with_context(|| format!("writing {}", path.display()))
        };
        save(&view.photograph, PHOTOGRAPH_FILE)?;
        save(&view.amplified, AMPLIFIED_FILE)?;
        save(&side_by_side(&view.photograph, &view.amplified), SIDE_BY_SIDE_FILE)?;
        let p = camera.position_m;
        let report = PhotoReport {
            dataset: self.view.dataset.display().to_string(),
            camera: [p.x, p.y, p.z, camera.yaw_deg, camera.pitch_deg],
            fov_deg: camera.fov_deg,
            time_s: self.view.time_s,
            adapter,
            figures: view.figures,
        };
        let json = out.join(REPORT_FILE);
        std::fs::write(&json, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("writing {}", json.display()))?;
        let [w, h] = report.figures.size_px;
        println!("{}: {w}×{h} px, photograph | amplified in {SIDE_BY_SIDE_FILE}", out.display());
        print!("{}", table(&report.figures));
        Ok(())
    }
}
