//! `terramp photo`: one view's amplified frame against its photograph frame (`terramp::photo`),
//! written as a folder and printed as a table.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::gpu::Gpu;
use terramp::photo::descent::{Descent, DescentFigures, descend};
use terramp::photo::truth::truth_flip;
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
/// A descent's figures (`DescentReport`) as JSON.
const DESCENT_FILE: &str = "descent.json";
/// A descent's pairs, one line each.
const DESCENT_CSV_FILE: &str = "descent.csv";

/// What `descent.json` holds.
#[derive(Serialize)]
struct DescentReport {
    dataset: String,
    /// The top camera: x, y, z (CRS metres), yaw, pitch (degrees).
    camera: [f64; 5],
    fov_deg: f64,
    bottom_m: f64,
    step: f64,
    time_s: f64,
    adapter: String,
    figures: DescentFigures,
}

#[derive(Args)]
pub struct PhotoArgs {
    #[command(flatten)]
    view: ViewArgs,
    /// Folder written: photograph.png, amplified.png, side_by_side.png, photo.json.
    #[arg(long)]
    out: PathBuf,
    /// Measure this PNG as the amplified frame instead of rendering it: a frame of the same view
    /// and size rendered elsewhere (another build's `terramp render`, say) with the display's
    /// `linear` curve (`display.tone_curve = "linear"`), as the measure renders its own.
    #[arg(long, conflicts_with = "descend_to")]
    amplified: Option<PathBuf>,
    /// Also judge the amplified frame against this truth image of the same view and size
    /// (`terramp truth`'s truth.png, perhaps another build's): FLIP over the mesh band, in colour
    /// and in luminance only (`terramp::photo::truth`).
    #[arg(long, conflicts_with = "descend_to")]
    truth: Option<PathBuf>,
    /// Instead of one view, descend straight down from the camera to this height above the
    /// ground below it (metres), and measure how much each ground block's colour changes from
    /// frame to frame (`terramp::photo::descent`): descent.json and descent.csv in the folder.
    #[arg(long)]
    descend_to: Option<f64>,
    /// With `--descend-to`: the share of its height the camera sinks each frame.
    #[arg(long, default_value_t = 0.02, requires = "descend_to")]
    step: f64,
}

impl PhotoArgs {
    pub fn run(self) -> Result<()> {
        let (settings, camera) = self.view.load()?;
        let dataset = Arc::new(Dataset::open(&self.view.dataset)?);
        let gpu = Gpu::new(settings.gpu.adapter)?;
        let adapter = gpu.describe();
        eprintln!("terramp: adapter {adapter}");
        if let Some(bottom_m) = self.descend_to {
            let descent = Descent { top: camera, bottom_m, step: self.step };
            return run_descent(&gpu, dataset, &settings, &descent, self.view.time_s, &self.out, adapter);
        }
        let given = match &self.amplified {
            Some(path) => {
                let image = image::open(path).with_context(|| format!("reading {}", path.display()))?;
                Some(image.to_rgba8())
            }
            None => None,
        };
        let view = measure_view(&gpu, dataset, &settings, &camera, self.view.time_s, given)?;
        let truth = match &self.truth {
            Some(path) => {
                let image = image::open(path).with_context(|| format!("reading {}", path.display()))?;
                let reach_m = settings.draw_seeds.reach_m[0];
                Some(truth_flip(&view.amplified, &image.to_rgba8(), &view.keys, reach_m)?)
            }
            None => None,
        };
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
            truth,
        };
        let json = out.join(REPORT_FILE);
        std::fs::write(&json, serde_json::to_string_pretty(&report)?)
            .with_context(|| format!("writing {}", json.display()))?;
        let [w, h] = report.figures.size_px;
        println!("{}: {w}×{h} px, photograph | amplified in {SIDE_BY_SIDE_FILE}", out.display());
        print!("{}", table(&report.figures));
        if let Some(t) = &report.truth {
            let num = |v: Option<f64>| v.map_or("-".to_owned(), |v| format!("{v:.4}"));
            println!(
                "against the truth, mesh band (< {} m, {} px): FLIP {} in colour, {} in luminance, {} in detail",
                t.mesh_reach_m,
                t.pixels,
                num(t.colour),
                num(t.luminance),
                num(t.detail)
            );
        }
        Ok(())
    }
}

/// Runs a descent, writes its report and pairs into `out` and prints the largest changes.
fn run_descent(
    gpu: &Gpu,
    dataset: Arc<Dataset>,
    settings: &Settings,
    descent: &Descent,
    time_s: f64,
    out: &std::path::Path,
    adapter: String,
) -> Result<()> {
    let folder = dataset.dir.display().to_string();
    let mut progress = |done: usize, of: usize| {
        if done.is_multiple_of(10) || done == of {
            eprintln!("terramp: descent frame {done} of {of}");
        }
    };
    let figures = descend(gpu, dataset, settings, descent, time_s, &mut progress)?;
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut csv = String::from(
        "height_m,next_height_m,block_texels,blocks,amplified,photograph,own,own_x_px,own_y_px\n",
    );
    let num = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.4}"));
    for p in &figures.pairs {
        csv.push_str(&format!(
            "{:.2},{:.2},{},{},{},{},{},{},{}\n",
            p.height_m[0],
            p.height_m[1],
            p.block_texels,
            p.blocks,
            num(p.amplified),
            num(p.photograph),
            num(p.own),
            p.own_at_px.map_or(String::new(), |a| a[0].to_string()),
            p.own_at_px.map_or(String::new(), |a| a[1].to_string()),
        ));
    }
    let path = out.join(DESCENT_CSV_FILE);
    std::fs::write(&path, csv).with_context(|| format!("writing {}", path.display()))?;
    let p = descent.top.position_m;
    let report = DescentReport {
        dataset: folder,
        camera: [p.x, p.y, p.z, descent.top.yaw_deg, descent.top.pitch_deg],
        fov_deg: descent.top.fov_deg,
        bottom_m: descent.bottom_m,
        step: descent.step,
        time_s,
        adapter,
        figures,
    };
    let path = out.join(DESCENT_FILE);
    std::fs::write(&path, serde_json::to_string_pretty(&report)?)
        .with_context(|| format!("writing {}", path.display()))?;
    let f = &report.figures;
    println!(
        "{}: {} frames, {} pairs; per pair the largest block change, CIEDE2000:",
        out.display(),
        f.frames,
        f.pairs.len()
    );
    for (name, figure) in [
        ("amplified", (|p| p.amplified) as fn(&terramp::photo::descent::PairFigures) -> Option<f64>),
        ("photograph", |p| p.photograph),
        ("own (amplification's)", |p| p.own),
    ] {
        match f.largest(figure) {
            Some((i, v)) => {
                let h = f.pairs[i].height_m;
                println!("  {name:<22} {v:>7.3}  between {:.0} m and {:.0} m", h[0], h[1]);
            }
            None => println!("  {name:<22}       -  (no block compared)"),
        }
    }
    Ok(())
}
