//! How it works: the CPU twin of `shaders/tile_load_map.wgsl`, function for function. It takes
//! exactly what the GPU pass reads (the uniforms, the ring spans, the height tile ranges and the
//! depth pyramid as CPU arrays) and writes the same `TlmCell`s. The f32 arithmetic is the
//! shader's, in the shader's order: products are plain `a * b` here (the shader's `mul` only
//! stops its compiler fusing them into FMAs, which Rust never does unasked), decisions compare
//! squares and products, and the one division only seeds a search settled by exact comparisons.
//! The depth pyramid it reads is `HizMips` (reduced on the CPU by `reference::depth_pyramid`).

use crate::gpu::gpu_types::{TlmCell, TlmSpan, TlmUniforms};
use crate::gpu::layout::{
    LevelRange, RADIAL_INACTIVE, TLM_CULLED, TLM_FIRST_PATTERN, TLM_RADIAL_BANDS, TLM_SPAN_COVERED,
    TLM_SPAN_INSIDE, TileSpan, tlm_visibility,
};
use crate::passes::depth_pyramid::frame::HizMips;
pub use crate::seeds::{cell_pattern, pattern_hash, pcg};

fn length_sq(v: [f32; 3]) -> f32 {
    v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
}

fn height_range(u: &TlmUniforms, ranges_m: &[[f32; 2]], ring: u32, tiles_x: u32, tiles_y: u32) -> [f32; 2] {
    let level = u.height_levels[u.rings_info[ring as usize].height_level as usize];
    let mut range = [3.4e38f32, -3.4e38];
    let (xs, ys) = (TileSpan::unpack(tiles_x), TileSpan::unpack(tiles_y));
    for ty in ys.first..=ys.last {
        for tx in xs.first..=xs.last {
            let r = ranges_m[(level[0] + ty * level[1] + tx) as usize];
            range = [range[0].min(r[0]), range[1].max(r[1])];
        }
    }
    range
}

/// The shader's `bent_box`: grid box `lo`..`hi` bent onto the Earth, as a camera-relative box
/// that holds where it is drawn (`earth::horizon::EarthBend`; the box as it came when flat).
pub fn bent_box(u: &TlmUniforms, lo: [f32; 3], hi: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let [e, ez] = u.earth_bend;
    let far: [f32; 2] = std::array::from_fn(|a| lo[a].abs().max(hi[a].abs()));
    // WGSL's clamp(e, lo, hi) is min(max(e, lo), hi).
    let near: [f32; 2] = std::array::from_fn(|a| 0.0f32.max(lo[a]).min(hi[a]));
    let far_sq = far[0] * far[0] + far[1] * far[1];
    let near_sq = near[0] * near[0] + near[1] * near[1];
    let l1 = far[0] + far[1];
    let across = e[1] * l1 + e[2] * far_sq + e[3] * (l1 * far_sq);
    let margin = [across, across, ez[0] * l1 + ez[1] * far_sq + ez[2] * (far_sq * far_sq)];
    let fall = [0.0, 0.0, e[0] * far_sq];
    let rise = [0.0, 0.0, e[0] * near_sq];
    (
        std::array::from_fn(|a| lo[a] - margin[a] - fall[a]),
        std::array::from_fn(|a| hi[a] + margin[a] - rise[a]),
    )
}

/// The shader's `below_horizon`: whether the Earth hides camera-relative point `p`.
fn below_horizon(u: &TlmUniforms, p: [f32; 3]) -> bool {
    let h = &u.horizon;
    let dot = |r: usize| h[r][0] * p[0] + h[r][1] * p[1] + h[r][2] * p[2];
    let along = dot(3);
    along > h[3][3] && along * along >= length_sq([dot(0), dot(1), dot(2)]) * h[3][3]
}

/// The shader's `beyond_horizon`: whether the Earth hides every corner of the box.
fn beyond_horizon(u: &TlmUniforms, lo: [f32; 3], hi: [f32; 3]) -> bool {
    (0..8).all(|c| below_horizon(u, std::array::from_fn(|a| if c & (1 << a) != 0 { hi[a] } else { lo[a] })))
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
    let tolerance_m = u.occlusion_tolerance_m + u.occlusion_tolerance_per_m * nearest_w;
    (nearest_w - tolerance_m) * farthest_depth > u.near_m
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
    let culled =
        TlmCell { visibility: TLM_CULLED, imagery_lod: 0, height_lod: 0, radial_lod: RADIAL_INACTIVE };
    let sx = spans[((ring * 2) * u.cells + cx) as usize];
    let sy = spans[((ring * 2 + 1) * u.cells + cy) as usize];
    let flags = sx.flags & sy.flags;
    if flags & TLM_SPAN_INSIDE == 0 || flags & TLM_SPAN_COVERED != 0 {
        return culled;
    }
    let heights = height_range(u, ranges_m, ring, sx.height_tiles, sy.height_tiles);
    let lo = [sx.rel_m[0], sy.rel_m[0], heights[0] - u.camera_z_m];
    let hi = [sx.rel_m[1], sy.rel_m[1], heights[1] - u.camera_z_m];
    let (placed_lo, placed_hi) = bent_box(u, lo, hi);
    if !in_frustum(u, placed_lo, placed_hi)
        || beyond_horizon(u, placed_lo, placed_hi)
        || occluded(u, hiz, placed_lo, placed_hi)
    {
        return culled;
    }
    // WGSL's clamp(e, lo, hi) is min(max(e, lo), hi).
    let near_sq = length_sq(std::array::from_fn(|a| 0.0f32.max(lo[a]).min(hi[a])));
    let far_sq = length_sq(std::array::from_fn(|a| lo[a].abs().max(hi[a].abs())));

    let mut cell = TlmCell { visibility: TLM_FIRST_PATTERN, ..Default::default() };
    if ring == 0 {
        let origin = u.rings_info[0].origin_cell;
        let g = [origin[0].wrapping_add(cx as i32), origin[1].wrapping_add(cy as i32)];
        cell.visibility = tlm_visibility(cell_pattern(g, u.seed, u.corner_colours));
    }
    if u.imagery_levels > 0 {
        cell.imagery_lod =
            LevelRange { min: imagery_level(u, near_sq), max: imagery_level(u, far_sq) }.pack();
    }
    cell.height_lod = LevelRange { min: height_lod(u, near_sq), max: height_lod(u, far_sq) }.pack();
    cell.radial_lod = RADIAL_INACTIVE;
    for k in (0..TLM_RADIAL_BANDS).rev() {
        if near_sq < u.radial_band_sq_m2[k as usize] {
            cell.radial_lod = k;
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
