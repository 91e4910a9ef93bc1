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
//!
//! Where the view grazes the canopy, horizontal slices show their gaps and a flat top, so a patch
//! seen from above by rays descending less than `texcells.silhouette_deg` also gets a *silhouette*
//! instance: the slab's top face, whose fragments march their ray through the 3D texture
//! (`Silhouettes`). Which kinds a patch draws is decided from the range of angles below the
//! horizon its box can be seen at, bounded exactly, so no fragment ever wants a kind its patch did
//! not draw; between the two angles the fragments themselves dither from one kind to the other.

use glam::DVec3;

use crate::config::Settings;
use crate::dataset::{Dataset, TileId};
use crate::gpu::gpu_types::{TexcellRecord, TexcellUniforms};
use crate::gpu::layout::{
    LCC_PACKED_LEVEL, TEXCELL_MAX_SAMPLES, TEXCELL_REGULAR, TEXCELL_REGULAR_SHARED, TEXCELL_SILHOUETTE,
    TexcellSlice,
};
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

/// Where silhouette texcells take over: the sines of a ray's angle below the horizon under which
/// they show alone, and over which regular texcells do (dithered between).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Silhouettes {
    /// Silhouettes alone below this sine.
    pub sin_start: f64,
    /// Regular slices alone above this one.
    pub sin_end: f64,
}

impl Silhouettes {
    /// The transition of `settings`, over `[θ, 1.5 θ]` for `texcells.silhouette_deg` = θ; `None`
    /// when silhouettes are off.
    pub fn of(settings: &Settings) -> Option<Self> {
        let t = &settings.texcells;
        t.silhouettes().then(|| {
            let deg = t.silhouette_deg;
            Self { sin_start: deg.to_radians().sin(), sin_end: (1.5 * deg).min(89.0).to_radians().sin() }
        })
    }

    /// Which kinds a patch whose canopy fills `canopy` draws from `camera_grid_m`: silhouettes
    /// when the eye is above its top and some ray to it rises less than `sin_end` (the lowest is
    /// to its top's farthest corner), regular slices when some ray to it is steeper than
    /// `sin_start` (the steepest is to its ground's nearest point) or the eye is not above it.
    pub fn kinds(&self, canopy: &QuadrantBox, camera_grid_m: DVec3) -> Kinds {
        let (near_m, far_m) = horizontal_range_m(canopy, camera_grid_m);
        let sine = |drop_m: f64, across_m: f64| drop_m / drop_m.hypot(across_m).max(1e-9);
        let above = camera_grid_m.z > canopy.max_m.z;
        let lowest = sine(camera_grid_m.z - canopy.max_m.z, far_m);
        let steepest = sine(camera_grid_m.z - canopy.min_m.z, near_m);
        Kinds { regular: !above || steepest > self.sin_start, silhouette: above && lowest < self.sin_end }
    }
}

/// The nearest and farthest horizontal distances from `eye` to a point of `b`'s footprint.
fn horizontal_range_m(b: &QuadrantBox, eye: DVec3) -> (f64, f64) {
    let gap = |lo: f64, hi: f64, p: f64| (lo - p).max(p - hi).max(0.0);
    let reach = |lo: f64, hi: f64, p: f64| (p - lo).abs().max((hi - p).abs());
    let near = gap(b.min_m.x, b.max_m.x, eye.x).hypot(gap(b.min_m.y, b.max_m.y, eye.y));
    let far = reach(b.min_m.x, b.max_m.x, eye.x).hypot(reach(b.min_m.y, b.max_m.y, eye.y));
    (near, far)
}

/// The kinds of texcell a patch draws (at least one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Kinds {
    /// Horizontal slices.
    pub regular: bool,
    /// The slab's top face, marching the 3D texture.
    pub silhouette: bool,
}

impl Kinds {
    /// Regular slices alone.
    pub const REGULAR: Self = Self { regular: true, silhouette: false };
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
    /// Its canopy's box: the ground's, raised by the slab.
    pub bounds: QuadrantBox,
    /// Which kinds it draws.
    pub kinds: Kinds,
}

