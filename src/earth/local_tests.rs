//! The camera's local frame and a node's polynomial, on nc's State Plane (EPSG:32119: Lambert
//! Conformal Conic on GRS 80, NAD83 taken as WGS 84 as PROJ's default step does; heights above
//! the ellipsoid here, so that the ground's shape is the ellipsoid's alone).

use glam::{DVec3, Vec3};

use super::*;
use crate::earth::test_frames::nc;

/// nc's centre, CRS metres.
const CENTRE_M: [f64; 2] = [637_500.0, 221_750.0];

/// The radius of curvature of the ellipsoid at latitude `lat` in the direction `azimuth` (Euler).
fn euler_radius_m(lat: f64, azimuth: f64) -> f64 {
    let e = Ellipsoid::WGS84;
    let w = (1.0 - e.e2() * lat.sin().powi(2)).sqrt();
    let (m, n) = (e.a_m * (1.0 - e.e2()) / w.powi(3), e.a_m / w);
    1.0 / (azimuth.cos().powi(2) / m + azimuth.sin().powi(2) / n)
}

#[test]
fn the_ground_below_the_camera_is_straight_down() {
    let earth = nc();
    let [x, y] = CENTRE_M;
    let frame = LocalFrame::at(&earth, x, y, 3_000.0);
    let below = frame.position_m(&earth, x, y, 100.0);
    assert!((below - DVec3::new(0.0, 0.0, -2_900.0)).length() < 1e-6, "{below}");
    assert!(frame.position_m(&earth, x, y, 3_000.0).length() < 1e-6);
}

/// The ground at the camera's height falls away below its horizontal plane as a circle of the
/// ellipsoid's radius of curvature in that direction does: R − √(R² − d²) at horizontal distance
/// d (4.4 m at 7.5 km, 196 m at 50 km, 785 m at 100 km on a sphere of 6,371 km).
#[test]
fn the_ground_falls_away_as_the_earth_curves() {
    let earth = nc();
    let [x, y] = CENTRE_M;
    let frame = LocalFrame::at(&earth, x, y, 0.0);
    let (lat, _) = earth.geodetic(x, y);
    for (dx, dy) in [(7_500.0, 0.0), (0.0, 50_000.0), (-70_000.0, 70_000.0), (100_000.0, 0.0)] {
        let p = frame.position_m(&earth, x + dx, y + dy, 0.0);
        let (d, azimuth) = (p.truncate().length(), p.x.atan2(p.y));
        let r = euler_radius_m(lat, azimuth);
        let drop_m = r - (r * r - d * d).sqrt();
        // Over 100 km an osculating circle and the ellipsoid part by a few parts in 10⁴ of the drop.
        assert!((-p.z - drop_m).abs() < 1e-3 * drop_m, "({dx}, {dy}): {} m against {drop_m} m", -p.z);
    }
}

/// The largest distance between a node's f32 polynomial and the exact mapping over a 9 × 9
/// lattice of its CRS offsets at two heights.
fn node_error_m(frame: &LocalFrame, earth: &EarthFrame, origin_m: DVec3, half_m: f64) -> (f64, f64) {
    let node = frame.node(earth, origin_m);
    let (mut worst, mut farthest) = (0.0f64, 0.0f64);
    for j in 0..9 {
        for i in 0..9 {
            for dh in [0.0, 800.0] {
                let (dx, dy) = (half_m * (i as f64 / 4.0 - 1.0), half_m * (j as f64 / 4.0 - 1.0));
                let exact = frame.position_m(earth, origin_m.x + dx, origin_m.y + dy, origin_m.z + dh);
                let drawn = node.position_m(Vec3::new(dx as f32, dy as f32, dh as f32)).as_dvec3();
                worst = worst.max((drawn - exact).length());
                farthest = farthest.max(exact.length());
            }
        }
    }
    (worst, farthest)
}

