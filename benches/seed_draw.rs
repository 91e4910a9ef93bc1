//! Seed selection (pass 3), compaction and drawing (pass 4) for a fixed camera over the default
//! synthetic dataset at 1280 × 720, balanced preset: the view is rendered until every tile is
//! resident, then the last frame's terrain depth is replayed alone, then with pass 3 and
//! compaction, then with the draw too (`Renderer::replay_seed_passes`): each stage's cost is the
//! difference from the one before. Throughput is in seeds checked per second. The nc table's models are baked from `../shared/data/models` into the target dir
//! on first use. Run with `WGPU_BACKEND=vulkan cargo bench --bench seed_draw`.
#![allow(clippy::unwrap_used, reason = "a benchmark that cannot set up has nothing to measure")]

use std::path::{Path, PathBuf};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::{Renderer, Replay};
use terramp::gpu::{AdapterChoice, Gpu};

fn dataset_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-default");
    if Dataset::open(&dir).is_err() {
        terramp::synth::synthesize(&dir, &terramp::synth::SynthParams::default(), false).expect("synthesize");
    }
    dir
}

/// The nc table's species, baked once into the target dir.
fn impostors() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bench-impostors");
    let models = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/models");
    let table = terramp::classes::ClassTable::load("nc").expect("nc table");
    let names: Vec<&str> = table.species.iter().map(|s| s.model.as_str()).collect();
    let options = terramp::bake::BakeOptions::default();
    let missing = terramp::bake::bake_missing(None, &models, &names, &dir, &options, false).expect("bake");
    assert!(missing.absent.is_empty(), "models missing: {:?}", missing.absent);
    dir
}

/// A renderer over forest and fields, 120 m up looking ahead and down, with everything resident
/// and the seeds of the final TLM selected.
fn renderer() -> Renderer {
    let mut settings = Settings::default();
    settings.draw_seeds.impostors = impostors().display().to_string();
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter");
    eprintln!("adapter: {}", gpu.describe());
    let dataset = Dataset::open(&dataset_dir()).expect("open");
    let mut renderer = Renderer::new(gpu, dataset, settings).expect("renderer");
    let m = &renderer.dataset.manifest;
    let [w, h] = m.extent_m();
    let grid = [0.3 * w, 0.3 * h];
    let ground = renderer.dataset.height_at(grid[0], grid[1], 0).expect("height");
    let camera = Camera {
        position_m: DVec3::new(m.origin_m[0] + grid[0], m.origin_m[1] + grid[1], ground + 120.0),
        yaw_deg: 45.0,
        pitch_deg: -12.0,
        roll_deg: 0.0,
        fov_deg: renderer.settings.render.fov_deg,
        near_m: renderer.settings.render.near_m,
    };
    renderer.render_resolved(&camera).expect("resolve");
    for _ in 0..3 {
        renderer.render(&camera).expect("render");
    }
    renderer
}

fn seed_passes(c: &mut Criterion) {
    let mut renderer = renderer();
    renderer.replay_seed_passes(Replay::Draw).expect("seed passes");
    let (_, counters) = renderer.read_seeds().expect("read seeds").expect("seeds");
    let drawn = renderer.read_compacted().expect("read").expect("compacted").drawn();
    eprintln!(
        "fixed camera: {} seeds checked, {} selected, {drawn} drawn",
        counters.checked, counters.selected
    );
    let mut group = c.benchmark_group("seed_passes");
    group.sample_size(10);
    group.throughput(Throughput::Elements(counters.checked.into()));
    for (name, through) in [
        ("depth", Replay::Depth),
        ("depth+select+compact", Replay::Select),
        ("depth+select+compact+draw", Replay::Draw),
    ] {
        group.bench_function(name, |b| b.iter(|| renderer.replay_seed_passes(through).expect("seed passes")));
    }
    group.finish();
}

criterion_group!(benches, seed_passes);
criterion_main!(benches);
