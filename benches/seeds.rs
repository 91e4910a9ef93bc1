//! Seeds checked per second by pass 3 (seed selection) for about 100 k, 1 M and 4 M checked seeds
//! per frame, and its CPU twin's rate on the same input in the same run (gpu÷twin: how many times
//! faster the GPU pass is; the twin is one CPU thread). The default synthetic
//! dataset (10 km) is pinned whole, one resolved frame gives the depth, then pass 3 alone runs over
//! a square block of ring-0 cells around the camera (4096 seeds each; the nc table's densities ×4
//! so that nearly every rank can grow a seed and is really checked). Beside each size, the pass's
//! floor (`support/floor.rs`): a kernel that reads the pattern entries of the seeds checked and
//! the cells, and writes the records and block table pass 3 wrote, timed the same way (texture
//! fetches are not counted: heights and land cover are read through the caches' textures, shared
//! by neighbouring seeds). Prints a table; run with `WGPU_BACKEND=vulkan cargo bench --bench seeds`.
//! The camera stands 150 m above the ground, or `SEEDS_BENCH_ABOVE_M` metres (a flight's altitude:
//! fewer summits near a silhouette, and shorter occlusion marches).
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

#[path = "support/floor.rs"]
mod floor;

use std::path::Path;
use std::time::Instant;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::{SeedBlock, SeedCell, SeedRecord};
use terramp::gpu::layout::SEED_WORKGROUP;
use terramp::gpu::{AdapterChoice, Gpu};
use terramp::passes::seed_select::frame::SeedCellRef;
use terramp::seeds::cell_pattern;

const SEEDS_PER_PATTERN: u32 = 4096;
const GPU_RUNS: usize = 7;

