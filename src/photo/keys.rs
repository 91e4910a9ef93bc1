//! How it works: what each pixel of a settled view stands on. The terrain's own depth (reversed-Z,
//! 0 for the sky; `Renderer::terrain_depth`, the terrain pass alone, so a tree's pixel is keyed by
//! the ground behind it, the ground the photograph shows there) is unprojected through the inverse
//! of the camera's clip-from-camera-relative-world matrix (in f64) at each pixel's centre, then
//! moved into grid space where the renderer placed it: the camera's grid position plus the offset
//! on the flat sheet, or the exact placing's inverse on the Earth (`ExactPlacing::grid_m`). The imagery's
//! level-0 texel there is `floor((p + ½ height spacing) / texel_m)`, as the ground truth's seeds
//! find it (`truth::scene`): cell layers cover the DEM's pixel-area extent, half a spacing beyond
//! grid space. The pixel is wooded when the land cover's class there (its source level, which
//! the exact oracle classifies seeds by; every level agrees) grows trees in the renderer's class
//! table (a rule of a tree species, or texcells): the forest the photograph is compared over, not
//! the fields whose bushes and stones are too small to show from above. Its **wooded fraction** is
//! the same flag interpolated bilinearly between the four nearest cells' centres: the smooth edge
//! the land cover allows, against which `edges` tells a staircase from a filtered edge, by the
//! trees in each pixel's ground area.

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
use crate::earth::placing::EarthPlacing;
use crate::frame::Renderer;

/// The keys of the view `renderer` last settled from `camera` (its terrain depth read back).
pub fn pixel_keys(renderer: &Renderer, camera: &Camera) -> Result<PixelKeys, PhotoError> {
    let depth = renderer.terrain_depth()?;
    let r = &renderer.settings.render;
    let view = View { camera, size_px: [r.width, r.height], curved_earth: r.curved_earth };
    keys_of_depth(&renderer.dataset, renderer.class_table(), &view, &depth)
}

/// The view whose keys are formed: its camera, its size, and whether the renderer drew the
/// dataset on the Earth (`render.curved_earth`).
pub struct View<'a> {
    /// The camera.
    pub camera: &'a Camera,
    /// The frame's size, pixels.
    pub size_px: [u32; 2],
    /// Whether the ground was drawn on the Earth where the manifest says where it lies.
    pub curved_earth: bool,
}

/// The keys of `view` whose terrain depth is `depth` (top row first).
pub fn keys_of_depth(
    dataset: &Dataset,
    table: Option<&ClassTable>,
    view: &View,
    depth: &[f32],
) -> Result<PixelKeys, PhotoError> {
    let (camera, size_px) = (view.camera, view.size_px);
    let [w, h] = size_px;
    let world_from_clip = (camera.clip_from_view(w, h)? * camera.view_from_world()).inverse();
    let manifest = &dataset.manifest;
    let eye_grid_m = camera.position_m - DVec3::new(manifest.origin_m[0], manifest.origin_m[1], 0.0);
    // Back from the camera's frame to the grid as the renderer placed it (flat: the eye plus).
    let placing = EarthPlacing::new(manifest.earth.as_ref(), manifest.origin_m, view.curved_earth);
    let exact = placing.exact(eye_grid_m);
    let half_spacing_m = 0.5 * manifest.height.spacing_m;
    let imagery = match (&manifest.imagery, &dataset.imagery) {
        (Some(meta), Some(layer)) => Some((meta.texel_m, layer.pyramid.size)),
        _ => None,
    };
    let mut landcover = Landcover::new(dataset, table);
    let mut coverage = Coverage { dataset, tiles: HashMap::new() };
    let pixels = (w as usize) * (h as usize);
    let mut keys = PixelKeys {
        size_px,
        texel: vec![NO_TEXEL; pixels],
        wooded: vec![false; pixels],
        wooded_fraction: vec![0.0; pixels],
        seeded_around: vec![false; pixels],
        ground_area_m2: vec![0.0; pixels],
        ground_distance_m: vec![f32::INFINITY; pixels],
        ground_depth_m: vec![f32::INFINITY; pixels],
    };
    let mut ground_m: Vec<Option<[f64; 2]>> = vec![None; pixels];
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
        let from_eye_m = rel.truncate() / rel.w;
        let p = exact.grid_m(from_eye_m);
        ground_m[i] = Some([p.x, p.y]);
        keys.ground_distance_m[i] = from_eye_m.truncate().length() as f32;
        // Reversed-Z with an infinite far plane: depth is near / view depth.
        keys.ground_depth_m[i] = (camera.near_m / f64::from(d)) as f32;
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
        let (fraction, seeded) = landcover.wooded_fraction([p.x, p.y], half_spacing_m)?;
        keys.wooded_fraction[i] = fraction as f32;
        keys.seeded_around[i] = seeded;
    }
    keys.ground_area_m2 = ground_areas(&ground_m, w as usize);
    Ok(keys)
}

