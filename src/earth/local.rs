//! How it works: the one mapping from a dataset's points to what the renderer draws (issue 44,
//! item 2). A point (x, y in the dataset's CRS, a height above its datum) goes, through
//! `EarthFrame`, to its Earth-centred position on WGS 84, less the camera's, turned into the
//! camera's local frame: east, north and up at the camera, up along the ellipsoid's normal through
//! it (`LocalFrame::position_m`, f64, exact to the frame's own accuracy). Seen that way the ground
//! falls away from the camera's horizontal plane as the Earth curves: 4.4 m at 7.5 km, 196 m at
//! 50 km, 785 m at 100 km.
//!
//! The GPU gets the mapping a node at a time (a terrain tile, a cell, a patch: anything whose
//! vertices lie within a known reach of an origin). The CPU forms the node origin's position in
//! f64 and rounds it once to f32 (relative to the eye, as Cesium does, so f32 holds it to its
//! relative precision whatever the distance), and the mapping's first and second derivatives
//! there; a vertex at CRS offset (dx, dy) from the origin and dh above it is then placed in f32 by
//! the second-order Taylor polynomial (`NodeMapping::position_m`)
//!
//! ```text
//! p ≈ p0 + Jx dx + Jy dy + Jh dh + ½Hxx dx² + Hxy dx dy + ½Hyy dy² + (Kx dx + Ky dy) dh
//! ```
//!
//! The height enters linearly (a point moves along its normal as it rises), so only the normal's
//! turn along the node (K) multiplies it. The derivatives are central differences of the exact
//! mapping `DIFFERENCE_STEP_M` apart: the second ones divide f64 rounding of a few nanometres
//! by the step squared, far below the curvature they measure (about 1 / 6.4e6 per metre). What
//! is left is the third order, about r³ / (6 R²) at the corners of a node of half-diagonal r, and
//! f32's rounding of the origin's position (6e-8 of its distance): on nc, beside the camera, the
//! tests measure 0.06 mm for a node 1 km across, 2.6 mm for 10 km and 2.3 m for 100 km (one that
//! large is far away, where a pixel spans more).

use glam::{DMat3, DVec3, Vec3};

use super::{EarthFrame, Ellipsoid};

/// How far apart the exact mapping is sampled for its derivatives, metres.
pub const DIFFERENCE_STEP_M: f64 = 500.0;

/// The camera's place on the Earth and its local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalFrame {
    /// The camera's Earth-centred position (WGS 84), metres.
    pub eye_ecef_m: DVec3,
    /// East, north and up at the camera (its rows): the local frame from Earth-centred axes.
    pub local_from_ecef: DMat3,
}

impl LocalFrame {
    /// The frame of a camera at CRS point (`x_m`, `y_m`), `height_m` above the datum of `earth`.
    pub fn at(earth: &EarthFrame, x_m: f64, y_m: f64, height_m: f64) -> Self {
        let eye_ecef_m = earth.ecef_m(x_m, y_m, height_m);
        let (lat, lon, _) = Ellipsoid::WGS84.geodetic(eye_ecef_m);
        Self { eye_ecef_m, local_from_ecef: local_from_ecef(lat, lon) }
    }

    /// The frame of a camera at CRS point (`x_m`, `y_m`), `height_m` above the datum, turned about
    /// its up so that its first axis is the CRS's x direction at the camera, in the horizontal
    /// plane: the frame the renderer draws in, where the dataset's grid and the drawn ground agree
    /// beside the camera up to the projection's scale there (the first order), so a camera's
    /// heading and pitch given in the grid mean what they meant on the flat sheet.
    pub fn grid_aligned(earth: &EarthFrame, x_m: f64, y_m: f64, height_m: f64) -> Self {
        let local = Self::at(earth, x_m, y_m, height_m);
        let (sin, cos) = grid_turn_rad(earth, x_m, y_m, height_m).sin_cos();
        let unturn = DMat3::from_cols(DVec3::new(cos, -sin, 0.0), DVec3::new(sin, cos, 0.0), DVec3::Z);
        Self { eye_ecef_m: local.eye_ecef_m, local_from_ecef: unturn * local.local_from_ecef }
    }

    /// The camera-relative position, in the camera's local frame (metres east, north, up), of
    /// CRS point (`x_m`, `y_m`) at `height_m`: exact, in f64.
    pub fn position_m(&self, earth: &EarthFrame, x_m: f64, y_m: f64, height_m: f64) -> DVec3 {
        self.local_from_ecef * (earth.ecef_m(x_m, y_m, height_m) - self.eye_ecef_m)
    }

