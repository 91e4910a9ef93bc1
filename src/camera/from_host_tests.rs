use glam::{DMat3, DMat4, DQuat, DVec3};

use super::*;

/// How far a rotation rebuilt from a camera may be from the one it was made from, per element:
/// f64 rounding through the angles' sines and cosines.
const ROUND_TRIP_OFF: f64 = 1e-12;

fn at() -> DVec3 {
    DVec3::new(637_500.0, 221_750.0, 3_000.0)
}

/// The largest difference between two matrices' elements.
fn off(a: DMat3, b: DMat3) -> f64 {
    (a - b).to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// Uniform rotations from a fixed sequence (Shoemake's method).
fn rotations(n: usize) -> Vec<DMat3> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = move || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            let (u1, u2, u3) = (next(), next(), next());
            let tau = std::f64::consts::TAU;
            let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
            let q = DQuat::from_xyzw(
                a * (tau * u2).sin(),
                a * (tau * u2).cos(),
                b * (tau * u3).sin(),
                b * (tau * u3).cos(),
            );
            DMat3::from_quat(q.normalize())
        })
        .collect()
}

#[test]
fn any_rotation_becomes_a_camera_whose_rotation_is_it() {
    let mut cases = rotations(2_000);
    // Straight down and straight up, at several headings, and the identity (straight down, north up).
    for yaw in [0.0f64, 37.0, 90.0, 181.0, -120.0] {
        for pitch in [-90.0, 90.0] {
            let c = Camera {
                yaw_deg: yaw,
                pitch_deg: pitch,
                ..Camera::parse_pose("0,0,0,0,0", 60.0, 1.0).unwrap()
            };
            cases.push(c.world_from_view_rotation());
        }
    }
    cases.push(DMat3::IDENTITY);
    let worst = cases
        .iter()
        .map(|&r| off(Camera::from_rotation(at(), r, 60.0, 1.0).unwrap().world_from_view_rotation(), r))
        .fold(0.0f64, f64::max);
    assert!(worst < ROUND_TRIP_OFF, "worst element off by {worst}");
}

#[test]
fn roll_turns_the_camera_about_its_view_direction_lowering_its_right_side() {
    for (i, r) in rotations(200).into_iter().enumerate() {
        let host = Camera::from_rotation(at(), r, 60.0, 1.0).unwrap();
        let roll = (i as f64 * 17.0) % 360.0 - 180.0;
        let rolled = Camera { roll_deg: roll, ..host };
        let level = Camera { roll_deg: 0.0, ..host };
        // The unrolled camera's axes as glam's look-to matrix gives them (up: the zenith), turned
        // about the forward direction by the roll.
        if level.forward().z.abs() > 0.999 {
            continue;
        }
        let look =
            DMat3::from_mat4(glam::dcamera::rh::view::look_to_mat4(DVec3::ZERO, level.forward(), DVec3::Z));
        let turn = DMat3::from_quat(DQuat::from_axis_angle(level.forward(), roll.to_radians()));
        let want = turn * look.transpose();
        assert!(off(rolled.world_from_view_rotation(), want) < 1e-12, "{rolled:?}");
    }
    let banked = Camera { roll_deg: 30.0, ..Camera::parse_pose("0,0,0,0,0", 60.0, 1.0).unwrap() };
    assert!(banked.world_from_view_rotation().x_axis.z < 0.0, "banking right lowers the right side");
}

#[test]
fn a_hosts_matrices_give_back_the_camera_that_made_them() {
    let (w, h) = (1280, 720);
    for (i, r) in rotations(100).into_iter().enumerate() {
        let fov = 1.0 + i as f64 * 1.7;
        let near = 0.01 * (1 + i) as f64;
        let made = Camera::from_rotation(at(), r, fov, near).unwrap();
        let (view, clip) = (made.view_from_world(), made.clip_from_view(w, h).unwrap());
        let taken = Camera::from_matrices(at(), view, clip, [w, h]).unwrap();
        assert!((taken.fov_deg - fov).abs() < 1e-9 && (taken.near_m - near).abs() < 1e-12, "{taken:?}");
        let (a, b) = (clip * view, taken.clip_from_view(w, h).unwrap() * taken.view_from_world());
        let scale = a.to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let worst = (a - b).to_cols_array().iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(worst < 1e-12 * scale, "{worst}");
    }
}

#[test]
fn other_kinds_of_matrices_are_refused_naming_what_differs() {
    use glam::dcamera::rh::proj::{directx, vulkan};
    let (fov, aspect, near) = (1.0, 16.0 / 9.0, 0.5);
    let view = DMat4::IDENTITY;
    let take = |clip: DMat4| Camera::from_matrices(at(), view, clip, [1600, 900]);
    assert!(take(directx::perspective_infinite_reverse(fov, aspect, near)).is_ok());
    let finite = take(directx::perspective(fov, aspect, near, 1e5));
    assert!(matches!(finite, Err(HostCameraError::Projection(2, 2, _, _))), "{finite:?}");
    let forward_z = take(directx::perspective_infinite(fov, aspect, near));
    assert!(matches!(forward_z, Err(HostCameraError::Projection(2, 2, _, _))), "{forward_z:?}");
    let flipped = take(vulkan::perspective_infinite_reverse(fov, aspect, near));
    assert_eq!(flipped, Err(HostCameraError::NotPositive("y scale", -1.0 / (0.5f64).tan())));
    let mut off_centre = directx::perspective_infinite_reverse(fov, aspect, near);
    off_centre.z_axis.x = 0.1;
    assert!(matches!(take(off_centre), Err(HostCameraError::Projection(2, 0, _, _))));
    let aspect_of = |a: f64| take(directx::perspective_infinite_reverse(fov, a, near));
    assert!(matches!(aspect_of(4.0 / 3.0), Err(HostCameraError::Aspect(_, _))));
    let clip = directx::perspective_infinite_reverse(fov, aspect, near);
    let moved = DMat4::from_translation(DVec3::new(1.0, 2.0, 3.0));
    assert_eq!(
        Camera::from_matrices(at(), moved, clip, [1600, 900]),
        Err(HostCameraError::Translation([1.0, 2.0, 3.0]))
    );
    let scaled = DMat4::from_scale(DVec3::splat(1.01));
    assert!(matches!(
        Camera::from_matrices(at(), scaled, clip, [1600, 900]),
        Err(HostCameraError::NotRotation(_))
    ));
    let mirrored = DMat3::from_cols(-DVec3::X, DVec3::Y, DVec3::Z);
    assert!(matches!(Camera::from_rotation(at(), mirrored, 60.0, 1.0), Err(HostCameraError::NotRotation(_))));
    let nan = DMat3::from_cols(DVec3::NAN, DVec3::Y, DVec3::Z);
    assert!(matches!(Camera::from_rotation(at(), nan, 60.0, 1.0), Err(HostCameraError::NotRotation(_))));
    let narrow = Camera::from_rotation(at(), DMat3::IDENTITY, 0.001, 1.0);
    assert_eq!(narrow, Err(HostCameraError::Camera(CameraError::Fov(0.001))));
}
