//! How it works: the colour follow-up's yardstick. Amara et al. keep amplified vegetation in the
//! photograph's colours; here a seed's foliage is scaled, per colour channel, by the photograph's
//! lit colour under it over what its own model shows on average seen from above (a ratio
//! transfer), so that a forest of seeds has the photograph's local mean while each crown keeps its
//! texture, its shading and its gaps (the gaps show the photograph itself).
//!
//! What a model shows from above is measured once per species and draw LOD from the geometry that
//! LOD draws (the mesh, a billboard cloud's planes, the slicings): every foliage triangle (bark is
//! left out: it keeps its own colour) is weighted by its area, by the share of its texels the alpha
//! test keeps, and by how squarely it faces a view from above (|n_up|, at least
//! `MIN_UP_FACING`: upright planes are still seen from 45°). Its albedo is its material's colour
//! times its texture's mean over the kept texels of its texture-coordinate box, times the crown
//! shading's mean at its height over the seed's turns (the side towards the sun averages out). Its
//! lighting depends on the frame's sun: the shader turns every normal to face the eye, so from
//! above a normal is known by its upward component alone, kept as a histogram of `UP_BINS` bins;
//! the sun's share over the seed's turns then has a closed form (`facing`). The CPU hands the
//! shader the mean albedo and that facing each frame (`yardstick`); the shader scales by the light
//! that reaches each seed through the air (`photo_scale_at` in `shaders/draw_seeds.wgsl`, whose
//! twin is `photo_scale`). Leaves hiding leaves are not modelled: every foliage triangle counts as
//! seen.

use glam::Vec3;

use crate::gpu::gpu_types::{SeedDrawArgs, SeedMaterial, SeedVertex};
use crate::gpu::layout::{
    FOLIAGE_SKY, FOLIAGE_SUN, FOLIAGE_SUN_WRAP, MATERIAL_BARK, MATERIAL_REPEAT, MATERIAL_TEXTURED,
};
use crate::impostor::mip_size;
use crate::texcell::pyramid::decode_srgb;

/// Bins of the foliage's upward normal component, 0 to 1.
const UP_BINS: usize = 32;
/// The least weight a triangle's facing gets (|n_up| below it counts as this): a billboard
/// plane or a slice stands upright, seen edge-on from straight above but squarely from 45°.
const MIN_UP_FACING: f32 = 0.5;
/// The texture level whose texels are averaged is the finest at most this many texels wide.
const MEAN_LEVEL_TEXELS: u32 = 64;

/// One species' geometry of one draw LOD, seen from above on average.
#[derive(Debug, Clone, PartialEq)]
pub struct FromAbove {
    /// Mean linear albedo (crown shading included) of what is seen.
    pub albedo: [f32; 3],
    /// Weight of the foliage whose upward normal component falls in each bin, and that
    /// component's weighted mean there (so that a bin of one normal is exact).
    up_bins: [(f32, f32); UP_BINS],
}

/// The light at a seed, per unit of the sun's irradiance above the air (`SunAndSky` in
/// `shaders/shared/air.wgsl`): the sun's share that reaches it and the sky's on level ground.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SeedLight {
    /// The sun through the air, per channel.
    pub sun: [f32; 3],
    /// The sky's light on a level surface, per channel.
    pub sky: [f32; 3],
}

impl FromAbove {
    /// max(n · sun, 0) averaged over the foliage's normals and the seed's turns, under a sun
    /// along `sun` (unit, towards it, +z up).
    pub fn facing(&self, sun: Vec3) -> f32 {
        let total: f32 = self.up_bins.iter().map(|(w, _)| w).sum();
        if total <= 0.0 {
            return 0.0;
        }
        let bins = self.up_bins.iter().filter(|(w, _)| *w > 0.0);
        bins.map(|&(w, up)| w * turned_facing(up, sun)).sum::<f32>() / total
    }

    /// What the shader needs of this geometry each frame: its mean albedo (xyz) and `facing`
    /// (w).
    pub fn yardstick(&self, sun: Vec3) -> [f32; 4] {
        let [r, g, b] = self.albedo;
        [r, g, b, self.facing(sun)]
    }

