//! How it works: the twin of pass 3's reads of the imagery (`shaders/seed_select_imagery.wgsl`),
//! with the same f32 operations in the same order. A level-0 texel is read from the finest
//! resident level holding it (sRGB decoded as the GPU decodes it); the photograph under a seed is
//! the mean of `GROUND_SAMPLES` bilinear reads at hashed points within the ground radius, as the
//! ground pass filters the imagery it drapes, packed as WGSL's `pack4x8unorm`; and the vegetation
//! index the imagery may carry, read bilinearly too, says whether a seed grows (pass 3's rule beside
//! altitude and slope).

use crate::gpu::gpu_types::SeedUniforms;
use crate::gpu::layout::{
    GROUND_SAMPLES, IMAGERY_BORDER, IMAGERY_TILE_TEXELS, VEGETATION_CODE_STEPS, VEGETATION_SALT, page_slot,
    vegetation_coverage,
};
use crate::seeds::{pcg, unit};

use super::{GridPos, TwinCache};

/// sRGB-encoded byte to linear, as the GPU decodes an sRGB texel.
fn srgb_to_linear(byte: u8) -> f32 {
    let c = f64::from(byte) / 255.0;
    (if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }) as f32
}

fn imagery_texel(u: &SeedUniforms, imagery: &TwinCache<[u8; 4]>, t: [u32; 2]) -> [f32; 4] {
    for level in 0..u.imagery_level_count {
        let info = u.imagery_levels[level as usize];
        let texel = t.map(|v| v >> level);
        let tile = [
            (texel[0] / IMAGERY_TILE_TEXELS).min(info[1] - 1),
            (texel[1] / IMAGERY_TILE_TEXELS).min(info[2] - 1),
        ];
        if let Some(slot) = page_slot(imagery.page_table[(info[0] + tile[1] * info[1] + tile[0]) as usize]) {
            let local = [0, 1].map(|a| texel[a] - tile[a] * IMAGERY_TILE_TEXELS + IMAGERY_BORDER);
            let rgba = imagery.load(slot, local[0], local[1]);
            return [
                srgb_to_linear(rgba[0]),
                srgb_to_linear(rgba[1]),
                srgb_to_linear(rgba[2]),
                f32::from(rgba[3]) / 255.0,
            ];
        }
    }
    [0.0; 4]
}

/// The imagery at `q` (level-0 texels from `base`'s corner), filtered bilinearly (the shader's
/// `imagery_bilinear`).
fn imagery_bilinear(u: &SeedUniforms, imagery: &TwinCache<[u8; 4]>, base: [i32; 2], q: [f32; 2]) -> [f32; 4] {
    // Texel centres lie half a texel in.
    let centred = q.map(|v| v - 0.5);
    let below = centred.map(f32::floor);
    let f = [centred[0] - below[0], centred[1] - below[1]];
    let last = u.imagery_size.map(|n| n as i32 - 1);
    let mut sum = [0.0f32; 4];
    for k in 0..4 {
        let d = [k & 1, k >> 1];
        let texel: [u32; 2] =
            std::array::from_fn(|a| (base[a] + below[a] as i32 + d[a]).clamp(0, last[a]) as u32);
        let w = [0, 1].map(|a| if d[a] == 1 { f[a] } else { 1.0 - f[a] });
        let mut colour = imagery_texel(u, imagery, texel);
        if u.vegetation[0] != 0.0 {
            colour[3] = vegetation_coverage(colour[3]);
        }
        for c in 0..4 {
            sum[c] += w[0] * w[1] * colour[c];
        }
    }
    sum
}

/// The photograph under a seed: the mean of the bilinear imagery at `GROUND_SAMPLES` hashed points
/// within the ground radius of `p`, packed as WGSL's `pack4x8unorm`.
pub(super) fn ground_colour(u: &SeedUniforms, imagery: &TwinCache<[u8; 4]>, p: &GridPos, hash: u32) -> u32 {
    if u.imagery_level_count == 0 {
        return 0;
    }
    let mut sum = [0.0f32; 4];
    let mut h = hash;
    for _ in 0..GROUND_SAMPLES {
        h = pcg(h);
        let offset = [
            (unit(h) * 2.0 - 1.0) * u.ground_radius_texels,
            (unit(pcg(h)) * 2.0 - 1.0) * u.ground_radius_texels,
        ];
        let q = [p.frac[0] + offset[0], p.frac[1] + offset[1]];
        for (s, c) in sum.iter_mut().zip(imagery_bilinear(u, imagery, p.texel, q)) {
            *s += c;
        }
    }
    let mean = sum.map(|c| c * (1.0 / GROUND_SAMPLES as f32));
    mean.iter()
        .enumerate()
        .fold(0, |word, (c, v)| word | (((v.clamp(0.0, 1.0) * 255.0).round() as u32) << (8 * c)))
}

