//! The round Earth's extremes (issue 44): geographic rasters made here over the antimeridian and
//! over the North Pole, each built into the builder's local azimuthal equidistant frame (centred on
//! the raster's centre, so neither the antimeridian nor the pole is an edge of it) and drawn on the
//! Earth from poses given in WGS 84; every frame settled and audited as the extremes are
//! (`terramp_testkit::audit`: depth, colour, the Tile Load Map and the seed records read back and
//! checked; holes and stray ground judged against rays placed on the Earth through the DEM).
//!
//! - The antimeridian: 1° square around 0° N 180° E, rolling hills continuous across it; from
//!   0.5 m above the ground at 179.9999° E looking east across it, from 2 km up at 179.99° W
//!   looking west across it, and from 30 km straight down on it.
//! - The pole: latitudes 89° N to 90° N at every longitude, the same hills laid out by distance
//!   from the pole; from 0.5 m above the ground 11 m from the pole, from 1 km up 1.1 km from it,
//!   from 50 km straight down on it and from 2 km up right over it. The geoid's lattice reaches
//!   the pole all the way round (the builder once stopped it at the grid's edges' latitudes: the
//!   undulation 11 m from the pole then depended on the meridian by 1.1 m).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp_testkit::TempDir;
use terramp_testkit::audit::{Dem, Tolerance, audit};

use support::{build, write_geotiff};

/// Hills: metres high, and their wavelength, metres.
const HILL_M: f64 = 120.0;
const WAVE_M: f64 = 7_000.0;
/// How far the drawn ground may lie from the DEM's where the finest LOD is drawn, metres, and
/// beyond (a coarser LOD's own error), metres.
const FINE_HEIGHT_M: f64 = 0.05;
const COARSE_HEIGHT_M: f64 = 30.0;
/// Metres per degree of latitude (WGS 84's meridian near the equator and the pole differ by 1 %:
/// the hills need only be smooth).
const M_PER_DEG: f64 = 111_000.0;

/// Heights of a raster of `size` samples whose sample (column, row) lies at ground position
/// `at(column, row)` (metres east and north on a local plane).
fn hills(size: [usize; 2], at: impl Fn(usize, usize) -> [f64; 2]) -> Vec<f32> {
    let mut heights = Vec::with_capacity(size[0] * size[1]);
    for row in 0..size[1] {
        for column in 0..size[0] {
            let [x, y] = at(column, row);
            let k = std::f64::consts::TAU / WAVE_M;
            heights.push((HILL_M * (0.6 + 0.25 * (k * x).sin() + 0.15 * (1.3 * k * y).cos())) as f32);
        }
    }
    heights
}

fn renderer(dataset: Dataset) -> Renderer {
    let mut settings = Settings::default();
    [settings.render.width, settings.render.height] = [320, 180];
    Renderer::new(terramp_testkit::gpu(), dataset, settings).unwrap()
}

/// Renders each pose (`lonlat:` or `lonlat-ground:` form) until settled, audits it and checks it
/// is sound, and that its rays meet some ground.
fn audit_poses(r: &mut Renderer, poses: &[&str]) {
    let dem = Dem::load(&r.dataset);
    let spacing_m = r.dataset.manifest.height.spacing_m;
    let tol =
        Tolerance { height_m: FINE_HEIGHT_M, coarse_height_m: COARSE_HEIGHT_M, margin_m: 3.0 * spacing_m };
    for pose in poses {
        let camera = r.dataset.camera_from(pose, 60.0, 0.1).unwrap();
        r.render_resolved(&camera).unwrap();
        let a = audit(r, &camera, &dem, tol, 4);
        println!(
            "{pose}: {} ground rays judged, {} holes, {} stray ground",
            a.expect_ground, a.holes, a.spurious
        );
        println!("{a:?}");
        a.assert_sound(pose);
        assert!(a.expect_ground >= 200, "{pose}: the rays meet too little ground ({a:?})");
    }
}

#[test]
fn across_the_antimeridian_the_ground_has_no_seam() {
    let dir = TempDir::new("earth-antimeridian");
    let (step_deg, samples) = (0.002, 500usize);
    // West edge 179.5° E, east edge 180.5° E (179.5° W): the hills run on across 180°.
    let transform = [179.5, step_deg, 0.0, 0.5, 0.0, -step_deg];
    let at = |c: usize, r: usize| {
        [(c as f64 + 0.5) * step_deg * M_PER_DEG, -(r as f64 + 0.5) * step_deg * M_PER_DEG]
    };
    let heights = hills([samples; 2], at);
    let dem = write_geotiff(&dir.path().join("am.tif"), [samples; 2], heights, transform, 4326, None);
    let dataset = build(&dir.path().join("am"), &["--dem", dem.to_str().unwrap()]).0;
    let earth = dataset.manifest.earth.as_ref().unwrap();
    println!("{}", earth.datum_note);
    let mut r = renderer(dataset);
    audit_poses(
        &mut r,
        &[
            "lonlat-ground:179.9999,0,0.5,90,-3",
            "lonlat-ground:-179.99,0.1,2000,270,-20",
            "lonlat-ground:180,0,30000,0,-90",
        ],
    );
}

#[test]
fn over_the_pole_the_ground_has_no_pinch() {
    let dir = TempDir::new("earth-pole");
    let (lon_step_deg, lat_step_deg) = (0.1, 0.004);
    let size = [3600usize, 250];
    let transform = [-180.0, lon_step_deg, 0.0, 90.0, 0.0, -lat_step_deg];
    // Laid out by distance from the pole along the sample's meridian: the same hills whatever the
    // longitude where the meridians meet.
    let at = |c: usize, r: usize| {
        let lon = (-180.0 + (c as f64 + 0.5) * lon_step_deg).to_radians();
        let from_pole_m = (r as f64 + 0.5) * lat_step_deg * M_PER_DEG;
        [from_pole_m * lon.sin(), -from_pole_m * lon.cos()]
    };
    let heights = hills(size, at);
    let dem = write_geotiff(&dir.path().join("pole.tif"), size, heights, transform, 4326, None);
    let dataset = build(&dir.path().join("pole"), &["--dem", dem.to_str().unwrap()]).0;
    // The geoid's lattice reaches the pole all the way round: one undulation there, whichever
    // meridian it is come to along, and PROJ's within its check's bound.
    let geoid = dataset.manifest.earth.as_ref().unwrap().geoid.clone().unwrap();
    let at_pole: Vec<f64> = [0.0f64, 90.0, 180.0, -90.0]
        .map(|lon| geoid.undulation_at(89.9999f64.to_radians(), lon.to_radians()))
        .into();
    println!("EGM96 11 m from the pole: {at_pole:?} m; against PROJ {} m", geoid.interpolation_error_m);
    assert!(at_pole.iter().all(|n| (n - at_pole[0]).abs() < 1e-3), "{at_pole:?}");
    assert!(geoid.interpolation_error_m < 0.1, "{}", geoid.interpolation_error_m);
    let mut r = renderer(dataset);
    audit_poses(
        &mut r,
        &[
            "lonlat-ground:0,89.9999,0.5,180,-3",
            "lonlat-ground:45,89.99,1000,180,-40",
            "lonlat-ground:0,89.9999,50000,0,-90",
            "lonlat-ground:0,90,2000,0,-60",
        ],
    );
}
