//! How it works: which tiles a view needs, and the caches that hold them on the GPU.
//!
//! The terrain selection says which height tiles the frame draws. For imagery, each drawn node asks
//! for the level whose texels match its pixels at its nearest point (a superset of what any of its
//! fragments asks, which look at it from further or more obliquely), and every ancestor of those
//! tiles up to the root, so a fragment always finds a resident tile on its way up. The list is
//! ordered coarse levels first, then nearest first: when the cache is too small, what is dropped
//! is the finest, farthest detail, and the view is blurry there, never holed.

pub mod cache;

pub use cache::{CacheStats, TileCache};

use std::collections::HashMap;

use crate::dataset::{Pyramid, TileId};

/// A rectangle of grid space wanting one cell layer at a given texel size.
#[derive(Debug, Clone, Copy)]
pub struct Footprint {
    /// Grid-space rectangle, metres relative to the layer's south-west corner.
    pub min_m: [f64; 2],
    pub max_m: [f64; 2],
    /// Metres one pixel covers there (at the rectangle's nearest point).
    pub pixel_m: f64,
    /// Distance from the camera, metres, for ordering.
    pub distance_m: f64,
}

/// The tiles of a cell layer (texel edge `texel_m` at level 0) that `footprints` want, with
/// their ancestors; coarse first, then near first. `lod_bias` is in log2 texels.
pub fn wanted_cell_tiles(
    pyramid: &Pyramid,
    texel_m: f64,
    lod_bias: f64,
    footprints: &[Footprint],
) -> Vec<TileId> {
    let top = pyramid.levels - 1;
    let mut nearest: HashMap<TileId, f64> = HashMap::new();
    let mut want = |id: TileId, distance_m: f64| {
        let d = nearest.entry(id).or_insert(f64::INFINITY);
        *d = d.min(distance_m);
    };
    for f in footprints {
        let wanted = (f.pixel_m / texel_m).max(1e-9).log2() + lod_bias;
        let level = (wanted.floor().max(0.0) as u32).min(top);
        let tile_m = texel_m * f64::from(pyramid.tile) * f64::from(1u32 << level);
        let tiles = pyramid.tiles_at(level);
        let range = |a: usize| {
            let lo = (f.min_m[a] / tile_m).floor().clamp(0.0, f64::from(tiles[a] - 1)) as u32;
            let hi = (f.max_m[a] / tile_m).floor().clamp(0.0, f64::from(tiles[a] - 1)) as u32;
            lo..=hi
        };
        for y in range(1) {
            for x in range(0) {
                let mut id = TileId::new(level, x, y);
                want(id, f.distance_m);
                while id.level < top {
                    id = TileId::new(id.level + 1, id.x / 2, id.y / 2);
                    want(id, f.distance_m);
                }
            }
        }
    }
    let mut tiles: Vec<(TileId, f64)> = nearest.into_iter().collect();
    tiles.sort_by(|(a, da), (b, db)| b.level.cmp(&a.level).then(da.total_cmp(db)).then(a.cmp(b)));
    tiles.into_iter().map(|(id, _)| id).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::Sampling;

    #[test]
    fn wanted_tiles_come_with_their_ancestors_coarse_first() {
        let pyramid = Pyramid::new([4096, 4096], 512, 8, Sampling::Cell);
        assert_eq!(pyramid.levels, 4);
        let near = Footprint { min_m: [0.0, 0.0], max_m: [100.0, 100.0], pixel_m: 1.0, distance_m: 10.0 };
        let far =
            Footprint { min_m: [3000.0, 3000.0], max_m: [3100.0, 3100.0], pixel_m: 4.0, distance_m: 900.0 };
        let tiles = wanted_cell_tiles(&pyramid, 1.0, 0.0, &[far, near]);
        assert_eq!(tiles[0], TileId::new(3, 0, 0));
        assert!(tiles.contains(&TileId::new(0, 0, 0)));
        assert!(tiles.contains(&TileId::new(2, 1, 1)) && !tiles.contains(&TileId::new(0, 5, 5)));
        assert!(tiles.windows(2).all(|w| w[0].level >= w[1].level));
        // A bias of +1 asks one level coarser.
        let coarser = wanted_cell_tiles(&pyramid, 1.0, 1.0, &[near]);
        assert!(!coarser.iter().any(|t| t.level == 0));
    }
}
