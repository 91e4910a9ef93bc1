//! How it works: the twin of the shader's ground reads (`height_tile`, `ground_in`) and its
//! occlusion march (`seed_select_march.wgsl`), with the same f32 operations in the same order. The
//! march steps from the eye to a seed's summit and reports whether the drawn ground rises above
//! the segment at any sample; where the segment passes at or above the top of a tile
//! (`height_tile_max_m`) or of a block of the resident tile drawing the sample (`block_max_m`), it
//! leaps to the last sample still in that square and over that top, found by bisection. A leap
//! takes the decision visiting every sample would (the shader's comment says why); with every top
//! +∞ the march never leaps, which is how the tests check that.

use crate::dataset::surface::drawn_height;
use crate::gpu::gpu_types::SeedUniforms;
use crate::gpu::layout::{
    HEIGHT_BLOCK_CELLS, HEIGHT_BLOCK_LEVELS, HEIGHT_BORDER, HEIGHT_TILE_BLOCKS, HEIGHT_TILE_CELLS, page_slot,
};

use super::{GridPos, SeedTwinInputs, TwinCache, grid_pos};

pub(super) struct Ground {
    pub height_m: f32,
    pub gradient: [f32; 2],
    pub level: u32,
}

/// The tile the drawn ground at level-0 sample `s0` comes from: the finest level whose tile there
/// is resident (no slot when none is, at the coarsest level).
struct HeightTile {
    level: u32,
    tile: [u32; 2],
    slot: Option<u32>,
}

/// The level-`level` tile holding level-0 sample `s0`, and its page-table index.
fn tile_at(u: &SeedUniforms, s0: [u32; 2], level: u32) -> ([u32; 2], usize) {
    let info = u.height_levels[level as usize];
    let tile = [
        ((s0[0] >> level) / HEIGHT_TILE_CELLS).min(info[1] - 1),
        ((s0[1] >> level) / HEIGHT_TILE_CELLS).min(info[2] - 1),
    ];
    (tile, (info[0] + tile[1] * info[1] + tile[0]) as usize)
}

fn height_tile(u: &SeedUniforms, heights: &TwinCache<f32>, s0: [u32; 2]) -> HeightTile {
    let mut level = 0;
    loop {
        let (tile, index) = tile_at(u, s0, level);
        let slot = page_slot(heights.page_table[index]);
        if slot.is_some() || level + 1 >= u.height_level_count {
            return HeightTile { level, tile, slot };
        }
        level += 1;
    }
}

/// The drawn ground at `p` (level-0 samples) from the finest resident level.
pub(super) fn ground_at(u: &SeedUniforms, heights: &TwinCache<f32>, p: &GridPos) -> Option<Ground> {
    ground_in(u, heights, &height_tile(u, heights, p.texel.map(|v| v as u32)), p)
}

fn ground_in(u: &SeedUniforms, heights: &TwinCache<f32>, hit: &HeightTile, p: &GridPos) -> Option<Ground> {
    let (slot, level, tile) = (hit.slot?, hit.level, hit.tile);
    let s0 = p.texel.map(|v| v as u32);
    let s = s0.map(|v| v >> level);
    let local = [
        s[0] - tile[0] * HEIGHT_TILE_CELLS + HEIGHT_BORDER,
        s[1] - tile[1] * HEIGHT_TILE_CELLS + HEIGHT_BORDER,
    ];
    let load = |dx: u32, dy: u32| heights.load(slot, local[0] + dx, local[1] + dy);
    let corners = [load(0, 0), load(1, 0), load(0, 1), load(1, 1)];
    let mask = (1u32 << level) - 1;
    let scale = 1.0 / (1u32 << level) as f32;
    let f = [((s0[0] & mask) as f32 + p.frac[0]) * scale, ((s0[1] & mask) as f32 + p.frac[1]) * scale];
    let (height_m, slope) = drawn_height(s, corners, f);
    let per_m = scale * u.inv_spacing_m;
    Some(Ground { height_m, gradient: [slope[0] * per_m, slope[1] * per_m], level })
}

/// The shader's `leap_level`: the finest level whose tiles are wider than a cell of the coarsest.
fn leap_level(u: &SeedUniforms) -> u32 {
    u.height_level_count - u.height_level_count.min(HEIGHT_TILE_CELLS.trailing_zeros() + 1)
}

/// The shader's `Leap`: the samples in the level-`level` grid square `square` of `cells` cells, while
/// the segment stays at or above `top_m`.
struct Leap {
    level: u32,
    cells: u32,
    square: [u32; 2],
    top_m: f32,
}

