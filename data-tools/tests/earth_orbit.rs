//! From orbit (issue 44): a geographic sea-level raster made here, 72° square around 0° N 0° E at
//! 0.1° (one azimuthal equidistant frame out to 4,000 km from its centre), built and drawn at
//! 960 × 540 with a 60° vertical field of view from 40,000 km, 20,000 km and 2,000 km up (straight
//! down, and from 2,000 km 30° down towards the limb).
//!
//! From that high a terrain node may hold a thousand kilometres, and its second-order mapping
//! misses the ellipsoid by its third order (about r³ / 6R² at half-diagonal r). The selection
//! splits a node whose bound on that (`PlacedView::miss_bound_m`) exceeds `terrain.placing_miss_px`
//! pixels at its distance. Every fourth pixel's ray that shows ground is unprojected from its depth
//! and taken back to the CRS by the exact inverse (`EarthFrame::crs_m`): the height it finds there,
//! the drawn surface's height above the sea along the normal, stays within `placing_miss_px` pixels
//! at its distance (less f32's rounding of the depth, 10⁻⁶ of the distance). The same frames with
//! the split off (`inf`) are printed beside them. Each ray's own meeting with the sea's ellipsoid
//! (in the ellipsoid's scaled space) says whether its pixel must show the dataset: more than
//! `RIM_PX` pixels inside its grid it does (no hole), as far outside it does not (no stray ground).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::sync::Arc;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::earth::Ellipsoid;
use terramp::earth::local::LocalFrame;
use terramp::frame::Renderer;
use terramp_testkit::TempDir;
use terramp_testkit::audit::Rays;

use support::sea_level;

const SIZE: [u32; 2] = [960, 540];
const FOV_DEG: f64 = 60.0;
/// Every how many pixels a ray is judged, along each axis.
const RAY_STEP_PX: u32 = 4;
/// How far inside (or outside) the grid's edge a ray's meeting with the sea must lie for its pixel
/// to be judged as ground (or sky), pixels at its distance: the grid's rim is drawn by its
/// coarsest samples.
const RIM_PX: f64 = 3.0;

/// What one view shows.
#[derive(Debug)]
struct Seen {
    nodes: usize,
    /// Rays judged that show ground, and the largest height they find there, pixels.
    ground_rays: usize,
    worst_miss_px: f64,
    /// Rays that must show the dataset and show sky, and rays that must show sky and show ground.
    holes: usize,
    stray: usize,
}

fn view(dataset: &Arc<Dataset>, camera: &Camera, placing_miss_px: f64) -> Seen {
    let mut settings = Settings::default();
    [settings.render.width, settings.render.height] = SIZE;
    settings.render.fov_deg = FOV_DEG;
    settings.terrain.placing_miss_px = placing_miss_px;
    let mut r = Renderer::new(terramp_testkit::gpu(), Arc::clone(dataset), settings).unwrap();
    let (report, _) = r.render_resolved(camera).unwrap();
    let depth = r.read_depth().unwrap();
    let rays = Rays::new(&r, camera);
    let metres_per_pixel_at_1m = camera.metres_per_pixel(1.0, SIZE[1]);
    let earth = dataset.manifest.earth.clone().unwrap();
    let frame = LocalFrame::grid_aligned(&earth, 0.0, 0.0, camera.position_m.z);
    let sea_m = earth.undulation_m(0.0, 0.0);
    let e = Ellipsoid::WGS84;
    let scale = DVec3::new(e.a_m + sea_m, e.a_m + sea_m, e.b_m() + sea_m).recip();
    let eye = frame.eye_ecef_m * scale;
    let span_m = dataset.height.pyramid.size.map(|n| dataset.manifest.height.spacing_m * f64::from(n - 1));
    let mut seen = Seen { nodes: report.nodes_drawn, ground_rays: 0, worst_miss_px: 0.0, holes: 0, stray: 0 };
    for y in (0..SIZE[1]).step_by(RAY_STEP_PX as usize) {
        for x in (0..SIZE[0]).step_by(RAY_STEP_PX as usize) {
            let d = depth[(y * SIZE[0] + x) as usize];
            let dir_local = rays.dir(x, y);
            // Where the ray meets the sea's ellipsoid (the geoid's height at the centre: it varies
            // by tens of metres over the sea, far below a pixel from this high).
            let dir = (frame.local_from_ecef.transpose() * dir_local) * scale;
            let b = eye.dot(dir);
            let disc = b * b - dir.length_squared() * (eye.length_squared() - 1.0);
            let meets = (b < 0.0 && disc >= 0.0).then(|| {
                let t = (-b - disc.sqrt()) / dir.length_squared();
                frame.turn((eye + dir * t) / scale - frame.eye_ecef_m)
            });
            if d > 0.0 {
                let rel = rays.point_rel(x, y, d, camera.near_m);
                let grid = rays.exact.grid_m(rel);
                let pixel_m = metres_per_pixel_at_1m * rel.length();
                let miss_px = (grid.z.abs() - 1e-6 * rel.length()).max(0.0) / pixel_m;
                seen.ground_rays += 1;
                seen.worst_miss_px = seen.worst_miss_px.max(miss_px);
            }
            let Some(at_m) = meets else {
                seen.stray += usize::from(d > 0.0);
                continue;
            };
            let grid = rays.exact.grid_m(at_m);
            let rim_m = RIM_PX * metres_per_pixel_at_1m * at_m.length();
            let inside = |v: f64, a: usize| v > rim_m && v < span_m[a] - rim_m;
            let outside = |v: f64, a: usize| v < -rim_m || v > span_m[a] + rim_m;
            if inside(grid.x, 0) && inside(grid.y, 1) && d == 0.0 {
                seen.holes += 1;
            } else if (outside(grid.x, 0) || outside(grid.y, 1)) && d > 0.0 {
                seen.stray += 1;
            }
        }
    }
    seen
}

#[test]
fn from_orbit_the_sea_lies_on_the_ellipsoid() {
    let dir = TempDir::new("earth-orbit");
    let dataset = Arc::new(sea_level(dir.path(), 0.1, 720));
    let miss_px = Settings::default().terrain.placing_miss_px;
    for (height_m, pitch_deg) in
        [(40_000_000.0, -90.0), (20_000_000.0, -90.0), (2_000_000.0, -90.0), (2_000_000.0, -30.0)]
    {
        let camera = Camera {
            position_m: DVec3::new(0.0, 0.0, height_m),
            yaw_deg: 0.0,
            pitch_deg,
            roll_deg: 0.0,
            fov_deg: FOV_DEG,
            near_m: 0.1,
        };
        let split = view(&dataset, &camera, miss_px);
        let whole = view(&dataset, &camera, f64::INFINITY);
        let what = format!("{:.0} km up, pitch {pitch_deg}°", height_m / 1e3);
        println!("{what}: split {split:?}");
        println!("{what}: not split {whole:?}");
        assert!(split.ground_rays > 300, "{what}: the sea is hardly seen: {split:?}");
        assert!(split.worst_miss_px <= miss_px, "{what}: the ground misses the ellipsoid: {split:?}");
        assert_eq!((split.holes, split.stray), (0, 0), "{what}: {split:?}");
        // From 2,000 km the rings' nodes are wide enough that the split changes what is drawn.
        if height_m < 1e7 {
            assert!(split.nodes > whole.nodes, "{what}: nothing split: {split:?} {whole:?}");
            assert!(split.worst_miss_px < 0.5 * whole.worst_miss_px, "{what}: {split:?} {whole:?}");
        }
    }
}
