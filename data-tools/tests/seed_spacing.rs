//! Seed spacing across ring-0 cell borders on real data (`nc/` and `zion/`, built into a
//! temporary folder), every preset: the GPU's selected seeds of settled views, in world xy, each
//! with its cell. The 1st-percentile nearest-neighbour distance of the seeds whose neighbour lies
//! across a border must be at least `MIN_BORDER_RATIO` (0.9) × that of the seeds whose neighbour
//! lies in their own cell (`seeds::spacing`). Prints the figures of `docs/seeds.md` ("Seed spacing
//! across cell borders"), the radial distribution functions, and with `TERRAMP_SPACING_PNG=DIR`
//! draws the balanced preset's seeds around the busiest cell corner of each dataset's first view.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::path::Path;

use glam::DVec3;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::seeds::spacing::{BorderSpacing, RDF_BIN, RDF_BINS, quantile};
use terramp_testkit::camera::posed;

use support::{build_nc, build_zion};
use terramp_testkit::{TempDir, shared_data};

/// Least 1st-percentile nearest neighbour across a border over inside a cell: a seamless process
/// gives about 1 (the midline control gave 0.97–1.00); the patterns before the tile set, whose
/// neighbours shared nothing across a border, gave 0.24–0.32.
const MIN_BORDER_RATIO: f64 = 0.9;

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
    let placing = r.exact_placing(&camera);
    let cell_m = r.settings.tlm.cell_m;
    let mut xy = Vec::with_capacity(records.len());
    let mut cells = Vec::with_capacity(records.len());
    for s in &records {
        let grid = placing.grid_m(DVec3::from(s.position_rel_m.map(f64::from)));
        let p = [grid.x, grid.y];
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

/// Draws the seeds within `half_m` of the cell corner that has the most, one colour per cell,
/// borders in grey, and a black segment from each seed to its nearest neighbour where that is
/// closer than `close_m`, into `path`.
fn draw_corner(path: &Path, xy: &[[f64; 2]], cells: &[[i64; 2]], cell_m: f64, half_m: f64, close_m: f64) {
    let mut per_corner = std::collections::HashMap::<[i64; 2], usize>::new();
    for p in xy {
        let corner = p.map(|v| (v / cell_m).round() as i64);
        if (0..2).all(|a| (p[a] - corner[a] as f64 * cell_m).abs() < half_m) {
            *per_corner.entry(corner).or_default() += 1;
        }
    }
    let Some((&corner, _)) = per_corner.iter().max_by_key(|&(c, n)| (*n, std::cmp::Reverse(*c))) else {
        return;
    };
    let corner_m = corner.map(|v| v as f64 * cell_m);
    let near: Vec<usize> = (0..xy.len())
        .filter(|&i| (0..2).all(|a| (xy[i][a] - corner_m[a]).abs() < half_m + close_m))
        .collect();
    let size = 720i64;
    let mut img = image::RgbImage::from_pixel(size as u32, size as u32, image::Rgb([255, 255, 255]));
    let to_px = |p: [f64; 2]| {
        let f = |v: f64, a: usize| (v - corner_m[a] + half_m) / (2.0 * half_m) * size as f64;
        [f(p[0], 0), size as f64 - f(p[1], 1)]
    };
    let dot = |img: &mut image::RgbImage, [x, y]: [f64; 2], r: i64, colour: [u8; 3]| {
        for dy in -r..=r {
            for dx in -r..=r {
                let (qx, qy) = (x as i64 + dx, y as i64 + dy);
                if dx * dx + dy * dy <= r * r && (0..size).contains(&qx) && (0..size).contains(&qy) {
                    img.put_pixel(qx as u32, qy as u32, image::Rgb(colour));
                }
            }
        }
    };
    for k in 0..size {
        dot(&mut img, [(size / 2) as f64, k as f64], 0, [170, 170, 170]);
        dot(&mut img, [k as f64, (size / 2) as f64], 0, [170, 170, 170]);
    }
    for &i in &near {
        let d = |j: usize| (xy[j][0] - xy[i][0]).hypot(xy[j][1] - xy[i][1]);
        let Some(j) = near.iter().copied().filter(|&j| j != i).min_by(|&a, &b| d(a).total_cmp(&d(b))) else {
            continue;
        };
        if d(j) < close_m {
            let (a, b) = (to_px(xy[i]), to_px(xy[j]));
            for t in 0..=64 {
                let t = f64::from(t) / 64.0;
                dot(&mut img, [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t], 1, [0, 0, 0]);
            }
        }
    }
    let palette = [[200, 40, 40], [30, 110, 200], [30, 150, 60], [150, 60, 170]];
    for &i in &near {
        let c = cells[i];
        dot(&mut img, to_px(xy[i]), 4, palette[((c[0] & 1) + 2 * (c[1] & 1)) as usize]);
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
        let gpu = terramp_testkit::gpu();
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
                // The busiest cell corner, 40 m around it; pairs closer than the inside 1st percentile.
                let png = Path::new(&dir).join(format!("seeds_border_{name}.png"));
                draw_corner(&png, &xy, &cells, r.settings.tlm.cell_m, 40.0, quantile(&s.inside, 0.01));
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
        // Real distances: seeds at one point would make the inside quantile 0 and the ratio ∞.
        assert!(quantile(&s.inside, 0.01) > 0.0, "{name} {preset}: seeds at one point");
        assert!(
            ratio >= MIN_BORDER_RATIO,
            "{name} {preset}: 1st-percentile nearest neighbour across borders / inside = {ratio:.3}"
        );
    }
}