/// Per pixel, the area of ground it covers, m² (horizontal): the parallelogram of the steps to the
/// next pixel across and down (back where the next has no ground); 0 where neither has.
fn ground_areas(ground_m: &[Option<[f64; 2]>], width: usize) -> Vec<f32> {
    let step = |i: usize, next: Option<usize>, back: Option<usize>| -> Option<[f64; 2]> {
        let p = ground_m[i]?;
        let forward = next.and_then(|n| ground_m[n]).map(|q| [q[0] - p[0], q[1] - p[1]]);
        forward.or_else(|| back.and_then(|b| ground_m[b]).map(|q| [p[0] - q[0], p[1] - q[1]]))
    };
    (0..ground_m.len())
        .map(|i| {
            let (x, len) = (i % width, ground_m.len());
            let across = step(i, (x + 1 < width).then_some(i + 1), (x > 0).then(|| i - 1));
            let down = step(i, (i + width < len).then_some(i + width), i.checked_sub(width));
            match (across, down) {
                (Some(a), Some(d)) => (a[0] * d[1] - a[1] * d[0]).abs() as f32,
                _ => 0.0,
            }
        })
        .collect()
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

/// A class grows trees: a rule of a tree species, or texcells.
const GROWS_TREES: u8 = 1;
/// A class grows seeds of any kind (a rule with a density).
const GROWS_SEEDS: u8 = 2;

/// The land cover's source level, read tile by tile as pixels need it.
pub(super) struct Landcover<'a> {
    dataset: &'a Dataset,
    /// Per palette index (0: bare), what its class grows (`GROWS_*` bits); empty without land cover.
    grows: Vec<u8>,
    /// Source texel edge, metres, the level's size and tile edge, and its tile extent.
    grid: Option<(f64, [u32; 2], u32, u32)>,
    tiles: HashMap<[u32; 2], Vec<u32>>,
}

impl<'a> Landcover<'a> {
    pub(super) fn new(dataset: &'a Dataset, table: Option<&ClassTable>) -> Self {
        let (Some(layer), Some(meta), Some(table)) = (&dataset.landcover, &dataset.manifest.landcover, table)
        else {
            return Self { dataset, grows: Vec::new(), grid: None, tiles: HashMap::new() };
        };
        let is_tree =
            |name: &str| table.species.iter().any(|s| s.name == name && s.kind == SpeciesKind::Tree);
        let grows_code = |code: u8| {
            table.class(code).map_or(0, |c| {
                let trees = c.texcells || c.seeds.iter().any(|r| is_tree(&r.species));
                let seeds = c.seeds.iter().any(|r| r.per_km2 > 0.0);
                (u8::from(trees) * GROWS_TREES) | (u8::from(seeds) * GROWS_SEEDS)
            })
        };
        let grows = std::iter::once(0).chain(meta.coding.palette.iter().map(|&c| grows_code(c))).collect();
        let p = &layer.pyramid;
        // Level 1 is the source: its texels are twice level 0's (`LandcoverLayer`).
        let grid = Some((2.0 * meta.layer.texel_m, p.size_at(LCC_SOURCE_LEVEL), p.tile, p.tile_extent()));
        Self { dataset, grows, grid, tiles: HashMap::new() }
    }

    /// Whether the class at grid point `p` grows trees (never outside the layer).
    pub(super) fn wooded(&mut self, p: [f64; 2], half_spacing_m: f64) -> Result<bool, PhotoError> {
        let Some((texel_m, ..)) = self.grid else { return Ok(false) };
        let q = p.map(|v| ((v + half_spacing_m) / texel_m).floor());
        Ok(self.cell_grows(q)? & GROWS_TREES != 0)
    }

    /// The share of trees' classes at grid point `p`: `wooded` of the four nearest cells, weighted
    /// bilinearly by the distance to their centres (cells outside the layer grow none); and
    /// whether all four grow seeds (seed selection dithers the edges between such classes only).
    pub(super) fn wooded_fraction(
        &mut self,
        p: [f64; 2],
        half_spacing_m: f64,
    ) -> Result<(f64, bool), PhotoError> {
        let Some((texel_m, ..)) = self.grid else { return Ok((0.0, false)) };
        let u = p.map(|v| (v + half_spacing_m) / texel_m - 0.5);
        let base = u.map(f64::floor);
        let f = [u[0] - base[0], u[1] - base[1]];
        let (mut fraction, mut all_seed) = (0.0, true);
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let w = (if dx > 0.0 { f[0] } else { 1.0 - f[0] }) * (if dy > 0.0 { f[1] } else { 1.0 - f[1] });
            let grows = self.cell_grows([base[0] + dx, base[1] + dy])?;
            all_seed &= grows & GROWS_SEEDS != 0;
            if grows & GROWS_TREES != 0 {
                fraction += w;
            }
        }
        Ok((fraction, all_seed))
    }

    /// What the source cell `q` (column, row, whole numbers) grows (`GROWS_*`; none outside).
    fn cell_grows(&mut self, q: [f64; 2]) -> Result<u8, PhotoError> {
        let Some((_, size, tile, extent)) = self.grid else { return Ok(0) };
        if q[0] < 0.0 || q[1] < 0.0 || q[0] >= f64::from(size[0]) || q[1] >= f64::from(size[1]) {
            return Ok(0);
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
        Ok(self.grows.get(index as usize).copied().unwrap_or(0))
    }
}
