//! How it works: a host's camera, as an f64 position with a rotation or with its view and
//! projection matrices, turned into a `Camera`. The rotation is taken apart into heading, pitch
//! and roll (the forward axis gives heading and pitch; the right axis against the level right
//! gives the roll; straight up or down, where the heading and the roll turn about the same axis,
//! the roll is 0 and the heading carries the turn), so the camera's own rotation rebuilds it to
//! f64 rounding. The projection must be terramp's kind, perspective with reversed Z and an
//! infinite far plane centred on the view (`Camera::clip_from_view`): its field of view and near
//! plane are read from it, and any other kind is refused naming the element that differs, since
//! the host's depth and terramp's must agree for the two to occlude each other.
//!
//! The host's world space is terramp's camera-relative one: x along the dataset grid's east, y its
//! north, z up at the camera (on the round Earth the camera's grid-aligned local frame, as
//! `earth::placing` draws it), the camera at the origin. A view matrix with a translation is
//! refused: the position goes in f64 beside it, where the GPU never sees it.

use glam::{DMat3, DMat4, DVec3};
use thiserror::Error;

use super::{Camera, CameraError};

/// How far a host's rotation may be from orthonormal (its columns' dot products and lengths), and
/// its projection's elements from their expected values relative to its largest: a rotation made
/// in f32 and widened is within about 1e-7.
pub const HOST_MATRIX_TOLERANCE: f64 = 1e-6;

