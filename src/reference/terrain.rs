//! How it works: the terrain pass's twin, the mesh of `shared/terrain_mesh.wgsl` as a frame drew
//! it, for the host's questions about the ground it sees (`Renderer::drawn_ground`). Each drawn
//! node quadrant is rebuilt from what the frame uploaded (the node's `TerrainNode`, its Earth
//! mapping, the samples of the height tile it read): its vertices morphed and displaced in f32 in
//! the shader's order, placed by the same polynomial, its cells cut along the mesh's diagonals.
//! The skirts are left out: they hang below seams, where the surface itself stands in front.
//!
//! A pick is the first front-facing triangle a ray from the camera meets (Möller–Trumbore in
//! f64 on the f32 vertices, each quadrant's box tried first); a height is the triangle over a
//! grid point on the flat sheet, where the morph has moved the vertices, interpolated there.

use std::sync::Arc;

use glam::{DMat4, DVec2, DVec3, Vec2, Vec3};

use crate::dataset::surface::diagonal_rises;
use crate::earth::local::NodeMapping;
use crate::gpu::gpu_types::{EarthNode, TerrainNode, TerrainUniforms};
use crate::gpu::layout::HEIGHT_TILE_EXTENT;

/// One node quadrant a frame drew, and what its vertex shader read.
#[derive(Debug, Clone)]
pub struct DrawnQuadrant {
    /// The instance as uploaded.
    pub node: TerrainNode,
    /// Its Earth mapping, as uploaded.
    pub earth: EarthNode,
    /// Which quadrant (south-west, south-east, north-west, north-east).
    pub quadrant: usize,
    /// The node's south-west corner in the grid, metres (exact: the GPU sees it camera-relative).
    pub origin_grid_m: DVec2,
    /// The samples of the height tile it read, `HEIGHT_TILE_EXTENT`² south row first.
    pub tile: Arc<Vec<f32>>,
}

/// A point of the drawn ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundPoint {
    /// Where it is relative to the camera, in the frame's world axes, metres.
    pub rel_m: DVec3,
    /// The grid point the drawn ground holds there: x, y and a height, metres, blended from its
    /// triangle's vertices as they were drawn (on the Earth it differs from the placing's exact
    /// inverse of `rel_m` by the node mapping's error).
    pub grid_m: DVec3,
    /// Its height above the datum, metres.
    pub height_m: f64,
    /// The unit normal of the triangle holding it, on the flat sheet (grid axes, z up).
    pub normal: DVec3,
}

/// A vertex of a rebuilt quadrant.
#[derive(Debug, Clone, Copy)]
struct Vertex {
    /// Placed, camera-relative, as the vertex shader forms it.
    rel_m: Vec3,
    /// Its morphed offset from the node's south-west corner on the flat sheet, and its height.
    offset_m: Vec2,
    height_m: f32,
}

/// One drawn quadrant's triangles, placed.
struct Patch {
    vertices: Vec<Vertex>,
    triangles: Vec<[usize; 3]>,
    /// The box of its placed vertices, camera-relative.
    lo: DVec3,
    hi: DVec3,
    origin_grid_m: DVec2,
}

/// The ground a frame drew, rebuilt on the CPU.
pub struct DrawnGround {
    patches: Vec<Patch>,
    /// The frame's matrix, camera-relative metres to clip, and its viewport, pixels.
    clip_from_rel_m: DMat4,
    viewport_px: [u32; 2],
}

impl DrawnGround {
    /// The ground of `quadrants`, drawn with `uniforms` (the frame's node cells and camera),
    /// seen through `clip_from_rel_m` in a `viewport_px` frame.
    pub fn new(
        quadrants: &[DrawnQuadrant],
        uniforms: &TerrainUniforms,
        (clip_from_rel_m, viewport_px): (DMat4, [u32; 2]),
    ) -> Self {
        let patches = quadrants.iter().map(|q| patch(q, uniforms)).collect();
        Self { patches, clip_from_rel_m, viewport_px }
    }

