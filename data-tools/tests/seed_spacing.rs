//! Seed spacing across ring-0 cell borders on real data (`nc/` and `zion/`, built into a
//! temporary folder), every preset: the GPU's selected seeds of settled views, in world xy, each
//! with its cell. The 1st-percentile nearest-neighbour distance of the seeds whose neighbour lies
//! across a border must be at least 0.9 × that of the seeds whose neighbour lies in their own
//! cell (`seeds::spacing`). Prints the figures of `docs/seeds.md` ("Seed spacing across cell
//! borders"), the radial distribution functions, and with `TERRAMP_SPACING_PNG=DIR` draws the
//! seeds around one border corner of each dataset.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::Path;

use glam::DVec3;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::{AdapterChoice, Gpu};
use terramp::seeds::spacing::{BorderSpacing, RDF_BIN, RDF_BINS, quantile};
use terramp_testkit::camera::posed;

use support::{build_nc, build_zion};
use terramp_testkit::{TempDir, shared_data};

/// The views of each dataset: the oblique and high views of `tests/seeds.rs`.
const NC_VIEWS: [(&str, [f64; 5]); 2] =
    [("oblique", [6000.0, 5000.0, 120.0, 40.0, -12.0]), ("high", [3000.0, 3000.0, 900.0, 60.0, -35.0])];
const ZION_VIEWS: [(&str, [f64; 5]); 2] =
    [("canyon", [17000.0, 20000.0, 60.0, 0.0, -5.0]), ("high", [12000.0, 25000.0, 800.0, 120.0, -25.0])];

/// The GPU's selected seeds of a settled view: grid-space xy and ring-0 cell.
fn selected_seeds(r: &mut Renderer, pose: [f64; 5]) -> (Vec<[f64; 2]>, Vec<[i64; 2]>) {
    let camera = posed(r, pose);
    r.render_resolved(&camera).unwrap();
    let (records, counters) = r.read_seeds().unwrap().unwrap();
    assert_eq!(counters.overflow, 0, "{counters:?}");
    let origin = r.dataset.manifest.origin_m;
    let eye = camera.position_m - DVec3::new(origin[0], origin[1], 0.0);
    let cell_m = r.settings.tlm.cell_m;
    let mut xy = Vec::with_capacity(records.len());
    let mut cells = Vec::with_capacity(records.len());
    for s in &records {
        let p = [eye.x + f64::from(s.position_rel_m[0]), eye.y + f64::from(s.position_rel_m[1])];
        let cell = s.address.map(i64::from);
        // A seed lies in its cell, up to the f32 rounding of its camera-relative position.
        for a in 0..2 {
            let local = p[a] / cell_m - cell[a] as f64;
            assert!((-1e-4..1.0 + 1e-4).contains(&local), "seed {s:?} at {p:?} outside its cell");
        }
        xy.push(p);
        cells.push(cell);
    }
    (xy, cells)
}

/// Draws the seeds within `half_m` of `corner_m` (a cell corner), one colour per cell, cell
/// borders in grey, into `path`.
fn draw_corner(path: &Path, xy: &[[f64; 2]], cells: &[[i64; 2]], corner_m: [f64; 2], half_m: f64) {
    let size = 720u32;
    let mut img = image::RgbImage::from_pixel(size, size, image::Rgb([255, 255, 255]));
    let px = |v: f64, a: usize| ((v - corner_m[a] + half_m) / (2.0 * half_m) * f64::from(size)) as i64;
    for k in 0..size {
        for (x, y) in [(size / 2, k), (k, size / 2)] {
            img.put_pixel(x, y, image::Rgb([170, 170, 170]));
        }
    }
    let palette = [[200, 40, 40], [30, 110, 200], [30, 150, 60], [150, 60, 170]];
    for (p, c) in xy.iter().zip(cells) {
        let (x, y) = (px(p[0], 0), i64::from(size) - 1 - px(p[1], 1));
        let colour = palette[((c[0] & 1) + 2 * (c[1] & 1)) as usize];
        for dy in -3i64..=3 {
            for dx in -3i64..=3 {
                let (qx, qy) = (x + dx, y + dy);
                if dx * dx + dy * dy <= 9
                    && (0..i64::from(size)).contains(&qx)
                    && (0..i64::from(size)).contains(&qy)
                {
                    img.put_pixel(qx as u32, qy as u32, image::Rgb(colour));
                }
            }
        }
    }
    img.save(path).unwrap();
}

