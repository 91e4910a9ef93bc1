//! How it works: what each pixel of a settled view stands on. The terrain's own depth (reversed-Z,
//! 0 for the sky; `Renderer::terrain_depth`, the terrain pass alone, so a tree's pixel is keyed by
//! the ground behind it, the ground the photograph shows there) is unprojected through the inverse
//! of the camera's clip-from-camera-relative-world matrix (in f64) at each pixel's centre, then
//! moved into grid space (the camera's CRS position less the dataset's origin). The imagery's
//! level-0 texel there is `floor((p + ½ height spacing) / texel_m)`, as the ground truth's seeds
//! find it (`truth::scene`): cell layers cover the DEM's pixel-area extent, half a spacing beyond
//! grid space. The pixel is wooded when the land cover's class there (its source level, which
//! the exact oracle classifies seeds by; every level agrees) grows trees in the renderer's class
//! table (a rule of a tree species, or texcells): the forest the photograph is compared over, not
//! the fields whose bushes and stones are too small to show from above.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::sync::Arc;

use glam::{DVec3, DVec4};

use super::PhotoError;
use super::measure::{NO_TEXEL, PixelKeys, texel_key};
use crate::camera::Camera;
use crate::classes::{ClassTable, SpeciesKind};
use crate::dataset::lcc::{LCC_BARE_INDEX, LCC_SOURCE_LEVEL};
use crate::dataset::{Dataset, TileId, imagery_texel_at};
use crate::frame::Renderer;

/// The keys of the view `renderer` last settled from `camera` (its terrain depth read back).
pub fn pixel_keys(renderer: &Renderer, camera: &Camera) -> Result<PixelKeys, PhotoError> {
    let depth = renderer.terrain_depth()?;
    let r = &renderer.settings.render;
    keys_of_depth(&renderer.dataset, renderer.class_table(), camera, [r.width, r.height], &depth)
}

/// The keys of a view `size_px` from `camera` whose terrain depth is `depth` (top row first).
pub fn keys_of_depth(
    dataset: &Dataset,
    table: Option<&ClassTable>,
    camera: &Camera,
    size_px: [u32; 2],
    depth: &[f32],
) -> Result<PixelKeys, PhotoError> {
    let [w, h] = size_px;
    let world_from_clip = (camera.clip_from_view(w, h)? * camera.view_from_world()).inverse();
    let manifest = &dataset.manifest;
    let eye_grid_m = camera.position_m - DVec3::new(manifest.origin_m[0], manifest.origin_m[1], 0.0);
    let half_spacing_m = 0.5 * manifest.height.spacing_m;
    let imagery = match (&manifest.imagery, &dataset.imagery) {
        (Some(meta), Some(layer)) => Some((meta.texel_m, layer.pyramid.size)),
        _ => None,
    };
    let mut landcover = Landcover::new(dataset, table);
    let mut coverage = Coverage { dataset, tiles: HashMap::new() };
    let pixels = (w as usize) * (h as usize);
    let mut keys = PixelKeys { size_px, texel: vec![NO_TEXEL; pixels], wooded: vec![false; pixels] };
    for (i, &d) in depth.iter().enumerate().take(pixels) {
        if d <= 0.0 {
            continue;
        }
        let (x, y) = ((i % w as usize) as f64, (i / w as usize) as f64);
        let ndc = DVec4::new(
            2.0 * (x + 0.5) / f64::from(w) - 1.0,
            1.0 - 2.0 * (y + 0.5) / f64::from(h),
            f64::from(d),
            1.0,
        );
        let rel = world_from_clip * ndc;
        let p = eye_grid_m + rel.truncate() / rel.w;
        if let Some((texel_m, size)) = imagery {
            let t = [p.x, p.y].map(|v| ((v + half_spacing_m) / texel_m).floor());
            if t[0] >= 0.0 && t[1] >= 0.0 && t[0] < f64::from(size[0]) && t[1] < f64::from(size[1]) {
                let t = [t[0] as u32, t[1] as u32];
                // Where the imagery has no data there is no photograph to compare with.
                if !coverage.has_data(t)? {
                    continue;
                }
                keys.texel[i] = texel_key(t);
            }
        }
        keys.wooded[i] = landcover.wooded([p.x, p.y], half_spacing_m)?;
    }
    Ok(keys)
}

