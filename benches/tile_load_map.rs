//! Pass 1's figures at 1280×720 with the default settings, and rings of 32, 64 (the default) and
//! 128 cells a side: the Tile Load Map's and the depth pyramid's GPU times (timestamp queries),
//! the CPU preparation of a frame (layout, uniforms, spans) and the twin's CPU time, for a view
//! over a synthetic dataset and one from 40 km away (four rings). Beside the pass, its floor
//! (`support/floor.rs`), timed the same way: a kernel reading what the pass reads per cell (the
//! 2 × 2 depth-pyramid texels of its screen rectangle and its height tile's range) and writing its
//! cells. `cargo bench --bench tile_load_map`.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

#[path = "support/floor.rs"]
mod floor;

use std::time::Instant;

use glam::DVec3;
use terramp::config::Settings;
use terramp::gpu::counter::Counting;
use terramp::gpu::gpu_types::TlmCell;
use terramp::gpu::{Profiler, TimeSource};
use terramp::passes::depth_pyramid::gpu::DepthPyramid;
use terramp::passes::tile_load_map::frame::{TlmImagery, TlmInputs, height_tile_ranges};
use terramp::passes::tile_load_map::gpu::TileLoadMapPass;
use terramp::reference::tile_load_map::tile_load_map;
use terramp_testkit::camera::{at_grid as camera_at, over};
use terramp_testkit::renderer;
use terramp_testkit::tlm::{assert_gpu_equals_twin, run, visible};

fn main() {
    let dataset = terramp_testkit::synth_dataset(1024, 5);
    for cells in [32, 64, 128] {
        let mut settings = Settings::default();
        settings.tlm.cells = cells;
        bench(renderer(&dataset, settings));
    }
}

/// The figures of `r`'s settings, near and far.
fn bench(mut r: terramp::frame::Renderer) {
    let [w, h] = r.dataset.manifest.extent_m();
    let ranges = height_tile_ranges(&r.dataset);
    let near = over(&r, [0.2 * w, 0.2 * h], 300.0, 45.0, -12.0);
    // 40 km south-west of the dataset: four rings to reach it.
    let far = camera_at(&r, DVec3::new(-40_000.0, -40_000.0, 3000.0), 45.0, -3.0);
    for camera in [near, far] {
        let warm = run(&mut r, &camera, &ranges);
        assert_gpu_equals_twin(&warm, "timing");
        let s = r.settings.clone();
        let device = &r.gpu.device;
        let hiz = DepthPyramid::new(device, s.render.width, s.render.height);
        let pass = TileLoadMapPass::new(device, &s);
        let bindings = pass.bind_group(device, &warm.ranges, &hiz);
        let imagery = TlmImagery::of(&r.dataset, &s.imagery);
        let inputs = TlmInputs {
            settings: &s.tlm,
            layout: &warm.layout,
            camera: &camera,
            camera_grid_m: warm.camera_grid_m,
            viewport_px: [s.render.width, s.render.height],
            lods: &warm.lods,
            imagery,
            hiz_mips: hiz.mips(),
            earth: r.tlm_earth(&camera),
        };
        let prepare_start = Instant::now();
        pass.prepare(&r.gpu.queue, &inputs).unwrap();
        let prepare_ms = prepare_start.elapsed().as_secs_f64() * 1000.0;
        let cell_count = u64::from(warm.layout.rings) * u64::from(warm.layout.cells).pow(2);
        // Per cell: 2 × 2 depth-pyramid texels and its height tile's range (two f32s).
        let floor =
            floor::Floor::new(&r.gpu, cell_count * (4 * 4 + 8), cell_count * size_of::<TlmCell>() as u64);
        let mut profiler = Profiler::new(&r.gpu, true);
        let depth = r.depth_texture().create_view(&Default::default());
        let mut frames = Vec::new();
        for _ in 0..12 {
            let mut encoder = device.create_command_encoder(&Default::default());
            profiler.pass(&r.gpu, &mut encoder, "hiz", |e| hiz.encode(e, &depth, Counting::OFF)).unwrap();
            profiler
                .pass(&r.gpu, &mut encoder, "tlm", |e| pass.encode(e, &bindings, &warm.frame, Counting::OFF))
                .unwrap();
            profiler.pass(&r.gpu, &mut encoder, "floor", |e| floor.encode(e)).unwrap();
            profiler.resolve(&mut encoder);
            r.gpu.queue.submit([encoder.finish()]);
            profiler.end_frame();
            r.gpu.wait().unwrap();
            frames.extend(std::iter::from_fn(|| profiler.finished_frame(&r.gpu)));
        }
        frames.extend(profiler.drain(&r.gpu).unwrap());
        println!(
            "{} rings × {}² cells, {} visible; prepare (layout, uniforms, spans) {prepare_ms:.3} ms",
            warm.layout.rings,
            warm.layout.cells,
            visible(&warm.gpu)
        );
        let median_ms = |label: &str| {
            let mut ms: Vec<f64> =
                frames.iter().flatten().filter(|t| t.label == label).map(|t| t.ms).collect();
            ms.sort_by(f64::total_cmp);
            let source = frames.iter().flatten().find(|t| t.label == label).map(|t| t.source);
            println!("  {label}: median {:.3} ms over {} frames ({source:?})", ms[ms.len() / 2], ms.len());
            assert!(source.is_some_and(|s| s != TimeSource::Cpu));
            ms[ms.len() / 2]
        };
        let (_, tlm_ms, floor_ms) = (median_ms("hiz"), median_ms("tlm"), median_ms("floor"));
        println!("  tlm ÷ floor: {:.2} ({cell_count} cells)", tlm_ms / floor_ms);
        let mut twin_ms: Vec<f64> = (0..5)
            .map(|_| {
                let start = Instant::now();
                std::hint::black_box(tile_load_map(
                    &warm.frame.uniforms,
                    &warm.frame.spans,
                    &warm.ranges,
                    &warm.hiz,
                ));
                start.elapsed().as_secs_f64() * 1000.0
            })
            .collect();
        twin_ms.sort_by(f64::total_cmp);
        println!("  twin (CPU, one thread): median {:.3} ms", twin_ms[2]);
    }
}