    /// The mean lit colour, per channel, under a sun along `sun` in `light`, clouds aside: the
    /// shader's foliage lighting averaged over the normals and the seed's turns.
    pub fn lit(&self, sun: Vec3, light: &SeedLight) -> [f32; 3] {
        let sun_share = FOLIAGE_SUN * self.facing(sun) + FOLIAGE_SUN_WRAP * sun.z.max(0.0);
        std::array::from_fn(|c| self.albedo[c] * (light.sun[c] * sun_share + light.sky[c] * FOLIAGE_SKY))
    }

    /// The factor per channel that turns this geometry's mean lit colour into the lit colour of
    /// level ground of albedo 1 (the imagery's colour then multiplies it in the shader); 0 where
    /// nothing is seen or nothing lights it (the shader then keeps the model's colour). Twin of
    /// `photo_scale_at`.
    pub fn photo_scale(&self, sun: Vec3, light: &SeedLight) -> [f32; 3] {
        let lit = self.lit(sun, light);
        if self.albedo[1] <= 0.0 || lit.iter().any(|l| *l <= 1e-6) {
            return [0.0; 3];
        }
        std::array::from_fn(|c| (light.sun[c] * sun.z.max(0.0) + light.sky[c]) / lit[c])
    }
}

/// max(n · sun, 0) for a normal of upward component `up`, averaged over its turns about the
/// vertical: with n · sun = a + b cos θ, the mean of its positive part is (a φ + b sin φ) / π
/// where φ = acos(−a / b) bounds the lit turns.
fn turned_facing(up: f32, sun: Vec3) -> f32 {
    let across = (1.0 - up * up).max(0.0).sqrt();
    let (a, b) = (up * sun.z, across * sun.truncate().length());
    if a >= b {
        return a;
    }
    if a <= -b {
        return 0.0;
    }
    let phi = (-a / b).acos();
    (a * phi + b * phi.sin()) / std::f32::consts::PI
}

/// The texture layers as uploaded (`SeedAssets::layers`), read for the materials' means.
pub struct Layers<'a> {
    /// Each layer's mips, RGBA8, colour sRGB-encoded.
    pub levels: &'a [Vec<Vec<u8>>],
    /// Level 0's side, texels.
    pub size: u32,
}

impl Layers<'_> {
    /// The mean linear colour and the kept share of layer `layer`'s texels in the box `uv`
    /// (min, max; wrapped when `repeat`), those below `cutoff` alpha cut away.
    fn mean(&self, layer: u32, uv: [[f32; 2]; 2], cutoff: f32, repeat: bool) -> ([f32; 3], f32) {
        let Some(mips) = self.levels.get(layer as usize) else { return ([1.0; 3], 1.0) };
        let level = (self.size / MEAN_LEVEL_TEXELS).max(1).ilog2().min(mips.len().saturating_sub(1) as u32);
        let [w, h] = mip_size([self.size; 2], level);
        let texels = &mips[level as usize];
        let span = |a: usize, n: u32| {
            let (lo, hi) = (uv[0][a] * n as f32, uv[1][a] * n as f32);
            let (lo, hi) = (lo.floor() as i64, (hi.ceil() as i64).max(lo.floor() as i64 + 1));
            (lo, hi.min(lo + i64::from(n)))
        };
        let (x0, x1) = span(0, w);
        let (y0, y1) = span(1, h);
        let (mut sum, mut kept, mut all) = ([0.0f32; 3], 0u32, 0u32);
        for y in y0..y1 {
            for x in x0..x1 {
                let fold = |v: i64, n: u32| {
                    if repeat { v.rem_euclid(i64::from(n)) } else { v.clamp(0, i64::from(n) - 1) }
                };
                let at = 4 * (fold(y, h) as usize * w as usize + fold(x, w) as usize);
                let Some(t) = texels.get(at..at + 4) else { continue };
                all += 1;
                if f32::from(t[3]) / 255.0 < cutoff {
                    continue;
                }
                kept += 1;
                for (s, &c) in sum.iter_mut().zip(t) {
                    *s += decode_srgb(c);
                }
            }
        }
        if kept == 0 {
            return ([0.0; 3], 0.0);
        }
        (sum.map(|s| s / kept as f32), kept as f32 / all.max(1) as f32)
    }
}