/// Why a host's camera cannot be taken.
#[derive(Debug, Error, PartialEq)]
pub enum HostCameraError {
    /// The rotation's columns are not orthonormal and right-handed within `HOST_MATRIX_TOLERANCE`
    /// (the largest departure).
    #[error(
        "host camera: the view's rotation is not orthonormal and right-handed (off by {0:.3e}; {HOST_MATRIX_TOLERANCE} allowed)"
    )]
    NotRotation(f64),
    /// The view matrix moves the origin (by this, metres): terramp's view matrices are
    /// camera-relative, the position given apart in f64.
    #[error(
        "host camera: the view matrix translates by {0:?} m; give it camera-relative (no translation) and the position apart in f64"
    )]
    Translation([f64; 3]),
    /// The view matrix is not a rotation with a last row of (0, 0, 0, 1).
    #[error("host camera: the view matrix is not affine (its last row is {0:?})")]
    NotAffine([f64; 4]),
    /// The projection is not perspective with reversed Z and an infinite far plane, centred: the
    /// element (column, row) that differs, its value and the value expected.
    #[error(
        "host camera: the projection is not terramp's (perspective, reversed Z, infinite far plane, centred): element [{0}][{1}] is {2}, expected {3}"
    )]
    Projection(usize, usize, f64, f64),
    /// The projection's x or y scale or its near plane (named) is not positive: mirrored, or
    /// upside down (a Vulkan-style projection), or forward Z.
    #[error("host camera: the projection's {0} is {1}; terramp's is positive")]
    NotPositive(&'static str, f64),
    /// The projection's aspect ratio (width / height) is not the viewport's.
    #[error("host camera: the projection's aspect {0} is not the viewport's {1}")]
    Aspect(f64, f64),
    /// The camera the host's matrices give is not one terramp can use.
    #[error(transparent)]
    Camera(#[from] CameraError),
}

impl Camera {
    /// The camera at `position_m` (dataset CRS, metres) whose view has the axes `world_from_view`
    /// (columns: the image's right, its up and backwards, in camera-relative world space), with a
    /// vertical field of view and near plane.
    pub fn from_rotation(
        position_m: DVec3,
        world_from_view: DMat3,
        fov_deg: f64,
        near_m: f64,
    ) -> Result<Self, HostCameraError> {
        let [right, up, back] = [world_from_view.x_axis, world_from_view.y_axis, world_from_view.z_axis];
        let departure = [
            right.length() - 1.0,
            up.length() - 1.0,
            back.length() - 1.0,
            right.dot(up),
            up.dot(back),
            back.dot(right),
            (right.cross(up) - back).length(),
        ]
        .into_iter()
        .fold(0.0f64, |worst, v| if v.is_nan() { f64::INFINITY } else { worst.max(v.abs()) });
        if departure > HOST_MATRIX_TOLERANCE {
            return Err(HostCameraError::NotRotation(departure));
        }
        let forward = -back.normalize();
        let pitch = forward.z.clamp(-1.0, 1.0).asin();
        // Straight up or down the heading and the roll turn about the same axis: the heading
        // takes it all, from the right axis (which is then level).
        let vertical = forward.x.hypot(forward.y) < 1e-12;
        let yaw = if vertical { (-right.y).atan2(right.x) } else { forward.x.atan2(forward.y) };
        let level = Self {
            position_m,
            yaw_deg: yaw.to_degrees(),
            pitch_deg: pitch.to_degrees(),
            roll_deg: 0.0,
            fov_deg,
            near_m,
        };
        let unrolled = level.world_from_view_rotation();
        let roll =
            if vertical { 0.0 } else { (-right.dot(unrolled.y_axis)).atan2(right.dot(unrolled.x_axis)) };
        let camera = Self { roll_deg: roll.to_degrees(), ..level };
        camera.validate()?;
        Ok(camera)
    }

    /// The camera at `position_m` (dataset CRS, metres) with a host's camera-relative
    /// `view_from_world` (a rotation, no translation) and `clip_from_view` (perspective, reversed
    /// Z, infinite far plane, centred: `Camera::clip_from_view`'s kind) for a `viewport` of width
    /// × height pixels.
    pub fn from_matrices(
        position_m: DVec3,
        view_from_world: DMat4,
        clip_from_view: DMat4,
        viewport: [u32; 2],
    ) -> Result<Self, HostCameraError> {
        let last_row = view_from_world.row(3).to_array();
        if last_row[..3].iter().any(|v| v.abs() > HOST_MATRIX_TOLERANCE)
            || (last_row[3] - 1.0).abs() > HOST_MATRIX_TOLERANCE
        {
            return Err(HostCameraError::NotAffine(last_row));
        }
        let translation = view_from_world.w_axis.truncate();
        if translation.length() > HOST_MATRIX_TOLERANCE {
            return Err(HostCameraError::Translation(translation.to_array()));
        }
        let rotation = DMat3::from_mat4(view_from_world).transpose();
        let (fov_deg, near_m, aspect) = perspective_of(&clip_from_view)?;
        if viewport[0] == 0 || viewport[1] == 0 {
            return Err(CameraError::Viewport(viewport[0], viewport[1]).into());
        }
        let viewport_aspect = f64::from(viewport[0]) / f64::from(viewport[1]);
        if ((aspect - viewport_aspect) / viewport_aspect).abs() > HOST_MATRIX_TOLERANCE {
            return Err(HostCameraError::Aspect(aspect, viewport_aspect));
        }
        Self::from_rotation(position_m, rotation, fov_deg, near_m)
    }
}

/// The vertical field of view (degrees), near plane (metres) and aspect of a perspective
/// projection with reversed Z and an infinite far plane: x_clip = f/a x, y_clip = f y,
/// z_clip = near, w_clip = −z.
fn perspective_of(clip_from_view: &DMat4) -> Result<(f64, f64, f64), HostCameraError> {
    let m = clip_from_view.to_cols_array_2d();
    let (x_scale, y_scale, near_m) = (m[0][0], m[1][1], m[3][2]);
    let scale = m.iter().flatten().fold(0.0f64, |a, v| a.max(v.abs()));
    let expected =
        [[x_scale, 0.0, 0.0, 0.0], [0.0, y_scale, 0.0, 0.0], [0.0, 0.0, 0.0, -1.0], [0.0, 0.0, near_m, 0.0]];
    for (column, (got, want)) in m.iter().zip(expected).enumerate() {
        for row in 0..4 {
            let close = (got[row] - want[row]).abs() <= HOST_MATRIX_TOLERANCE * scale;
            if !close {
                return Err(HostCameraError::Projection(column, row, got[row], want[row]));
            }
        }
    }
    for (name, value) in [("x scale", x_scale), ("y scale", y_scale), ("near plane", near_m)] {
        if value.is_nan() || value <= 0.0 {
            return Err(HostCameraError::NotPositive(name, value));
        }
    }
    Ok((2.0 * (1.0 / y_scale).atan().to_degrees(), near_m, y_scale / x_scale))
}

#[cfg(test)]
#[path = "from_host_tests.rs"]
mod tests;
