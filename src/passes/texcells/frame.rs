//! The texcell pass's CPU half: which terrain node quadrants carry texcells and how many slices
//! each draws (`place`), the instances that makes (`records`), the land-cover tiles their
//! fragments read (`landcover_tiles`) and the pass's uniforms (`texcell_uniforms`).
//!
//! A *patch* is one quadrant of a terrain node the frame draws, so texcells stand on exactly the
//! ground drawn, morphs included. A patch is kept when part of it lies in the texcell band (from
//! where the last billboard clouds start fading out to `texcells.reach_m`). Its slice level comes
//! from its nearest point: the slice pyramid's level `i` draws `2^(N − i)` slices whose texels are
//! `2^i` finest texels wide, so `i` is the coarser of what the texture needs there (its mip level,
//! seen from above) and what the slab's parallax needs (`slice_px` pixels per slice, seen
//! edge-on) allows. Patches are drawn far to near, each one's slices farthest from the eye's
//! height first: premultiplied "over" blending then composites them in depth order.

use glam::DVec3;

use crate::config::Settings;
use crate::dataset::{Dataset, TileId};
use crate::gpu::gpu_types::{TexcellRecord, TexcellUniforms};
use crate::gpu::layout::{LCC_PACKED_LEVEL, TexcellSlice};
use crate::passes::terrain::frame::{NodeBatches, QuadrantBox};
use crate::streaming::page_levels;

/// Slice instances one frame can draw; beyond it the farthest patches are dropped (counted).
pub const MAX_RECORDS: u32 = 1 << 16;

/// Where texcells are drawn, metres from the camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Band {
    /// Where they start fading in: where the last billboard clouds start fading out.
    pub fade_in_m: f64,
    /// Over how far they fade in: the clouds' fade band (at least a metre).
    pub fade_in_width_m: f64,
    /// Where they end: `texcells.reach_m`.
    pub reach_m: f64,
    /// Over how far before it they fade out.
    pub fade_out_width_m: f64,
}

/// The share of the reach over which texcells fade out to the bare ground.
const FADE_OUT_SHARE: f64 = 0.1;

impl Band {
    /// The band of `settings`: from the last draw LOD's fade band to the texcell reach.
    pub fn of(settings: &Settings) -> Self {
        let d = &settings.draw_seeds;
        let last = d.reach_m[d.reach_m.len() - 1];
        let width = (last * d.fade_fraction).max(1.0);
        let reach_m = settings.texcells.reach_m;
        Self {
            fade_in_m: last - width,
            fade_in_width_m: width,
            reach_m,
            fade_out_width_m: reach_m * FADE_OUT_SHARE,
        }
    }
}

/// What decides a patch's slice count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceRule {
    /// The pixel's footprint per metre of distance (`Camera::metres_per_pixel(1, height)`).
    pub metres_per_px_at_1m: f64,
    /// The finest texel's edge, metres.
    pub texel_m: f64,
    /// The slab's thickness, metres.
    pub slab_m: f64,
    /// `texcells.slice_px`.
    pub slice_px: f64,
    /// N: the finest level has 2^N slices.
    pub finest_level: u32,
}

impl SliceRule {
    /// The slice pyramid level a patch whose nearest point is `distance_m` away draws.
    pub fn level(&self, distance_m: f64) -> u32 {
        let n = self.finest_level;
        let px_m = distance_m.max(1.0) * self.metres_per_px_at_1m;
        let mip = (px_m / self.texel_m).log2().floor().max(0.0);
        let slices = (self.slab_m / (px_m * self.slice_px)).max(1.0);
        let parallax = f64::from(n) - slices.log2().ceil().min(f64::from(n));
        mip.min(parallax).clamp(0.0, f64::from(n)) as u32
    }
}

/// One node quadrant carrying texcells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Patch {
    /// The terrain instance it stands on: its index in the terrain pass's node buffer.
    pub instance: u32,
    /// Which quadrant of the node (bit 0 east, bit 1 north).
    pub quadrant: u32,
    /// The slice pyramid level it draws.
    pub level: u32,
    /// The distance to its nearest point, metres.
    pub nearest_m: f64,
    /// Its ground's box.
    pub bounds: QuadrantBox,
}

