//! How it works: the camera lives in f64 in the dataset's CRS (metres east, north, height above the
//! datum). The GPU never sees those large numbers: matrices are built for *camera-relative* world
//! space (the camera at the origin, axes east/north/up), and every position sent to a shader is
//! subtracted from the camera in f64 first. Depth is reversed-Z with an infinite far plane, so
//! 0.1 m to hundreds of kilometres share one Depth32Float buffer without z-fighting.
//!
//! Angles: `yaw_deg` is the compass heading (0 = north, 90 = east), `pitch_deg` the elevation of
//! the view direction above the horizon (negative looks down), `roll_deg` the turn of the camera
//! about its view direction (positive lowers its right side, as an aircraft banking right: the
//! world in the image turns counter-clockwise).
//! The view's rotation is built from them in closed form, so every pose has one, straight up and
//! down included; a host's own rotation or matrices become a camera in `camera::from_host`.
//!
//! `validate` refuses what the f32 GPU side cannot carry, with a typed error rather than a frame
//! of garbage: non-finite numbers, a near plane that is not positive, a field of view outside
//! [`MIN_FOV_DEG`, 180°), coordinates beyond `MAX_COORDINATE_M`.

use glam::{DMat3, DMat4, DVec3, DVec4, Mat4};

mod from_host;
pub use from_host::HostCameraError;
use thiserror::Error;

/// Narrowest vertical field of view, degrees. The GPU computes clip coordinates in f32 from
/// camera-relative positions, with a relative error of about 1e-7: a pixel's angle, fov / height,
/// must stay well above that for pixels to land where they belong. At 0.01° over 1080 rows a point
/// lands within 0.46 px of its place; at 0.001°, 4.2 px away (`tests/extremes.rs`).
pub const MIN_FOV_DEG: f64 = 0.01;
/// Largest |coordinate| of a camera position, metres (a hundred times the Earth's circumference).
/// Beyond it ring and cell indices leave i64 and relative positions lose every metre in f32.
pub const MAX_COORDINATE_M: f64 = 4e9;
/// Nearest near plane, metres. Reversed-Z depth is `near / distance`: a smaller near plane would
/// push far depths into f32 denormals, which GPUs flush to 0, the sky.
pub const MIN_NEAR_M: f64 = 1e-6;

/// Why a camera cannot be used: a value the f32 GPU side could not carry, or a pose that does not
/// parse.
#[derive(Debug, Error, PartialEq)]
pub enum CameraError {
    /// A coordinate, angle, field of view or near plane is NaN or infinite (its name: "x", "yaw",
    /// "near"…).
    #[error("camera: {0} is not a finite number")]
    NotFinite(&'static str),
    /// The vertical field of view, degrees, is below `MIN_FOV_DEG` or not below 180°.
    #[error("camera: field of view {0}° must be at least {MIN_FOV_DEG}° and below 180°")]
    Fov(f64),
    /// The near plane, metres, is below `MIN_NEAR_M` (zero and negative included).
    #[error("camera: near plane {0} m must be at least {MIN_NEAR_M} m")]
    Near(f64),
    /// A coordinate of the position (its name, its value in metres) is beyond `MAX_COORDINATE_M`.
    #[error("camera: {0} = {1} m is beyond ±{MAX_COORDINATE_M} m")]
    TooFar(&'static str, f64),
    /// A projection was asked for a viewport (width × height, pixels) with no pixels.
    #[error("camera: viewport {0}×{1} has no area")]
    Viewport(u32, u32),
    /// A pose given as text is not five or six comma-separated numbers.
    #[error(
        "camera: `{0}` is not X,Y,Z,YAW,PITCH[,ROLL] (five or six numbers: metres, metres, metres, degrees, degrees, degrees)"
    )]
    Parse(String),
}

/// A pinhole camera in the dataset CRS, in f64; the GPU gets camera-relative matrices from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Position in the dataset CRS, metres (z: height above the datum).
    pub position_m: DVec3,
    /// Compass heading of the view, degrees clockwise from north (90 = east).
    pub yaw_deg: f64,
    /// Elevation of the view direction above the horizon, degrees (negative looks down).
    pub pitch_deg: f64,
    /// Turn of the camera about its view direction, degrees: positive lowers its right side (the
    /// world in the image turns counter-clockwise).
    pub roll_deg: f64,
    /// Vertical field of view, degrees.
    pub fov_deg: f64,
    /// Near plane, metres (at least `MIN_NEAR_M`); the far plane is at infinity.
    pub near_m: f64,
}

