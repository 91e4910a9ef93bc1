//! An independent CPU rasteriser for the truth's test: a pinhole camera built from its yaw, pitch
//! and field of view alone (not the library's matrices), triangles clipped against the near plane,
//! sampled at sample centres with a reversed-Z depth test in f64, and perspective-correct
//! barycentrics for the alpha test. Slow and simple, as a reference should be.

use glam::{DVec2, DVec3};
use terramp::camera::Camera;

/// A pinhole view: camera-relative world space to sample coordinates and view depth.
pub struct Pinhole {
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    /// Half extents of the image plane at distance 1.
    half: DVec2,
    near_m: f64,
    size: [u32; 2],
}

impl Pinhole {
    /// The view of `camera` over `size` samples.
    pub fn new(camera: &Camera, size: [u32; 2]) -> Self {
        let (yaw, pitch) = (camera.yaw_deg.to_radians(), camera.pitch_deg.to_radians());
        let forward = DVec3::new(yaw.sin() * pitch.cos(), yaw.cos() * pitch.cos(), pitch.sin());
        let right = forward.cross(DVec3::Z).normalize();
        let up = right.cross(forward);
        let tan = (0.5 * camera.fov_deg.to_radians()).tan();
        let aspect = f64::from(size[0]) / f64::from(size[1]);
        Self { forward, right, up, half: DVec2::new(tan * aspect, tan), near_m: camera.near_m, size }
    }

    /// Sample coordinates (x right, y down, in samples) and view distance along the axis.
    fn project(&self, p: DVec3) -> (DVec2, f64) {
        let z = self.forward.dot(p);
        let ndc = DVec2::new(self.right.dot(p), self.up.dot(p)) / (z * self.half);
        let [w, h] = self.size.map(f64::from);
        (DVec2::new((ndc.x + 1.0) * 0.5 * w, (1.0 - ndc.y) * 0.5 * h), z)
    }

    /// Normalised device x of a camera-relative point (−1 and 1 are the view's sides).
    pub fn ndc_x(&self, p: DVec3) -> f64 {
        self.right.dot(p) / (self.forward.dot(p) * self.half.x)
    }
}

/// What a sample shows: reversed-Z depth (near / distance; 0 for the sky) and an id.
pub struct Raster {
    pub size: [u32; 2],
    pub depth: Vec<f64>,
    pub ids: Vec<u32>,
}

/// A triangle corner: camera-relative position and texture coordinates.
#[derive(Clone, Copy)]
pub struct Corner {
    pub rel_m: DVec3,
    pub uv: DVec2,
}

impl Raster {
    pub fn new(size: [u32; 2]) -> Self {
        let n = (size[0] * size[1]) as usize;
        Self { size, depth: vec![0.0; n], ids: vec![0; n] }
    }

    /// Draws a triangle (either winding) with `id`; `keep(uv)` is the alpha test.
    pub fn triangle(&mut self, view: &Pinhole, corners: [Corner; 3], id: u32, keep: &dyn Fn(DVec2) -> bool) {
        // Clip against the near plane (view distance ≥ near), Sutherland–Hodgman.
        let inside = |c: &Corner| view.forward.dot(c.rel_m) >= view.near_m;
        let mut polygon: Vec<Corner> = Vec::with_capacity(4);
        for i in 0..3 {
            let (a, b) = (corners[i], corners[(i + 1) % 3]);
            if inside(&a) {
                polygon.push(a);
            }
            if inside(&a) != inside(&b) {
                let (da, db) = (view.forward.dot(a.rel_m), view.forward.dot(b.rel_m));
                let t = (view.near_m - da) / (db - da);
                polygon.push(Corner { rel_m: a.rel_m.lerp(b.rel_m, t), uv: a.uv.lerp(b.uv, t) });
            }
        }
        for k in 1..polygon.len().saturating_sub(1) {
            self.clipped(view, [polygon[0], polygon[k], polygon[k + 1]], id, keep);
        }
    }

    fn clipped(&mut self, view: &Pinhole, corners: [Corner; 3], id: u32, keep: &dyn Fn(DVec2) -> bool) {
        let projected = corners.map(|c| view.project(c.rel_m));
        let [a, b, c] = projected.map(|(s, _)| s);
        let area = (b - a).perp_dot(c - a);
        if area.abs() < 1e-12 {
            return;
        }
        let lo = a.min(b).min(c).floor().max(DVec2::ZERO);
        let hi = a.max(b).max(c).ceil().min(DVec2::new(f64::from(self.size[0]), f64::from(self.size[1])));
        for y in lo.y as u32..hi.y as u32 {
            for x in lo.x as u32..hi.x as u32 {
                let p = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                let w = [(c - b).perp_dot(p - b), (a - c).perp_dot(p - c), (b - a).perp_dot(p - a)]
                    .map(|e| e / area);
                if w.iter().any(|&e| e < 0.0) {
                    continue;
                }
                // Reversed-Z depth (near / distance) is affine in screen space.
                let depth = (0..3).map(|i| w[i] * view.near_m / projected[i].1).sum::<f64>();
                let at = (y * self.size[0] + x) as usize;
                if depth <= self.depth[at] {
                    continue;
                }
                // Perspective-correct weights for the texture coordinates.
                let pw: [f64; 3] = std::array::from_fn(|i| w[i] / projected[i].1);
                let sum: f64 = pw.iter().sum();
                let uv = (0..3).fold(DVec2::ZERO, |acc, i| acc + corners[i].uv * (pw[i] / sum));
                if keep(uv) {
                    self.depth[at] = depth;
                    self.ids[at] = id;
                }
            }
        }
    }
}
