//! How it works: the CPU analysis of a Tile Load Map read back from the GPU (paper § 4.2). Each
//! visible cell names the imagery levels its pixels need (`tlod_min..=tlod_max`), the terrain LODs
//! it is drawn at, and for ring-0 cells a radial LOD and a seed pattern. From those cells come the
//! load maps: the ground (imagery) tiles, a prefetch of height tiles, the classification (land
//! cover) tiles the seeds will read near the camera, and the seed patterns in use. Each map is a
//! list most important first (coarse levels, then near), ready for `TileCache::set_wanted`; the
//! caches turn it into the push list (what is neither resident nor in flight).
//!
//! A TLM is read against the layout of the frame that computed it (the camera has moved since).

use glam::DVec3;

use crate::dataset::{Dataset, HEIGHT_TILE_CELLS, TileId};
use crate::gpu::gpu_types::TlmCell;
use crate::gpu::layout::{LevelRange, RADIAL_INACTIVE, tlm_pattern};
use crate::passes::seed_select::frame::SeedCellRef;
use crate::streaming::wants::{AreaWant, tiles_over};

use super::layout::TlmLayout;

/// The load maps of one TLM.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoadMaps {
    /// The frame whose TLM this is.
    pub frame: u64,
    /// Ground (imagery) tiles, most important first: the GLM.
    pub ground: Vec<TileId>,
    /// Height tiles the cells' terrain LODs read: prefetch behind the terrain selection's own list.
    pub heights: Vec<TileId>,
    /// Land-cover tiles for seeds near the camera (level = radial LOD): the CLM.
    pub classification: Vec<TileId>,
    /// Seed patterns in use and how many cells use each, by pattern index: the PLM.
    pub patterns: Vec<(u32, u32)>,
    /// The ring-0 cells whose seeds pass 3 checks, in TLM order.
    pub seed_cells: Vec<SeedCellRef>,
    /// Cells of any ring the TLM found visible.
    pub visible_cells: usize,
}

/// The load maps of `cells`, computed by frame `frame` with `layout`, for a camera that was at
/// `camera_grid_m` then.
pub fn analyse(
    frame: u64,
    layout: &TlmLayout,
    cells: &[TlmCell],
    camera_grid_m: DVec3,
    dataset: &Dataset,
) -> LoadMaps {
    let manifest = &dataset.manifest;
    // Cell layers start half a height spacing south-west of grid space's origin.
    let half_spacing = 0.5 * manifest.height.spacing_m;
    let mut ground = Vec::new();
    let mut heights = Vec::new();
    let mut classification = Vec::new();
    let mut patterns = std::collections::BTreeMap::<u32, u32>::new();
    let mut seed_cells = Vec::new();
    let mut visible_cells = 0;
    for (index, cell) in cells.iter().enumerate().take(layout.cell_count()) {
        let Some(pattern) = tlm_pattern(cell.visibility) else { continue };
        visible_cells += 1;
        let (ring, cx, cy) = layout.cell_of(index);
        let (min_m, max_m) = layout.cell_rect_m(ring, cx, cy);
        let nearest = [camera_grid_m.x.clamp(min_m[0], max_m[0]), camera_grid_m.y.clamp(min_m[1], max_m[1])];
        let distance_m = (nearest[0] - camera_grid_m.x).hypot(nearest[1] - camera_grid_m.y);
        let in_cell_layer = |levels| AreaWant {
            min_m: min_m.map(|v| v + half_spacing),
            max_m: max_m.map(|v| v + half_spacing),
            levels,
            distance_m,
        };
        let lods = |packed: u32| {
            let LevelRange { min, max } = LevelRange::unpack(packed);
            [min, max]
        };
        if dataset.imagery.is_some() {
            ground.push(in_cell_layer(lods(cell.imagery_lod)));
        }
        heights.push(AreaWant { min_m, max_m, levels: lods(cell.height_lod), distance_m });
        if ring == 0 && cell.radial_lod < RADIAL_INACTIVE {
            classification.push(in_cell_layer([cell.radial_lod; 2]));
            // Seeds stand on the finest heights, whatever the mesh draws there.
            heights.push(AreaWant { min_m, max_m, levels: [0, 0], distance_m });
            *patterns.entry(pattern).or_default() += 1;
            let address = layout.global_address(0, cx, cy);
            seed_cells.push(SeedCellRef {
                address: [address.x, address.y],
                pattern,
                radial_lod: cell.radial_lod,
            });
        }
    }
    let height_tile_m = f64::from(HEIGHT_TILE_CELLS) * manifest.height.spacing_m;
    LoadMaps {
        frame,
        ground: match (&dataset.imagery, &manifest.imagery) {
            (Some(layer), Some(meta)) => {
                tiles_over(&layer.pyramid, cell_tile_m(layer.pyramid.tile, meta.texel_m), &ground)
            }
            _ => Vec::new(),
        },
        heights: tiles_over(&dataset.height.pyramid, height_tile_m, &heights),
        classification: match (&dataset.landcover, &manifest.landcover) {
            (Some(layer), Some(meta)) => tiles_over(
                &layer.pyramid,
                cell_tile_m(layer.pyramid.tile, meta.layer.texel_m),
                &classification,
            ),
            _ => Vec::new(),
        },
        patterns: patterns.into_iter().collect(),
        seed_cells,
        visible_cells,
    }
}

fn cell_tile_m(tile_texels: u32, texel_m: f64) -> f64 {
    f64::from(tile_texels) * texel_m
}
