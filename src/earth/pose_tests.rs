//! Poses on the Earth into nc's State Plane and a local azimuthal frame.

use glam::DVec3;

use super::*;
use crate::earth::GeoidLattice;
use crate::earth::local::LocalFrame;
use crate::earth::test_frames::nc;

fn raleigh(heading_deg: f64, pitch_deg: f64) -> GeoPose {
    GeoPose { lon_deg: -78.64, lat_deg: 35.78, height_m: 1_500.0, heading_deg, pitch_deg }
}

/// The CRS point lands where the pose is, to a micrometre, and a camera with the returned yaw and
/// pitch in the renderer's frame looks along the pose's heading and pitch on the Earth.
#[test]
fn a_pose_on_the_earth_lands_where_it_is_and_looks_where_it_looks() {
    let earth = nc();
    for (heading, pitch) in [(0.0, 0.0), (30.0, -20.0), (250.0, 45.0)] {
        let pose = raleigh(heading, pitch);
        let crs = pose.in_crs(&earth).unwrap();
        let wanted =
            Ellipsoid::WGS84.ecef_m(pose.lat_deg.to_radians(), pose.lon_deg.to_radians(), pose.height_m);
        let p = crs.position_m;
        assert!((earth.ecef_m(p.x, p.y, p.z) - wanted).length() < 1e-6, "{p}");
        let frame = LocalFrame::grid_aligned(&earth, p.x, p.y, p.z);
        let (yaw, pitch) = (crs.yaw_deg.to_radians(), crs.pitch_deg.to_radians());
        let forward = DVec3::new(yaw.sin() * pitch.cos(), yaw.cos() * pitch.cos(), pitch.sin());
        let enu = LocalFrame::at(&earth, p.x, p.y, p.z).local_from_ecef
            * (frame.local_from_ecef.transpose() * forward);
        let azimuth = enu.x.atan2(enu.y).to_degrees();
        let elevation = enu.z.asin().to_degrees();
        let turn = (azimuth - heading + 180.0).rem_euclid(360.0) - 180.0;
        assert!(turn.abs() < 1e-9 && (elevation - pose.pitch_deg).abs() < 1e-9, "{azimuth} {elevation}");
    }
    // Raleigh lies east of the cone's central meridian (79° W): grid north turns east of true
    // north by the convergence, about sin(φ0) × 0.36° = 0.21°.
    let yaw = raleigh(0.0, 0.0).in_crs(&earth).unwrap().yaw_deg;
    assert!((360.0 - yaw - 0.21).abs() < 0.01, "{yaw}");
}

/// Heights above a geoid: the pose's height above the ellipsoid less the undulation.
#[test]
fn a_pose_height_is_taken_above_the_datum_s_geoid() {
    let mut earth = nc();
    earth.geoid = Some(GeoidLattice {
        name: "test".into(),
        south_west_deg: [30.0, -85.0],
        step_deg: 1.0,
        size: [12, 12],
        undulation_m: vec![-30.0; 144],
        interpolation_error_m: 0.0,
    });
    let crs = raleigh(0.0, 0.0).in_crs(&earth).unwrap();
    assert!((crs.position_m.z - 1_530.0).abs() < 1e-6, "{}", crs.position_m);
}

#[test]
fn a_pose_out_of_range_or_out_of_reach_is_an_error() {
    let pose = GeoPose { lat_deg: 95.0, ..raleigh(0.0, 0.0) };
    assert!(matches!(pose.in_crs(&nc()), Err(PoseError::Range("latitude", ..))));
    let pose = GeoPose { height_m: f64::NAN, ..raleigh(0.0, 0.0) };
    assert!(matches!(pose.in_crs(&nc()), Err(PoseError::Range("height", ..))));
    // A local azimuthal frame does not reach its centre's antipode.
    let aeqd = crate::earth::test_frames::globe();
    let antipode = GeoPose { lon_deg: -135.0, lat_deg: -25.0, ..raleigh(0.0, 0.0) };
    assert!(
        matches!(antipode.in_crs(&aeqd), Err(PoseError::Unreachable { .. })),
        "{:?}",
        antipode.in_crs(&aeqd)
    );
}
