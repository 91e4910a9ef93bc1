//! How it works: what pass 3's occlusion march (`shaders/seed_select_march.wgsl`) leaps by. The
//! march asks whether the drawn ground rises above the segment from the eye to a seed's summit at
//! any of its samples; wherever the segment passes at or above every height that can be drawn
//! under a run of samples, it leaps over the run. Two kinds of top bound those heights:
//!
//! - per height tile (`height_tile_max_m`, uploaded once): the top of the Tile Load Map's range of
//!   the tile and its eight neighbours, every level-0 sample under them, which bounds whatever
//!   level draws the ground there (decimated heights never leave their level-0 range);
//! - per block of HEIGHT_BLOCK_CELLS cells of each resident tile (`block_max_m`, made from the
//!   tile's samples when the height cache places it, `BLOCK_TOPS`): the highest corner sample of
//!   the block's cells, which bounds what the tile itself draws there.
//!
//! Both are exact maxima, so the twin, reading the same, leaps alike; the shader says why a leap
//! takes the decision visiting would.

use crate::dataset::Dataset;
use crate::gpu::layout::{HEIGHT_BLOCK_CELLS, HEIGHT_BORDER, HEIGHT_TILE_BLOCKS, HEIGHT_TILE_EXTENT};
use crate::passes::tile_load_map::frame::height_tile_ranges;
use crate::streaming::SlotSummary;

/// Per height tile, in page-table (pack) order, the highest ground the terrain can draw over it
/// at any level whose cells are no wider than the tile: the top of the Tile Load Map's ranges. A
/// tile without a finite top gets +∞: the march never leaps over it.
pub fn height_tile_max_m(dataset: &Dataset) -> Vec<f32> {
    let top = |max_m: f32| if max_m.is_finite() { max_m } else { f32::INFINITY };
    height_tile_ranges(dataset).into_iter().map(|[_, max_m]| top(max_m)).collect()
}

/// Tops per height tile: HEIGHT_TILE_BLOCKS² of them.
pub const BLOCKS_PER_TILE: usize = (HEIGHT_TILE_BLOCKS * HEIGHT_TILE_BLOCKS) as usize;

/// The highest corner sample of each block of a height tile's cells, row by row from its south-west
/// block, from the tile's samples (`HEIGHT_TILE_EXTENT`² of them, border included, row-major).
/// A NaN sample is left out (it never rises above anything); a block of NaN only has top −∞.
pub fn block_max_m(samples: &[f32]) -> Vec<f32> {
    let extent = HEIGHT_TILE_EXTENT as usize;
    let at =
        |x: u32, y: u32| samples.get((y + HEIGHT_BORDER) as usize * extent + (x + HEIGHT_BORDER) as usize);
    let mut tops = Vec::with_capacity(BLOCKS_PER_TILE);
    for by in 0..HEIGHT_TILE_BLOCKS {
        for bx in 0..HEIGHT_TILE_BLOCKS {
            let corners = |c: u32| c * HEIGHT_BLOCK_CELLS..=(c + 1) * HEIGHT_BLOCK_CELLS;
            let top = corners(by)
                .flat_map(|y| corners(bx).map(move |x| (x, y)))
                .filter_map(|(x, y)| at(x, y).copied())
                .fold(f32::NEG_INFINITY, f32::max);
            tops.push(top);
        }
    }
    tops
}

/// What the height cache keeps beside each slot: its tile's block tops, as f32 bits.
pub const BLOCK_TOPS: SlotSummary = SlotSummary {
    label: "height block tops",
    words_per_slot: BLOCKS_PER_TILE as u32,
    make: |payload| {
        let samples: Vec<f32> = bytemuck::pod_collect_to_vec(payload);
        block_max_m(&samples).into_iter().map(f32::to_bits).collect()
    },
};

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_tops_hold_every_corner_of_their_cells_and_no_more() {
        let extent = HEIGHT_TILE_EXTENT as usize;
        let samples: Vec<f32> = (0..extent * extent)
            .map(|i| ((i * 7919) % 1013) as f32 - if i % 97 == 0 { f32::NAN } else { 0.0 })
            .collect();
        let tops = block_max_m(&samples);
        assert_eq!(tops.len(), BLOCKS_PER_TILE);
        let b = HEIGHT_BORDER as usize;
        for (i, &top) in tops.iter().enumerate() {
            let (bx, by) = (i % HEIGHT_TILE_BLOCKS as usize, i / HEIGHT_TILE_BLOCKS as usize);
            let n = HEIGHT_BLOCK_CELLS as usize;
            let mut highest = f32::NEG_INFINITY;
            for y in by * n..=(by + 1) * n {
                for x in bx * n..=(bx + 1) * n {
                    let h = samples[(y + b) * extent + x + b];
                    assert!(
                        h.is_nan() || h <= top,
                        "block {bx}, {by}: sample {x}, {y} at {h} above its top {top}"
                    );
                    highest = highest.max(h);
                }
            }
            assert_eq!(top, highest, "block {bx}, {by}: the top is not a corner sample");
        }
    }
}
