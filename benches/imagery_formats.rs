//! Imagery stored plain or in blocks, side by side: for each dataset (the first is the reference,
//! the others the same ground stored in another `ImageryFormat`), the imagery pack's bytes on disk,
//! a cache slot's bytes and the slots that fit 128 MiB, the bytes uploaded per frame over a flight
//! from cold, and the ground's PSNR and mean FLIP against the reference's at views along the flight
//! (every tile resident, no seeds). `cargo bench --bench imagery_formats -- PATH.toml REF DIR...`;
//! `FRAMES` (default 90) sets the flight's length, `BLOCKS` (`auto`, `sample`, `decode`) the
//! setting `imagery.blocks`, `OUT` (default `target/imagery_formats`) where the views are written
//! as PNG.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

use std::path::{Path, PathBuf};
use std::time::Instant;

use terramp::dataset::Dataset;
use terramp::path::CameraPath;
use terramp::reference::image_metrics::flip_map;
use terramp_testkit::images::psnr;
use terramp_testkit::{ground_settings, renderer, settled_colour};

/// Points along the flight whose resolved views are compared.
const VIEWS: [f64; 4] = [0.1, 0.35, 0.6, 0.85];
/// The budget `slots in budget` is counted against: a modest share of a GPU.
const BUDGET_BYTES: usize = 128 << 20;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with("--")).collect();
    let [path, reference, others @ ..] = args.as_slice() else {
        panic!("usage: imagery_formats PATH.toml REFERENCE_DATASET DATASET...");
    };
    let path = CameraPath::load(Path::new(path)).unwrap();
    let frames: usize = std::env::var("FRAMES").ok().and_then(|v| v.parse().ok()).unwrap_or(90);
    let out = PathBuf::from(std::env::var("OUT").unwrap_or_else(|_| "target/imagery_formats".into()));
    std::fs::create_dir_all(&out).unwrap();
    println!(
        "| dataset | format | imagery pack | cache | slot | slots in 128 MiB | uploaded per frame (mean, max) | flight | PSNR (mean, min) | FLIP (mean) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let reference_views = measure(Path::new(reference), &path, frames, &out, None);
    let mut first_views = vec![reference_views[0].clone()];
    for other in others {
        first_views.push(measure(Path::new(other), &path, frames, &out, Some(&reference_views)).remove(0));
    }
    let name = Path::new(reference).file_name().unwrap().to_string_lossy().into_owned();
    side_by_side(&first_views).save(out.join(format!("{name}_crops.png"))).unwrap();
}

/// The middle of the lower half of each first view (the nearest ground, finest texels), doubled,
/// side by side in the order given.
fn side_by_side(views: &[image::RgbaImage]) -> image::RgbaImage {
    const CROP: [u32; 2] = [320, 180];
    let mut out = image::RgbaImage::new(2 * CROP[0] * views.len() as u32, 2 * CROP[1]);
    for (k, view) in views.iter().enumerate() {
        let (x0, y0) = ((view.width() - CROP[0]) / 2, view.height() / 2 + (view.height() / 2 - CROP[1]) / 2);
        for (x, y, pixel) in out.enumerate_pixels_mut() {
            if x / (2 * CROP[0]) == k as u32 {
                *pixel = *view.get_pixel(x0 + (x % (2 * CROP[0])) / 2, y0 + y / 2);
            }
        }
    }
    out
}

/// Prints one row for `dir` and returns its views.
fn measure(
    dir: &Path,
    path: &CameraPath,
    frames: usize,
    out: &Path,
    reference: Option<&[image::RgbaImage]>,
) -> Vec<image::RgbaImage> {
    let name = dir.file_name().unwrap().to_string_lossy().into_owned();
    let dataset = Dataset::open(dir).unwrap();
    let meta = dataset.manifest.imagery.as_ref().expect("a dataset with imagery");
    let pack_bytes = std::fs::metadata(dir.join(&meta.pack)).unwrap().len();
    let format = meta.format.clone();
    let mut settings = ground_settings(1280, 720);
    if let Ok(blocks) = std::env::var("BLOCKS") {
        settings.imagery.blocks = toml::Value::String(blocks).try_into().unwrap();
    }
    let mut r = renderer(dir, settings);
    let (fov_deg, near_m) = (r.settings.render.fov_deg, r.settings.render.near_m);
    let cache = r.imagery_cache();
    let (slot, slots, cached) = (cache.tile_bytes(), cache.capacity(), format!("{:?}", cache.format()));
    // What the driver allocated for the cache's texture, where wgpu's allocator reports it.
    let allocated = r.gpu.device.generate_allocator_report().map_or_else(
        || "no allocator report".to_owned(),
        |report| {
            let bytes: u64 =
                report.allocations.iter().filter(|a| a.name.contains("imagery cache")).map(|a| a.size).sum();
            format!("{:.1} MiB allocated", bytes as f64 / f64::from(1 << 20))
        },
    );
    // Warm the shaders up before timing.
    r.render(&path.camera_at(0.0, fov_deg, near_m)).unwrap();
    let start = Instant::now();
    let mut uploaded = Vec::with_capacity(frames);
    for i in 0..frames {
        let t = i as f64 / (frames.max(2) - 1) as f64;
        r.set_time_s(i as f64 / 60.0);
        let report = r.render(&path.camera_at(t, fov_deg, near_m)).unwrap();
        uploaded.push(report.imagery.bytes_uploaded);
    }
    let flight_s = start.elapsed().as_secs_f64();
    let views: Vec<image::RgbaImage> = VIEWS
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let view = settled_colour(&mut r, &path.camera_at(t, fov_deg, near_m));
            view.save(out.join(format!("{name}_{k}.png"))).unwrap();
            view
        })
        .collect();
    let mib = |b: f64| b / f64::from(1 << 20);
    let mean = uploaded.iter().sum::<u64>() as f64 / frames as f64;
    let max = uploaded.iter().copied().max().unwrap_or(0) as f64;
    let quality = reference.map_or_else(
        || "reference | reference".to_owned(),
        |reference| {
            let db: Vec<f64> = views.iter().zip(reference).map(|(v, r)| psnr(r, v)).collect();
            let flip: Vec<f64> = views
                .iter()
                .zip(reference)
                .map(|(v, r)| {
                    let map = flip_map(r, v).unwrap();
                    map.iter().map(|&e| f64::from(e)).sum::<f64>() / map.len() as f64
                })
                .collect();
            let min = db.iter().copied().fold(f64::INFINITY, f64::min);
            format!(
                "{:.1} dB, {min:.1} dB | {:.4}",
                db.iter().sum::<f64>() / db.len() as f64,
                flip.iter().sum::<f64>() / flip.len() as f64
            )
        },
    );
    println!(
        "| {name} | {format} | {:.2} MiB | {cached}, {allocated} | {:.1} KiB × {slots} | {} | {:.2} MiB, {:.2} MiB | {frames} frames, {flight_s:.1} s | {quality} |",
        mib(pack_bytes as f64),
        slot as f64 / 1024.0,
        BUDGET_BYTES / slot,
        mib(mean),
        mib(max),
    );
    views
}
