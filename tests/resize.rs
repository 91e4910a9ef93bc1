//! `Renderer::resize`: resizing is a call on a running renderer, not a new renderer. Over a
//! synthetic dataset with the shared trees drawn multisampled and their fragments counted (both
//! sized by the frame), a renderer resized from 256 × 144 to 200 × 120:
//! - keeps its tiles: its first frame after the resize has every tile it had before, more than a
//!   fresh renderer's first frame has;
//! - draws what a renderer made at 200 × 120 draws once both have settled: the same terrain nodes
//!   and seed counters, the image within a stated PSNR (the running one may keep finer tiles
//!   resident than the fresh one asked for); control: the fresh one turned by half a degree
//!   falls below it;
//! - refuses a size the adapter cannot hold, and draws on at its size after the refusal.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::camera::Camera;
use terramp::frame::{FrameReport, RenderError, Renderer};
use terramp_testkit::{camera, psnr, renderer, small_settings, synth_dataset};

/// Least PSNR between the resized renderer's frame and a fresh one's at the same size, dB.
const SAME_FRAME_PSNR_DB: f64 = 40.0;

/// Tiles resident after a frame, of the three caches.
fn resident(report: &FrameReport) -> usize {
    report.height.resident + report.imagery.resident + report.landcover.resident
}

/// What a settled frame draws and counts, and its image.
fn settled(r: &mut Renderer, pose: &Camera) -> (String, image::RgbaImage) {
    // Pass 3's counters come back a frame or two late.
    for _ in 0..2 {
        r.render_resolved(pose).unwrap();
    }
    let (report, _): (FrameReport, u32) = r.render_resolved(pose).unwrap();
    let counters = serde_json::to_string(&report.seeds.map(|s| s.counters)).unwrap();
    (format!("nodes {} seeds {counters}", report.nodes_drawn), r.read_colour().unwrap())
}

#[test]
fn a_resized_renderer_keeps_its_tiles_and_draws_what_one_made_at_that_size_draws() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    let mut settings = small_settings(256, 144);
    settings.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
    settings.draw_seeds.samples = 4;
    settings.gpu.count_fragments = true;
    let mut running = renderer(&dir, settings.clone());
    let pose = camera::over_fraction(&running, [0.45, 0.35], 25.0, 20.0, -10.0);
    let (before, _) = running.render_resolved(&pose).unwrap();

    let max = running.gpu.device.limits().max_texture_dimension_2d;
    assert!(matches!(running.resize(max + 1, 120), Err(RenderError::ViewportTooLarge { .. })));
    assert!(matches!(running.resize(0, 120), Err(RenderError::Camera(_))));
    let refused = running.render(&pose).unwrap();
    assert_eq!(running.read_colour().unwrap().dimensions(), (256, 144));

    running.resize(200, 120).unwrap();
    let first = running.render(&pose).unwrap();
    println!(
        "tiles resident: {} before the resize, {} after the refusals, {} at its first frame",
        resident(&before),
        resident(&refused),
        resident(&first)
    );
    assert!(resident(&first) >= resident(&before));
    let (counts, image) = settled(&mut running, &pose);
    assert_eq!(image.dimensions(), (200, 120));

    (settings.render.width, settings.render.height) = (200, 120);
    let mut fresh = renderer(&dir, settings);
    let fresh_first = fresh.render(&pose).unwrap();
    println!("a fresh renderer's first frame: {} tiles resident", resident(&fresh_first));
    assert!(resident(&fresh_first) < resident(&first));
    let (fresh_counts, fresh_image) = settled(&mut fresh, &pose);
    let db = psnr(&image, &fresh_image);
    println!("resized against made at 200 × 120: {db:.1} dB; {counts} | {fresh_counts}");
    assert_eq!(counts, fresh_counts);
    assert!(db >= SAME_FRAME_PSNR_DB, "{db:.1} dB");
    // Control: half a degree of turn is seen.
    let turned = camera::over_fraction(&fresh, [0.45, 0.35], 25.0, 20.5, -10.0);
    let (_, turned_image) = settled(&mut fresh, &turned);
    let control_db = psnr(&turned_image, &fresh_image);
    println!("turned by half a degree: {control_db:.1} dB");
    assert!(control_db < SAME_FRAME_PSNR_DB, "{control_db:.1} dB");
}
