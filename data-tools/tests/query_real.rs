//! The host's questions on real data (`terramp_testkit::query`): nc (NED DEM on State Plane,
//! Landsat, land use) and zion (a canyon's relief on UTM, NLCD), each on the round Earth where
//! its manifest places it. Picks at `PICKS` pixels of two views of each land where the depth
//! buffer has the ground (within `PICK_FLOOR_M` or the depth's own precision) and the drawn
//! ground under each is the pick's height; the plants near `PLANT_POINTS` picked points of a low
//! view are the seeds pass 3 wrote there.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp_testkit::query::{picks, plants};
use terramp_testkit::{TempDir, camera, gpu, shared_data, small_settings};

use support::{build_nc, build_zion, forest_near_water};

const SIZE: [u32; 2] = [320, 180];

fn renderer(dataset: Dataset) -> Renderer {
    let settings: Settings = small_settings(SIZE[0], SIZE[1]);
    Renderer::new(gpu(), dataset, settings).unwrap()
}

#[test]
fn picks_and_plants_over_nc() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("query-nc");
    let dataset = build_nc(&tmp.path().join("nc"));
    let ([x, y], heading) = forest_near_water(&dataset);
    let mut r = renderer(dataset);
    let low = camera::posed(&r, [x, y, 30.0, heading, -10.0]);
    let high = camera::over_fraction(&r, [0.3, 0.3], 1_500.0, 45.0, -20.0);
    for (what, pose) in [("nc, 30 m up over forest", &low), ("nc, 1.5 km up", &high)] {
        picks(&mut r, pose).check(what);
    }
    plants(&mut r, &low).check("nc, 30 m up over forest");
}

#[test]
fn picks_and_plants_over_zion() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("query-zion");
    let mut r = renderer(build_zion(&tmp.path().join("zion")));
    let canyon = camera::over_fraction(&r, [0.5, 0.5], 2_000.0, 30.0, -15.0);
    let low = camera::over_fraction(&r, [0.4, 0.6], 40.0, 200.0, -12.0);
    for (what, pose) in [("zion, 2 km up over the canyon", &canyon), ("zion, 40 m up", &low)] {
        picks(&mut r, pose).check(what);
    }
    plants(&mut r, &low).check("zion, 40 m up");
}