/// The patches of a frame's node instances (`batches`, of which `instance(q, i)` names the ones
/// uploaded) in `band` seen from `camera_grid_m`, far to near.
pub fn place(
    batches: &NodeBatches,
    instance: impl Fn(usize, usize) -> Option<u32>,
    camera_grid_m: DVec3,
    band: &Band,
    rule: &SliceRule,
) -> Vec<Patch> {
    let mut patches = Vec::new();
    for (q, boxes) in batches.boxes.iter().enumerate() {
        for (i, b) in boxes.iter().enumerate() {
            let Some(instance) = instance(q, i) else { continue };
            let canopy = QuadrantBox { min_m: b.min_m, max_m: b.max_m + DVec3::new(0.0, 0.0, rule.slab_m) };
            let nearest_m = canopy.distance_m(camera_grid_m);
            if nearest_m >= band.reach_m || canopy.farthest_m(camera_grid_m) <= band.fade_in_m {
                continue;
            }
            let level = rule.level(nearest_m);
            patches.push(Patch { instance, quadrant: q as u32, level, nearest_m, bounds: canopy });
        }
    }
    patches.sort_by(|a, b| b.nearest_m.total_cmp(&a.nearest_m).then(a.instance.cmp(&b.instance)));
    patches
}

/// The instances drawing `patches` (2^(N − level) slices each), at most `MAX_RECORDS`: the
/// farthest patches are left out first. A patch's slices go farthest from the eye's height first
/// (its ground taken at the middle of its height range, under a slab `slab_m` thick): bottom up
/// seen from above the canopy, top down from below it, so "over" blending composites each patch
/// in depth order. Also the patches left out.
pub fn records(
    patches: &[Patch],
    finest_level: u32,
    camera_z_m: f64,
    slab_m: f64,
) -> (Vec<TexcellRecord>, usize) {
    let slices = |p: &Patch| 1usize << finest_level.saturating_sub(p.level);
    let mut total: usize = patches.iter().map(slices).sum();
    let mut skip = 0;
    while total > MAX_RECORDS as usize {
        total -= slices(&patches[skip]);
        skip += 1;
    }
    let mut records = Vec::with_capacity(total);
    for p in &patches[skip..] {
        let n = slices(p) as u32;
        let ground_m = 0.5 * (p.bounds.min_m.z + p.bounds.max_m.z - slab_m);
        let below_eye =
            |index: u32| camera_z_m - (ground_m + (f64::from(index) + 0.5) / f64::from(n) * slab_m);
        let mut order: Vec<u32> = (0..n).collect();
        order.sort_by(|&a, &b| below_eye(b).abs().total_cmp(&below_eye(a).abs()).then(a.cmp(&b)));
        records.extend(order.into_iter().map(|index| TexcellRecord {
            node: p.instance,
            slice: TexcellSlice { quadrant: p.quadrant, index, level: p.level }.pack(),
        }));
    }
    (records, skip)
}

/// The land-cover tiles (level `LCC_PACKED_LEVEL`, the cheapest whole coding) under `patches`.
pub fn landcover_tiles(dataset: &Dataset, patches: &[Patch]) -> Vec<TileId> {
    let (Some(layer), Some(meta)) = (&dataset.landcover, &dataset.manifest.landcover) else {
        return Vec::new();
    };
    let pyramid = &layer.pyramid;
    let level = LCC_PACKED_LEVEL.min(pyramid.levels.saturating_sub(1));
    let tile_m = meta.layer.texel_m * f64::from(1u32 << level) * f64::from(pyramid.tile);
    let offset_m = 0.5 * dataset.manifest.height.spacing_m;
    let [nx, ny] = pyramid.tiles_at(level);
    let index = |m: f64, n: u32| ((m + offset_m) / tile_m).floor().clamp(0.0, f64::from(n - 1)) as u32;
    let mut tiles: Vec<TileId> = patches
        .iter()
        .flat_map(|p| {
            let (x0, x1) = (index(p.bounds.min_m.x, nx), index(p.bounds.max_m.x, nx));
            let (y0, y1) = (index(p.bounds.min_m.y, ny), index(p.bounds.max_m.y, ny));
            (y0..=y1).flat_map(move |y| (x0..=x1).map(move |x| TileId::new(level, x, y)))
        })
        .collect();
    tiles.sort();
    tiles.dedup();
    tiles
}

/// What the texcell uniforms are made of besides the settings and the dataset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleShape {
    /// The forest samples' ground cell edge, metres.
    pub cell_m: f64,
    /// The slab's thickness, metres.
    pub slab_m: f64,
    /// Texels along the finest slices' side.
    pub texels: u32,
    /// Slices of the finest level.
    pub finest_slices: u32,
    /// `texcell::tiling::sample_cells_word`.
    pub tile_cells: u32,
}