/// Whether the imagery's vegetation index lets seed `hash` grow at `p`, where the imagery
/// carries one (the caller asks; the shader's `vegetation_grows`, step by step).
pub(super) fn vegetation_grows(
    u: &SeedUniforms,
    imagery: &TwinCache<[u8; 4]>,
    p: &GridPos,
    hash: u32,
) -> bool {
    let q = p.frac.map(|f| f - 0.5);
    let below = q.map(f32::floor);
    let f = [q[0] - below[0], q[1] - below[1]];
    let last = u.imagery_size.map(|n| n as i32 - 1);
    let (mut alpha, mut weight) = (0.0f32, 0.0f32);
    for k in 0..4u32 {
        let d = [(k & 1) as i32, (k >> 1) as i32];
        let t: [u32; 2] =
            std::array::from_fn(|a| (p.texel[a] + below[a] as i32 + d[a]).clamp(0, last[a]) as u32);
        let side = |a: usize| if d[a] == 1 { f[a] } else { 1.0 - f[a] };
        let w = side(0) * side(1);
        let a = imagery_texel(u, imagery, t)[3];
        if a > 0.0 {
            alpha += w * a;
            weight += w;
        }
    }
    if weight <= 0.0 {
        return true;
    }
    let index = ((alpha / weight) * 255.0 - 1.0) * (2.0 / VEGETATION_CODE_STEPS as f32) - 1.0;
    let growth = ((index - u.vegetation[1]) * u.vegetation[2]).clamp(0.0, 1.0);
    unit(pcg(hash ^ VEGETATION_SALT)) < growth
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

    use bytemuck::Zeroable;

    use super::*;
    use crate::gpu::layout::page_entry;

    /// One resident level-0 tile of 2 × 1 texels: black, then white (sRGB 255: linear 1).
    fn black_then_white() -> (SeedUniforms, TwinCache<[u8; 4]>) {
        let mut u = SeedUniforms::zeroed();
        u.imagery_level_count = 1;
        u.imagery_size = [2, 1];
        u.imagery_levels[0] = [0, 1, 1, 0];
        let extent = IMAGERY_TILE_TEXELS + 2 * IMAGERY_BORDER;
        let mut texels = vec![[0u8; 4]; (extent * extent) as usize];
        let at = |x: u32| ((IMAGERY_BORDER * extent) + IMAGERY_BORDER + x) as usize;
        texels[at(0)] = [0, 0, 0, 255];
        texels[at(1)] = [255, 255, 255, 255];
        let imagery = TwinCache { page_table: vec![page_entry(0)], extent, slots: [(0, texels)].into() };
        (u, imagery)
    }

    #[test]
    fn the_photograph_under_a_seed_is_filtered_bilinearly_in_linear_light() {
        let (u, imagery) = black_then_white();
        let red_at = |x: f32| imagery_bilinear(&u, &imagery, [0, 0], [x, 0.5])[0];
        // At each texel's centre its own colour; between them the mean of the linear values
        // (sRGB 188, not 128); a quarter of the way, a quarter; past the last centre, clamped.
        assert_eq!((red_at(0.5), red_at(1.5)), (0.0, 1.0));
        assert!((red_at(1.0) - 0.5).abs() < 1e-6 && (red_at(0.75) - 0.25).abs() < 1e-6);
        assert_eq!(red_at(1.9), 1.0);
        // Coverage is filtered with the colour: the data's edge fades, not steps.
        assert!((imagery_bilinear(&u, &imagery, [0, 0], [1.0, 0.5])[3] - 1.0).abs() < 1e-6);
        // Packed for pass 4 with no radius: every hashed point is the seed's own.
        let p = GridPos { texel: [0, 0], frac: [1.0, 0.5] };
        assert_eq!(ground_colour(&u, &imagery, &p, 7) & 0xff, 128);
    }
}