    /// The direction from the camera through the centre of pixel (`x`, `y`) (from the top left),
    /// in the frame's world axes.
    pub fn pixel_ray(&self, [x, y]: [u32; 2]) -> DVec3 {
        let [w, h] = self.viewport_px.map(f64::from);
        let ndc = DVec2::new((f64::from(x) + 0.5) / w * 2.0 - 1.0, 1.0 - (f64::from(y) + 0.5) / h * 2.0);
        // Reversed-Z: depth 1 is the near plane, a point on the ray from the camera.
        self.clip_from_rel_m.inverse().project_point3(ndc.extend(1.0)).normalize()
    }

    /// The first drawn point seen through the centre of pixel (`x`, `y`).
    pub fn pick_pixel(&self, pixel: [u32; 2]) -> Option<GroundPoint> {
        self.pick(self.pixel_ray(pixel))
    }

    /// The camera-relative point at the depth buffer's `depth` (reversed-Z) in pixel (`x`, `y`):
    /// how a host reads back what it drew.
    pub fn depth_point(&self, [x, y]: [u32; 2], depth: f32) -> DVec3 {
        let [w, h] = self.viewport_px.map(f64::from);
        let ndc = DVec3::new(
            (f64::from(x) + 0.5) / w * 2.0 - 1.0,
            1.0 - (f64::from(y) + 0.5) / h * 2.0,
            f64::from(depth),
        );
        self.clip_from_rel_m.inverse().project_point3(ndc)
    }

    /// Triangles rebuilt, for reports.
    pub fn triangles(&self) -> usize {
        self.patches.iter().map(|p| p.triangles.len()).sum()
    }

    /// The first drawn point along the ray from the camera in direction `direction` (the frame's
    /// world axes), if it meets the ground; faces turned away are passed through, as the pass
    /// culls them.
    pub fn pick(&self, direction: DVec3) -> Option<GroundPoint> {
        let direction = direction.try_normalize()?;
        let mut best: Option<(f64, &Patch, [usize; 3], [f64; 2])> = None;
        for patch in &self.patches {
            let near_m = best.map_or(f64::INFINITY, |b| b.0);
            if !ray_meets_box(direction, patch.lo, patch.hi, near_m) {
                continue;
            }
            for &t in &patch.triangles {
                let [a, b, c] = t.map(|i| patch.vertices[i].rel_m.as_dvec3());
                if let Some((distance, uv)) = ray_triangle(direction, [a, b, c])
                    && distance < best.map_or(f64::INFINITY, |b| b.0)
                {
                    best = Some((distance, patch, t, uv));
                }
            }
        }
        let (distance, patch, t, [u, v]) = best?;
        let [a, b, c] = t.map(|i| patch.vertices[i]);
        // The triangle's own grid point, blended as its height is (what `at_grid` gives back),
        // not the exact inverse of the placing, which differs by the node mapping's error.
        let weights = [1.0 - u - v, u, v];
        let blend = |f: fn(&Vertex) -> DVec3| f(&a) * weights[0] + f(&b) * weights[1] + f(&c) * weights[2];
        let offset_m = blend(|v| v.offset_m.as_dvec2().extend(f64::from(v.height_m)));
        let grid_m = patch.origin_grid_m.extend(0.0) + offset_m;
        Some(GroundPoint {
            rel_m: direction * distance,
            grid_m,
            height_m: grid_m.z,
            normal: sheet_normal([a, b, c]),
        })
    }

    /// The drawn ground over grid point (`x_m`, `y_m`): the triangle holding it on the flat
    /// sheet, as the morph moved it; `None` where the frame drew no ground there.
    pub fn at_grid(&self, x_m: f64, y_m: f64) -> Option<GroundPoint> {
        for patch in &self.patches {
            let p = DVec2::new(x_m, y_m) - patch.origin_grid_m;
            for &t in &patch.triangles {
                let [a, b, c] = t.map(|i| patch.vertices[i]);
                let Some([wa, wb, wc]) = barycentric(p, [a, b, c].map(|v| v.offset_m.as_dvec2())) else {
                    continue;
                };
                let blend = |f: fn(&Vertex) -> DVec3| f(&a) * wa + f(&b) * wb + f(&c) * wc;
                let rel_m = blend(|v| v.rel_m.as_dvec3());
                let height_m = blend(|v| DVec3::splat(f64::from(v.height_m))).x;
                let grid_m = DVec3::new(x_m, y_m, height_m);
                return Some(GroundPoint { rel_m, grid_m, height_m, normal: sheet_normal([a, b, c]) });
            }
        }
        None
    }
}