impl Camera {
    /// Parses `X,Y,Z,YAW,PITCH` or `X,Y,Z,YAW,PITCH,ROLL` as given on the command line.
    pub fn parse_pose(text: &str, fov_deg: f64, near_m: f64) -> Result<Self, CameraError> {
        let values: Vec<f64> = text
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| CameraError::Parse(text.into()))?;
        let (x, y, z, yaw_deg, pitch_deg, roll_deg) = match values[..] {
            [x, y, z, yaw, pitch] => (x, y, z, yaw, pitch, 0.0),
            [x, y, z, yaw, pitch, roll] => (x, y, z, yaw, pitch, roll),
            _ => return Err(CameraError::Parse(text.into())),
        };
        let camera = Self { position_m: DVec3::new(x, y, z), yaw_deg, pitch_deg, roll_deg, fov_deg, near_m };
        camera.validate()?;
        Ok(camera)
    }

    /// Refuses what the f32 GPU side cannot carry: non-finite numbers, a field of view or near
    /// plane out of range, coordinates beyond `MAX_COORDINATE_M`.
    pub fn validate(&self) -> Result<(), CameraError> {
        let named = [
            ("x", self.position_m.x),
            ("y", self.position_m.y),
            ("z", self.position_m.z),
            ("yaw", self.yaw_deg),
            ("pitch", self.pitch_deg),
            ("roll", self.roll_deg),
            ("fov", self.fov_deg),
            ("near", self.near_m),
        ];
        if let Some((name, _)) = named.iter().find(|(_, v)| !v.is_finite()) {
            return Err(CameraError::NotFinite(name));
        }
        if !(self.fov_deg >= MIN_FOV_DEG && self.fov_deg < 180.0) {
            return Err(CameraError::Fov(self.fov_deg));
        }
        if self.near_m < MIN_NEAR_M {
            return Err(CameraError::Near(self.near_m));
        }
        if let Some((name, v)) = named[..3].iter().find(|(_, v)| v.abs() > MAX_COORDINATE_M) {
            return Err(CameraError::TooFar(name, *v));
        }
        Ok(())
    }

    /// Unit view direction (x east, y north, z up).
    pub fn forward(&self) -> DVec3 {
        let (yaw, pitch) = (self.yaw_deg.to_radians(), self.pitch_deg.to_radians());
        DVec3::new(yaw.sin() * pitch.cos(), yaw.cos() * pitch.cos(), pitch.sin())
    }

    /// The view's axes in camera-relative world space, as columns: the image's right, its up, and
    /// backwards (the view looks along −z, as in wgpu's right-handed view space). Unrolled, right
    /// is level (the heading turned 90° clockwise) and up is the forward direction pitched up by
    /// 90°; the roll turns both about the forward direction. Defined for every pose: straight
    /// down, right is still the heading's right.
    pub fn world_from_view_rotation(&self) -> DMat3 {
        let (sin_yaw, cos_yaw) = self.yaw_deg.to_radians().sin_cos();
        let (sin_pitch, cos_pitch) = self.pitch_deg.to_radians().sin_cos();
        let (sin_roll, cos_roll) = self.roll_deg.to_radians().sin_cos();
        let level_right = DVec3::new(cos_yaw, -sin_yaw, 0.0);
        let level_up = DVec3::new(-sin_yaw * sin_pitch, -cos_yaw * sin_pitch, cos_pitch);
        let right = level_right * cos_roll - level_up * sin_roll;
        let up = level_up * cos_roll + level_right * sin_roll;
        DMat3::from_cols(right, up, -self.forward())
    }

    /// View-from-world for camera-relative world space.
    pub fn view_from_world(&self) -> DMat4 {
        DMat4::from_mat3(self.world_from_view_rotation().transpose())
    }

    /// Reversed-Z, infinite-far projection.
    pub fn clip_from_view(&self, width: u32, height: u32) -> Result<DMat4, CameraError> {
        if width == 0 || height == 0 {
            return Err(CameraError::Viewport(width, height));
        }
        let aspect = f64::from(width) / f64::from(height);
        // wgpu clip space is DirectX-like: z in [0, 1], y up.
        Ok(glam::dcamera::rh::proj::directx::perspective_infinite_reverse(
            self.fov_deg.to_radians(),
            aspect,
            self.near_m,
        ))
    }

    /// Clip-from-camera-relative-world, in f32 for the GPU.
    pub fn clip_from_view_world(&self, width: u32, height: u32) -> Result<Mat4, CameraError> {
        Ok((self.clip_from_view(width, height)? * self.view_from_world()).as_mat4())
    }

    /// Metres covered by one pixel at distance `distance_m`, for a viewport `height_px` tall.
    pub fn metres_per_pixel(&self, distance_m: f64, height_px: u32) -> f64 {
        2.0 * distance_m * (0.5 * self.fov_deg.to_radians()).tan() / f64::from(height_px.max(1))
    }
}

/// The side planes and near plane of a view, in camera-relative world space, for culling.
#[derive(Debug, Clone)]
pub struct Frustum {
    planes: [DVec4; 5],
}

