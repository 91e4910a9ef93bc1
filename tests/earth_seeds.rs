//! Pass 3 on the Earth: a synthetic dataset 10 km across placed on nc's State Plane (its manifest
//! given an `[earth]`), seen from near the ground looking across it and from above. The GPU's
//! seeds equal its twin's to the bit; each seed's anchor lies where the exact mapping (f64,
//! `ExactPlacing::position_rel_m`) puts its grid point and sunk height, which the flat sheet
//! misses by the Earth's drop; the anchor is sunk along the exact local vertical; and the
//! occlusion march, whose segment sags on the Earth, leaps only where visiting every sample
//! would decide the same.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::HashMap;

use glam::DVec3;
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::EarthNode;
use terramp::passes::seed_select::march::BLOCKS_PER_TILE;
use terramp::reference::seed_select::{SeedComparison, seed_select};
use terramp_testkit::audit::Dem;
use terramp_testkit::camera::at_grid;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::{gpu, small_settings};

/// Most an anchor may lie from the exact mapping's point, metres: f32 positions relative to the
/// eye (a few roundings of a distance of kilometres, a quarter of a millimetre each); its cell's
/// polynomial's third order adds nothing over 256 m.
const MAX_ANCHOR_MISS_M: f64 = 0.002;
/// Most the vertical a seed is sunk and stood along may part from the exact one, radians: its
/// cell's mapping's up at the seed (pass 3), and the camera's at the seed's offset (pass 4), first
/// order in the offset (the bend itself is 5e-4 rad at 3 km).
const MAX_TILT_RAD: f64 = 1e-5;

