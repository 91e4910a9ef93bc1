//! The horizon on the Earth (issue 44): a geographic sea-level raster made here, 24° square around
//! 0° N 0° E (2,670 km across), with one cone 1,000 m high about 150 km north of its centre (807 m
//! once the builder has resampled it), built (the builder's local azimuthal equidistant frame,
//! heights above EGM96) and drawn at 1920 × 1080 with a 60° vertical field of view, level.
//!
//! - From 10 m, 1 km, 10 km and 100 km up, looking south, the first ground row of five columns across the frame
//!   lies within a pixel of where the ellipsoid puts the horizon: a sea whose radius of curvature
//!   in the column's azimuth is ρ (Euler's, at the equator: between the meridian's 6,335 km and
//!   the prime vertical's 6,378 km) dips below the horizontal by δ = acos(ρ / (ρ + h)) seen from
//!   h above it (the sea taken at the geoid's height under the camera: its slope over the view
//!   moves the horizon by well under a pixel), and the column's ray at azimuth φ off the view's
//!   centre reaches that dip tan δ / cos φ focal lengths below the image's middle.
//! - The Tile Load Map culls its cells beyond the horizon (`the_tlm_culls_cells_beyond_the_horizon`).
//! - From 1,000 km up, over a wider, coarser sea, the horizon lies where the rays of each column
//!   first meet the ellipsoid (`from_1000_km_the_horizon_dips_as_the_ellipsoid_says`).
//! - From 1 km up, the peak's top stands where the exact mapping (f64, `ExactPlacing`) of its
//!   highest sample puts it, within a pixel: about 1,770 m below the camera's horizontal by the
//!   drop alone (d² / 2ρ; no refraction is modelled), where the flat sheet had it level.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::earth::Ellipsoid;
use terramp::earth::local::LocalFrame;
use terramp::earth::placing::EarthPlacing;
use terramp::frame::Renderer;
use terramp::passes::tile_load_map::frame::height_tile_ranges;
use terramp_testkit::TempDir;
use terramp_testkit::audit::Dem;
use terramp_testkit::tlm;

use support::{build, sea_level, write_geotiff};

const SIZE: [u32; 2] = [1920, 1080];
/// How far a drawn row may lie from the ellipsoid's, pixels: the bound.
const MISS_PX: u32 = 1;
const FOV_DEG: f64 = 60.0;
/// The raster: degrees per sample, and samples per side.
const STEP_DEG: f64 = 0.025;
const SAMPLES: usize = 960;
/// The peak: metres high, and kilometres north of the centre.
const PEAK_M: f32 = 1_000.0;
const PEAK_NORTH_KM: f64 = 150.0;

/// The sea with its peak, built.
fn sea(dir: &TempDir) -> Dataset {
    let half = 0.5 * SAMPLES as f64 * STEP_DEG;
    let transform = [-half, STEP_DEG, 0.0, half, 0.0, -STEP_DEG];
    let mut heights = vec![0.0f32; SAMPLES * SAMPLES];
    // The peak: a cone two samples in radius around the sample nearest 150 km north (on the
    // meridian, 1° is 110.57 km at the equator).
    let peak_row = SAMPLES / 2 - (PEAK_NORTH_KM / 110.574 / STEP_DEG).round() as usize;
    let peak_column = SAMPLES / 2;
    for dr in -2i64..=2 {
        for dc in -2i64..=2 {
            let r = ((dr * dr + dc * dc) as f32).sqrt();
            let (row, column) = ((peak_row as i64 + dr) as usize, (peak_column as i64 + dc) as usize);
            heights[row * SAMPLES + column] = (PEAK_M * (1.0 - r / 3.0)).max(0.0);
        }
    }
    let dem = write_geotiff(&dir.path().join("sea.tif"), [SAMPLES, SAMPLES], heights, transform, 4326, None);
    build(&dir.path().join("sea"), &["--dem", dem.to_str().unwrap()]).0
}