/// The triangle's unit normal on the flat sheet (offsets and heights), up.
fn sheet_normal(t: [Vertex; 3]) -> DVec3 {
    let [a, b, c] = t.map(|v| v.offset_m.as_dvec2().extend(f64::from(v.height_m)));
    (b - a).cross(c - a).normalize_or(DVec3::Z)
}

/// Weights of `p` in triangle `t`, if it lies in it (edges included); `None` for one with no area.
fn barycentric(p: DVec2, [a, b, c]: [DVec2; 3]) -> Option<[f64; 3]> {
    let area = (b - a).perp_dot(c - a);
    if area.abs() < 1e-12 {
        return None;
    }
    let wb = (p - a).perp_dot(c - a) / area;
    let wc = (b - a).perp_dot(p - a) / area;
    let wa = 1.0 - wb - wc;
    let inside = |w: f64| w >= -1e-9;
    (inside(wa) && inside(wb) && inside(wc)).then_some([wa, wb, wc])
}

/// Where a ray from the origin along unit `d` meets triangle `t` from its front (counter-clockwise
/// seen from it): the distance and the weights of its second and third corners.
fn ray_triangle(d: DVec3, [a, b, c]: [DVec3; 3]) -> Option<(f64, [f64; 2])> {
    let (e1, e2) = (b - a, c - a);
    let p = d.cross(e2);
    let det = e1.dot(p);
    // Front faces only: a ray down onto a triangle counter-clockwise from above has det > 0.
    if det <= 0.0 {
        return None;
    }
    let s = -a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    let distance = e2.dot(q) / det;
    let on = |w: f64| (-1e-9..=1.0 + 1e-9).contains(&w);
    (on(u) && on(v) && u + v <= 1.0 + 1e-9 && distance > 0.0).then_some((distance, [u, v]))
}

/// Whether a ray from the origin along unit `d` meets the box nearer than `limit_m`.
fn ray_meets_box(d: DVec3, lo: DVec3, hi: DVec3, limit_m: f64) -> bool {
    let (mut enter, mut leave) = (0.0f64, limit_m);
    for axis in 0..3 {
        let (l, h, v) = (lo[axis], hi[axis], d[axis]);
        if v == 0.0 {
            if l > 0.0 || h < 0.0 {
                return false;
            }
            continue;
        }
        let (t0, t1) = ((l / v), (h / v));
        enter = enter.max(t0.min(t1));
        leave = leave.min(t0.max(t1));
    }
    enter <= leave
}

