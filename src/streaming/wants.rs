//! How it works: the wanted lists of a frame, most important first. Heights: the tiles the
//! selected terrain nodes read. Imagery: per node, the level whose texels match its pixels at its
//! nearest point, with every ancestor up to the root. Both lists start with the *pinned* tiles,
//! the coarsest levels of each layer, loaded before the first frame and never evicted, so every
//! place of the dataset always has some resident ancestor to stand in.

use std::collections::HashMap;

use glam::DVec3;

use crate::camera::Camera;
use crate::dataset::{Dataset, Pyramid, TileId};
use crate::terrain::select::{Lods, Selected};

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
pub fn after_pinned(pinned: &[TileId], wants: Vec<TileId>) -> Vec<TileId> {
    let mut list = pinned.to_vec();
    list.extend(wants.into_iter().filter(|id| !pinned.contains(id)));
    list
}

/// The height tiles the selected nodes read, coarse first (they stand in for everything finer).
pub fn height_tiles(lods: &Lods, selected: &[Selected]) -> Vec<TileId> {
    let mut tiles: Vec<TileId> = selected.iter().map(|s| lods.tile_of(s.node)).collect();
    tiles.sort_by(|a, b| b.level.cmp(&a.level).then(a.cmp(b)));
    tiles.dedup();
    tiles
}

/// The imagery tiles the selected nodes' pixels ask for.
pub fn imagery_tiles(
    dataset: &Dataset,
    lods: &Lods,
    selected: &[Selected],
    camera: &Camera,
    camera_grid_m: DVec3,
    height_px: u32,
    lod_bias: f64,
) -> Vec<TileId> {
    let (Some(layer), Some(meta)) = (&dataset.imagery, &dataset.manifest.imagery) else {
        return Vec::new();
    };
    let half_spacing = 0.5 * dataset.manifest.height.spacing_m;
    let [low_m, high_m] = [dataset.manifest.height.min_m, dataset.manifest.height.max_m].map(f64::from);
    let footprints: Vec<Footprint> = selected
        .iter()
        .map(|s| {
            let size = lods.node_m(s.node.lod);
            let min = [f64::from(s.node.x) * size, f64::from(s.node.y) * size];
            let max = [min[0] + size, min[1] + size];
            let nearest = DVec3::new(
                camera_grid_m.x.clamp(min[0], max[0]),
                camera_grid_m.y.clamp(min[1], max[1]),
                camera_grid_m.z.clamp(low_m, high_m),
            );
            let distance_m = (nearest - camera_grid_m).length().max(camera.near_m);
            Footprint {
                min_m: min.map(|v| v + half_spacing),
                max_m: max.map(|v| v + half_spacing),
                pixel_m: camera.metres_per_pixel(distance_m, height_px),
                distance_m,
            }
        })
        .collect();
    wanted_cell_tiles(&layer.pyramid, meta.texel_m, lod_bias, &footprints)
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
        assert_eq!(after_pinned(&pinned[..1], wants), vec![TileId::new(3, 0, 0), TileId::new(0, 1, 1)]);
    }

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
