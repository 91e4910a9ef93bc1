//! From 100 km above nc down to 2 m above its forest (issue 44): nc built with its `[earth]` and
//! drawn on the Earth, one camera over its middle descending through eight heights, its pitch
//! steepest high up; each frame settled and audited as the extremes are (`support::audit`: depth,
//! colour, the Tile Load Map and the seed records read back and checked; holes and stray ground
//! judged against rays placed on the Earth through the DEM).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp_testkit::audit::{Dem, Tolerance, audit, camera_at};
use terramp_testkit::{TempDir, shared_data};

/// The descent: metres above the ground, and pitch (degrees).
const DESCENT: [(f64, f64); 8] = [
    (100_000.0, -80.0),
    (30_000.0, -70.0),
    (10_000.0, -55.0),
    (3_000.0, -40.0),
    (1_000.0, -25.0),
    (300.0, -15.0),
    (30.0, -8.0),
    (2.0, -3.0),
];

#[test]
fn from_100_km_above_nc_down_to_2_m_every_frame_is_sound() {
    let Some(_) = shared_data() else { return };
    let dir = TempDir::new("earth-descent");
    let dataset = support::build_nc(&dir.path().join("nc"));
    assert!(dataset.manifest.earth.is_some(), "nc built without its [earth]");
    let dem = Dem::load(&dataset);
    let spacing_m = dataset.manifest.height.spacing_m;
    let mut settings = Settings::default();
    [settings.render.width, settings.render.height] = [320, 180];
    let mut r = Renderer::new(terramp_testkit::gpu(), dataset, settings).unwrap();
    let span = dem.span_m();
    let middle = [0.5 * span[0], 0.5 * span[1]];
    let tol = Tolerance { height_m: 0.05, coarse_height_m: 60.0, margin_m: 3.0 * spacing_m };
    for (above_m, pitch_deg) in DESCENT {
        let what = format!("{above_m} m up, pitch {pitch_deg}°");
        let camera = camera_at(&r, &dem, middle, above_m, 30.0, pitch_deg);
        r.render_resolved(&camera).unwrap();
        let a = audit(&r, &camera, &dem, tol, 4);
        println!("{what}: {} ground rays judged, {} holes, {} seeds", a.expect_ground, a.holes, a.seeds);
        a.assert_sound(&what);
        assert!(a.expect_ground >= 20, "{what}: the rays meet too little ground ({a:?})");
    }
}