fn renderer(dataset: Dataset) -> Renderer {
    let mut settings = Settings::default();
    [settings.render.width, settings.render.height] = SIZE;
    settings.render.fov_deg = FOV_DEG;
    Renderer::new(terramp_testkit::gpu(), dataset, settings).unwrap()
}

/// A camera `height_m` above the datum over the frame's centre (CRS 0, 0), looking south (away
/// from the peak), level.
fn camera(height_m: f64) -> Camera {
    Camera {
        position_m: DVec3::new(0.0, 0.0, height_m),
        yaw_deg: 180.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        fov_deg: FOV_DEG,
        near_m: 0.1,
    }
}

/// The first row from the top showing ground in `column` of the last frame.
fn first_ground_row(depth: &[f32], column: u32) -> u32 {
    (0..SIZE[1]).find(|&y| depth[(y * SIZE[0] + column) as usize] > 0.0).unwrap_or(SIZE[1])
}

/// The focal length, pixels.
fn focal_px() -> f64 {
    0.5 * f64::from(SIZE[1]) / (0.5 * FOV_DEG).to_radians().tan()
}

/// The first row whose centre lies `below` focal lengths (a tangent) under the image's middle.
fn row_below(below: f64) -> u32 {
    (0.5 * f64::from(SIZE[1]) + focal_px() * below - 0.5).ceil() as u32
}

#[test]
fn the_horizon_dips_as_the_ellipsoid_says() {
    let dir = TempDir::new("earth-horizon");
    let dataset = sea(&dir);
    let earth = dataset.manifest.earth.clone().unwrap();
    let (lat, lon) = earth.geodetic(0.0, 0.0);
    let sea_m = earth.geoid.as_ref().map_or(0.0, |g| g.undulation_at(lat, lon));
    let e = Ellipsoid::WGS84;
    let w = (1.0 - e.e2() * lat.sin().powi(2)).sqrt();
    let (meridian_m, prime_m) = (e.a_m * (1.0 - e.e2()) / w.powi(3), e.a_m / w);
    let mut r = renderer(dataset);
    let mut worst = 0i64;
    for height_m in [10.0, 1_000.0, 10_000.0, 100_000.0] {
        r.render_resolved(&camera(height_m)).unwrap();
        let depth = r.read_depth().unwrap();
        for column in [160, 560, 960, 1360, 1760] {
            let across = (f64::from(column) + 0.5 - 0.5 * f64::from(SIZE[0])) / focal_px();
            let azimuth = across.atan();
            let rho = 1.0 / (azimuth.cos().powi(2) / meridian_m + azimuth.sin().powi(2) / prime_m) + sea_m;
            let dip = (rho / (rho + height_m)).acos();
            let expected = row_below(dip.tan() / azimuth.cos());
            let drawn = first_ground_row(&depth, column);
            println!("{height_m} m, column {column}: horizon at row {drawn}, the ellipsoid's {expected}");
            worst = worst.max((i64::from(drawn) - i64::from(expected)).abs());
            assert!(
                drawn.abs_diff(expected) <= MISS_PX,
                "{height_m} m, column {column}: row {drawn}, not {expected}"
            );
        }
    }
    println!("largest miss: {worst} px");
}

