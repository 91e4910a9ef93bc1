//! The Tile Load Map on the Earth: a synthetic dataset 60 km across placed on nc's State Plane
//! (its manifest given an `[earth]`). The GPU equals its twin cell for cell with the cells' boxes
//! bent onto the Earth and culled by its horizon; no pixel shows ground of a culled cell; every
//! cell's bent box holds its ground where the exact mapping puts it. (The horizon's culling of
//! cells: `data-tools/tests/earth_horizon.rs`, over a sea that reaches past it.)
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DVec3;
use terramp::frame::Renderer;
use terramp::passes::tile_load_map::frame::height_tile_ranges;
use terramp::reference::tile_load_map::bent_box;
use terramp_testkit::audit::Dem;
use terramp_testkit::camera::at_grid;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::tlm::{assert_gpu_equals_twin, assert_no_false_culls, cell_height_range, run};
use terramp_testkit::{gpu, small_settings};

/// Views of the dataset: grid point, height above the ground, heading and pitch.
const VIEWS: [([f64; 2], f64, f64, f64); 3] = [
    ([3_000.0, 3_000.0], 20.0, 45.0, -1.0),
    ([30_000.0, 30_000.0], 3_000.0, 200.0, -35.0),
    ([10_000.0, 50_000.0], 600.0, 120.0, -8.0),
];

#[test]
fn the_tlm_on_the_earth_equals_its_twin_and_its_bent_boxes_hold_the_ground() {
    let dataset = std::sync::Arc::new(synth_on_nc(600, 100.0, 5));
    let dem = Dem::load(&dataset);
    let ranges = height_tile_ranges(&dataset);
    let mut r = Renderer::new(gpu(), std::sync::Arc::clone(&dataset), small_settings(320, 180)).unwrap();
    let (mut boxes, mut worst_slack_m, mut farthest_m) = (0, 0.0f64, 0.0f64);
    for (i, ([x, y], above_m, yaw, pitch)) in VIEWS.into_iter().enumerate() {
        let camera = at_grid(&r, DVec3::new(x, y, dem.mesh_height_m(x, y) + above_m), yaw, pitch);
        let what = format!("view {i}");
        let tlm = run(&mut r, &camera, &ranges);
        assert_gpu_equals_twin(&tlm, &what);
        assert_no_false_culls(&r, &tlm, &what);
        assert!(tlm.frame.uniforms.earth_bend[0] > 0.0, "{what}: flat boxes on the Earth");
        // Every cell over the dataset: a lattice of its ground points at its tiles' lowest and
        // highest heights, placed exactly, lies in its bent box.
        let u = &tlm.frame.uniforms;
        for index in 0..tlm.layout.cell_count() {
            let (ring, cx, cy) = tlm.layout.cell_of(index);
            let (sx, sy) = (
                tlm.frame.spans[((ring * 2) * u.cells + cx) as usize],
                tlm.frame.spans[((ring * 2 + 1) * u.cells + cy) as usize],
            );
            if sx.flags & sy.flags & terramp::gpu::layout::TLM_SPAN_INSIDE == 0 {
                continue;
            }
            let heights = cell_height_range(&tlm, ring, cx, cy);
            let lo = [sx.rel_m[0], sy.rel_m[0], heights[0] - u.camera_z_m];
            let hi = [sx.rel_m[1], sy.rel_m[1], heights[1] - u.camera_z_m];
            let (bent_lo, bent_hi) = bent_box(u, lo, hi);
            let (bent_lo, bent_hi) =
                (DVec3::from(bent_lo.map(f64::from)), DVec3::from(bent_hi.map(f64::from)));
            let (mut held_lo, mut held_hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for j in 0..=4 {
                for k in 0..=4 {
                    for h in heights {
                        let f = |a: usize, n: i32| {
                            f64::from(lo[a]) + f64::from(hi[a] - lo[a]) * f64::from(n) / 4.0
                        };
                        let grid = tlm.camera_grid_m + DVec3::new(f(0, j), f(1, k), 0.0);
                        let p = tlm.placing.position_rel_m(DVec3::new(grid.x, grid.y, f64::from(h)));
                        assert!(
                            p.cmpge(bent_lo).all() && p.cmple(bent_hi).all(),
                            "{what}: cell {:?}: {p} outside {bent_lo}..{bent_hi}",
                            (ring, cx, cy)
                        );
                        (held_lo, held_hi) = (held_lo.min(p), held_hi.max(p));
                        farthest_m = farthest_m.max(p.truncate().length());
                    }
                }
            }
            worst_slack_m = worst_slack_m.max((held_lo - bent_lo).max(bent_hi - held_hi).max_element());
            boxes += 1;
        }
    }
    println!(
        "{boxes} bent boxes hold their ground out to {farthest_m:.0} m, slack at most {worst_slack_m:.2} m"
    );
    assert!(boxes > 100 && farthest_m > 50_000.0, "{boxes} boxes, out to {farthest_m} m");
}
