//! How it works: the CPU twin of `shaders/tile_load_map.wgsl`, function for function. It takes
//! exactly what the GPU pass reads (the uniforms, the ring spans, the height tile ranges and the
//! depth pyramid as CPU arrays) and writes the same `TlmCell`s. The f32 arithmetic is the
//! shader's, in the shader's order: products are plain `a * b` here (the shader's `mul` only
//! stops its compiler fusing them into FMAs, which Rust never does unasked), decisions compare
//! squares and products, and the one division only seeds a search settled by exact comparisons.
//!
//! `HizMips` is the CPU form of the depth pyramid, with the reference min-reduction the GPU
//! pyramid is tested against.

use crate::gpu::gpu_types::{TlmCell, TlmSpan, TlmUniforms};
use crate::passes::tile_load_map::{TLM_SPAN_COVERED, TLM_SPAN_INSIDE};
pub use crate::seeds::{pattern_hash, pcg};

/// A depth pyramid on the CPU: level sizes and texels (top row first) of every level.
#[derive(Debug, Clone, PartialEq)]
pub struct HizMips {
    pub sizes: Vec<[u32; 2]>,
    pub levels: Vec<Vec<f32>>,
}

impl HizMips {
    /// The reference reduction of a `width` × `height` reversed-Z depth image (top row first):
    /// each texel the minimum of what it covers, the last texel of an odd edge covering three.
    pub fn from_depth(depth: &[f32], width: u32, height: u32) -> Self {
        let sizes = crate::passes::depth_pyramid::level_sizes(width, height);
        let mut levels: Vec<Vec<f32>> = Vec::with_capacity(sizes.len());
        let mut source = ([width, height], depth.to_vec());
        for &size in &sizes {
            let covered = |x: u32, n: u32, source_n: u32| {
                let last = if x + 1 == n { source_n - 1 } else { 2 * x + 1 };
                (2 * x).min(source_n - 1)..=last.min(source_n - 1)
            };
            let mut texels = Vec::with_capacity((size[0] * size[1]) as usize);
            for y in 0..size[1] {
                for x in 0..size[0] {
                    let mut farthest = f32::INFINITY;
                    for sy in covered(y, size[1], source.0[1]) {
                        for sx in covered(x, size[0], source.0[0]) {
                            farthest = farthest.min(source.1[(sy * source.0[0] + sx) as usize]);
                        }
                    }
                    texels.push(farthest);
                }
            }
            levels.push(texels.clone());
            source = (size, texels);
        }
        Self { sizes, levels }
    }

    /// Texel (`x`, `y`) of `level`.
    pub fn texel(&self, level: u32, x: u32, y: u32) -> f32 {
        let [w, _] = self.sizes[level as usize];
        self.levels[level as usize][(y * w + x) as usize]
    }
}

fn length_sq(v: [f32; 3]) -> f32 {
    v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
}

fn height_range(u: &TlmUniforms, ranges_m: &[[f32; 2]], ring: u32, tiles_x: u32, tiles_y: u32) -> [f32; 2] {
    let level = u.height_levels[u.rings_info[ring as usize].height_level as usize];
    let mut range = [3.4e38f32, -3.4e38];
    for ty in tiles_y & 0xffff..=tiles_y >> 16 {
        for tx in tiles_x & 0xffff..=tiles_x >> 16 {
            let r = ranges_m[(level[0] + ty * level[1] + tx) as usize];
            range = [range[0].min(r[0]), range[1].max(r[1])];
        }
    }
    range
}

fn in_frustum(u: &TlmUniforms, lo: [f32; 3], hi: [f32; 3]) -> bool {
    u.frustum_planes.iter().all(|p| {
        let c: [f32; 3] = std::array::from_fn(|a| if p[a] >= 0.0 { hi[a] } else { lo[a] });
        p[0] * c[0] + p[1] * c[1] + p[2] * c[2] + p[3] >= 0.0
    })
}

/// Clip-space x, y and w of camera-relative point `p`.
fn project(u: &TlmUniforms, p: [f32; 3]) -> [f32; 3] {
    let m = &u.clip_from_view_world;
    let row = |r: usize| m[0][r] * p[0] + m[1][r] * p[1] + m[2][r] * p[2] + m[3][r];
    [row(0), row(1), row(3)]
}

fn pixel_of(q: f32, w: f32, ndc_per_px: f32, pixels: u32) -> u32 {
    let n = pixels as i32;
    let guess = (q / w + 1.0) / ndc_per_px;
    let mut i = guess.floor().clamp(-1.0, n as f32) as i32;
    let edge = |i: i32| (i as f32 * ndc_per_px - 1.0) * w;
    for _ in 0..4 {
        if i < n && q >= edge(i + 1) {
            i += 1;
        }
    }
    for _ in 0..4 {
        if i > -1 && q < edge(i) {
            i -= 1;
        }
    }
    i.clamp(0, n - 1) as u32
}

