//! How it works: where the land cover holds a class drawn as texcells, so that a patch over fields,
//! water or town is not drawn at all. Its fragments would each look up the four level-1 texels
//! around them (`forest_at` in `shaders/texcells.wgsl`), find no forest class and leave the pixel
//! unchanged, but only after being rasterised and shaded, every slice of them. Each level-1
//! land-cover tile is read once, on first use, into a grid of `CELL_TEXELS`-wide cells, each
//! flagging whether any of its texels is a class with a forest sample. A patch is drawn when any
//! cell within one texel of its footprint (the bilinear lookup's reach) is flagged, so a patch is
//! left out only where none of its fragments could find forest, and the frame is unchanged.
//! A tile that cannot be read counts as forest everywhere.

use std::collections::HashMap;

use crate::dataset::{Dataset, TileId};
use crate::gpu::layout::LCC_SOURCE_LEVEL;

/// Level-1 texels along a cell's side.
const CELL_TEXELS: u32 = 16;

/// Which parts of a dataset's level-1 land cover hold a class with a forest sample.
pub struct DenseCover {
    /// By palette index (0: no class): whether that class is drawn as texcells.
    dense: Vec<bool>,
    /// Level-1 texel size and the offset of the texel grid's origin, metres (grid space).
    texel_m: f64,
    origin_m: f64,
    /// Level-1 size in texels, and texels along a tile's side.
    size: [u32; 2],
    tile: u32,
    /// Words along a stored tile's row (its texels and border).
    extent: u32,
    /// Per tile read so far, its cells' flags, row by row.
    tiles: HashMap<TileId, Vec<bool>>,
}

impl DenseCover {
    /// The cover of `dataset`'s land cover for the classes `sample_of_class` gives a sample (by
    /// palette index, 0: none); `None` without land cover.
    pub fn new(dataset: &Dataset, sample_of_class: &[u32]) -> Option<Self> {
        let (layer, meta) = (dataset.landcover.as_ref()?, dataset.manifest.landcover.as_ref()?);
        Some(Self {
            dense: sample_of_class.iter().map(|&s| s != 0).collect(),
            // As the shader's `lcc_frame` (`texcell_uniforms`): level-1 texels are twice level
            // 0's, their grid starting half a height cell west and south of grid space's origin.
            texel_m: 2.0 * meta.layer.texel_m,
            origin_m: -0.5 * dataset.manifest.height.spacing_m,
            size: layer.pyramid.size_at(LCC_SOURCE_LEVEL),
            tile: layer.pyramid.tile,
            extent: layer.pyramid.tile_extent(),
            tiles: HashMap::new(),
        })
    }

    /// Whether a fragment anywhere over the ground rectangle `[min_m, max_m]` (grid space, x and y)
    /// may find a class with a forest sample: false only when no level-1 texel within one of the
    /// rectangle holds one.
    pub fn any_dense(&mut self, dataset: &Dataset, min_m: [f64; 2], max_m: [f64; 2]) -> bool {
        // The lookup reads texels floor(t − 0.5) and the next, t in texels from the grid's origin.
        let texel = |m: f64, a: usize, offset: f64| {
            let t = ((m - self.origin_m) / self.texel_m + offset).floor();
            t.clamp(0.0, f64::from(self.size[a] - 1)) as u32
        };
        let lo = [texel(min_m[0], 0, -1.5), texel(min_m[1], 1, -1.5)];
        let hi = [texel(max_m[0], 0, 1.5), texel(max_m[1], 1, 1.5)];
        let (tile, per_tile) = (self.tile, self.tile.div_ceil(CELL_TEXELS));
        for ty in lo[1] / tile..=hi[1] / tile {
            for tx in lo[0] / tile..=hi[0] / tile {
                let id = TileId::new(LCC_SOURCE_LEVEL, tx, ty);
                let cells = self.tiles.entry(id).or_insert_with(|| {
                    summarise(dataset, id, &self.dense, self.size, [tile, self.extent]).unwrap_or_default()
                });
                // An empty summary is a tile that could not be read: forest, to be safe.
                if cells.is_empty() {
                    return true;
                }
                // The tile's cells the texels [lo, hi] fall in.
                let local = |q: u32, t: u32| q.clamp(t * tile, t * tile + tile - 1) - t * tile;
                let (x0, x1) = (local(lo[0], tx) / CELL_TEXELS, local(hi[0], tx) / CELL_TEXELS);
                let (y0, y1) = (local(lo[1], ty) / CELL_TEXELS, local(hi[1], ty) / CELL_TEXELS);
                if (y0..=y1).any(|y| (x0..=x1).any(|x| cells[(y * per_tile + x) as usize])) {
                    return true;
                }
            }
        }
        false
    }
}