#[test]
fn a_peak_beyond_the_curve_stands_as_high_as_the_earth_allows() {
    let dir = TempDir::new("earth-peak");
    let dataset = sea(&dir);
    let dem = Dem::load(&dataset);
    let m = dataset.manifest.clone();
    // The built peak's highest sample (the builder resamples the raster onto its frame).
    let [w, h] = dem.size;
    let (mut top, mut top_m) = ([0u32; 2], f64::MIN);
    for j in 0..h {
        for i in 0..w {
            let z = dem.sample_m(i, j);
            if z > top_m {
                (top, top_m) = ([i, j], z);
            }
        }
    }
    let top_grid = DVec3::new(f64::from(top[0]) * dem.spacing_m, f64::from(top[1]) * dem.spacing_m, top_m);
    let camera_grid = DVec3::new(-m.origin_m[0], -m.origin_m[1], 1_000.0);
    let exact = EarthPlacing::new(m.earth.as_ref(), m.origin_m, true).exact(camera_grid);
    let rel = exact.position_rel_m(top_grid);
    let distance_m = rel.truncate().length();
    let drop_m = top_m - camera_grid.z - rel.z;
    println!(
        "peak {top_m:.0} m high {distance_m:.0} m away: {drop_m:.0} m below the camera's horizontal by the drop"
    );
    // d² / 2ρ over the meridian (6,335 km at the equator): 1,776 m at 150 km.
    let circle_m = distance_m * distance_m / (2.0 * 6_335_439.0);
    assert!(
        (distance_m - 1e3 * PEAK_NORTH_KM).abs() < 3e3 && (drop_m - circle_m).abs() < 0.01 * circle_m,
        "{rel}"
    );
    let mut r = renderer(dataset);
    // Turned to face the peak (north), so that it stands in the middle column.
    let yaw_deg = rel.x.atan2(rel.y).to_degrees();
    r.render_resolved(&Camera { yaw_deg, ..camera(1_000.0) }).unwrap();
    let depth = r.read_depth().unwrap();
    let expected = row_below(-rel.z / distance_m);
    let drawn = first_ground_row(&depth, SIZE[0] / 2);
    println!(
        "the peak's top at row {drawn}, the Earth's {expected} (the flat sheet's {})",
        row_below((1_000.0 - top_m) / distance_m)
    );
    assert!(drawn.abs_diff(expected) <= MISS_PX, "row {drawn}, not {expected}");
}

/// Horizon culling drops the nodes the Earth hides and no pixel: from 1 km, 10 km and 100 km up,
/// looking level and 20° down, the frame's depth is the same with it and without, with fewer nodes.
#[test]
fn horizon_culling_drops_nodes_not_pixels() {
    let dir = TempDir::new("earth-horizon-culling");
    let dataset = std::sync::Arc::new(sea(&dir));
    let frames = |culling: bool| {
        let mut settings = Settings::default();
        [settings.render.width, settings.render.height] = [480, 270];
        settings.render.fov_deg = FOV_DEG;
        settings.terrain.horizon_culling = culling;
        let mut r = Renderer::new(terramp_testkit::gpu(), std::sync::Arc::clone(&dataset), settings).unwrap();
        let mut out = Vec::new();
        for (height_m, pitch_deg) in [(1_000.0, 0.0), (10_000.0, 0.0), (10_000.0, -20.0), (100_000.0, -20.0)]
        {
            let camera = Camera { pitch_deg, ..camera(height_m) };
            let (report, _) = r.render_resolved(&camera).unwrap();
            out.push((height_m, pitch_deg, report.nodes_drawn, r.read_depth().unwrap()));
        }
        out
    };
    for ((height_m, pitch_deg, culled, depth), (_, _, all, all_depth)) in
        frames(true).into_iter().zip(frames(false))
    {
        println!(
            "{height_m} m up, pitch {pitch_deg}°: {culled} nodes drawn with horizon culling, {all} without"
        );
        assert!(depth == all_depth, "{height_m} m, {pitch_deg}°: the depth differs");
        assert!(culled <= all, "{height_m} m, {pitch_deg}°: {culled} > {all}");
    }
}