/// Whether the imagery has data at a level-0 texel (its alpha above 0), read tile by tile.
struct Coverage<'a> {
    dataset: &'a Dataset,
    tiles: HashMap<[u32; 2], Arc<[u8]>>,
}

impl Coverage<'_> {
    fn has_data(&mut self, t: [u32; 2]) -> Result<bool, PhotoError> {
        let Some(layer) = &self.dataset.imagery else { return Ok(false) };
        let (tile, index) = imagery_texel_at(t);
        let texels = match self.tiles.entry([tile.x, tile.y]) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => e.insert(layer.tile_texels(tile)?),
        };
        Ok(texels.get(4 * index + 3).is_some_and(|&a| a > 0))
    }
}

/// The land cover's source level, read tile by tile as pixels need it.
struct Landcover<'a> {
    dataset: &'a Dataset,
    /// Per palette index (0: bare), whether its class grows trees; empty without land cover.
    grows: Vec<bool>,
    /// Source texel edge, metres, the level's size and tile edge, and its tile extent.
    grid: Option<(f64, [u32; 2], u32, u32)>,
    tiles: HashMap<[u32; 2], Vec<u32>>,
}

impl<'a> Landcover<'a> {
    fn new(dataset: &'a Dataset, table: Option<&ClassTable>) -> Self {
        let (Some(layer), Some(meta), Some(table)) = (&dataset.landcover, &dataset.manifest.landcover, table)
        else {
            return Self { dataset, grows: Vec::new(), grid: None, tiles: HashMap::new() };
        };
        let is_tree =
            |name: &str| table.species.iter().any(|s| s.name == name && s.kind == SpeciesKind::Tree);
        let grows_code = |code: u8| {
            table.class(code).is_some_and(|c| c.texcells || c.seeds.iter().any(|r| is_tree(&r.species)))
        };
        let grows =
            std::iter::once(false).chain(meta.coding.palette.iter().map(|&c| grows_code(c))).collect();
        let p = &layer.pyramid;
        // Level 1 is the source: its texels are twice level 0's (`LandcoverLayer`).
        let grid = Some((2.0 * meta.layer.texel_m, p.size_at(LCC_SOURCE_LEVEL), p.tile, p.tile_extent()));
        Self { dataset, grows, grid, tiles: HashMap::new() }
    }

    /// Whether the class at grid point `p` grows trees (never outside the layer).
    fn wooded(&mut self, p: [f64; 2], half_spacing_m: f64) -> Result<bool, PhotoError> {
        let Some((texel_m, size, tile, extent)) = self.grid else { return Ok(false) };
        let q = p.map(|v| ((v + half_spacing_m) / texel_m).floor());
        if q[0] < 0.0 || q[1] < 0.0 || q[0] >= f64::from(size[0]) || q[1] >= f64::from(size[1]) {
            return Ok(false);
        }
        let q = q.map(|v| v as u32);
        let t = q.map(|v| v / tile);
        let words = match self.tiles.entry(t) {
            Entry::Occupied(e) => e.into_mut(),
            Entry::Vacant(e) => {
                e.insert(self.dataset.landcover_words(TileId::new(LCC_SOURCE_LEVEL, t[0], t[1]))?)
            }
        };
        let local = q.map(|v| v % tile);
        // At the source level a word is a palette index (`LccCoding::decode`).
        let index = words.get((local[1] * extent + local[0]) as usize).copied().unwrap_or(LCC_BARE_INDEX);
        Ok(self.grows.get(index as usize).copied().unwrap_or(false))
    }
}