/// What `template`'s triangles (of `vertices` and `indices`, materials `materials`) show from
/// above, for a species of crown shading `crown_shading` and model height 1 / `inv_height_m`;
/// `None` when none of them is foliage.
pub fn from_above(
    template: &SeedDrawArgs,
    (vertices, indices): (&[SeedVertex], &[u32]),
    materials: &[SeedMaterial],
    layers: &Layers<'_>,
    (crown_shading, inv_height_m): (f32, f32),
) -> Option<FromAbove> {
    let first = template.first_index as usize;
    let run = indices.get(first..first + template.index_count as usize)?;
    let mut albedo = [0.0f32; 3];
    let mut up_bins = [(0.0f32, 0.0f32); UP_BINS];
    let mut total = 0.0f32;
    for triangle in run.chunks_exact(3) {
        let corner = |k: usize| vertices.get((template.base_vertex as i64 + i64::from(triangle[k])) as usize);
        let (Some(a), Some(b), Some(c)) = (corner(0), corner(1), corner(2)) else { continue };
        let Some(material) = materials.get(a.material as usize) else { continue };
        if material.flags & MATERIAL_BARK != 0 {
            continue;
        }
        let p = [a, b, c].map(|v| Vec3::from(v.position_model_m));
        let cross = (p[1] - p[0]).cross(p[2] - p[0]);
        let area = 0.5 * cross.length();
        if area <= 0.0 {
            continue;
        }
        // Model space is y up (glTF).
        let up = (cross.y / (2.0 * area)).abs();
        let (colour, coverage) = material_mean(material, [a, b, c], layers);
        let weight = area * coverage * up.max(MIN_UP_FACING);
        if weight <= 0.0 {
            continue;
        }
        let height = ((p[0].y + p[1].y + p[2].y) / 3.0 * inv_height_m).clamp(0.0, 1.0);
        // The crown shading's mean over the seed's turns: its side term averages to none.
        let shading = 1.0 - crown_shading * (0.5 * (1.0 - height) + 0.25);
        for (s, c) in albedo.iter_mut().zip(colour) {
            *s += weight * c * shading;
        }
        let bin = &mut up_bins[((up * UP_BINS as f32) as usize).min(UP_BINS - 1)];
        bin.1 = (bin.1 * bin.0 + up * weight) / (bin.0 + weight);
        bin.0 += weight;
        total += weight;
    }
    (total > 0.0).then(|| FromAbove { albedo: albedo.map(|s| s / total), up_bins })
}

/// A triangle's material colour (linear) and the share of its texels the alpha test keeps.
fn material_mean(material: &SeedMaterial, corners: [&SeedVertex; 3], layers: &Layers<'_>) -> ([f32; 3], f32) {
    let base = [material.base_colour[0], material.base_colour[1], material.base_colour[2]];
    if material.flags & MATERIAL_TEXTURED == 0 {
        return (base, if material.base_colour[3] >= material.alpha_cutoff { 1.0 } else { 0.0 });
    }
    let lo = [0, 1].map(|a| corners.iter().map(|v| v.uv[a]).fold(f32::INFINITY, f32::min));
    let hi = [0, 1].map(|a| corners.iter().map(|v| v.uv[a]).fold(f32::NEG_INFINITY, f32::max));
    let repeat = material.flags & MATERIAL_REPEAT != 0;
    // The texel's alpha is multiplied by the base colour's before the test.
    let cutoff = material.alpha_cutoff / material.base_colour[3].max(1e-6);
    let (texel, coverage) = layers.mean(material.layer, [lo, hi], cutoff, repeat);
    (std::array::from_fn(|c| base[c] * texel[c]), coverage)
}

#[cfg(test)]
#[path = "from_above_tests.rs"]
mod tests;
