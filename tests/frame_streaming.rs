//! Streaming through whole frames on the software adapter: a fixed view converges to everything
//! it needs and then looks like an all-resident reference; budgets and capacities hold over a
//! flight; a corrupt tile is reported, stood in for by its ancestor, and the frames still render.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::{Path, PathBuf};

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::{FrameReport, Renderer};

use terramp_testkit::camera::over_fraction;
use terramp_testkit::{ground_settings, psnr, renderer, synth_dataset};

/// The view the convergence test looks at: low over the dataset's south-west quarter, looking
/// north-east across it, so near tiles want fine imagery and far ones coarse.
fn view(r: &Renderer) -> Camera {
    over_fraction(r, [0.2, 0.25], 60.0, 40.0, -8.0)
}

/// Settings that make streaming visible: a few uploads per frame, one loader thread.
fn trickle(width: u32, height: u32) -> Settings {
    let mut settings = ground_settings(width, height);
    settings.cache.upload_tiles_per_frame = 2;
    settings.cache.loader_threads = 1;
    settings
}

#[test]
fn a_fixed_view_converges_to_the_all_resident_picture() {
    let dataset = synth_dataset(1200, 11);
    let mut streamed = renderer(&dataset, trickle(192, 108));
    let camera = view(&streamed);
    // The first frame, drawn from the pinned coarse levels before anything streamed: the control.
    streamed.render(&camera).unwrap();
    let first = streamed.read_colour().unwrap();
    let (report, frames) = streamed.render_resolved(&camera).unwrap();
    assert!(streamed.is_resolved(&report), "not resolved after {frames} frames: {report:?}");
    assert!(frames > 2, "with 2 uploads a frame, streaming takes several frames ({frames})");
    for stats in [&report.height, &report.imagery] {
        assert_eq!(stats.needed_resident, stats.needed, "{stats:?}");
    }
    // Once converged, nothing more moves.
    let settled = streamed.render(&camera).unwrap();
    assert_eq!(settled.height.uploaded + settled.imagery.uploaded, 0, "{settled:?}");

    let mut all = ground_settings(192, 108);
    all.cache.imagery_slots = 160;
    all.cache.landcover_slots = 160;
    let mut reference = renderer(&dataset, all);
    reference.pin_everything().unwrap();
    reference.render_resolved(&camera).unwrap();
    let all_resident = reference.read_colour().unwrap();
    let db = psnr(&streamed.read_colour().unwrap(), &all_resident);
    let first_db = psnr(&first, &all_resident);
    println!(
        "converged after {frames} more frames; PSNR against all-resident: {db:.1} dB (first frame {first_db:.1} dB)"
    );
    assert!(db >= CONVERGED_PSNR_DB, "PSNR {db:.1} dB");
    // Control: the frame before streaming, coarse where the view needs fine tiles, fails it.
    assert!(first_db < CONVERGED_PSNR_DB, "the first frame is already at {first_db:.1} dB: a weak test");
}

/// Least PSNR of the converged frame against the all-resident one, dB: the Tile Load Map asks for
/// at least the levels the pixels use, so the pictures agree (on lavapipe bit for bit); the bound
/// leaves room for an adapter whose filtering differs where a finer level than the pixels need is
/// resident in one and not the other. The first frame, before streaming, is at 32.8 dB.
const CONVERGED_PSNR_DB: f64 = 40.0;

/// Checks one frame's report against the settings' capacities and budgets.
fn check_budgets(report: &FrameReport, settings: &Settings) {
    let c = &settings.cache;
    for (stats, slots) in [
        (&report.height, c.height_slots),
        (&report.imagery, c.imagery_slots),
        (&report.landcover, c.landcover_slots),
    ] {
        assert!(stats.resident <= slots as usize, "frame {}: {stats:?}", report.frame);
        // The first tile of a frame always goes, whatever its size.
        assert!(
            stats.uploaded <= (c.upload_tiles_per_frame as usize).max(1),
            "frame {}: {stats:?}",
            report.frame
        );
        assert!(
            stats.uploaded <= 1 || stats.bytes_uploaded <= c.upload_bytes_per_frame,
            "frame {}: {stats:?}",
            report.frame
        );
        assert!(stats.needed_resident <= stats.needed && stats.needed_resident <= stats.resident);
    }
}