/// What the occlusion march found: whether the ground hides the summit, and how many samples'
/// ground it read to decide (the leaps skip the rest).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OcclusionMarch {
    /// The drawn ground rises above the segment from the eye to the summit at some sample.
    pub hidden: bool,
    /// Samples whose drawn ground was read.
    pub samples_read: u32,
}

/// The shader's `dem_blocks`: whether the drawn ground rises above the segment from the eye to
/// `target` (its grid offset from the camera, and its height above the camera's), sagging on the
/// Earth (`SeedUniforms::chord_sag_per_m2`), leaping where the tops allow.
pub fn occlusion_march(inputs: &SeedTwinInputs, target: [f32; 3]) -> OcclusionMarch {
    let u = &inputs.frame.uniforms;
    let length_sq = target[0] * target[0] + target[1] * target[1];
    let wanted_sq = (length_sq * 4.0) * (u.inv_spacing_m * u.inv_spacing_m);
    let mut steps = 2u32;
    while steps < u.refine_max_steps && ((steps * steps) as f32) < wanted_sq {
        steps *= 2;
    }
    let dt = 1.0 / steps as f32;
    let sag_m = u.chord_sag_per_m2 * (length_sq + 2.0 * (target[2] * target[2]));
    // Sample `k`: where it lies in the height grid, whether that is in the dataset, the segment's
    // height there and the floor under it (the shader's `march_point`).
    let point = |k: u32| {
        let t = k as f32 * dt;
        let p = target.map(|v| v * t);
        let sample = grid_pos(u.camera_sample, u.camera_sample_frac, [p[0], p[1]], u.inv_spacing_m);
        let inside = (0..2).all(|a| sample.texel[a] >= 0 && sample.texel[a] < u.height_size[a] as i32);
        let (line_m, sag_t) = (p[2] + u.camera_z_m, sag_m * t);
        (sample, inside, line_m - (sag_t - sag_t * t), line_m - sag_t)
    };
    let square_of =
        |sample: &GridPos, level: u32, cells: u32| sample.texel.map(|v| ((v as u32) >> level) / cells);
    // The last sample from `k` (where `leap` holds) to `steps` where it still holds.
    let leap_end = |k: u32, leap: Leap| {
        let holds = |j: u32| {
            let (sample, inside, _, floor_m) = point(j);
            inside && square_of(&sample, leap.level, leap.cells) == leap.square && leap.top_m <= floor_m
        };
        let (mut clear, mut beyond) = (k, steps);
        while beyond - clear > 1 {
            let mid = clear + (beyond - clear) / 2;
            if holds(mid) {
                clear = mid;
            } else {
                beyond = mid;
            }
        }
        clear
    };
    let tile_level = leap_level(u);
    let (mut k, mut samples_read) = (1, 0);
    while k < steps {
        let (sample, inside, z_m, floor_m) = point(k);
        if !inside {
            k += 1;
            continue;
        }
        let s0 = sample.texel.map(|v| v as u32);
        let tile_top_m = inputs.height_tile_max_m[tile_at(u, s0, tile_level).1];
        if tile_top_m <= floor_m {
            let square = square_of(&sample, tile_level, HEIGHT_TILE_CELLS);
            k = leap_end(k, Leap { level: tile_level, cells: HEIGHT_TILE_CELLS, square, top_m: tile_top_m })
                + 1;
            continue;
        }
        let hit = height_tile(u, inputs.heights, s0);
        if let Some(slot) = hit.slot.filter(|_| hit.level <= HEIGHT_BLOCK_LEVELS) {
            let block = square_of(&sample, hit.level, HEIGHT_BLOCK_CELLS);
            let local = [0, 1].map(|a| block[a].wrapping_sub(hit.tile[a] * HEIGHT_TILE_BLOCKS));
            if local.iter().all(|&b| b < HEIGHT_TILE_BLOCKS) {
                let top_m =
                    inputs.height_block_max_m[&slot][(local[1] * HEIGHT_TILE_BLOCKS + local[0]) as usize];
                if top_m <= floor_m {
                    let level = hit.level;
                    k = leap_end(k, Leap { level, cells: HEIGHT_BLOCK_CELLS, square: block, top_m }) + 1;
                    continue;
                }
            }
        }
        samples_read += 1;
        if ground_in(u, inputs.heights, &hit, &sample).is_some_and(|g| g.height_m > z_m) {
            return OcclusionMarch { hidden: true, samples_read };
        }
        k += 1;
    }
    OcclusionMarch { hidden: false, samples_read }
}
