//! How it works: the geometry of one layer's tile quadtree, shared by the builder, the readers
//! and (later) the streaming caches.
//!
//! A layer is a raster on the dataset's *grid space*: x grows east, y grows north, and level 0 is
//! the finest. Level `l` has `ceil(size / 2^l)` texels per axis (for vertex-centred heights,
//! `ceil((size - 1) / 2^l) + 1` samples), cut into tiles of `tile` steps. Each stored tile carries
//! a border of `border` texels on every side, copied from its neighbours (or the replicated edge),
//! so filtering and normals never need a second tile. Levels stop when one tile covers the layer.
//! Tiles are numbered level by level, row by row, which gives every tile an O(1) index.

use serde::{Deserialize, Serialize};

/// The largest stored tile a pyramid read from a file may have, texels a side, border included:
/// the largest 2D texture wgpu's default limits allow (`max_texture_dimension_2d`). Its bytes,
/// 16 a texel at most, stay within u32 (2^30), so no size computed from it overflows.
pub const MAX_TILE_EXTENT: u32 = 8192;

/// Where a layer's values sit on its grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Samples at grid vertices (heights): neighbouring tiles share their edge samples, so a tile
    /// of `tile` cells stores `tile + 1` samples per axis before the border.
    Vertex,
    /// Texels are cell areas (imagery, land cover): a tile stores `tile` texels before the border.
    Cell,
}

/// A tile address in a layer's quadtree.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct TileId {
    /// Quadtree level, 0 the finest.
    pub level: u32,
    /// Tile column at its level, counted east from the west edge.
    pub x: u32,
    /// Tile row at its level, counted north from the south edge.
    pub y: u32,
}

impl TileId {
    /// Tile (`x`, `y`) of `level`; `const`, so tiles can be named in constants.
    pub const fn new(level: u32, x: u32, y: u32) -> Self {
        Self { level, x, y }
    }

    /// The tile one level coarser that covers this one.
    pub fn parent(self) -> Option<TileId> {
        Some(TileId::new(self.level + 1, self.x / 2, self.y / 2))
    }
}

/// The tile quadtree of one layer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Pyramid {
    /// Texels (or samples) per axis at level 0.
    pub size: [u32; 2],
    /// Grid steps per tile side (cells for `Vertex`, texels for `Cell`).
    pub tile: u32,
    /// Texels copied from the neighbours on each side of a stored tile.
    pub border: u32,
    /// Whether values sit at grid vertices (heights) or cover cells (imagery, land cover).
    pub sampling: Sampling,
    /// Levels stored, level 0 the finest; the last one is a single tile.
    pub levels: u32,
}

impl Pyramid {
    /// A pyramid deep enough for its coarsest level to be one tile.
    pub fn new(size: [u32; 2], tile: u32, border: u32, sampling: Sampling) -> Self {
        let mut pyramid = Self { size, tile, border, sampling, levels: 1 };
        while pyramid.tiles_at(pyramid.levels - 1) != [1, 1] {
            pyramid.levels += 1;
        }
        pyramid
    }

    /// Texels (samples) per axis at `level`.
    pub fn size_at(&self, level: u32) -> [u32; 2] {
        // In u64: a 2^32-texel layer in 1-texel tiles reaches level 32, whose 2^32 passes u32.
        let halvings = 1u64 << level.min(63);
        self.size.map(|n| {
            let n = u64::from(n.max(1));
            let at_level = match self.sampling {
                Sampling::Vertex => (n - 1).div_ceil(halvings) + 1,
                Sampling::Cell => n.div_ceil(halvings),
            };
            at_level as u32
        })
    }

    /// Grid steps (cells or texels) per axis at `level`: what tiles have to cover.
    fn steps_at(&self, level: u32) -> [u32; 2] {
        self.size_at(level).map(|n| match self.sampling {
            Sampling::Vertex => n - 1,
            Sampling::Cell => n,
        })
    }

    /// Tiles per axis at `level`, at least one, the last ones partial at the east and north edges.
    pub fn tiles_at(&self, level: u32) -> [u32; 2] {
        self.steps_at(level).map(|n| n.div_ceil(self.tile).max(1))
    }

    /// Texels per side of a stored tile at mip 0, border included.
    pub fn tile_extent(&self) -> u32 {
        let shared_edge = u32::from(self.sampling == Sampling::Vertex);
        self.tile + shared_edge + 2 * self.border
    }

    /// Texels per side of mip `mip` of a stored tile (the border halves with each mip).
    pub fn mip_extent(&self, mip: u32) -> u32 {
        self.tile_extent() >> mip
    }

