//! The Tile Load Map on the Earth: a synthetic dataset 60 km across placed on nc's State Plane
//! (its manifest given an `[earth]`). The GPU equals its twin cell for cell with the cells' boxes
//! bent onto the Earth and culled by its horizon; no pixel shows ground of a culled cell; every
//! cell's bent box holds its ground where the exact mapping puts it. (The horizon's culling of
//! cells: `data-tools/tests/earth_horizon.rs`, over a sea that reaches past it.)
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DVec3;
use terramp::frame::Renderer;
use terramp::passes::tile_load_map::frame::height_tile_ranges;
use terramp_testkit::audit::Dem;
use terramp_testkit::camera::at_grid;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::tlm::{assert_gpu_equals_twin, assert_no_false_culls, bent_boxes_hold, run};
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
        assert!(tlm.frame.uniforms.earth_bend[0][0] > 0.0, "{what}: flat boxes on the Earth");
        let held = bent_boxes_hold(&tlm);
        boxes += held.boxes;
        worst_slack_m = worst_slack_m.max(held.slack_m);
        farthest_m = farthest_m.max(held.farthest_m);
    }
    println!(
        "{boxes} bent boxes hold their ground out to {farthest_m:.0} m, slack at most {worst_slack_m:.2} m"
    );
    assert!(boxes > 100 && farthest_m > 50_000.0, "{boxes} boxes, out to {farthest_m} m");
}