fn occluded(u: &TlmUniforms, hiz: &HizMips, lo: [f32; 3], hi: [f32; 3]) -> bool {
    let mut nearest_w = 3.4e38f32;
    let mut rect = [u32::MAX, u32::MAX, 0, 0];
    for corner in 0..8u32 {
        let p: [f32; 3] = std::array::from_fn(|a| if corner & (1 << a) != 0 { hi[a] } else { lo[a] });
        let clip = project(u, p);
        if clip[2] < u.near_m {
            return false;
        }
        nearest_w = nearest_w.min(clip[2]);
        let x = pixel_of(clip[0], clip[2], u.ndc_per_px[0], u.screen_px[0]);
        let y = pixel_of(-clip[1], clip[2], u.ndc_per_px[1], u.screen_px[1]);
        rect = [rect[0].min(x), rect[1].min(y), rect[2].max(x), rect[3].max(y)];
    }
    let mut level = 0u32;
    let (first, last) = loop {
        let [w, h] = hiz.sizes[level as usize];
        let first = [(rect[0] >> (level + 1)).min(w - 1), (rect[1] >> (level + 1)).min(h - 1)];
        let last = [(rect[2] >> (level + 1)).min(w - 1), (rect[3] >> (level + 1)).min(h - 1)];
        if (last[0] - first[0] <= 1 && last[1] - first[1] <= 1) || level + 1 >= u.hiz_mips {
            break (first, last);
        }
        level += 1;
    };
    let mut farthest_depth = 1.0f32;
    for y in first[1]..=last[1] {
        for x in first[0]..=last[0] {
            farthest_depth = farthest_depth.min(hiz.texel(level, x, y));
        }
    }
    (nearest_w - u.occlusion_tolerance_m) * farthest_depth > u.near_m
}

fn imagery_level(u: &TlmUniforms, d_sq: f32) -> u32 {
    let x = d_sq * u.imagery_scale_sq;
    let exponent = ((x.to_bits() >> 23) & 0xff) as i32 - 127;
    (exponent >> 1).clamp(0, u.imagery_levels as i32 - 1) as u32
}

fn height_lod(u: &TlmUniforms, d_sq: f32) -> u32 {
    for m in 0..u.height_lod_count {
        let range = u.height_lod_range_m[(m / 4) as usize][(m % 4) as usize];
        if d_sq <= range * range {
            return m;
        }
    }
    u.height_lod_count - 1
}

fn tlm_cell(
    u: &TlmUniforms,
    spans: &[TlmSpan],
    ranges_m: &[[f32; 2]],
    hiz: &HizMips,
    ring: u32,
    cx: u32,
    cy: u32,
) -> TlmCell {
    let culled = TlmCell { visibility: 0, imagery_lod: 0, height_lod: 0, radial_lod: 3 };
    let sx = spans[((ring * 2) * u.cells + cx) as usize];
    let sy = spans[((ring * 2 + 1) * u.cells + cy) as usize];
    let flags = sx.flags & sy.flags;
    if flags & TLM_SPAN_INSIDE == 0 || flags & TLM_SPAN_COVERED != 0 {
        return culled;
    }
    let heights = height_range(u, ranges_m, ring, sx.height_tiles, sy.height_tiles);
    let lo = [sx.rel_m[0], sy.rel_m[0], heights[0] - u.camera_z_m];
    let hi = [sx.rel_m[1], sy.rel_m[1], heights[1] - u.camera_z_m];
    if !in_frustum(u, lo, hi) || occluded(u, hiz, lo, hi) {
        return culled;
    }
    // WGSL's clamp(e, lo, hi) is min(max(e, lo), hi).
    let near_sq = length_sq(std::array::from_fn(|a| 0.0f32.max(lo[a]).min(hi[a])));
    let far_sq = length_sq(std::array::from_fn(|a| lo[a].abs().max(hi[a].abs())));

    let mut cell = TlmCell { visibility: 1, ..Default::default() };
    if ring == 0 {
        let origin = u.rings_info[0].origin_cell;
        let g = [origin[0].wrapping_add(cx as i32), origin[1].wrapping_add(cy as i32)];
        cell.visibility = 1 + pattern_hash(g[0] as u32, g[1] as u32, u.seed) % u.patterns;
    }
    if u.imagery_levels > 0 {
        cell.imagery_lod = imagery_level(u, near_sq) | (imagery_level(u, far_sq) << 8);
    }
    cell.height_lod = height_lod(u, near_sq) | (height_lod(u, far_sq) << 8);
    cell.radial_lod = 3;
    for k in (0..3).rev() {
        if near_sq < u.radial_lod_sq_m2[k] {
            cell.radial_lod = k as u32;
        }
    }
    cell
}

/// Every cell of the TLM, ring by ring, row by row, as the GPU pass writes them.
pub fn tile_load_map(
    uniforms: &TlmUniforms,
    spans: &[TlmSpan],
    height_ranges_m: &[[f32; 2]],
    hiz: &HizMips,
) -> Vec<TlmCell> {
    let n = uniforms.cells;
    let mut cells = Vec::with_capacity((uniforms.rings * n * n) as usize);
    for ring in 0..uniforms.rings {
        for cy in 0..n {
            for cx in 0..n {
                cells.push(tlm_cell(uniforms, spans, height_ranges_m, hiz, ring, cx, cy));
            }
        }
    }
    cells
}
