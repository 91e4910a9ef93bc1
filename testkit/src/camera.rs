//! Cameras for tests, in the dataset's grid space (metres east and north of its origin): at a
//! grid position, above the ground at a grid position, or above the ground at a fraction of the
//! dataset's extent. All look with a 60° field of view and a 0.1 m near plane. (The audit adds
//! cameras over its own derivation of the drawn ground: `audit::camera_at`.)

use glam::DVec3;
use terramp::camera::Camera;
use terramp::frame::Renderer;

/// A camera at CRS position `position_m`.
pub fn looking(position_m: DVec3, yaw_deg: f64, pitch_deg: f64) -> Camera {
    Camera { position_m, yaw_deg, pitch_deg, roll_deg: 0.0, fov_deg: 60.0, near_m: 0.1 }
}

/// A camera at grid-space position `grid_m` (height included).
pub fn at_grid(r: &Renderer, grid_m: DVec3, yaw_deg: f64, pitch_deg: f64) -> Camera {
    let o = r.dataset.manifest.origin_m;
    looking(grid_m + DVec3::new(o[0], o[1], 0.0), yaw_deg, pitch_deg)
}

/// A camera `above_m` over the drawn ground at grid (`x`, `y`).
pub fn over(r: &Renderer, [x, y]: [f64; 2], above_m: f64, yaw_deg: f64, pitch_deg: f64) -> Camera {
    let ground_m = r.dataset.height_at(x, y, 0).unwrap();
    at_grid(r, DVec3::new(x, y, ground_m + above_m), yaw_deg, pitch_deg)
}

/// A camera `above_m` over the drawn ground at fraction (`fx`, `fy`) of the dataset's extent.
pub fn over_fraction(r: &Renderer, [fx, fy]: [f64; 2], above_m: f64, yaw_deg: f64, pitch_deg: f64) -> Camera {
    let [w, h] = r.dataset.manifest.extent_m();
    over(r, [fx * w, fy * h], above_m, yaw_deg, pitch_deg)
}

/// A camera at a pose as tests list them: grid x and y, metres above the drawn ground there,
/// heading and pitch (degrees).
pub fn posed(r: &Renderer, [x, y, above_m, yaw_deg, pitch_deg]: [f64; 5]) -> Camera {
    over(r, [x, y], above_m, yaw_deg, pitch_deg)
}