/// A node's polynomial against the exact mapping, for nodes from 1 km to 100 km across, near the
/// camera and far from it: within f32's rounding of the farthest point (2⁻²⁴ of its distance,
/// a few such roundings) plus the third-order term r³ / (6 R²) a node of half-diagonal r leaves
/// (doubled, and 3 × d / R more for a node at distance d where the drop's third derivative grows).
#[test]
fn a_node_s_polynomial_places_its_points_within_f32_and_the_third_order() {
    let earth = nc();
    let [x, y] = CENTRE_M;
    let frame = LocalFrame::at(&earth, x, y, 1_500.0);
    let radius_m = 6.371e6;
    for half_m in [500.0, 5_000.0, 50_000.0] {
        for (ox, oy, oz) in [(0.0, 0.0, 150.0), (20_000.0, -10_000.0, 80.0), (-150_000.0, 90_000.0, 300.0)] {
            let (error_m, farthest_m) = node_error_m(&frame, &earth, DVec3::new(x + ox, y + oy, oz), half_m);
            let distance_m = f64::hypot(ox, oy);
            let half_diagonal_m = std::f64::consts::SQRT_2 * half_m;
            let third_order =
                half_diagonal_m.powi(3) / (6.0 * radius_m * radius_m) * (2.0 + 3.0 * distance_m / radius_m);
            let rounding = 4.0 * farthest_m * f64::from(f32::EPSILON);
            let bound = rounding + third_order;
            println!("half-size {half_m} m at ({ox}, {oy}): {error_m:.6} m (bound {bound:.6} m)");
            assert!(error_m <= bound, "half-size {half_m} m at ({ox}, {oy}): {error_m} m > {bound} m");
        }
    }
}

/// Without the second-order terms a node 10 km across near the camera misses by the Earth's
/// drop across it (about 4 m at its corner): the polynomial's curvature is what places it.
#[test]
fn the_curvature_terms_are_what_bend_a_node() {
    let earth = nc();
    let [x, y] = CENTRE_M;
    let frame = LocalFrame::at(&earth, x, y, 1_500.0);
    let origin_m = DVec3::new(x, y, 150.0);
    let node = frame.node(&earth, origin_m);
    let flat = NodeMapping { d_xx: Vec3::ZERO, d_xy: Vec3::ZERO, d_yy: Vec3::ZERO, ..node };
    let corner = Vec3::new(5_000.0, 5_000.0, 0.0);
    let exact = frame.position_m(&earth, x + 5_000.0, y + 5_000.0, 150.0);
    let (bent, unbent) = (node.position_m(corner).as_dvec3(), flat.position_m(corner).as_dvec3());
    assert!((bent - exact).length() < 0.01, "{bent} against {exact}");
    let drop_m = 50_000_000.0 / (2.0 * 6.38e6);
    assert!(((unbent - exact).length() - drop_m).abs() < 0.1 * drop_m, "{unbent} against {exact}");
}

/// The geoid enters a node's mapping to the first order: a kink of its bilinear lattice (a node
/// meridian 100 m from the node's origin) costs the polynomial the slope's jump times the distance
/// past it, growing with the node's size (twice as large a node, about twice the miss), where
/// second differences across the kink would turn it into a curvature (about four times); inside
/// a lattice cell the node misses by the ellipsoid's third order alone. The lattice's nodes differ
/// by up to 2 m.
#[test]
fn a_kink_in_the_geoid_costs_a_slope_not_a_curvature() {
    let mut frame = nc();
    let (w, h) = (24u32, 16u32);
    let undulation_m: Vec<f32> =
        (0..w * h).map(|i| -34.0 + (i.wrapping_mul(2_654_435_761) >> 24) as f32 / 128.0).collect();
    frame.geoid = Some(crate::earth::GeoidLattice {
        name: "test".into(),
        south_west_deg: [33.0, -82.0],
        step_deg: 0.25,
        size: [w, h],
        undulation_m,
        interpolation_error_m: 0.0,
    });
    let [x_line, y_line] =
        frame.projection.forward(&frame.ellipsoid, 35.6f64.to_radians(), (-78.75f64).to_radians());
    let miss = |dx: f64, side_m: f64| {
        let origin = DVec3::new(x_line + dx, y_line, 0.0);
        let node = EcefNode::at(&frame, origin);
        let mut worst = 0.0f64;
        for j in 0..=8 {
            for i in 0..=8 {
                let f = |k: i32| (f64::from(k) / 8.0 - 0.5) * side_m;
                let offset = DVec3::new(f(i), f(j), 0.0);
                let p = origin + offset;
                worst = worst.max((node.position_m(offset) - frame.ecef_m(p.x, p.y, p.z)).length());
            }
        }
        worst
    };
    let [near_5, near_10, inside_10] =
        [miss(100.0, 5_000.0), miss(100.0, 10_000.0), miss(11_000.0, 10_000.0)];
    println!(
        "100 m from a kink: {near_5:.4} m (5 km node), {near_10:.4} m (10 km); inside a cell: {inside_10:.4} m"
    );
    assert!(near_10 < 3.0 * near_5, "{near_5} {near_10}: the kink bends the polynomial");
    assert!(inside_10 < 0.005, "{inside_10}");
}
