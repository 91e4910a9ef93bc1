//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::{AdapterChoice, Gpu};

pub mod audit;

/// The synthetic datasets this test process built, by parameters.
static BUILT: Mutex<Vec<(String, PathBuf)>> = Mutex::new(Vec::new());

/// A synthetic dataset of `size`² samples, built once per test process (never reused across runs,
/// so a change to the generator is always what is tested) and shared by its tests.
pub fn synth_dataset(size: u32, seed: u64) -> PathBuf {
    synth_dataset_with(&terramp::synth::SynthParams { size, seed, ..Default::default() })
}

/// As `synth_dataset`, for any parameters (spacing, origin, water level).
pub fn synth_dataset_with(params: &terramp::synth::SynthParams) -> PathBuf {
    let key = format!("{params:?}");
    let mut built = BUILT.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, dir)) = built.iter().find(|(k, _)| *k == key) {
        return dir.clone();
    }
    let root = Path::new(env!("CARGO_TARGET_TMPDIR"));
    if built.is_empty() {
        // Earlier runs' datasets: cargo runs test binaries one after another, so none is in use.
        for entry in std::fs::read_dir(root).into_iter().flatten().flatten() {
            if entry.file_name().to_string_lossy().starts_with("synth-") {
                let _ = std::fs::remove_dir_all(entry.path());
            }
        }
    }
    let (size, seed, n) = (params.size, params.seed, built.len());
    let dir = root.join(format!("synth-{size}-{seed}-{n}-{}", std::process::id()));
    terramp::synth::synthesize(&dir, params, false).unwrap();
    built.push((key, dir.clone()));
    dir
}

/// The software adapter tests run on (CI forces `WGPU_BACKEND=vulkan`).
pub fn gpu() -> Gpu {
    Gpu::new(AdapterChoice::Auto).expect("tests need a GPU adapter; install mesa-vulkan-drivers")
}

pub fn small_settings(width: u32, height: u32) -> Settings {
    let mut settings = Settings::default();
    settings.render.width = width;
    settings.render.height = height;
    settings
}

pub fn renderer(dataset: &Path, settings: Settings) -> Renderer {
    Renderer::new(gpu(), Dataset::open(dataset).unwrap(), settings).unwrap()
}

/// `../shared/data`, or `None` outside CI when it is absent. Under CI its absence is a failure.
pub fn shared_data() -> Option<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data");
    if dir.join("README.md").exists() {
        return Some(dir);
    }
    if std::env::var("CI").is_ok_and(|v| v == "true") {
        panic!("{} is missing: CI must run with ../shared beside the repository", dir.display());
    }
    eprintln!("skipping: {} is not there", dir.display());
    None
}

/// Peak signal-to-noise ratio between two same-sized RGBA images, RGB channels, dB (infinite when
/// identical): the library's, which the speed trade reports.
pub fn psnr(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    terramp::reference::image_metrics::psnr_db(a, b).unwrap()
}
