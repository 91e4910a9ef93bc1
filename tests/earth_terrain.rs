//! The terrain drawn on the Earth: a synthetic dataset 60 km across placed on nc's State Plane
//! (its manifest given an `[earth]`), seen from 800 m up looking across it. Each ground pixel's
//! depth, unprojected, is held to the exact mapping (f64, `ExactPlacing::position_rel_m`) of the
//! finest mesh's ground under it; the flat sheet misses it by the Earth's drop (196 m at 50 km),
//! which shows the measure can tell. A frame over the default LOD rings has no hole below its
//! horizon. Cameras written in longitude and latitude land where they are.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DVec3;
use terramp::dataset::Dataset;
use terramp::dataset::pose::CameraPoseError;
use terramp::earth::placing::EarthPlacing;
use terramp::frame::Renderer;
use terramp_testkit::audit::{Dem, Rays};
use terramp_testkit::camera::at_grid;
use terramp_testkit::earth::synth_on_nc;
use terramp_testkit::{gpu, ground_settings};

/// The longitude and latitude, degrees, of `dataset`'s grid point `grid_m`.
fn lon_lat_deg(dataset: &Dataset, [x, y]: [f64; 2]) -> [f64; 2] {
    let [ox, oy] = dataset.manifest.origin_m;
    let (lat, lon) = dataset.manifest.earth.as_ref().unwrap().geodetic(ox + x, oy + y);
    [lon.to_degrees(), lat.to_degrees()]
}

/// Per ground pixel (every 4th row and column), the distance from the camera and how far the
/// drawn ground lies above the exact mapping's ground under it, metres.
fn vertical_misses(r: &Renderer, camera: &terramp::camera::Camera, dem: &Dem) -> Vec<(f64, f64)> {
    let rays = Rays::new(r, camera);
    let depth = r.read_depth().unwrap();
    let m = &r.dataset.manifest;
    let placed = EarthPlacing::new(m.earth.as_ref(), m.origin_m, true).exact(rays.eye_grid_m);
    let span = dem.span_m();
    let mut misses = Vec::new();
    for y in (0..rays.height).step_by(4) {
        for x in (0..rays.width).step_by(4) {
            let d = depth[(y * rays.width + x) as usize];
            if d <= 0.0 {
                continue;
            }
            let drawn = rays.point_rel(x, y, d, camera.near_m);
            // The grid point whose ground the exact mapping puts under the drawn point.
            let mut grid = rays.eye_grid_m.truncate() + drawn.truncate();
            let mut exact = DVec3::ZERO;
            for _ in 0..8 {
                grid = grid.clamp(glam::DVec2::ZERO, glam::DVec2::from(span));
                exact = placed.position_rel_m(grid.extend(dem.mesh_height_m(grid.x, grid.y)));
                grid += drawn.truncate() - exact.truncate();
            }
            let margin = 2.0 * dem.spacing_m;
            if grid.x < margin || grid.y < margin || grid.x > span[0] - margin || grid.y > span[1] - margin {
                continue;
            }
            misses.push((drawn.length(), drawn.z - exact.z));
        }
    }
    misses
}

#[test]
fn the_drawn_ground_lies_where_the_exact_mapping_puts_it() {
    let dataset = std::sync::Arc::new(synth_on_nc(600, 100.0, 5));
    let dem = Dem::load(&dataset);
    let mut settings = ground_settings(320, 180);
    // The finest LOD everywhere (no morph): the drawn ground is the finest mesh the oracle derives.
    settings.terrain.triangle_px = 0.01;
    let mut worst = [0.0f64; 2];
    let mut farthest = 0.0f64;
    for curved in [true, false] {
        settings.render.curved_earth = curved;
        let mut r = Renderer::new(gpu(), std::sync::Arc::clone(&dataset), settings.clone()).unwrap();
        let eye = DVec3::new(3_000.0, 3_000.0, dem.mesh_height_m(3_000.0, 3_000.0) + 800.0);
        let camera = at_grid(&r, eye, 45.0, -2.0);
        r.render_resolved(&camera).unwrap();
        let misses = vertical_misses(&r, &camera, &dem);
        let rays_pixel_at_1m = camera.metres_per_pixel(1.0, r.settings.render.height);
        assert!(misses.len() > 500, "{} ground pixels", misses.len());
        farthest = misses.iter().map(|m| m.0).fold(0.0, f64::max);
        if curved {
            for &(distance_m, miss_m) in &misses {
                // f32 positions relative to the eye (a few roundings of the distance: millimetres
                // here), the node polynomial's third order (well under a millimetre for 3.2 km
                // nodes) and the rasteriser's snapping of vertices to its sub-pixel grid (a pixel
                // here spans 6.4 m per km; lavapipe's largest miss is 8 cm at 40 km).
                let pixel_m = distance_m * rays_pixel_at_1m;
                let bound_m = 0.02 + 1e-3 * pixel_m;
                worst[0] = worst[0].max(miss_m.abs());
                assert!(miss_m.abs() <= bound_m, "{miss_m} m off at {distance_m} m");
            }
        } else {
            // The flat sheet stands above the Earth's ground by the drop, d² / 2R.
            let (distance_m, miss_m) = *misses.iter().max_by(|a, b| a.0.total_cmp(&b.0)).unwrap();
            let drop_m = distance_m * distance_m / (2.0 * 6.37e6);
            worst[1] = miss_m;
            assert!(
                (miss_m - drop_m).abs() < 0.05 * drop_m,
                "flat: {miss_m} m at {distance_m} m (drop {drop_m})"
            );
        }
    }
    println!(
        "farthest ground pixel {farthest:.0} m; largest miss on the Earth {:.4} m, flat {:.1} m",
        worst[0], worst[1]
    );
}

