//! How it works: the wanted lists of a frame, most important first. Heights: the tiles the
//! selected terrain nodes read (`passes::terrain`). Other layers: the tiles the Tile Load Map's
//! cells ask for (`passes::tile_load_map`'s analysis, through `tiles_over`), each with every
//! ancestor up to the root. Every list starts with the *pinned* tiles,
//! the coarsest levels of each layer, loaded before the first frame and never evicted, so every
//! place of the dataset always has some resident ancestor to stand in.

use std::collections::HashMap;

use crate::dataset::{Pyramid, TileId};

/// A rectangle of a layer wanting the levels `levels` (inclusive), from `distance_m` away.
#[derive(Debug, Clone, Copy)]
pub struct AreaWant {
    /// Rectangle in the layer's own frame: metres east/north of its texel (0, 0) corner.
    pub min_m: [f64; 2],
    /// The rectangle's north-east corner, in the same frame, metres (`min_m` is its south-west).
    pub max_m: [f64; 2],
    /// Finest and coarsest level wanted.
    pub levels: [u32; 2],
    /// Distance from the camera, metres, for ordering.
    pub distance_m: f64,
}

/// The tiles of a layer (`tile_edge_m`: a level-0 tile's edge) that `wants` ask for, with every
/// ancestor up to the root; coarse levels first, then nearest first.
pub fn tiles_over(pyramid: &Pyramid, tile_edge_m: f64, wants: &[AreaWant]) -> Vec<TileId> {
    let top = pyramid.levels - 1;
    let mut nearest: HashMap<TileId, f64> = HashMap::new();
    let mut want = |id: TileId, distance_m: f64| {
        let d = nearest.entry(id).or_insert(f64::INFINITY);
        *d = d.min(distance_m);
    };
    for w in wants {
        let [finest, coarsest] = w.levels.map(|l| l.min(top));
        for level in finest..=coarsest.max(finest) {
            let tile_m = tile_edge_m * f64::from(1u32 << level);
            let tiles = pyramid.tiles_at(level);
            let range = |a: usize| {
                let index = |v: f64| (v / tile_m).floor().clamp(0.0, f64::from(tiles[a] - 1)) as u32;
                index(w.min_m[a])..=index(w.max_m[a])
            };
            for y in range(1) {
                for x in range(0) {
                    let mut id = TileId::new(level, x, y);
                    want(id, w.distance_m);
                    while id.level < top {
                        id = TileId::new(id.level + 1, id.x / 2, id.y / 2);
                        want(id, w.distance_m);
                    }
                }
            }
        }
    }
    let mut tiles: Vec<(TileId, f64)> = nearest.into_iter().collect();
    tiles.sort_by(|(a, da), (b, db)| b.level.cmp(&a.level).then(da.total_cmp(db)).then(a.cmp(b)));
    tiles.into_iter().map(|(id, _)| id).collect()
}

/// The coarsest levels of `pyramid`, whole, as long as they total at most `max_tiles` (the top
/// level always, even alone above the limit), coarsest first.
pub fn pinned_tiles(pyramid: &Pyramid, max_tiles: usize) -> Vec<TileId> {
    let mut tiles = Vec::new();
    for level in (0..pyramid.levels).rev() {
        let [nx, ny] = pyramid.tiles_at(level);
        if !tiles.is_empty() && tiles.len() + (nx * ny) as usize > max_tiles {
            break;
        }
        tiles.extend((0..ny).flat_map(|y| (0..nx).map(move |x| TileId::new(level, x, y))));
    }
    tiles
}

/// `pinned` then `wants` without the pinned ones: the order a cache is asked in.
pub fn after_pinned(pinned: &[TileId], wants: &[TileId]) -> Vec<TileId> {
    let mut list = pinned.to_vec();
    list.extend(wants.iter().filter(|id| !pinned.contains(id)));
    list
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::Sampling;

    #[test]
    fn pinned_tiles_are_the_coarsest_whole_levels() {
        let pyramid = Pyramid::new([4096, 4096], 512, 8, Sampling::Cell);
        let pinned = pinned_tiles(&pyramid, 21);
        assert_eq!(pinned.len(), 1 + 4 + 16);
        assert_eq!(pinned[0], TileId::new(3, 0, 0));
        assert_eq!(pinned_tiles(&pyramid, 0), vec![TileId::new(3, 0, 0)]);
        let wants = vec![TileId::new(0, 1, 1), TileId::new(3, 0, 0)];
        assert_eq!(after_pinned(&pinned[..1], &wants), vec![TileId::new(3, 0, 0), TileId::new(0, 1, 1)]);
    }

    #[test]
    fn wanted_tiles_come_with_their_ancestors_coarse_first() {
        let pyramid = Pyramid::new([4096, 4096], 512, 8, Sampling::Cell);
        assert_eq!(pyramid.levels, 4);
        let near = AreaWant { min_m: [0.0, 0.0], max_m: [100.0, 100.0], levels: [0, 0], distance_m: 10.0 };
        let far =
            AreaWant { min_m: [3000.0, 3000.0], max_m: [3100.0, 3100.0], levels: [2, 3], distance_m: 900.0 };
        let tiles = tiles_over(&pyramid, 512.0, &[far, near]);
        assert_eq!(tiles[0], TileId::new(3, 0, 0));
        assert!(tiles.contains(&TileId::new(0, 0, 0)));
        assert!(tiles.contains(&TileId::new(2, 1, 1)) && !tiles.contains(&TileId::new(0, 5, 5)));
        assert!(tiles.windows(2).all(|w| w[0].level >= w[1].level));
        // Within a level, nearer first.
        let level1: Vec<_> = tiles.iter().filter(|t| t.level == 1).collect();
        assert_eq!(level1[0], &TileId::new(1, 0, 0));
    }
}
