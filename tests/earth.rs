//! The Earth mapping's shader (`shaders/shared/earth.wgsl`) against its Rust twin
//! (`earth::local::NodeMapping::position_m`): nodes 1 km to 100 km across, near zion's camera and
//! far from it, each placing a 9 × 9 lattice of points at two heights. The two sum the same terms
//! in the same order; a GPU may fuse a product into the sum it feeds, so they agree to a few
//! roundings of the largest term, not to the bit. And `earth_stand`, which stands a seed's model on
//! its place, against the exact rotation.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::{DQuat, DVec3, Vec3};
use terramp::earth::gpu::{probe_positions, probe_stand};
use terramp::earth::local::LocalFrame;
use terramp::earth::{EarthFrame, Ellipsoid, Projection};
use terramp::gpu::gpu_types::{EarthNode, EarthProbePoint};
use terramp_testkit::gpu;

/// The GPU's result and the twin's within this many roundings (f32's epsilon) of the largest
/// term's magnitude: each of the polynomial's nine products may be fused or not.
const ROUNDINGS: f32 = 8.0;

/// zion's UTM zone 12 N on NAD83 (EPSG:26912), NAD83 taken as WGS 84, heights above the ellipsoid.
fn zion() -> EarthFrame {
    EarthFrame::ellipsoidal(
        Projection::TransverseMercator {
            lat_origin_deg: 0.0,
            lon_origin_deg: -111.0,
            scale: 0.9996,
            false_easting_m: 500_000.0,
            false_northing_m: 0.0,
        },
        Ellipsoid::GRS80,
        "NAD83 (EPSG:26912), taken as WGS 84",
    )
}

#[test]
fn the_shader_places_points_as_its_twin_does() {
    let earth = zion();
    let (x, y) = (316_900.0, 4_136_000.0);
    let frame = LocalFrame::at(&earth, x, y, 2_600.0);
    let mut mappings = Vec::new();
    let mut points = Vec::new();
    for half_m in [500.0f32, 5_000.0, 50_000.0] {
        for (ox, oy, oz) in
            [(0.0, 0.0, 1_200.0), (30_000.0, 10_000.0, 1_500.0), (-200_000.0, 150_000.0, 2_000.0)]
        {
            let node = mappings.len() as u32;
            mappings.push(frame.node(&earth, DVec3::new(x + ox, y + oy, oz)));
            for j in 0..9 {
                for i in 0..9 {
                    for dh in [0.0, 800.0] {
                        let offset_m = [half_m * (i as f32 / 4.0 - 1.0), half_m * (j as f32 / 4.0 - 1.0), dh];
                        points.push(EarthProbePoint { offset_m, node });
                    }
                }
            }
        }
    }
    let nodes: Vec<EarthNode> = mappings.iter().map(EarthNode::from).collect();
    let on_gpu = probe_positions(&gpu(), &nodes, &points).unwrap();
    assert_eq!(on_gpu.len(), points.len());
    let mut worst = 0.0f32;
    for (point, gpu) in points.iter().zip(&on_gpu) {
        let mapping = &mappings[point.node as usize];
        let twin = mapping.position_m(Vec3::from(point.offset_m));
        let largest = mapping.origin_m.length().max(Vec3::from(point.offset_m).length());
        let miss = (Vec3::from(*gpu) - twin).length();
        worst = worst.max(miss / largest);
        assert!(miss <= ROUNDINGS * f32::EPSILON * largest, "{point:?}: GPU {gpu:?}, twin {twin}");
    }
    println!("{} points: the largest miss {worst:.2e} of the largest term", points.len());
}

/// Most the shader's stood vector may part from the exact rotation's, in units of the vector's
/// length: f32's rounding of a rotation's few products and sums.
const STAND_MISS: f32 = 1e-6;

/// `earth_stand` (how pass 4 stands a seed's model on its place) against the exact least rotation
/// that takes straight up to the place's vertical (f64, `DQuat::from_rotation_arc`): verticals of
/// nodes up to 1,000 km from zion's camera (9° of tilt), vectors a plant's size in every
/// direction. Straight up, every vector comes back to the bit.
#[test]
fn the_shader_stands_vectors_on_the_local_vertical() {
    let earth = zion();
    let (x, y) = (316_900.0, 4_136_000.0);
    let frame = LocalFrame::at(&earth, x, y, 2_600.0);
    let mut nodes = vec![EarthNode::FLAT];
    for (ox, oy) in [(0.0, 0.0), (3_000.0, -2_000.0), (-80_000.0, 50_000.0), (700_000.0, 700_000.0)] {
        nodes.push(EarthNode::from(&frame.node(&earth, DVec3::new(x + ox, y + oy, 0.0))));
    }
    let mut points = Vec::new();
    for node in 0..nodes.len() as u32 {
        for k in 0..64 {
            let (a, b) = (f64::from(k) * 0.7, f64::from(k) * 1.3);
            let v = [
                (a.cos() * b.sin() * 12.0) as f32,
                (a.sin() * b.sin() * 12.0) as f32,
                (b.cos() * 20.0) as f32,
            ];
            points.push(EarthProbePoint { offset_m: v, node });
        }
    }
    let stood = probe_stand(&gpu(), &nodes, &points).unwrap();
    let mut worst = 0.0f32;
    let mut tilt = 0.0f64;
    for (point, gpu) in points.iter().zip(&stood) {
        let d_h = nodes[point.node as usize].d_h;
        let up = DVec3::new(d_h[0].into(), d_h[1].into(), d_h[2].into()).normalize();
        tilt = tilt.max(up.angle_between(DVec3::Z));
        let v = DVec3::new(point.offset_m[0].into(), point.offset_m[1].into(), point.offset_m[2].into());
        let exact = (DQuat::from_rotation_arc(DVec3::Z, up) * v).as_vec3();
        let miss = (Vec3::from(*gpu) - exact).length() / exact.length();
        worst = worst.max(miss);
        assert!(miss <= STAND_MISS, "{point:?}: GPU {gpu:?}, exact {exact}");
        if point.node == 0 {
            assert_eq!(*gpu, point.offset_m, "straight up changed a vector");
        }
    }
    println!(
        "{} vectors, verticals up to {:.2}° off: the largest miss {worst:.2e} of a vector",
        points.len(),
        tilt.to_degrees()
    );
    assert!(tilt.to_degrees() > 5.0, "tilts up to {tilt} rad say little");
}