#[test]
fn a_curved_frame_has_no_hole_below_its_horizon() {
    let dataset = synth_on_nc(600, 100.0, 5);
    let dem = Dem::load(&dataset);
    let mut r = Renderer::new(gpu(), dataset, ground_settings(240, 136)).unwrap();
    for (yaw, pitch, above_m) in [(30.0, -1.0, 300.0), (200.0, -8.0, 2_000.0), (120.0, -0.2, 20.0)] {
        let (x, y) = (30_000.0, 30_000.0);
        let camera = at_grid(&r, DVec3::new(x, y, dem.mesh_height_m(x, y) + above_m), yaw, pitch);
        r.render_resolved(&camera).unwrap();
        let width = r.settings.render.width as usize;
        let depth = r.read_depth().unwrap();
        let rows: Vec<&[f32]> = depth.chunks(width).collect();
        for column in 0..width {
            let first = rows.iter().position(|row| row[column] > 0.0).unwrap_or(rows.len());
            let hole = rows[first..].iter().position(|row| row[column] == 0.0);
            assert!(hole.is_none(), "yaw {yaw}: hole at column {column}, row {}", first + hole.unwrap_or(0));
        }
    }
}

/// A camera written on the Earth lands in the dataset's CRS where the pose is: `lonlat:` at its
/// height above the ellipsoid, `lonlat-ground:` that far above the ground there; the CRS form is
/// read as before, and a dataset that does not say where it lies refuses the Earth's forms.
#[test]
fn cameras_are_placed_from_longitude_and_latitude() {
    let dataset = synth_on_nc(600, 100.0, 5);
    let earth = dataset.manifest.earth.clone().unwrap();
    let [ox, oy] = dataset.manifest.origin_m;
    let [lon_deg, lat_deg] = lon_lat_deg(&dataset, [30_000.0, 20_000.0]);
    let (lat, lon) = (lat_deg.to_radians(), lon_deg.to_radians());
    let on_earth =
        dataset.camera_from(&format!("lonlat:{lon_deg},{lat_deg},2500,90,-30"), 60.0, 0.1).unwrap();
    let p = on_earth.position_m;
    assert!((p.x - ox - 30_000.0).abs() < 1e-4 && (p.y - oy - 20_000.0).abs() < 1e-4, "{p}");
    let wanted = terramp::earth::Ellipsoid::WGS84.ecef_m(lat, lon, 2_500.0);
    assert!((earth.ecef_m(p.x, p.y, p.z) - wanted).length() < 1e-5, "{p}");
    assert_eq!(on_earth.pitch_deg, -30.0);
    let above =
        dataset.camera_from(&format!("lonlat-ground:{lon_deg},{lat_deg},40,90,-30"), 60.0, 0.1).unwrap();
    let ground_m = dataset.height_at(30_000.0, 20_000.0, 0).unwrap();
    assert!((above.position_m.z - ground_m - 40.0).abs() < 1e-3, "{} over {ground_m}", above.position_m);
    // The grid's north, taken 2.5 km higher, turns by under 10⁻⁶°.
    assert!((above.yaw_deg - on_earth.yaw_deg).abs() < 1e-5, "{} {}", above.yaw_deg, on_earth.yaw_deg);
    let crs = dataset.camera_from("630000,200000,900,10,-20", 60.0, 0.1).unwrap();
    assert_eq!((crs.position_m, crs.yaw_deg), (DVec3::new(630_000.0, 200_000.0, 900.0), 10.0));
    for bad in ["lonlat:1,2,3", "lonlat:a,2,3,4,5", "geo:1,2,3,4,5", "1,2,3"] {
        assert!(matches!(dataset.camera_from(bad, 60.0, 0.1), Err(CameraPoseError::Parse(_))), "{bad}");
    }
    let mut flat = synth_on_nc(600, 100.0, 5);
    flat.manifest.earth = None;
    let refused = flat.camera_from("lonlat:-78.6,35.7,900,0,-20", 60.0, 0.1);
    assert!(matches!(refused, Err(CameraPoseError::NotOnEarth(_))), "{refused:?}");
}

/// A camera path whose keyframes are given on the Earth lands, key by key, where the cameras
/// written the same way land.
#[test]
fn camera_paths_on_the_earth_are_placed_in_the_dataset() {
    let dataset = synth_on_nc(600, 100.0, 5);
    let [lon_deg, lat_deg] = lon_lat_deg(&dataset, [10_000.0, 40_000.0]);
    let dir = terramp_testkit::TempDir::new("earth-path");
    let file = dir.path().join("path.toml");
    let text = format!(
        "[[key]]\nlonlat = [{lon_deg}, {lat_deg}, 3000.0]\nheading_deg = 45.0\npitch_deg = -20.0\n\
         [[key]]\nlonlat = [{lon_deg}, {lat_deg}, 50.0]\nheading_deg = 0.0\npitch_deg = -5.0\nabove_ground = true\n"
    );
    std::fs::write(&file, text).unwrap();
    let path = terramp::profile::load_path(&dataset, &file).unwrap();
    for (key, written) in path.keys.iter().zip([
        format!("lonlat:{lon_deg},{lat_deg},3000,45,-20"),
        format!("lonlat-ground:{lon_deg},{lat_deg},50,0,-5"),
    ]) {
        let camera = dataset.camera_from(&written, 60.0, 0.1).unwrap();
        assert_eq!(
            (DVec3::from(key.at), key.yaw_deg, key.pitch_deg),
            (camera.position_m, camera.yaw_deg, camera.pitch_deg)
        );
    }
    let mut flat = synth_on_nc(600, 100.0, 5);
    flat.manifest.earth = None;
    assert!(terramp::profile::load_path(&flat, &file).unwrap_err().to_string().contains("keyframe 0"));
}