/// Every preset's spacing on `dataset`, pooled over `views`: (preset, figures).
fn measure(name: &str, dataset: &Path, views: &[(&str, [f64; 5])]) -> Vec<(&'static str, BorderSpacing)> {
    let mut out = Vec::new();
    for preset in ["fast", "balanced", "accurate"] {
        let dataset = Dataset::open(dataset).unwrap();
        let mut settings = Settings::preset(preset).unwrap();
        settings.render.width = 640;
        settings.render.height = 360;
        let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter (install mesa-vulkan-drivers)");
        let mut r = Renderer::new(gpu, dataset, settings).unwrap();
        let mut pooled = BorderSpacing::default();
        for &(view, pose) in views {
            let (xy, cells) = selected_seeds(&mut r, pose);
            let s = BorderSpacing::of(&xy, &cells, r.settings.tlm.cell_m);
            println!(
                "{name} {view} {preset}: {} seeds, {} with their neighbour across a border; 1st percentile \
                 across {:.3} m, inside {:.3} m, midline {:.3} m; ratio {:.3} (midline {:.3})",
                s.seeds,
                s.across.len(),
                quantile(&s.across, 0.01),
                quantile(&s.inside, 0.01),
                quantile(&s.midline, 0.01),
                s.ratio(),
                s.midline_ratio()
            );
            if let Some(dir) = std::env::var_os("TERRAMP_SPACING_PNG")
                && preset == "balanced"
                && view == views[0].0
            {
                // The cell corner nearest the median seed, and 24 m around it.
                let mut sorted: Vec<[f64; 2]> = xy.clone();
                sorted.sort_by(|a, b| a[0].total_cmp(&b[0]));
                let median = sorted[sorted.len() / 2];
                let cell_m = r.settings.tlm.cell_m;
                let corner = median.map(|v| (v / cell_m).round() * cell_m);
                draw_corner(
                    &Path::new(&dir).join(format!("seeds_border_{name}.png")),
                    &xy,
                    &cells,
                    corner,
                    24.0,
                );
            }
            pooled.merge(&s);
        }
        assert!(
            pooled.across.len() >= 500,
            "{name} {preset}: only {} seeds by a border",
            pooled.across.len()
        );
        out.push((preset, pooled));
    }
    out
}

#[test]
fn seed_spacing_across_cell_borders() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("seed-spacing");
    let (nc, zion) = (tmp.path().join("nc"), tmp.path().join("zion"));
    build_nc(&nc);
    build_zion(&zion);
    let mut rows = Vec::new();
    for (name, dir, views) in [("nc", &nc, &NC_VIEWS), ("zion", &zion, &ZION_VIEWS)] {
        for (preset, s) in measure(name, dir, views) {
            rows.push((name, preset, s));
        }
    }
    println!(
        "| dataset | preset | seeds | NN across | 1 % across | 1 % inside | ratio | 1 % midline | midline ratio |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, preset, s) in &rows {
        println!(
            "| {name} | {preset} | {} | {} | {:.2} m | {:.2} m | {:.3} | {:.2} m | {:.3} |",
            s.seeds,
            s.across.len(),
            quantile(&s.across, 0.01),
            quantile(&s.inside, 0.01),
            s.ratio(),
            quantile(&s.midline, 0.01),
            s.midline_ratio()
        );
    }
    println!("radial distribution (r in local spacings: g over all pairs / g across borders)");
    for (name, preset, s) in &rows {
        let curve: Vec<String> =
            (0..RDF_BINS).map(|k| format!("{:.2}/{:.2}", s.rdf_all[k], s.rdf_across[k])).collect();
        println!("rdf {name} {preset} bin {RDF_BIN}: {}", curve.join(" "));
    }
    for (name, preset, s) in &rows {
        let ratio = s.ratio();
        assert!(
            ratio >= 0.9,
            "{name} {preset}: 1st-percentile nearest neighbour across borders / inside = {ratio:.3}"
        );
    }
}
