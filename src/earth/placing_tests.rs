//! The renderer's placing on nc's State Plane (EPSG:32119, heights above the ellipsoid) and flat.

use glam::{DVec3, Vec3};

use super::*;
use crate::earth::local::NodeMapping;
use crate::earth::test_frames::nc;

/// nc's grid origin, CRS metres (as its manifest would hold a south-west corner).
const ORIGIN_M: [f64; 2] = [600_000.0, 180_000.0];

fn mapping(node: &EarthNode) -> NodeMapping {
    let v = |a: [f32; 4]| Vec3::new(a[0], a[1], a[2]);
    NodeMapping {
        origin_m: v(node.origin_m),
        d_x: v(node.d_x),
        d_y: v(node.d_y),
        d_h: v(node.d_h),
        d_xx: v(node.d_xx),
        d_xy: v(node.d_xy),
        d_yy: v(node.d_yy),
        d_xh: v(node.d_xh),
        d_yh: v(node.d_yh),
    }
}

/// Flat, a node's polynomial is the sum the flat sheet forms: its origin less the camera's, plus
/// the offset, to the bit.
#[test]
fn flat_placing_is_the_flat_sheet_to_the_bit() {
    let mut placing = EarthPlacing::new(Some(&nc()), ORIGIN_M, false);
    assert!(!placing.is_round());
    let camera = DVec3::new(37_512.3, 41_007.9, 1_733.25);
    let exact = placing.exact(camera);
    let mut view = placing.view(&exact);
    let origin = DVec3::new(36_480.0, 40_960.0, 0.0);
    let node = mapping(&view.node(origin));
    let origin_rel = (origin - camera).as_vec3();
    for offset in [Vec3::new(0.0, 0.0, 812.5), Vec3::new(2_560.0, 17.5, 1_233.4), Vec3::new(-3.75, -1e3, 0.1)]
    {
        assert_eq!(node.position_m(offset), origin_rel + offset);
    }
    assert_eq!(view.box_rel_m(origin, origin + 1.0), (origin - camera, origin + 1.0 - camera));
}

/// The grid-aligned frame: straight down is down, and the grid's x direction at the camera is the
/// frame's first axis (no north turn left), the drop along it the Earth's.
#[test]
fn the_camera_frame_follows_the_grid_and_the_vertical() {
    let placing = EarthPlacing::new(Some(&nc()), ORIGIN_M, true);
    let camera = DVec3::new(40_000.0, 40_000.0, 2_000.0);
    assert!(placing.is_round());
    let view = placing.exact(camera);
    let below = view.position_rel_m(DVec3::new(camera.x, camera.y, 150.0));
    assert!((below - DVec3::new(0.0, 0.0, -1_850.0)).length() < 1e-6, "{below}");
    // The grid's line y = const bends away from the frame's axis only in the second order (the
    // convergence grows along it): 7 cm after 10 km, 0.7 mm after 1 km.
    let near = view.position_rel_m(DVec3::new(camera.x + 1_000.0, camera.y, 2_000.0));
    let along = view.position_rel_m(DVec3::new(camera.x + 10_000.0, camera.y, 2_000.0));
    assert!(
        near.y.abs() < 1e-3 && along.y.abs() < 0.1 && along.y.abs() > 50.0 * near.y.abs(),
        "{near} {along}"
    );
    let drop_m = 1e8 / (2.0 * 6.37e6);
    assert!((-along.z - drop_m).abs() < 0.01 * drop_m, "{along}");
    // The projection's scale near its standard parallels: within 10⁻³.
    assert!((along.x / 10_000.0 - 1.0).abs() < 1e-3, "{along}");
}

/// Every point of a 17 × 17 × 3 lattice over a box, placed exactly, lies in the box `box_rel_m`
/// gives, for boxes 1 km to 300 km across, beside the camera and 250 km from it; and that box is
/// not much larger.
#[test]
fn a_box_holds_what_its_ground_becomes() {
    let mut placing = EarthPlacing::new(Some(&nc()), ORIGIN_M, true);
    let camera = DVec3::new(40_000.0, 40_000.0, 3_000.0);
    let placement = placing.exact(camera);
    let mut view = placing.view(&placement);
    for side_m in [1_000.0, 20_000.0, 300_000.0] {
        for (ox, oy) in [(0.0, 0.0), (60_000.0, -20_000.0), (-200_000.0, 150_000.0)] {
            let min = DVec3::new(camera.x + ox - 0.5 * side_m, camera.y + oy - 0.3 * side_m, 50.0);
            let max = min + DVec3::new(side_m, 0.8 * side_m, 1_400.0);
            let (lo, hi) = view.box_rel_m(min, max);
            let mut exact = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for j in 0..=16 {
                for i in 0..=16 {
                    for k in 0..=2 {
                        let f = DVec3::new(f64::from(i) / 16.0, f64::from(j) / 16.0, f64::from(k) / 2.0);
                        let p = placement.position_rel_m(min + (max - min) * f);
                        assert!(p.cmpge(lo).all() && p.cmple(hi).all(), "{side_m} m at ({ox}, {oy}): {p}");
                        exact = (exact.0.min(p), exact.1.max(p));
                    }
                }
            }
            let slack = ((exact.0 - lo).max_element()).max((hi - exact.1).max_element());
            println!("{side_m} m box at ({ox}, {oy}): slack {slack:.3} m");
            assert!(slack < 0.01 * side_m, "{side_m} m at ({ox}, {oy}): slack {slack} m");
        }
    }
}