    /// The mapping around a node's origin, CRS point `origin_m` (x, y and a height), for the GPU.
    pub fn node(&self, earth: &EarthFrame, origin_m: DVec3) -> NodeMapping {
        self.place(&EcefNode::at(earth, origin_m))
    }

    /// A node's mapping, known in Earth-centred axes, in this frame.
    pub fn place(&self, node: &EcefNode) -> NodeMapping {
        let turn = |v: DVec3| (self.local_from_ecef * v).as_vec3();
        NodeMapping {
            origin_m: turn(node.origin_m - self.eye_ecef_m),
            d_x: turn(node.d_x),
            d_y: turn(node.d_y),
            d_h: turn(node.d_h),
            d_xx: turn(node.d_xx),
            d_xy: turn(node.d_xy),
            d_yy: turn(node.d_yy),
            d_xh: turn(node.d_xh),
            d_yh: turn(node.d_yh),
        }
    }

    /// This frame's vector of Earth-centred vector `v`.
    pub fn turn(&self, v: DVec3) -> DVec3 {
        self.local_from_ecef * v
    }
}

/// A node's mapping in Earth-centred axes (WGS 84, f64): its origin's position and the mapping's
/// derivatives there, as `NodeMapping` holds them in a camera's frame. It depends on nothing but
/// the node and the dataset, so a renderer forms it once per node and turns it into each frame's
/// camera (`LocalFrame::place`: a subtraction and nine products), instead of the thirteen exact
/// mappings (about 12 µs on nc's projection) it costs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EcefNode {
    /// The origin's Earth-centred position, metres.
    pub origin_m: DVec3,
    /// ∂p/∂x, per metre of CRS offset.
    pub d_x: DVec3,
    /// ∂p/∂y.
    pub d_y: DVec3,
    /// ∂p/∂h, per metre of height.
    pub d_h: DVec3,
    /// ½ ∂²p/∂x², per square metre.
    pub d_xx: DVec3,
    /// ∂²p/∂x∂y.
    pub d_xy: DVec3,
    /// ½ ∂²p/∂y².
    pub d_yy: DVec3,
    /// ∂²p/∂x∂h.
    pub d_xh: DVec3,
    /// ∂²p/∂y∂h.
    pub d_yh: DVec3,
}

impl EcefNode {
    /// The mapping around CRS point `origin_m` (x, y and a height): central differences of the
    /// exact mapping `DIFFERENCE_STEP_M` apart, the geoid held at its undulation at the origin; the
    /// geoid then enters to the first order only, along the normal, by its slope over the same
    /// step. Its lattice is bilinear, kinked along its nodes' meridians and parallels: a second
    /// difference across a kink would turn a slope's jump into a curvature, a miss growing with
    /// the square of the node's size (`a_kink_in_the_geoid_costs_a_slope_not_a_curvature`).
    pub fn at(earth: &EarthFrame, origin_m: DVec3) -> Self {
        let s = DIFFERENCE_STEP_M;
        let held_m = origin_m.z + earth.undulation_m(origin_m.x, origin_m.y);
        let at = |dx: f64, dy: f64, dh: f64| {
            earth.ecef_above_ellipsoid_m(origin_m.x + dx, origin_m.y + dy, held_m + dh)
        };
        let slope = |ux: f64, uy: f64| {
            let n = |k: f64| earth.undulation_m(origin_m.x + k * ux, origin_m.y + k * uy);
            (n(s) - n(-s)) / (2.0 * s)
        };
        let p0 = at(0.0, 0.0, 0.0);
        let [east, west, north, south] =
            [at(s, 0.0, 0.0), at(-s, 0.0, 0.0), at(0.0, s, 0.0), at(0.0, -s, 0.0)];
        let corners = (at(s, s, 0.0) - at(s, -s, 0.0)) - (at(-s, s, 0.0) - at(-s, -s, 0.0));
        // Linear in the height: the rise of one step is exact, wherever it is taken.
        let up_at = |dx: f64, dy: f64| (at(dx, dy, s) - at(dx, dy, 0.0)) / s;
        let d_h = up_at(0.0, 0.0);
        Self {
            origin_m: p0,
            d_x: (east - west) / (2.0 * s) + d_h * slope(1.0, 0.0),
            d_y: (north - south) / (2.0 * s) + d_h * slope(0.0, 1.0),
            d_h,
            d_xx: ((east - p0) + (west - p0)) / (2.0 * s * s),
            d_xy: corners / (4.0 * s * s),
            d_yy: ((north - p0) + (south - p0)) / (2.0 * s * s),
            d_xh: (up_at(s, 0.0) - up_at(-s, 0.0)) / (2.0 * s),
            d_yh: (up_at(0.0, s) - up_at(0.0, -s)) / (2.0 * s),
        }
    }

