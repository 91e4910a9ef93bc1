//! How it works: what the Earth hides from an eye above it, and how far a grid box bends onto it,
//! for the passes' culling. `HorizonCone` is Cesium's horizon culling worked in the ellipsoid's
//! scaled space, where the ellipsoid (lowered below the dataset's lowest ground) is the unit
//! sphere and the test is exact: a point is hidden when it lies inside the cone of tangents from
//! the eye and beyond the plane of their points of contact, a convex region, so a box whose eight
//! corners lie there is hidden whole. The test needs only the point's offset from the eye, so the
//! GPU runs it on camera-relative positions in f32 (`HorizonCone::gpu`).
//!
//! `EarthBend` bounds how far the mapping of the grid point under the camera (`NodeMapping`,
//! second order) moves a camera-relative grid box: the ground's fall, d² / 2R at horizontal
//! distance d, taken exactly per corner, and what else the mapping does, bounded by margins that
//! grow the box: across, its first-order departure from the identity (the projection's scale),
//! its other second-order terms and its third order (d³ / R²); up and down, the first and second
//! orders' vertical parts and the fall's fourth order (d⁴ / 8R³: the quadratic has no third-order
//! vertical term to miss on a sphere), so a box far off stays as low as the Earth puts it, which
//! the horizon's culling needs.

use glam::{DMat3, DVec3};

use super::Ellipsoid;
use crate::gpu::gpu_types::EarthNode;

/// The smallest radius of curvature WGS 84 has (the meridian's, at the equator), metres.
pub const SMALLEST_RADIUS_M: f64 = 6_335_439.0;

/// The horizon seen from one eye.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HorizonCone {
    /// Scaled space (the lowered ellipsoid the unit sphere) from camera-relative metres.
    scaled_from_rel: DMat3,
    /// The cone's axis, from the eye towards the centre, pulled back into camera-relative space
    /// (`scaled_from_relᵀ` times the scaled eye, negated: a point's projection on the axis is
    /// its dot product with this).
    axis_rel: DVec3,
    /// |eye|² − 1 in scaled space: the squared length of a tangent.
    tangent_sq: f64,
}

impl HorizonCone {
    /// The cone of an eye at Earth-centred `eye_ecef_m` whose camera frame turns Earth-centred
    /// axes by `local_from_ecef`, over WGS 84's ellipsoid grown by `height_m` on every axis
    /// (negative: shrunk); `None` when the eye is not above it (nothing is hidden).
    pub fn new(eye_ecef_m: DVec3, local_from_ecef: DMat3, height_m: f64) -> Option<Self> {
        let e = Ellipsoid::WGS84;
        let scale = DVec3::new(e.a_m + height_m, e.a_m + height_m, e.b_m() + height_m).recip();
        let eye = eye_ecef_m * scale;
        let tangent_sq = eye.length_squared() - 1.0;
        (tangent_sq > 0.0).then(|| {
            let scaled_from_rel = DMat3::from_diagonal(scale) * local_from_ecef.transpose();
            Self { scaled_from_rel, axis_rel: -(scaled_from_rel.transpose() * eye), tangent_sq }
        })
    }

    /// Whether the Earth hides the camera-relative point `p`: beyond the plane of contact
    /// (along > tangent², the axis's length folded in) and inside the cone (along² ≥ |p|² |axis|²
    /// cos², cos² = tangent² / |axis|²).
    pub fn hides(&self, p: DVec3) -> bool {
        let along = self.axis_rel.dot(p);
        along > self.tangent_sq
            && along * along >= (self.scaled_from_rel * p).length_squared() * self.tangent_sq
    }

