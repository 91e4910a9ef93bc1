//! Time to render one warm frame (terrain pass, submit, wait) of the default synthetic dataset at
//! 1280 × 720, from the demo's first pose and a low grazing pose. Run with
//! `WGPU_BACKEND=vulkan cargo bench --bench frame`; the dataset is synthesized into the target dir
//! on first use.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

use std::path::Path;

use criterion::{Criterion, criterion_group, criterion_main};
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::{AdapterChoice, Gpu};

fn renderer() -> Renderer {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-default");
    if Dataset::open(&dir).is_err() {
        terramp::synth::synthesize(&dir, &terramp::synth::SynthParams::default(), false).expect("synthesize");
    }
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter");
    eprintln!("adapter: {}", gpu.describe());
    Renderer::new(gpu, Dataset::open(&dir).expect("open"), Settings::default()).expect("renderer")
}

fn pose(renderer: &Renderer, above_m: f64, pitch_deg: f64) -> Camera {
    terramp_testkit::camera::over_fraction(renderer, [0.3, 0.3], above_m, 45.0, pitch_deg)
}

fn frame(c: &mut Criterion) {
    let mut renderer = renderer();
    let mut group = c.benchmark_group("frame_1280x720");
    group.sample_size(10);
    for (name, above_m, pitch_deg) in [("oblique_120m", 120.0, -12.0), ("grazing_2m", 2.0, 0.0)] {
        let camera = pose(&renderer, above_m, pitch_deg);
        // Warm up: shaders compile and tiles load on the first frames.
        for _ in 0..3 {
            renderer.render(&camera).expect("render");
        }
        group.bench_function(name, |b| {
            b.iter(|| {
                renderer.render(&camera).expect("render");
                renderer.gpu.wait().expect("wait");
            })
        });
    }
    group.finish();
}

criterion_group!(benches, frame);
criterion_main!(benches);