    /// The Earth-centred position, by the second-order polynomial in f64, of the point at CRS
    /// offset (x, y) from the origin and height offset z above it (`NodeMapping::position_m`'s
    /// polynomial, without its f32 rounding).
    pub fn position_m(&self, offset_m: DVec3) -> DVec3 {
        let (dx, dy, dh) = (offset_m.x, offset_m.y, offset_m.z);
        let curved = self.d_xx * (dx * dx) + self.d_xy * (dx * dy) + self.d_yy * (dy * dy);
        let turned = (self.d_xh * dx + self.d_yh * dy) * dh;
        self.origin_m + (self.d_x * dx + self.d_y * dy + self.d_h * dh + (curved + turned))
    }
}

/// How far the CRS's x direction at CRS point (`x_m`, `y_m`), `height_m` up, turns from east in
/// the horizontal, anticlockwise seen from above, radians: the meridians' convergence there (and
/// the projection's skew where it has one).
pub fn grid_turn_rad(earth: &EarthFrame, x_m: f64, y_m: f64, height_m: f64) -> f64 {
    let local = LocalFrame::at(earth, x_m, y_m, height_m);
    let s = DIFFERENCE_STEP_M;
    let along_x =
        local.position_m(earth, x_m + s, y_m, height_m) - local.position_m(earth, x_m - s, y_m, height_m);
    along_x.y.atan2(along_x.x)
}

/// East, north and up at geodetic latitude `lat` and longitude `lon` (radians) as the rows of
/// the matrix that turns Earth-centred vectors into local ones.
pub fn local_from_ecef(lat: f64, lon: f64) -> DMat3 {
    let (sin_lat, cos_lat) = lat.sin_cos();
    let (sin_lon, cos_lon) = lon.sin_cos();
    let east = DVec3::new(-sin_lon, cos_lon, 0.0);
    let north = DVec3::new(-sin_lat * cos_lon, -sin_lat * sin_lon, cos_lat);
    let up = DVec3::new(cos_lat * cos_lon, cos_lat * sin_lon, sin_lat);
    DMat3::from_cols(east, north, up).transpose()
}

/// A node's mapping to the camera's local frame, in f32 for the GPU: its origin's
/// camera-relative position and the mapping's derivatives there (`LocalFrame::node`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeMapping {
    /// The origin's position, metres, rounded once from f64.
    pub origin_m: Vec3,
    /// ∂p/∂x, per metre of CRS offset.
    pub d_x: Vec3,
    /// ∂p/∂y.
    pub d_y: Vec3,
    /// ∂p/∂h, per metre of height: the origin's up, in the camera's frame.
    pub d_h: Vec3,
    /// ½ ∂²p/∂x², per square metre: with the next two, the Earth's curvature.
    pub d_xx: Vec3,
    /// ∂²p/∂x∂y.
    pub d_xy: Vec3,
    /// ½ ∂²p/∂y².
    pub d_yy: Vec3,
    /// ∂²p/∂x∂h, per square metre: with the next, the normal turning along the node.
    pub d_xh: Vec3,
    /// ∂²p/∂y∂h.
    pub d_yh: Vec3,
}

impl NodeMapping {
    /// The camera-relative position, metres, of the point at CRS offset (x, y) from the node's
    /// origin and height offset z above it, in f32 as a shader forms it: the small terms summed
    /// first, the origin added last.
    pub fn position_m(&self, offset_m: Vec3) -> Vec3 {
        let (dx, dy, dh) = (offset_m.x, offset_m.y, offset_m.z);
        let curved = self.d_xx * (dx * dx) + self.d_xy * (dx * dy) + self.d_yy * (dy * dy);
        let turned = (self.d_xh * dx + self.d_yh * dy) * dh;
        let linear = self.d_x * dx + self.d_y * dy + self.d_h * dh;
        self.origin_m + (linear + (curved + turned))
    }
}

#[cfg(test)]
#[path = "local_tests.rs"]
mod tests;