/// The built-in nc table with every `per_km2` multiplied by `factor`.
fn dense_table(factor: f64) -> String {
    include_str!("../config/classes/nc.toml")
        .lines()
        .map(|line| match line.split_once("per_km2 = ") {
            Some((head, tail)) => {
                let (number, rest) =
                    tail.split_at(tail.find(|c: char| c != '.' && !c.is_ascii_digit()).unwrap_or(tail.len()));
                format!("{head}per_km2 = {:.1}{rest}", number.parse::<f64>().expect("a density") * factor)
            }
            None => line.to_owned(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn main() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-default");
    if Dataset::open(&dir).is_err() {
        terramp::synth::synthesize(&dir, &terramp::synth::SynthParams::default(), false).expect("synthesize");
    }
    let dataset = Dataset::open(&dir).expect("open");
    let mut settings = Settings::default();
    settings.seeds.seeds_per_pattern = SEEDS_PER_PATTERN;
    settings.seeds.capacity = 1 << 21;
    settings.tlm.radial_bands_m = [3000.0, 6000.0, 12000.0];
    settings.draw_seeds.reach_m = [120.0, 3000.0, 6000.0, 12000.0];
    // The nc table with every density × 4 (forest 62,000 per km²): nearly every rank of a pattern
    // can grow a seed, so the checked seeds are real work and 4 M of them fit the 10 km dataset.
    let dense = dense_table(4.0);
    let table_path = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-seeds-dense.toml");
    std::fs::write(&table_path, dense).expect("write the dense table");
    settings.seeds.class_table = table_path.to_str().expect("a UTF-8 path").to_owned();
    let tiles = |p: Option<&terramp::dataset::LayerPack>| p.map_or(1, |l| l.pyramid.tile_count() as u32);
    settings.cache.height_slots = tiles(Some(&dataset.height)).max(16);
    settings.cache.imagery_slots = tiles(dataset.imagery.as_ref()).max(16);
    settings.cache.landcover_slots = tiles(dataset.landcover.as_ref()).max(16);
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter");
    println!("adapter: {}", gpu.describe());
    let mut r = Renderer::new(gpu, dataset, settings).expect("renderer");
    r.pin_everything().expect("the dataset fits its caches");
    let m = &r.dataset.manifest;
    let [w, h] = m.extent_m();
    let centre = [0.5 * w, 0.5 * h];
    let ground = r.dataset.height_at(centre[0], centre[1], 0).expect("height");
    let above_m: f64 = std::env::var("SEEDS_BENCH_ABOVE_M").map_or(150.0, |v| v.parse().expect("metres"));
    println!("camera {above_m} m above the ground");
    let camera = Camera {
        position_m: DVec3::new(m.origin_m[0] + centre[0], m.origin_m[1] + centre[1], ground + above_m),
        yaw_deg: 30.0,
        pitch_deg: -20.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: 0.1,
    };
    r.render_resolved(&camera).expect("render");
    let cell_m = r.settings.tlm.cell_m;
    // Pass 3 checks only the ranks some class can grow (the densest class's share of a pattern).
    let ranks = r.seed_world().expect("land cover").0.active_ranks();
    println!("{ranks} of {SEEDS_PER_PATTERN} ranks per cell can grow a seed");
    let (seed, colours) = (r.settings.tlm.seed, r.settings.tlm.corner_colours());
    println!(
        "{:>10} {:>7} {:>10} {:>12} {:>14} {:>12} {:>14} {:>8} {:>10} {:>8}",
        "checked",
        "cells",
        "selected",
        "gpu ms",
        "gpu seeds/s",
        "twin ms",
        "twin seeds/s",
        "gpu÷twin",
        "floor ms",
        "÷floor"
    );
    for target in [100_000u64, 1_000_000, 4_000_000] {
        let side = ((target as f64 / f64::from(ranks)).sqrt().round() as i64).max(1);
        let camera_cell = centre.map(|v| (v / cell_m).floor() as i64);
        let cells: Vec<SeedCellRef> = (0..side * side)
            .map(|k| {
                let address = [camera_cell[0] - side / 2 + k % side, camera_cell[1] - side / 2 + k / side];
                let distance_m = (((address[0] as f64 + 0.5) * cell_m - centre[0])
                    .hypot((address[1] as f64 + 0.5) * cell_m - centre[1]))
                .max(0.0);
                let radial_lod =
                    r.settings.tlm.radial_bands_m.iter().filter(|&&t| distance_m >= t).count() as u32;
                SeedCellRef {
                    address,
                    pattern: cell_pattern([address[0] as i32, address[1] as i32], seed, colours),
                    radial_lod: radial_lod.min(2),
                }
            })
            .collect();
        let checked = cells.len() as u64 * u64::from(ranks);
        r.run_seed_select(&camera, &cells).expect("warm-up");
        let mut gpu_ms: Vec<f64> = (0..GPU_RUNS)
            .map(|_| {
                let start = Instant::now();
                r.run_seed_select(&camera, &cells).expect("seed select");
                start.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        gpu_ms.sort_by(f64::total_cmp);
        let gpu_ms = gpu_ms[GPU_RUNS / 2];
        let (_, counters) = r.read_seeds().expect("read back").expect("land cover");
        let snapshot = r.seed_snapshot().expect("snapshot").expect("land cover");
        let start = Instant::now();
        let (_, twin) = terramp::reference::seed_select::seed_select(&snapshot.inputs());
        let twin_ms = start.elapsed().as_secs_f64() * 1e3;
        assert_eq!(twin, counters, "the twin disagrees with the GPU");
        let rate = |ms: f64| checked as f64 / (ms * 1e-3);
        // Each checked seed reads its pattern entry (8 bytes); each workgroup writes a block.
        let blocks = cells.len() as u64 * u64::from(ranks.div_ceil(SEED_WORKGROUP));
        let in_bytes = checked * 8 + cells.len() as u64 * size_of::<SeedCell>() as u64;
        let out_bytes = u64::from(counters.selected) * size_of::<SeedRecord>() as u64
            + blocks * size_of::<SeedBlock>() as u64;
        let floor = floor::Floor::new(&r.gpu, in_bytes, out_bytes);
        let floor_ms = floor::median_ms(&r.gpu, GPU_RUNS, |e| floor.encode(e));
        println!(
            "{:>10} {:>7} {:>10} {:>12.2} {:>14.3e} {:>12.1} {:>14.3e} {:>8.2} {:>10.3} {:>8.2}",
            checked,
            cells.len(),
            counters.selected,
            gpu_ms,
            rate(gpu_ms),
            twin_ms,
            rate(twin_ms),
            twin_ms / gpu_ms,
            floor_ms,
            gpu_ms / floor_ms
        );
    }
}