/// The patches of a frame's node instances (`batches`, of which `instance(q, i)` names the ones
/// uploaded) in `band` seen from `camera_grid_m`, far to near, each with the kinds `silhouettes`
/// gives it (regular slices alone without).
pub fn place(
    batches: &NodeBatches,
    instance: impl Fn(usize, usize) -> Option<u32>,
    camera_grid_m: DVec3,
    band: &Band,
    rule: &SliceRule,
    silhouettes: Option<&Silhouettes>,
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
            let kinds = silhouettes.map_or(Kinds::REGULAR, |s| s.kinds(&canopy, camera_grid_m));
            patches.push(Patch { instance, quadrant: q as u32, level, nearest_m, bounds: canopy, kinds });
        }
    }
    patches.sort_by(|a, b| b.nearest_m.total_cmp(&a.nearest_m).then(a.instance.cmp(&b.instance)));
    patches
}

/// The instances drawing `patches` (2^(N − level) slices each if regular, and one silhouette
/// first if it has one), at most `MAX_RECORDS`: the farthest patches are left out first. A patch's
/// slices go farthest from the eye's height first (its ground taken at the middle of its height
/// range, under a slab `slab_m` thick): bottom up seen from above the canopy, top down from below
/// it, so "over" blending composites each patch in depth order (its silhouette's fragments and its
/// slices' never cover the same pixel). Also the patches left out.
pub fn records(
    patches: &[Patch],
    finest_level: u32,
    camera_z_m: f64,
    slab_m: f64,
) -> (Vec<TexcellRecord>, usize) {
    // Regular slices a patch draws (its level's), and its records (plus a silhouette).
    let regular = |p: &Patch| 1u32 << finest_level.saturating_sub(p.level);
    let slices =
        |p: &Patch| usize::from(p.kinds.silhouette) + if p.kinds.regular { regular(p) as usize } else { 0 };
    let mut total: usize = patches.iter().map(slices).sum();
    let mut skip = 0;
    while total > MAX_RECORDS as usize {
        total -= slices(&patches[skip]);
        skip += 1;
    }
    let mut records = Vec::with_capacity(total);
    for p in &patches[skip..] {
        let record = |index: u32, kind: u32| TexcellRecord {
            node: p.instance,
            slice: TexcellSlice { quadrant: p.quadrant, index, level: p.level, kind }.pack(),
        };
        if p.kinds.silhouette {
            records.push(record(0, TEXCELL_SILHOUETTE));
        }
        if !p.kinds.regular {
            continue;
        }
        let kind = if p.kinds.silhouette { TEXCELL_REGULAR_SHARED } else { TEXCELL_REGULAR };
        let n = regular(p);
        let ground_m = 0.5 * (p.bounds.min_m.z + p.bounds.max_m.z - slab_m);
        let below_eye =
            |index: u32| camera_z_m - (ground_m + (f64::from(index) + 0.5) / f64::from(n) * slab_m);
        let mut order: Vec<u32> = (0..n).collect();
        order.sort_by(|&a, &b| below_eye(b).abs().total_cmp(&below_eye(a).abs()).then(a.cmp(&b)));
        records.extend(order.into_iter().map(|index| record(index, kind)));
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
    /// Forest samples (one per dense class baked).
    pub samples: u32,
    /// Each sample's mean albedo from above (`ForestSample::albedo_from_above`), linear RGB
    /// (samples past `samples` unused).
    pub albedo_from_above: [[f32; 3]; TEXCELL_MAX_SAMPLES as usize],
}

/// The pass's uniforms, for a view whose pixels are `metres_per_px_at_1m` wide a metre away.
pub fn texcell_uniforms(
    settings: &Settings,
    dataset: &Dataset,
    band: &Band,
    shape: &SampleShape,
    metres_per_px_at_1m: f64,
) -> TexcellUniforms {
    let t = &settings.texcells;
    let silhouette_sin =
        Silhouettes::of(settings).map_or([0.0; 2], |s| [s.sin_start as f32, s.sin_end as f32]);
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
        silhouette_sin,
        metres_per_px_at_1m: metres_per_px_at_1m as f32,
        silhouette_steps: t.silhouette_steps,
        sample_count: shape.samples,
        sample_albedo: std::array::from_fn(|i| {
            let [r, g, b] = shape.albedo_from_above[i];
            [r, g, b, 0.0]
        }),
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
        let patches = place(&b, |_, i| Some(i as u32), camera, &band, &rule(), None);
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
        assert!(place(&b, |_, _| None, camera, &band, &rule(), None).is_empty());
    }

    #[test]
    fn silhouettes_go_where_the_view_grazes_the_canopy_from_above() {
        // 5°: silhouettes alone below 5°, regular slices alone above 7.5°.
        let s = Silhouettes { sin_start: 5f64.to_radians().sin(), sin_end: 7.5f64.to_radians().sin() };
        // A 500 m square of canopy from 100 to 150 m, 4 km north of the eye.
        let min_m = DVec3::new(-250.0, 4000.0, 100.0);
        let canopy = QuadrantBox { min_m, max_m: min_m + DVec3::new(500.0, 500.0, 50.0) };
        let eye = |z: f64| DVec3::new(0.0, 0.0, z);
        let kinds = |z: f64| s.kinds(&canopy, eye(z));
        // 2 km up it is seen at 22–25°: regular slices only.
        assert_eq!(kinds(2000.0), Kinds::REGULAR);
        // 200 m up, at 0.6–1.4°: silhouettes only.
        assert_eq!(kinds(200.0), Kinds { regular: false, silhouette: true });
        // 560 m up, at 5.2° (the top's far corner) to 6.5° (the ground's near edge): both.
        assert_eq!(kinds(560.0), Kinds { regular: true, silhouette: true });
        // An eye below the canopy's top sees no silhouette; one inside its footprint sees slices.
        assert_eq!(kinds(140.0), Kinds::REGULAR);
        assert!(s.kinds(&canopy, DVec3::new(0.0, 4200.0, 400.0)).regular);
        // Every ray to the box lies in the range the kinds were chosen from: sample the box.
        for z in [180.0, 400.0, 560.0, 700.0, 900.0] {
            let k = kinds(z);
            for (fx, fy, fz) in
                [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (0.5, 0.0, 1.0), (0.0, 1.0, 0.5), (1.0, 0.3, 0.0)]
            {
                let q = canopy.min_m + (canopy.max_m - canopy.min_m) * DVec3::new(fx, fy, fz);
                let sin_e = (z - q.z) / (eye(z) - q).length();
                assert!(sin_e >= s.sin_end || k.silhouette, "{z} m: {sin_e} wants a silhouette");
                assert!(sin_e <= s.sin_start || k.regular, "{z} m: {sin_e} wants slices");
            }
        }
        // A patch with a silhouette draws it first, then its slices, marked as shared.
        let patch = Patch {
            instance: 3,
            quadrant: 1,
            level: 2,
            nearest_m: 4000.0,
            bounds: canopy,
            kinds: kinds(560.0),
        };
        let (drawn, _) = records(&[patch], 5, 560.0, 50.0);
        let kind = |r: &TexcellRecord| TexcellSlice::unpack(r.slice).kind;
        assert_eq!(drawn.len(), 1 + 8);
        assert_eq!(kind(&drawn[0]), TEXCELL_SILHOUETTE);
        assert!(drawn[1..].iter().all(|r| kind(r) == TEXCELL_REGULAR_SHARED));
        let alone = Patch { kinds: Kinds { regular: false, silhouette: true }, ..patch };
        assert_eq!(records(&[alone], 5, 200.0, 50.0).0.len(), 1);
    }
}