/// Tile `id`'s cells (`CELL_TEXELS` level-1 texels wide, row by row): whether any texel of each,
/// within the layer's `size`, is a `dense` palette index; `None` when the tile cannot be read.
/// Tiles hold `tile` texels a side, stored `extent` words a row.
fn summarise(
    dataset: &Dataset,
    id: TileId,
    dense: &[bool],
    size: [u32; 2],
    [tile, extent]: [u32; 2],
) -> Option<Vec<bool>> {
    let words = dataset.landcover_words(id).ok()?;
    let per_tile = tile.div_ceil(CELL_TEXELS);
    let mut cells = vec![false; (per_tile * per_tile) as usize];
    let first = [id.x * tile, id.y * tile];
    for ly in 0..tile.min(size[1].saturating_sub(first[1])) {
        for lx in 0..tile.min(size[0].saturating_sub(first[0])) {
            let word = *words.get((ly * extent + lx) as usize)?;
            if dense.get(word as usize).copied().unwrap_or(false) {
                cells[((ly / CELL_TEXELS) * per_tile + lx / CELL_TEXELS) as usize] = true;
            }
        }
    }
    Some(cells)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

    use super::*;
    use crate::seeds::pcg;
    use crate::synth::{SynthParams, synthesize};

    /// Over random rectangles of a synthetic dataset, `any_dense` says "no forest" only where no
    /// level-1 texel within one texel of the rectangle is a dense class, read texel by texel.
    #[test]
    fn a_rectangle_is_bare_only_where_no_texel_near_it_is_dense() {
        let dir = std::env::temp_dir().join(format!("terramp-dense-cover-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        synthesize(&dir, &SynthParams { size: 600, seed: 5, ..Default::default() }, false).unwrap();
        let dataset = Dataset::open(&dir).unwrap();
        let palette = dataset.lcc_coding().unwrap().palette.len();
        let size = dataset.landcover.as_ref().unwrap().pyramid.size_at(LCC_SOURCE_LEVEL);
        let index = |q: [u32; 2]| dataset.landcover_index(LCC_SOURCE_LEVEL, q).unwrap() as usize;
        let grid: Vec<usize> =
            (0..size[1]).flat_map(|y| (0..size[0]).map(move |x| [x, y])).map(index).collect();
        // The class of the texel at the middle, alone, is drawn as texcells.
        let middle = grid[(size[1] / 2 * size[0] + size[0] / 2) as usize];
        let mut sample_of_class = vec![0u32; palette + 1];
        sample_of_class[middle] = 1;
        let mut cover = DenseCover::new(&dataset, &sample_of_class).unwrap();
        let (texel_m, origin_m) = (cover.texel_m, cover.origin_m);
        let mut state = pcg(11);
        let mut unit = move || {
            state = pcg(state);
            f64::from(state >> 8) / f64::from(1u32 << 24)
        };
        let extent_m = [0, 1].map(|a| f64::from(size[a]) * texel_m);
        let (mut bare, mut dense) = (0, 0);
        for _ in 0..400 {
            let min_m = [0, 1].map(|a| unit() * extent_m[a] + origin_m);
            let side_m = unit() * 8.0 * texel_m;
            let max_m = min_m.map(|v| v + side_m);
            if cover.any_dense(&dataset, min_m, max_m) {
                dense += 1;
                continue;
            }
            bare += 1;
            // Every texel a fragment over the rectangle could read: floor(t − 0.5) and the next.
            let range = |a: usize| {
                let t = |m: f64| (m - origin_m) / texel_m - 0.5;
                let clamp = |v: f64| v.clamp(0.0, f64::from(size[a] - 1)) as u32;
                clamp(t(min_m[a]).floor())..=clamp(t(max_m[a]).floor() + 1.0)
            };
            for y in range(1) {
                for x in range(0) {
                    let class = grid[(y * size[0] + x) as usize];
                    assert_ne!(class, middle, "texel [{x}, {y}] is dense, near bare {min_m:?}..{max_m:?}");
                }
            }
        }
        println!("{bare} bare and {dense} dense rectangles");
        assert!(bare > 20 && dense > 20, "{bare} bare, {dense} dense: a weak test");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
