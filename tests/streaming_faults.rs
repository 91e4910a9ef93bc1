//! Fault injection into tile streaming (`[faults]`): a flight whose reads fail, arrive corrupt or
//! late never shows a hole (ancestors stand in: no frame shows less ground than the same flight's
//! without faults), remembers exactly the tiles whose reads were made to fail, and keeps the
//! loader's queue within the caches' slots.
#![allow(clippy::unwrap_used, reason = "tests")]

use glam::DVec3;
use terramp::config::FaultSettings;
use terramp::dataset::Pyramid;
use terramp::streaming::faults::Fate;
use terramp::streaming::{Faults, LayerKind};
use terramp_testkit::camera::at_grid;
use terramp_testkit::{ground_settings, renderer, synth_dataset};

const FRAMES: usize = 100;

/// Every tile of `pyramid`.
fn tiles(pyramid: &Pyramid) -> impl Iterator<Item = terramp::dataset::TileId> + '_ {
    (0..pyramid.levels).flat_map(move |level| {
        let [nx, ny] = pyramid.tiles_at(level);
        (0..ny).flat_map(move |y| (0..nx).map(move |x| terramp::dataset::TileId::new(level, x, y)))
    })
}

/// What a flight saw: per frame, the pixels showing no ground; the failures counted; the longest
/// queue of one cache.
struct Flight {
    renderer: terramp::frame::Renderer,
    no_ground_px: Vec<usize>,
    failed: usize,
    worst_queue: usize,
}

/// Flies `FRAMES` frames with `faults` over ground that fills every view, checking that no pixel
/// is black and that each cache's queue fits its slots.
fn fly(faults: &FaultSettings) -> Flight {
    let dataset = synth_dataset(2048, 9);
    let mut settings = ground_settings(320, 180);
    settings.faults = *faults;
    let mut r = renderer(&dataset, settings);
    let [w, h] = r.dataset.manifest.extent_m();
    let (mut failed, mut worst_queue, mut no_ground_px) = (0usize, 0usize, Vec::new());
    for frame in 0..FRAMES {
        // Low and looking down across the dataset, so that every pixel must show ground.
        let f = frame as f64 / (FRAMES - 1) as f64;
        let at = DVec3::new((0.15 + 0.6 * f) * w, (0.2 + 0.5 * f) * h, 900.0);
        let camera = at_grid(&r, at, 45.0 + 30.0 * f, -60.0);
        let report = r.render(&camera).unwrap();
        let depth = r.read_depth().unwrap();
        no_ground_px.push(depth.iter().filter(|&&d| d == 0.0).count());
        let colour = r.read_colour().unwrap();
        let black = colour.pixels().filter(|p| p[0] == 0 && p[1] == 0 && p[2] == 0).count();
        assert_eq!(black, 0, "{faults:?} frame {frame}: {black} black pixels");
        for (stats, cache) in [report.height, report.imagery, report.landcover].iter().zip(r.tile_caches()) {
            failed += stats.failed;
            let queue = stats.in_flight + stats.staged;
            worst_queue = worst_queue.max(queue);
            assert!(
                queue <= cache.capacity(),
                "frame {frame}: {queue} tiles queued for {} slots",
                cache.capacity()
            );
        }
    }
    Flight { renderer: r, no_ground_px, failed, worst_queue }
}

#[test]
fn a_flight_over_failing_corrupt_and_slow_reads_shows_no_hole() {
    // The control: the same flight with no fault. It fails nothing, and shows ground everywhere
    // but for one pixel of frame 70, (214, 10): not a crack in the mesh but a sliver of LOD 1's
    // finishing morph that lavapipe's back-face cull drops though its rasteriser finds it
    // front-facing (the terrain pipeline's `cull_mode` says why the cull stays).
    let control = fly(&FaultSettings { fail: 0.0, corrupt: 0.0, delay_ms: 0, seed: 3 });
    assert_eq!(control.failed, 0);
    assert!(control.no_ground_px.iter().all(|&px| px <= 2), "{:?}", control.no_ground_px);
    let faults = FaultSettings { fail: 0.25, corrupt: 0.15, delay_ms: 12, seed: 3 };
    let Flight { renderer: r, no_ground_px, failed, worst_queue } = fly(&faults);
    for (frame, (&px, &control_px)) in no_ground_px.iter().zip(&control.no_ground_px).enumerate() {
        assert!(px <= control_px, "frame {frame}: {px} pixels show no ground, {control_px} without faults");
    }
    // The tiles remembered as failed are exactly those read and made to fail, some of each kind.
    let injected = Faults::new(&faults);
    let mut fates = Vec::new();
    for cache in r.tile_caches() {
        let layer = cache.layer();
        for id in tiles(cache.pyramid()).filter(|&id| cache.is_failed(id)) {
            let (fate, _) = injected.fate(layer, id);
            assert_ne!(fate, Fate::Read, "{layer} tile {id:?} failed with no fault injected");
            fates.push((layer, fate));
        }
    }
    assert_eq!(fates.len(), failed, "every failure counted once");
    assert!(fates.iter().any(|(_, f)| *f == Fate::Fail), "{fates:?}");
    assert!(fates.iter().any(|(_, f)| matches!(f, Fate::Corrupt { .. })), "{fates:?}");
    assert!(
        fates.iter().any(|(l, _)| *l == LayerKind::Height)
            && fates.iter().any(|(l, _)| *l == LayerKind::Imagery)
    );
    eprintln!("{failed} tiles failed over {FRAMES} frames; at most {worst_queue} tiles queued in one cache");
}