/// A quadrant's vertices and triangles, as the vertex shader places them.
fn patch(q: &DrawnQuadrant, u: &TerrainUniforms) -> Patch {
    let cells = u.node_cells;
    let half = cells / 2;
    let mapping = NodeMapping::from(&q.earth);
    let centre = 0.5 * cells as f32 * q.node.cell_m;
    let [x0, y0] = [q.quadrant & 1, q.quadrant >> 1].map(|side| side as u32 * half);
    let row = half + 1;
    let mut vertices = Vec::with_capacity((row * row) as usize);
    for j in 0..=half {
        for i in 0..=half {
            let corner = Vec2::new((x0 + i) as f32, (y0 + j) as f32);
            let g = corner.min(Vec2::from(q.node.cells_inside));
            let (offset_m, height_m) = surface_vertex(&q.node, &q.tile, u.camera_grid_m[2], g);
            let from_centre = Vec3::new(offset_m.x - centre, offset_m.y - centre, height_m);
            vertices.push(Vertex { rel_m: mapping.position_m(from_centre), offset_m, height_m });
        }
    }
    let mut triangles = Vec::with_capacity((2 * half * half) as usize);
    for j in 0..half {
        for i in 0..half {
            let at = |di: u32, dj: u32| ((j + dj) * row + i + di) as usize;
            let (sw, se, nw, ne) = (at(0, 0), at(1, 0), at(0, 1), at(1, 1));
            let cut = if diagonal_rises([x0 + i, y0 + j]) {
                [[sw, se, ne], [sw, ne, nw]]
            } else {
                [[sw, se, nw], [se, ne, nw]]
            };
            triangles.extend(cut);
        }
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for v in &vertices {
        lo = lo.min(v.rel_m.as_dvec3());
        hi = hi.max(v.rel_m.as_dvec3());
    }
    Patch { vertices, triangles, lo, hi, origin_grid_m: q.origin_grid_m }
}

/// `surface_vertex`'s morphed offset and height (`shared/terrain_mesh.wgsl`), in its f32 steps.
fn surface_vertex(node: &TerrainNode, tile: &[f32], camera_z_m: f32, g: Vec2) -> (Vec2, f32) {
    let h = height_at(node, tile, g) - camera_z_m;
    let distance = (Vec2::from(node.origin_rel_m) + g * node.cell_m).extend(h).length();
    let morph = ((distance - node.morph_start_m) / (node.morph_end_m - node.morph_start_m)).clamp(0.0, 1.0);
    let half_fract = (g * 0.5).fract();
    let g_morphed = (g - half_fract * 2.0 * morph).min(Vec2::from(node.cells_inside));
    (g_morphed * node.cell_m, height_at(node, tile, g_morphed))
}

/// `height_at`: bilinear between the tile's samples at the node's grid position `g`.
fn height_at(node: &TerrainNode, tile: &[f32], g: Vec2) -> f32 {
    let sample = Vec2::from(node.sample_offset) + g * node.sample_step;
    let base = sample.floor();
    let f = sample - base;
    let s = base.as_ivec2();
    let limit = HEIGHT_TILE_EXTENT as i32 - 1;
    let at = |dx: i32, dy: i32| {
        let (x, y) = ((s.x + dx).clamp(0, limit), (s.y + dy).clamp(0, limit));
        tile[(y * (limit + 1) + x) as usize]
    };
    let mix = |a: f32, b: f32, t: f32| a * (1.0 - t) + b * t;
    mix(mix(at(0, 0), at(1, 0), f.x), mix(at(0, 1), at(1, 1), f.x), f.y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_meets_a_triangle_from_above_only_and_inside_it() {
        // Counter-clockwise from above, 10 m below the camera.
        let t = [DVec3::new(-1.0, -1.0, -10.0), DVec3::new(3.0, -1.0, -10.0), DVec3::new(-1.0, 3.0, -10.0)];
        let (distance, [u, v]) = ray_triangle(-DVec3::Z, t).unwrap();
        assert!((distance - 10.0).abs() < 1e-12 && (u - 0.25).abs() < 1e-12 && (v - 0.25).abs() < 1e-12);
        // Its back face, and a ray beside it, are not met.
        assert!(ray_triangle(-DVec3::Z, [t[0], t[2], t[1]]).is_none());
        assert!(ray_triangle(DVec3::new(0.5, 0.5, -0.1).normalize(), t).is_none());
        assert!(ray_triangle(DVec3::Z, t.map(|p| -p)).is_none(), "the triangle above, seen from below");
    }

    #[test]
    fn a_ray_meets_a_box_it_crosses_within_the_limit() {
        let (lo, hi) = (DVec3::new(5.0, -1.0, -1.0), DVec3::new(6.0, 1.0, 1.0));
        assert!(ray_meets_box(DVec3::X, lo, hi, f64::INFINITY));
        assert!(!ray_meets_box(DVec3::X, lo, hi, 4.0), "beyond the nearest hit so far");
        assert!(!ray_meets_box(-DVec3::X, lo, hi, f64::INFINITY), "behind the camera");
        assert!(!ray_meets_box(DVec3::Y, lo, hi, f64::INFINITY));
    }

    #[test]
    fn weights_hold_points_inside_and_refuse_points_outside() {
        let t = [DVec2::ZERO, DVec2::X, DVec2::Y];
        let [a, b, c] = barycentric(DVec2::new(0.25, 0.5), t).unwrap();
        assert!((a - 0.25).abs() < 1e-12 && (b - 0.25).abs() < 1e-12 && (c - 0.5).abs() < 1e-12);
        assert!(barycentric(DVec2::new(0.75, 0.5), t).is_none());
        assert!(barycentric(DVec2::ZERO, [DVec2::ZERO, DVec2::X, DVec2::X * 2.0]).is_none(), "no area");
    }
}
