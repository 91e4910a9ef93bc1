//! How it works: a build too large for one process is cut into partitions that any number of
//! machines build independently, then merged into the dataset one process would have written,
//! byte for byte.
//!
//! Each layer's quadtree is cut at a *split level* `k` (`Split`): every tile of level `k` roots a
//! subtree (itself and the tiles beneath it down to level 0), and the roots, in row-major order,
//! are dealt to the partitions in contiguous runs. `k` is the coarsest level with at least one
//! root per partition whose subtree's level images fit `SUBTREE_IMAGE_BYTES`, so a job's memory
//! is bounded whatever the dataset's size. A partition writes its subtrees into a *part pack*: a
//! pack whose slots are its tiles in global order (`PartSlots`). A subtree's tiles near its edge
//! read texels of their neighbours (borders, and the reduction's window one level down), so the
//! part writer (`subtree`) does not read back tiles as `write_layer` does: it computes each level
//! as an image over the window the subtree needs, from the source, a little beyond the subtree on
//! every side. The tiles' payloads are therefore exactly `write_layer`'s; their value ranges,
//! which in `write_layer` also span the neighbour tiles a tile was reduced from, are kept as each
//! tile's own and completed at the merge (`merge`), which copies every part's stored bytes into
//! the dataset's pack in the single build's order and reduces the levels above `k` from them.

pub mod merge;
mod subtree;

pub use merge::{merge_layer, merge_lcc};
pub use subtree::{write_layer_part, write_lcc_part};

use super::Window;
use super::pyramid::{Pyramid, TileId};

/// Bytes of level images a subtree may hold at once (every level together): with tiles in flight
/// and the readers' caches, a partition job stays well inside 512 MiB.
pub const SUBTREE_IMAGE_BYTES: u64 = 128 << 20;

/// How one layer's quadtree is cut into subtrees and dealt to partitions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Split {
    /// The layer's quadtree.
    pub pyramid: Pyramid,
    /// The level of the subtrees' roots; the levels above are reduced at the merge.
    pub level: u32,
    /// How many partitions the roots are dealt to.
    pub partitions: u32,
}

impl Split {
    /// The split of `pyramid` (texels of `texel_bytes`) for `partitions` jobs, rooted no lower
    /// than `min_level` (the land cover's level 0 is derived from level 1, so its roots are ≥ 1).
    pub fn new(pyramid: Pyramid, partitions: u32, texel_bytes: u64, min_level: u32) -> Self {
        let partitions = partitions.max(1);
        let top = pyramid.levels - 1;
        let min_level = min_level.min(top);
        // A subtree rooted at k spans 2^k tiles per side at level 0, plus a margin of borders. In
        // u128: a source of 2^31 texels a side (a GeoTIFF's header may say so) has subtrees past
        // u64's bytes.
        let fits = |k: u32| {
            let side = u128::from(pyramid.tile + 2 * pyramid.border + 2) << k;
            side * side * u128::from(texel_bytes) * 4 / 3 <= u128::from(SUBTREE_IMAGE_BYTES)
        };
        let roots = |k: u32| {
            let [nx, ny] = pyramid.tiles_at(k);
            u64::from(nx) * u64::from(ny)
        };
        let level = (min_level..=top)
            .rev()
            .find(|&k| fits(k) && roots(k) >= u64::from(partitions))
            // Fewer roots than partitions at every level that fits: the finest, and some idle.
            .unwrap_or(min_level);
        Self { pyramid, level, partitions }
    }

    /// The subtree roots partition `part` builds, in row-major order (none when there are fewer
    /// roots than partitions and this one is left over).
    pub fn roots(&self, part: u32) -> Vec<TileId> {
        let [nx, ny] = self.pyramid.tiles_at(self.level);
        // In u128: up to 2^32 partitions times up to 2^48 roots.
        let count = u128::from(nx) * u128::from(ny);
        let (part, parts) = (u128::from(part), u128::from(self.partitions));
        let (first, end) = ((part * count / parts) as u64, ((part + 1) * count / parts) as u64);
        (first..end)
            .map(|i| TileId::new(self.level, (i % u64::from(nx)) as u32, (i / u64::from(nx)) as u32))
            .collect()
    }

    /// The partition whose subtree holds `id` (a tile at or below the split level).
    pub fn part_of(&self, id: TileId) -> u32 {
        let shift = self.level - id.level;
        let [nx, ny] = self.pyramid.tiles_at(self.level);
        let root = u128::from(id.y >> shift) * u128::from(nx) + u128::from(id.x >> shift);
        let count = u128::from(nx) * u128::from(ny);
        // The largest part whose first root is at or before `root` (in u128, as in `roots`).
        let parts = u128::from(self.partitions);
        let mut part = (root * parts / count).min(parts - 1);
        while (part + 1) * count / parts <= root {
            part += 1;
        }
        while part * count / parts > root {
            part -= 1;
        }
        part as u32
    }

    /// The tiles of `root`'s subtree at `level` (≤ the split level), row-major.
    pub fn subtree_at(&self, root: TileId, level: u32) -> Vec<TileId> {
        let shift = root.level - level;
        let [nx, ny] = self.pyramid.tiles_at(level);
        let xs = (root.x << shift)..((root.x + 1) << shift).min(nx);
        let ys = (root.y << shift)..((root.y + 1) << shift).min(ny);
        ys.flat_map(|y| xs.clone().map(move |x| TileId::new(level, x, y))).collect()
    }

    /// The window of level `source_level` (0; the land cover's source is its level 1) that
    /// partition `part` reads from its source: the union of its subtrees' (`None`: no roots).
    pub fn input_window(&self, part: u32, source_level: u32) -> Option<Window> {
        let rects = self.roots(part).into_iter().map(|root| subtree::needed_rects(&self.pyramid, self, root));
        rects
            .map(|rects| rects[source_level as usize])
            .reduce(subtree::Rect::union)
            .map(subtree::Rect::window)
    }

    /// Every tile partition `part` writes, in the pyramid's global order.
    pub fn tiles(&self, part: u32) -> Vec<TileId> {
        let mut tiles: Vec<TileId> = self
            .roots(part)
            .into_iter()
            .flat_map(|root| (0..=self.level).flat_map(move |level| self.subtree_at(root, level)))
            .collect();
        tiles.sort_by_key(|&id| self.pyramid.tile_index(id));
        tiles
    }
}

/// Where a part pack keeps each of its tiles: their rank in the pyramid's global order.
pub struct PartSlots {
    globals: Vec<u64>,
}

impl PartSlots {
    /// The slots of `tiles` (as `Split::tiles` lists them) in `pyramid`.
    pub fn new(pyramid: &Pyramid, tiles: &[TileId]) -> Self {
        Self { globals: tiles.iter().map(|&id| pyramid.tile_index(id).unwrap_or(u64::MAX)).collect() }
    }

    /// Tiles in the part.
    pub fn len(&self) -> u64 {
        self.globals.len() as u64
    }

    /// Whether the part holds no tile.
    pub fn is_empty(&self) -> bool {
        self.globals.is_empty()
    }

    /// The slot of the tile whose global index is `global`, if the part holds it.
    pub fn slot(&self, global: u64) -> Option<u64> {
        self.globals.binary_search(&global).ok().map(|slot| slot as u64)
    }
}

#[cfg(test)]
mod tests;