    /// Tiles of all levels together: the tile count of the layer's pack.
    pub fn tile_count(&self) -> u64 {
        (0..self.levels).map(|l| self.level_tile_count(l)).sum()
    }

    fn level_tile_count(&self, level: u32) -> u64 {
        let [nx, ny] = self.tiles_at(level);
        u64::from(nx) * u64::from(ny)
    }

    /// The tile's position in the pack, or `None` outside the pyramid.
    pub fn tile_index(&self, id: TileId) -> Option<u64> {
        if id.level >= self.levels {
            return None;
        }
        let [nx, ny] = self.tiles_at(id.level);
        if id.x >= nx || id.y >= ny {
            return None;
        }
        let before: u64 = (0..id.level).map(|l| self.level_tile_count(l)).sum();
        Some(before + u64::from(id.y) * u64::from(nx) + u64::from(id.x))
    }

    /// Every tile of the pyramid in pack order: level by level, south row first, west to east.
    pub fn tiles(&self) -> impl Iterator<Item = TileId> + '_ {
        (0..self.levels).flat_map(move |level| {
            let [nx, ny] = self.tiles_at(level);
            (0..ny).flat_map(move |y| (0..nx).map(move |x| TileId::new(level, x, y)))
        })
    }

    /// Checks the tile of a pyramid read from a file (a manifest): at least one step, and stored
    /// tiles of at most `MAX_TILE_EXTENT` texels a side, so that no size computed from them passes
    /// u32. The error names the field and says why, its value first.
    pub fn check_tiles(&self) -> Result<(), (&'static str, String)> {
        let (tile, border) = (self.tile, self.border);
        if tile == 0 {
            return Err(("tile", "0: a tile is at least 1 step".into()));
        }
        let shared_edge = u64::from(self.sampling == Sampling::Vertex);
        let extent = u64::from(tile) + shared_edge + 2 * u64::from(border);
        if extent > u64::from(MAX_TILE_EXTENT) {
            let (field, value) = if tile >= MAX_TILE_EXTENT { ("tile", tile) } else { ("border", border) };
            let reason = format!(
                "{value}: tiles of {tile} with a border of {border} are stored {extent} texels a side, over {MAX_TILE_EXTENT}"
            );
            return Err((field, reason));
        }
        Ok(())
    }

    /// Level-`level` grid coordinate of the first stored texel (border included) of tile `id`.
    pub fn tile_origin(&self, id: TileId) -> [i64; 2] {
        [id.x, id.y].map(|t| i64::from(t) * i64::from(self.tile) - i64::from(self.border))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertex_pyramid_of_nc_dem() {
        let p = Pyramid::new([500, 450], 256, 1, Sampling::Vertex);
        assert_eq!(p.levels, 2);
        assert_eq!(p.tiles_at(0), [2, 2]);
        assert_eq!(p.size_at(1), [251, 226]);
        assert_eq!(p.tiles_at(1), [1, 1]);
        assert_eq!(p.tile_extent(), 259);
        assert_eq!(p.tile_count(), 5);
        assert_eq!(p.tile_index(TileId::new(1, 0, 0)), Some(4));
        assert_eq!(p.tile_index(TileId::new(0, 1, 1)), Some(3));
        assert_eq!(p.tile_index(TileId::new(0, 2, 0)), None);
        assert_eq!(p.tiles().count() as u64, p.tile_count());
    }

    #[test]
    fn exact_multiple_of_tile_needs_no_extra_tile() {
        let p = Pyramid::new([257, 257], 256, 1, Sampling::Vertex);
        assert_eq!(p.levels, 1);
        let c = Pyramid::new([1024, 512], 512, 8, Sampling::Cell);
        assert_eq!(c.tiles_at(0), [2, 1]);
        assert_eq!(c.levels, 2);
        assert_eq!(c.mip_extent(3), 66);
    }

    #[test]
    fn a_single_texel_is_one_tile() {
        let p = Pyramid::new([1, 1], 512, 8, Sampling::Cell);
        assert_eq!((p.levels, p.tiles_at(0)), (1, [1, 1]));
        let v = Pyramid::new([1, 1], 256, 1, Sampling::Vertex);
        assert_eq!((v.levels, v.tiles_at(0)), (1, [1, 1]));
    }

    #[test]
    fn indices_are_dense_and_unique() {
        let p = Pyramid::new([3000, 1700], 256, 1, Sampling::Vertex);
        for (i, id) in p.tiles().enumerate() {
            assert_eq!(p.tile_index(id), Some(i as u64));
        }
    }
}