impl Frustum {
    /// From a reversed-Z clip matrix (Gribb & Hartmann; the far plane is at infinity, so none).
    pub fn from_clip(clip_from_world: DMat4) -> Self {
        let m = clip_from_world.transpose();
        let (x, y, z, w) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
        let planes = [w + x, w - x, w + y, w - y, w - z].map(|p| p / p.truncate().length().max(1e-300));
        Self { planes }
    }

    /// False only when the box is certainly outside.
    pub fn intersects_box(&self, min: DVec3, max: DVec3) -> bool {
        self.planes.iter().all(|p| {
            let corner = DVec3::new(
                if p.x >= 0.0 { max.x } else { min.x },
                if p.y >= 0.0 { max.y } else { min.y },
                if p.z >= 0.0 { max.z } else { min.z },
            );
            p.truncate().dot(corner) + p.w >= 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> Camera {
        Camera::parse_pose("630000,215000,500,90,-10", 60.0, 0.1).unwrap()
    }

    #[test]
    fn headings_are_compass_bearings() {
        let c = Camera { yaw_deg: 0.0, pitch_deg: 0.0, ..camera() };
        assert!((c.forward() - DVec3::Y).length() < 1e-12);
        let east = Camera { yaw_deg: 90.0, ..c };
        assert!((east.forward() - DVec3::X).length() < 1e-12);
        assert!(camera().forward().z < 0.0);
    }

    #[test]
    fn reversed_z_puts_near_at_one_and_far_towards_zero() {
        let c = Camera { yaw_deg: 0.0, pitch_deg: 0.0, ..camera() };
        let clip = c.clip_from_view(100, 100).unwrap() * c.view_from_world();
        let depth = |d: f64| {
            let p = clip * DVec4::new(0.0, d, 0.0, 1.0);
            p.z / p.w
        };
        assert!((depth(0.1) - 1.0).abs() < 1e-9);
        assert!(depth(500_000.0) > 0.0 && depth(500_000.0) < 1e-6);
        assert!(depth(1.0) > depth(2.0));
    }

    #[test]
    fn frustum_keeps_what_is_ahead_and_drops_what_is_behind() {
        let c = Camera { yaw_deg: 0.0, pitch_deg: 0.0, ..camera() };
        let f = Frustum::from_clip(c.clip_from_view(100, 100).unwrap() * c.view_from_world());
        let unit = DVec3::splat(1.0);
        assert!(f.intersects_box(DVec3::new(0.0, 100.0, 0.0) - unit, DVec3::new(0.0, 100.0, 0.0) + unit));
        assert!(!f.intersects_box(DVec3::new(0.0, -100.0, 0.0) - unit, DVec3::new(0.0, -100.0, 0.0) + unit));
        assert!(
            !f.intersects_box(DVec3::new(500.0, 100.0, 0.0) - unit, DVec3::new(500.0, 100.0, 0.0) + unit)
        );
    }

    #[test]
    fn bad_poses_are_errors() {
        assert!(matches!(Camera::parse_pose("1,2,3", 60.0, 0.1), Err(CameraError::Parse(_))));
        assert!(matches!(Camera::parse_pose("1,2,3,4,5,6,7", 60.0, 0.1), Err(CameraError::Parse(_))));
        assert_eq!(Camera::parse_pose("1,2,3,4,5,6", 60.0, 0.1).map(|c| c.roll_deg), Ok(6.0));
        assert!(matches!(
            Camera::parse_pose("1,2,3,4,5,nan", 60.0, 0.1),
            Err(CameraError::NotFinite("roll"))
        ));
        assert!(matches!(Camera::parse_pose("1,2,3,4,x", 60.0, 0.1), Err(CameraError::Parse(_))));
        assert!(matches!(Camera::parse_pose("1,2,3,4,5", 180.0, 0.1), Err(CameraError::Fov(_))));
        assert!(matches!(Camera::parse_pose("1,2,inf,4,5", 60.0, 0.1), Err(CameraError::NotFinite("z"))));
        assert!(camera().clip_from_view(0, 10).is_err());
        let c = camera();
        assert_eq!(Camera { fov_deg: 0.001, ..c }.validate(), Err(CameraError::Fov(0.001)));
        assert_eq!(Camera { fov_deg: 180.0, ..c }.validate(), Err(CameraError::Fov(180.0)));
        assert!(Camera { fov_deg: MIN_FOV_DEG, ..c }.validate().is_ok());
        assert!(Camera { fov_deg: 179.999, ..c }.validate().is_ok());
        assert_eq!(Camera { near_m: 0.0, ..c }.validate(), Err(CameraError::Near(0.0)));
        assert_eq!(Camera { near_m: -1.0, ..c }.validate(), Err(CameraError::Near(-1.0)));
        let far = Camera { position_m: DVec3::new(0.0, -1e20, 0.0), ..c };
        assert_eq!(far.validate(), Err(CameraError::TooFar("y", -1e20)));
        assert!(Camera { position_m: DVec3::splat(1e7), ..c }.validate().is_ok());
    }
}