    /// Whether the Earth hides every point of the camera-relative box `lo`..`hi`.
    pub fn hides_box(&self, lo: DVec3, hi: DVec3) -> bool {
        (0..8).all(|k| {
            self.hides(DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ))
        })
    }

    /// The cone as the GPU reads it: the rows of `scaled_from_rel` (xyz), and the axis (xyz) with
    /// tangent² (w), each rounded once.
    pub fn gpu(&self) -> [[f32; 4]; 4] {
        let m = self.scaled_from_rel.transpose();
        let row = |v: DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        [row(m.x_axis, 0.0), row(m.y_axis, 0.0), row(m.z_axis, 0.0), row(self.axis_rel, self.tangent_sq)]
    }

    /// What the GPU reads when nothing is hidden: a tangent no point's projection exceeds.
    pub const GPU_NONE: [[f32; 4]; 4] = [[0.0; 4], [0.0; 4], [0.0; 4], [0.0, 0.0, 0.0, f32::MAX]];
}

/// 1 / 2R, how fast the ground falls away from the camera's nadir (per square metre of horizontal
/// distance, d² / 2R) in `nadir`, its mapping at height 0: the second-order term's vertical part,
/// the mean of x's and y's (which differ by under 1 %); 0 on the flat sheet.
pub fn fall_per_m2(nadir: &EarthNode) -> f64 {
    (-0.5 * (f64::from(nadir.d_xx[2]) + f64::from(nadir.d_yy[2]))).max(0.0)
}

/// How a camera-relative grid box bends onto the Earth: `[drop, per_m, per_m2, per_m3]` and
/// `[z_per_m, z_per_m2, z_per_m4, 0]`. A box corner at horizontal distance d from the camera
/// falls by `drop` d²; its sides move out by `per_m` L + `per_m2` d² + `per_m3` L d², its top and
/// bottom by `z_per_m` L + `z_per_m2` d² + `z_per_m4` d⁴ (L ≥ d the corner's farthest |x| + |y|).
/// All zero on the flat sheet.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EarthBend(pub [[f32; 4]; 2]);

impl EarthBend {
    /// The bend of the mapping `nadir` of the grid point under the camera (at height 0), for
    /// boxes whose heights lie within `max_abs_height_m` of 0.
    pub fn of(nadir: &EarthNode, max_abs_height_m: f64) -> Self {
        let v = |c: [f32; 4]| DVec3::new(c[0].into(), c[1].into(), c[2].into());
        let (d_x, d_y) = (v(nadir.d_x), v(nadir.d_y));
        let (d_xx, d_xy, d_yy) = (v(nadir.d_xx), v(nadir.d_xy), v(nadir.d_yy));
        if d_xx == DVec3::ZERO && d_xy == DVec3::ZERO && d_yy == DVec3::ZERO {
            return Self::default();
        }
        let drop = fall_per_m2(nadir);
        // First order: the mapping's axes against the grid's, and the vertical turning along the
        // box at its heights (d_xh, d_yh: 1 / R).
        let first = (d_x - DVec3::X).abs() + (d_y - DVec3::Y).abs();
        let turn = (v(nadir.d_xh).abs() + v(nadir.d_yh).abs()) * max_abs_height_m;
        let first = first + turn;
        // Second order, less the fall taken per corner.
        let second = d_xx.abs() + d_xy.abs() + d_yy.abs();
        let residual_z = (d_xx.z + drop).abs() + d_xy.z.abs() + (d_yy.z + drop).abs();
        // Third order across: the sphere's and the projection's scale's, about d³ / 6R² each.
        let per_m3 = 1.0 / (SMALLEST_RADIUS_M * SMALLEST_RADIUS_M);
        // Fourth order up and down: the fall's, d⁴ / 8R³, doubled.
        let z_per_m4 = 1.0 / (4.0 * SMALLEST_RADIUS_M.powi(3));
        // Rounded up, so the f32 margins still hold what the f64 ones do.
        let up = |x: f64| (x as f32).next_up();
        Self([
            [drop as f32, up(first.x.max(first.y)), up(second.x.max(second.y)), up(per_m3)],
            [up(first.z), up(residual_z), up(z_per_m4), 0.0],
        ])
    }
}
