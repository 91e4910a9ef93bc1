//! terramp on a device the host made (`Gpu::from_host`), on the tests' adapter:
//! - a device made with exactly `passes::limits::needed_limits()` holds every pass (wgpu's
//!   default error handler, which this device keeps, panics on any pipeline beyond its limits),
//!   and a renderer on it draws the frame a renderer on terramp's own device draws, trees and all;
//! - a device made with wgpu's default limits is refused by `Renderer::new`, naming the limit,
//!   before any pipeline is made.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::dataset::Dataset;
use terramp::frame::{RenderError, Renderer};
use terramp::gpu::Gpu;
use terramp::passes::limits::needed_limits;
use terramp_testkit::{camera, differing_pixels, gpu, lavapipe_only, psnr, small_settings, synth_dataset};

/// Least PSNR between the two devices' frames off lavapipe, dB (on lavapipe they are compared
/// pixel for pixel).
const SAME_FRAME_PSNR_DB: f64 = 40.0;

/// A device the host makes on terramp's adapter with `limits` and the features terramp uses.
fn host_device(limits: wgpu::Limits) -> Gpu {
    let adapter = gpu().adapter;
    let wanted = wgpu::Features::INDIRECT_FIRST_INSTANCE
        | wgpu::Features::TEXTURE_COMPRESSION_BC
        | wgpu::Features::TIMESTAMP_QUERY
        | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
        | wgpu::Features::PIPELINE_STATISTICS_QUERY;
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("the host's device"),
        required_features: adapter.features() & wanted,
        required_limits: limits,
        ..Default::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&descriptor)).unwrap();
    Gpu::from_host(adapter, device, queue)
}

#[test]
fn a_host_device_with_the_needed_limits_draws_what_terramps_own_device_draws() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    let mut settings = small_settings(256, 144);
    settings.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
    let needed = needed_limits();
    println!(
        "needed per stage: {} storage buffers, {} uniform buffers, {} sampled textures, {} storage \
         textures, {} samplers; {} bind groups",
        needed.max_storage_buffers_per_shader_stage,
        needed.max_uniform_buffers_per_shader_stage,
        needed.max_sampled_textures_per_shader_stage,
        needed.max_storage_textures_per_shader_stage,
        needed.max_samplers_per_shader_stage,
        needed.max_bind_groups
    );
    let draw = |gpu: Gpu| {
        let mut r = Renderer::new(gpu, Dataset::open(&dir).unwrap(), settings.clone()).unwrap();
        let pose = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
        // Pass 3's counters come back a frame or two late.
        for _ in 0..2 {
            r.render_resolved(&pose).unwrap();
        }
        let (report, _) = r.render_resolved(&pose).unwrap();
        (r.read_colour().unwrap(), report.seeds.unwrap().counters.selected, r.gpu)
    };
    let (host_frame, host_selected, host_gpu) = draw(host_device(needed));
    let (own_frame, own_selected, _) = draw(gpu());
    println!("seeds selected: host's device {host_selected}, terramp's {own_selected}");
    assert!(host_selected > 100, "the view must draw trees: {host_selected}");
    assert_eq!(host_selected, own_selected);
    if lavapipe_only(&host_gpu, "the two devices' frames pixel for pixel") {
        assert_eq!(differing_pixels(&host_frame, &own_frame), 0);
    } else {
        let db = psnr(&host_frame, &own_frame);
        assert!(db >= SAME_FRAME_PSNR_DB, "{db:.1} dB");
    }
}

#[test]
fn a_host_device_short_of_a_limit_is_refused_naming_it() {
    // wgpu's defaults allow 8 storage buffers per stage; seed selection binds more.
    let defaults = wgpu::Limits::default();
    let needed = needed_limits();
    assert!(needed.max_storage_buffers_per_shader_stage > defaults.max_storage_buffers_per_shader_stage);
    let host = host_device(defaults.clone());
    let dir = synth_dataset(64, 3);
    let refused = Renderer::new(host, Dataset::open(&dir).unwrap(), small_settings(64, 36));
    let Err(RenderError::Limits(short)) = refused else {
        panic!("a device short of a limit was not refused for it")
    };
    assert_eq!(short.name, "max_storage_buffers_per_shader_stage");
    assert_eq!(short.has, u64::from(defaults.max_storage_buffers_per_shader_stage));
    println!("{short}");
}

#[test]
fn the_page_quotes_the_limits_the_tables_give() {
    // docs/host.md states what `needed_limits` computes; a binding added or removed changes it.
    let page = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/host.md")).unwrap();
    let page = page.split_whitespace().collect::<Vec<_>>().join(" ");
    let n = needed_limits();
    let quote = format!(
        "at most {} storage buffers (seed selection's settle step), {} uniform buffers, {} sampled \
         textures, {} storage textures and {} samplers, in {} bind groups",
        n.max_storage_buffers_per_shader_stage,
        n.max_uniform_buffers_per_shader_stage,
        n.max_sampled_textures_per_shader_stage,
        n.max_storage_textures_per_shader_stage,
        n.max_samplers_per_shader_stage,
        n.max_bind_groups
    );
    assert!(page.contains(&quote), "docs/host.md should say: {quote}");
    let refusal = format!("and terramp's passes need {}`", n.max_storage_buffers_per_shader_stage);
    assert!(page.contains(&refusal), "docs/host.md should say: {refusal}");
}