#[test]
fn budgets_and_capacities_hold_over_a_flight() {
    let dataset = synth_dataset(1200, 11);
    let mut settings = trickle(128, 72);
    settings.cache.height_slots = 16;
    settings.cache.imagery_slots = 16;
    let mut r = renderer(&dataset, settings.clone());
    let start = view(&r);
    let (mut uploads, mut evictions) = (0, 0);
    for i in 0..60 {
        let t = f64::from(i) / 59.0;
        // Across the dataset and turning: the caches must evict to follow.
        let camera = Camera {
            position_m: start.position_m + DVec3::new(4000.0 * t, 3000.0 * t, 200.0 * t),
            yaw_deg: 40.0 + 120.0 * t,
            ..start
        };
        let report = r.render(&camera).unwrap();
        check_budgets(&report, &settings);
        assert!(report.nodes_drawn > 0 && report.nodes_dropped == 0, "{report:?}");
        uploads += report.height.uploaded + report.imagery.uploaded;
        evictions += report.height.evicted + report.imagery.evicted;
    }
    // The 16-slot caches cannot hold the flight's tiles: following it means evicting.
    assert!(uploads > 16 && evictions > 0, "the flight streamed ({uploads} uploads, {evictions} evictions)");
}

/// A copy of `dataset` with bytes flipped inside one level-0 tile of `pack`.
fn corrupted_copy(dataset: &Path, pack: &str, name: &str) -> PathBuf {
    let copy = dataset.with_file_name(format!("{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&copy);
    std::fs::create_dir_all(&copy).unwrap();
    for entry in std::fs::read_dir(dataset).unwrap() {
        let entry = entry.unwrap();
        std::fs::copy(entry.path(), copy.join(entry.file_name())).unwrap();
    }
    let path = copy.join(pack);
    // Tile 0: level 0, the south-west corner.
    let span = terramp::dataset::Pack::open(&path).unwrap().stored_span(0).unwrap();
    let mut bytes = std::fs::read(&path).unwrap();
    let middle = (span.start + span.end) as usize / 2;
    for b in &mut bytes[middle..(middle + 40).min(span.end as usize)] {
        *b ^= 0x5a;
    }
    std::fs::write(&path, bytes).unwrap();
    copy
}

#[test]
fn a_corrupt_tile_is_reported_and_the_frame_still_renders() {
    let dataset = synth_dataset(1200, 11);
    for pack in ["imagery.pack", "height.pack"] {
        let copy = corrupted_copy(&dataset, pack, &format!("corrupt-{}", pack.replace('.', "-")));
        let mut r = renderer(&copy, ground_settings(128, 72));
        // Low over the corrupted south-west corner, looking into the dataset.
        let m = r.dataset.manifest.clone();
        let camera = Camera {
            position_m: DVec3::new(
                m.origin_m[0] + 200.0,
                m.origin_m[1] + 200.0,
                f64::from(m.height.max_m) + 30.0,
            ),
            yaw_deg: 45.0,
            pitch_deg: -30.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
            near_m: 0.1,
        };
        let mut failed = 0;
        for _ in 0..40 {
            let report = r.render(&camera).unwrap();
            failed += report.height.failed + report.imagery.failed;
            assert!(report.nodes_drawn > 0 && report.nodes_dropped == 0, "{pack}: {report:?}");
        }
        assert_eq!(failed, 1, "{pack}: the corrupt tile is found once, and only it");
        let depth = r.read_depth().unwrap();
        assert!(depth[depth.len() / 2..].iter().all(|&d| d > 0.0), "{pack}: the ground has no hole");
        std::fs::remove_dir_all(&copy).unwrap();
    }
}