/// A mapping formed once and turned into another camera's frame is that camera's own.
#[test]
fn a_kept_mapping_serves_every_camera() {
    let mut placing = EarthPlacing::new(Some(&nc()), ORIGIN_M, true);
    let origin = DVec3::new(52_000.0, 38_000.0, 0.0);
    let node_from = |placing: &mut EarthPlacing, camera: DVec3| {
        let exact = placing.exact(camera);
        placing.view(&exact).node(origin)
    };
    let first = node_from(&mut placing, DVec3::new(40_000.0, 40_000.0, 2_000.0));
    let camera = DVec3::new(70_000.0, 20_000.0, 900.0);
    let kept = node_from(&mut placing, camera);
    assert_ne!(first, kept);
    let mut fresh = EarthPlacing::new(Some(&nc()), ORIGIN_M, true);
    let frame = LocalFrame::grid_aligned(&nc(), camera.x + ORIGIN_M[0], camera.y + ORIGIN_M[1], camera.z);
    let own = frame.node(&nc(), origin + DVec3::new(ORIGIN_M[0], ORIGIN_M[1], 0.0));
    assert_eq!(kept, node_from(&mut fresh, camera));
    assert_eq!(mapping(&kept), own);
}

/// `grid_m` undoes `position_rel_m` to a micrometre, beside the camera and 1,000 km away (and,
/// on an azimuthal equidistant frame, from 20,000 km up: `the_crs_point_of_a_position_is_where_it_came_from`).
#[test]
fn the_exact_placing_goes_back_to_the_grid() {
    let placing = EarthPlacing::new(Some(&nc()), ORIGIN_M, true);
    let exact = placing.exact(DVec3::new(40_000.0, 40_000.0, 3_000.0));
    for grid in [DVec3::new(40_010.0, 39_990.0, 100.0), DVec3::new(-300_000.0, 900_000.0, 2_500.0)] {
        let back = exact.grid_m(exact.position_rel_m(grid));
        assert!((back - grid).length() < 1e-6, "{grid} came back as {back}");
    }
    let flat = EarthPlacing::new(None, ORIGIN_M, true).exact(DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(flat.grid_m(DVec3::new(10.0, 20.0, -3.0)), DVec3::new(11.0, 22.0, 0.0));
}

/// A node's polynomial (in f64: f32's rounding, 6e-8 of the distance, is apart) misses the
/// exact mapping by no more than `miss_bound_m` says, on an azimuthal equidistant frame as wide as
/// GLOBE's tile (25° N 45° E), for nodes 30 km to 3,000 km across out to 5,000 km from the frame's
/// centre, where its scale across is 1.1.
#[test]
fn the_miss_bound_holds_a_continent_wide() {
    let globe = crate::earth::test_frames::globe();
    let placing = EarthPlacing::new(Some(&globe), [0.0, 0.0], true);
    let exact = placing.exact(DVec3::new(0.0, 0.0, 2.0e7));
    let mut kept = HashMap::new();
    let view = PlacedView { exact: &exact, kept: &mut kept };
    for side_m in [30e3, 300e3, 1_000e3, 3_000e3] {
        for centre in [DVec3::ZERO, DVec3::new(2_000e3, -1_000e3, 0.0), DVec3::new(-3_500e3, 3_500e3, 0.0)] {
            let half = DVec3::new(0.5 * side_m, 0.5 * side_m, 0.0);
            let (min, max) = (centre - half, centre + half + DVec3::Z * 8_000.0);
            let node = EcefNode::at(&globe, centre);
            let mut worst = 0.0f64;
            for j in 0..=8 {
                for i in 0..=8 {
                    for h in [0.0, 8_000.0] {
                        let offset = DVec3::new(
                            (f64::from(i) / 8.0 - 0.5) * side_m,
                            (f64::from(j) / 8.0 - 0.5) * side_m,
                            h,
                        );
                        let p = centre + offset;
                        worst = worst.max((node.position_m(offset) - globe.ecef_m(p.x, p.y, p.z)).length());
                    }
                }
            }
            let bound = view.miss_bound_m(min, max);
            let at_km = centre / 1e3;
            println!(
                "{:.0} km node at ({:.0}, {:.0}) km: misses {worst:.3} m, bound {bound:.3} m",
                side_m / 1e3,
                at_km.x,
                at_km.y
            );
            assert!(worst <= bound, "{side_m} m at {centre}: {worst} > {bound}");
        }
    }
}