/// The Tile Load Map over the sea, level from 1 km and 10 km up: with horizon culling its cells
/// beyond the horizon are culled (the GPU equal to its twin, no pixel's ground in a culled cell),
/// and fewer stay visible than without; with it or not, every cell's bent box holds its ground
/// where the exact mapping puts it, out to the sea's far corners (1,860 km).
#[test]
fn the_tlm_culls_cells_beyond_the_horizon() {
    let dir = TempDir::new("earth-horizon-tlm");
    let dataset = std::sync::Arc::new(sea(&dir));
    let ranges = height_tile_ranges(&dataset);
    for height_m in [1_000.0, 10_000.0] {
        let mut visible_cells = [0; 2];
        for (k, culling) in [true, false].into_iter().enumerate() {
            let mut settings = Settings::default();
            [settings.render.width, settings.render.height] = [480, 270];
            settings.render.fov_deg = FOV_DEG;
            settings.terrain.horizon_culling = culling;
            let mut r =
                Renderer::new(terramp_testkit::gpu(), std::sync::Arc::clone(&dataset), settings).unwrap();
            let what = format!("{height_m} m up, horizon culling {culling}");
            let run = tlm::run(&mut r, &camera(height_m), &ranges);
            tlm::assert_gpu_equals_twin(&run, &what);
            tlm::assert_no_false_culls(&r, &run, &what);
            let held = tlm::bent_boxes_hold(&run);
            assert!(held.farthest_m > 1.8e6, "{what}: {held:?}");
            visible_cells[k] = tlm::visible(&run.gpu);
        }
        let [culled, all] = visible_cells;
        println!("{height_m} m up, level: {culled} TLM cells visible with horizon culling, {all} without");
        assert!(culled < all, "{height_m} m: {culled} visible with horizon culling, {all} without");
    }
}

/// From 1,000 km up (pitched 25° down: the horizon dips 30°, past a level view's edge) over a
/// sea-level raster 72° square at 0.1° (reaching past the horizon's 3,700 km), each of five
/// columns' first ground row lies within a pixel of the first whose ray meets the ellipsoid
/// (raised by the geoid's undulation under the camera): found exactly, row by row, in the
/// ellipsoid's scaled space (the ray meets the unit sphere where its quadratic has a root).
#[test]
fn from_1000_km_the_horizon_dips_as_the_ellipsoid_says() {
    let dir = TempDir::new("earth-horizon-1000km");
    let dataset = sea_level(dir.path(), 0.1, 720);
    let earth = dataset.manifest.earth.clone().unwrap();
    let sea_m = earth.undulation_m(0.0, 0.0);
    let (height_m, pitch_deg) = (1_000_000.0, -25.0);
    let mut r = renderer(dataset);
    let camera = Camera { pitch_deg, ..camera(height_m) };
    r.render_resolved(&camera).unwrap();
    let depth = r.read_depth().unwrap();
    // The camera's axes in its frame (x east, y north, z up along the ellipsoid's normal).
    let (yaw, pitch) = (camera.yaw_deg.to_radians(), pitch_deg.to_radians());
    let forward = DVec3::new(yaw.sin() * pitch.cos(), yaw.cos() * pitch.cos(), pitch.sin());
    let right = DVec3::new(yaw.cos(), -yaw.sin(), 0.0);
    let up = right.cross(forward);
    let frame = LocalFrame::grid_aligned(&earth, 0.0, 0.0, height_m);
    let e = Ellipsoid::WGS84;
    let scale = DVec3::new(e.a_m + sea_m, e.a_m + sea_m, e.b_m() + sea_m).recip();
    let eye = frame.eye_ecef_m * scale;
    let meets = |x_px: f64, y_px: f64| {
        let d_local = right * (x_px / focal_px()) - up * (y_px / focal_px()) + forward;
        let d = (frame.local_from_ecef.transpose() * d_local) * scale;
        let b = eye.dot(d);
        b < 0.0 && b * b >= d.length_squared() * (eye.length_squared() - 1.0)
    };
    let mut worst = 0i64;
    for column in [160, 560, 960, 1360, 1760] {
        let x_px = f64::from(column) + 0.5 - 0.5 * f64::from(SIZE[0]);
        let expected = (0..SIZE[1]).find(|&row| meets(x_px, f64::from(row) + 0.5 - 0.5 * f64::from(SIZE[1])));
        let expected = expected.unwrap_or(SIZE[1]);
        let drawn = first_ground_row(&depth, column);
        println!("1,000 km, column {column}: horizon at row {drawn}, the ellipsoid's {expected}");
        worst = worst.max((i64::from(drawn) - i64::from(expected)).abs());
        assert!(expected > 50 && expected < SIZE[1] - 50, "column {column}: the horizon off the frame");
        assert!(drawn.abs_diff(expected) <= MISS_PX, "column {column}: row {drawn}, not {expected}");
    }
    println!("largest miss: {worst} px");
}