#[test]
fn seeds_on_the_earth_equal_their_twin_and_stand_where_the_exact_mapping_puts_them() {
    let dataset = std::sync::Arc::new(synth_on_nc(1024, 10.0, 7));
    let dem = Dem::load(&dataset);
    let mut r = Renderer::new(gpu(), std::sync::Arc::clone(&dataset), small_settings(320, 180)).unwrap();
    let cell_m = r.settings.tlm.cell_m;
    let sink_fraction = r.settings.seeds.sink_fraction;
    let views = [([2_000.0, 2_000.0], 30.0, 45.0, -3.0), ([5_000.0, 3_000.0], 400.0, 120.0, -20.0)];
    let (mut farthest_m, mut worst_m, mut flat_worst_m, mut worst_tilt, mut occluded) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0);
    for (i, ([x, y], above_m, yaw, pitch)) in views.into_iter().enumerate() {
        let camera = at_grid(&r, DVec3::new(x, y, dem.mesh_height_m(x, y) + above_m), yaw, pitch);
        r.render_resolved(&camera).unwrap();
        let (gpu_seeds, gpu_counters) = r.read_seeds().unwrap().unwrap();
        let (twin, twin_counters) = r.seed_twin().unwrap().unwrap();
        assert!(twin.len() > 200, "view {i}: {} seeds ({twin_counters:?})", twin.len());
        assert_eq!(gpu_counters, twin_counters, "view {i}");
        let diff = SeedComparison::of(&gpu_seeds, &twin);
        assert!(diff.only_gpu.is_empty() && diff.only_twin.is_empty(), "view {i}: {diff:?}");
        assert!(diff.mismatched.is_empty() && diff.non_finite.is_empty(), "view {i}: {diff:?}");
        assert_eq!(diff.max_length_error_m, 0.0, "view {i}");
        occluded += twin_counters.occlusion;

        // Each seed's grid point, in f64, from its cell and its pattern's position.
        let snapshot = r.seed_snapshot().unwrap().unwrap();
        let per_pattern = snapshot.frame.uniforms.seeds_per_pattern;
        let cells: HashMap<[i32; 2], _> = snapshot.frame.cells.iter().map(|c| (c.address, c)).collect();
        let placing = r.exact_placing(&camera);
        let (nadir, eye) = (placing.nadir_node(), placing.camera_grid_m());
        let v = |c: [f32; 4]| DVec3::new(c[0].into(), c[1].into(), c[2].into());
        let up_at = |e: &EarthNode, x: f64, y: f64| v(e.d_h) + v(e.d_xh) * x + v(e.d_yh) * y;
        for seed in &gpu_seeds {
            let cell = cells[&seed.address];
            let unit = snapshot.patterns_unit[(cell.pattern * per_pattern + seed.rank) as usize];
            let grid = [0, 1].map(|a| (f64::from(seed.address[a]) + f64::from(unit[a])) * cell_m);
            let (ground_m, sink_m) = (f64::from(seed.ground_m), f64::from(seed.height_m) * sink_fraction);
            let exact = placing.position_rel_m(DVec3::new(grid[0], grid[1], ground_m - sink_m));
            let anchor = DVec3::from(seed.position_rel_m.map(f64::from));
            let flat = DVec3::new(grid[0], grid[1], ground_m - sink_m) - eye;
            worst_m = worst_m.max((anchor - exact).length());
            flat_worst_m = flat_worst_m.max((anchor - flat).length());
            farthest_m = farthest_m.max(exact.truncate().length());
            // Sunk and stood along the local vertical: the up pass 3's cell mapping gives at the
            // seed (the twin's, which the GPU's equals), and the up pass 4 stands its model along
            // (the camera's mapping's at the anchor's offset), against the exact mapping's. The
            // anchor's own offset from the foot is too short to measure a direction by (f32 steps
            // of 0.2 mm at 3 km).
            let foot = placing.position_rel_m(DVec3::new(grid[0], grid[1], ground_m));
            let up =
                (placing.position_rel_m(DVec3::new(grid[0], grid[1], ground_m + 1.0)) - foot).normalize();
            let in_cell = unit.map(|u| f64::from(u) * cell_m);
            let sunk = up_at(&cell.earth, in_cell[0], in_cell[1]);
            let stood = up_at(&nadir, anchor.x, anchor.y);
            worst_tilt = worst_tilt.max(up.angle_between(sunk)).max(up.angle_between(stood));
        }

        // The march's leaps, against the twin visiting every sample, with the segment sagging.
        let mut no_leap = snapshot.inputs();
        let every_sample = vec![f32::INFINITY; snapshot.caches.height_tile_max_m.len()];
        let every_block = snapshot
            .caches
            .height_block_max_m
            .keys()
            .map(|&s| (s, vec![f32::INFINITY; BLOCKS_PER_TILE]))
            .collect();
        no_leap.height_tile_max_m = &every_sample;
        no_leap.height_block_max_m = &every_block;
        assert!(snapshot.frame.uniforms.chord_sag_per_m2 > 0.0, "view {i}: no sag on the Earth");
        assert_eq!(seed_select(&snapshot.inputs()), seed_select(&no_leap), "view {i}");
    }
    println!(
        "farthest seed {farthest_m:.0} m; anchors off the exact mapping by {:.3} mm at most (flat: {:.3} m); \
         sunk at most {worst_tilt:.1e} rad off the vertical; {occluded} occluded",
        worst_m * 1e3,
        flat_worst_m
    );
    assert!(occluded > 0, "no seed occluded: the march went untested");
    assert!(worst_m <= MAX_ANCHOR_MISS_M, "an anchor {worst_m} m off the exact mapping");
    assert!(worst_tilt <= MAX_TILT_RAD, "an anchor sunk {worst_tilt} rad off the vertical");
    // The flat sheet misses the farthest seeds by the Earth's drop (d² / 2R): the measure can tell.
    let drop_m = farthest_m * farthest_m / (2.0 * 6.37e6);
    assert!(
        flat_worst_m > 0.5 * drop_m && drop_m > 100.0 * MAX_ANCHOR_MISS_M,
        "flat {flat_worst_m}, drop {drop_m}"
    );
}
