//! A guard against per-frame leaks on the path every frame with seeds takes: three orbits of
//! `ORBIT` frames round a synthetic dataset with trees drawn (the shared models' impostors), the
//! wind swaying them and cloud shadows drifting, so that every frame uploads new constants to the
//! terrain, pass 3 and `draw_seeds`. Lavapipe keeps a shader variant per distinct value set of the
//! uniforms that steer a shader's loops and branches: the TLM once leaked 0.55 MiB a frame that
//! way, and `draw_seeds` 0.35 MiB (at three times the frame time) until its constants moved to a
//! storage buffer.
//!
//! The first orbit warms up: every tile and view of the flight is met once, every cache slot
//! written. The second and third fly the same frames again, so without a leak they hold the same
//! memory: the floor of the anonymous resident memory over the third orbit may not rise above the
//! second's by more than `MAX_ANON_GROWTH_KIB`, which a leak of 0.05 MiB a frame (7.5 MiB over an
//! orbit) exceeds. The long soak (10,000 frames, memory every 100) is `scripts/soak.sh`.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::time::Instant;

use terramp::profile::orbit_path;
use terramp_testkit::memory::{floor, memory, mib};
use terramp_testkit::{renderer, small_settings, synth_dataset};

/// Frames per orbit: a leak of 0.05 MiB a frame adds 7.5 MiB over one, above the bound.
const ORBIT: usize = 150;
/// Small frames: the software rasteriser's share of the wall time stays low; the seeds' passes
/// still run over every cell the view needs.
const SIZE: [u32; 2] = [192, 108];
/// Allowed rise of the anonymous-memory floor from the second orbit to the third: measured
/// without a leak −0.2 MiB (598.3 → 598.1), with the uniform binding's leak +86.8 MiB (689.7 →
/// 776.5, docs/streaming.md); 6 MiB is room for the allocator's slack, under the 7.5 MiB that
/// one orbit of a 0.05 MiB-a-frame leak adds (`ORBIT`).
const MAX_ANON_GROWTH_KIB: u64 = 6 * 1024;
/// Cache slots: few enough that every slot is written during the first orbit (lavapipe's texture
/// memory becomes resident when first written), enough for every frame's tiles at this size.
const SLOTS: [u32; 3] = [64, 32, 16];

#[test]
fn a_flight_with_seeds_wind_and_clouds_keeps_memory_flat() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(600, 3);
    let mut settings = small_settings(SIZE[0], SIZE[1]);
    settings.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
    // Billboard clouds only: meshes cost lavapipe's vertex stage ten times the frame, and draw
    // through the same pass, constants and buffers.
    settings.draw_seeds.reach_m = [0.0, 300.0, 600.0, 1200.0];
    settings.wind.speed_m_s = 9.0;
    settings.clouds.coverage = 0.4;
    let c = &mut settings.cache;
    [c.height_slots, c.imagery_slots, c.landcover_slots] = SLOTS;
    let mut r = renderer(&dir, settings);
    let (path, _) = orbit_path(&r.dataset).unwrap();
    let (fov, near) = (r.settings.render.fov_deg, r.settings.render.near_m);

    let start = Instant::now();
    let mut samples = Vec::with_capacity(3 * ORBIT);
    let mut selected = Vec::with_capacity(3 * ORBIT);
    for i in 0..3 * ORBIT {
        let k = i % ORBIT;
        let camera = path.camera_at(k as f64 / ORBIT as f64, fov, near);
        r.set_time_s(r.settings.wind.time_of_frame_s(k));
        let report = r.render(&camera).unwrap_or_else(|e| panic!("frame {i} at {camera:?}: {e}"));
        selected.push(report.seeds.map_or(0, |s| s.counters.selected));
        samples.push(memory());
    }
    let flight_s = start.elapsed().as_secs_f64();
    let [first, second, third] = [0, 1, 2].map(|o| floor(&samples[o * ORBIT..(o + 1) * ORBIT]));
    selected.sort_unstable();
    let median_selected = selected[selected.len() / 2];
    println!(
        "{} frames with seeds in {flight_s:.1} s ({:.0} ms per frame), {median_selected} seeds selected in the \
         median frame; anonymous floor per orbit {:.1}, {:.1}, {:.1} MiB (VmRSS {:.1}, {:.1}, {:.1} MiB)",
        3 * ORBIT,
        flight_s * 1000.0 / (3 * ORBIT) as f64,
        mib(first.anon << 10),
        mib(second.anon << 10),
        mib(third.anon << 10),
        mib(first.rss << 10),
        mib(second.rss << 10),
        mib(third.rss << 10),
    );
    assert!(median_selected > 1000, "the flight draws seeds: {median_selected} in the median frame");
    // Real: the memory was read (a growth of 0 from two zeros would pass any bound).
    assert!(second.anon > 0 && third.anon > 0, "no anonymous memory read: {second:?}, {third:?}");
    let growth = third.anon.saturating_sub(second.anon);
    assert!(
        growth <= MAX_ANON_GROWTH_KIB,
        "anonymous memory grew {:.1} MiB from the second orbit to the third (bound {:.1} MiB)",
        mib(growth << 10),
        mib(MAX_ANON_GROWTH_KIB << 10)
    );
}