/// The pass's uniforms.
pub fn texcell_uniforms(
    settings: &Settings,
    dataset: &Dataset,
    band: &Band,
    shape: &SampleShape,
) -> TexcellUniforms {
    let t = &settings.texcells;
    let mut u = TexcellUniforms {
        fade_m: [
            band.fade_in_m as f32,
            band.fade_in_width_m as f32,
            (band.reach_m - band.fade_out_width_m) as f32,
            band.fade_out_width_m as f32,
        ],
        slab_height_m: shape.slab_m as f32,
        inv_cell_m: (1.0 / shape.cell_m) as f32,
        seed: settings.tlm.seed,
        tile_cells: shape.tile_cells,
        texels: shape.texels as f32,
        finest_slices: shape.finest_slices,
        opacity_max_factor: t.opacity_max_factor as f32,
        ground_blend: t.ground_blend as f32,
        lcc_level: LCC_PACKED_LEVEL,
        ..Default::default()
    };
    if let (Some(layer), Some(meta)) = (&dataset.landcover, &dataset.manifest.landcover) {
        // Level-1 texels are twice level 0's; their grid starts half a height cell west and south.
        let texel_m = 2.0 * meta.layer.texel_m;
        let offset_m = -0.5 * dataset.manifest.height.spacing_m;
        u.lcc_levels = page_levels(&layer.pyramid);
        u.lcc_size = layer.pyramid.size_at(1);
        u.lcc_sub_bits = meta.coding.sub_bits();
        u.lcc_frame = [offset_m as f32, offset_m as f32, (1.0 / texel_m) as f32, 0.0];
    }
    u
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule() -> SliceRule {
        // 1280 × 720 at 60°: 1.6 mm per pixel per metre.
        SliceRule { metres_per_px_at_1m: 0.0016, texel_m: 0.25, slab_m: 20.0, slice_px: 1.0, finest_level: 5 }
    }

    #[test]
    fn farther_patches_draw_fewer_slices() {
        let r = rule();
        let levels: Vec<u32> = [10.0, 500.0, 3000.0, 6000.0, 12_000.0, 1e6].map(|d| r.level(d)).to_vec();
        assert!(levels.windows(2).all(|w| w[0] <= w[1]), "{levels:?}");
        assert_eq!(levels[0], 0, "up close: every slice");
        assert_eq!(levels[5], 5, "far away: one slice");
        // At 3 km a pixel is ~4.8 m: the 20 m slab spans ~4 pixels, so 4 to 8 slices.
        assert!((2..=3).contains(&levels[2]), "{levels:?}");
        let finer = SliceRule { slice_px: 0.25, ..r };
        assert!(finer.level(3000.0) < r.level(3000.0));
    }

    fn batches(boxes: &[(f64, f64)]) -> NodeBatches {
        let mut b = NodeBatches::default();
        for &(x, y) in boxes {
            b.by_quadrant[0].push(bytemuck::Zeroable::zeroed());
            let min_m = DVec3::new(x, y, 100.0);
            b.boxes[0].push(QuadrantBox { min_m, max_m: min_m + DVec3::new(500.0, 500.0, 50.0) });
        }
        b
    }

    #[test]
    fn patches_are_those_in_the_band_far_first_with_their_slices_bottom_first() {
        let band =
            Band { fade_in_m: 2700.0, fade_in_width_m: 300.0, reach_m: 10_000.0, fade_out_width_m: 1000.0 };
        let camera = DVec3::new(0.0, 0.0, 600.0);
        // Near (inside the seed band), straddling its end, far, beyond the reach.
        let b = batches(&[(0.0, 0.0), (2500.0, 0.0), (6000.0, 0.0), (12_000.0, 0.0)]);
        let patches = place(&b, |_, i| Some(i as u32), camera, &band, &rule());
        let kept: Vec<u32> = patches.iter().map(|p| p.instance).collect();
        assert_eq!(kept, [2, 1]);
        let (drawn, dropped) = records(&patches, 5, camera.z, 20.0);
        assert_eq!(dropped, 0);
        let count = |p: &Patch| 1usize << (5 - p.level);
        assert_eq!(drawn.len(), count(&patches[0]) + count(&patches[1]));
        // Seen from above: the far patch's slices first, bottom up, then the near patch's.
        let first: Vec<(u32, u32)> =
            drawn.iter().map(|r| (r.node, TexcellSlice::unpack(r.slice).index)).collect();
        let far = count(&patches[0]);
        assert!(first[..far].iter().all(|&(node, _)| node == 2));
        assert!(first[..far].windows(2).all(|w| w[0].1 < w[1].1), "{first:?}");
        // From inside the slab: the slices farthest from the eye's height first, either side.
        let ground_m = 0.5 * (patches[0].bounds.min_m.z + patches[0].bounds.max_m.z - 20.0);
        let (inside, _) = records(&patches[..1], 5, ground_m + 10.0, 20.0);
        let n = inside.len() as u32;
        let order: Vec<u32> = inside.iter().map(|r| TexcellSlice::unpack(r.slice).index).collect();
        assert!(
            [0, n - 1].contains(&order[0])
                && [(n / 2).saturating_sub(1), n / 2].contains(&order[order.len() - 1]),
            "{order:?}"
        );
        // Instances the terrain did not upload carry no texcells.
        assert!(place(&b, |_, _| None, camera, &band, &rule()).is_empty());
    }
}
