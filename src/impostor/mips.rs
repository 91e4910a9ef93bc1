//! How it works: mip chains for alpha-tested RGBA8 sRGB images (straight alpha). Each level is a
//! 2 × 2 box filter of the level above, kept in f32: colour averaged in linear light weighted by
//! alpha (a premultiplied average, so transparent texels add nothing), alpha averaged plainly.
//! Averaging alone makes alpha-tested foliage thin out and vanish with distance, so, given the
//! alpha cutoff, each region's alpha at each level is scaled by the factor (found by bisection)
//! that keeps the fraction of its texels passing the cutoff equal to that of level 0 (Castaño,
//! "Computing alpha mipmaps", 2010); the unscaled values feed the next level. Regions are the
//! atlas rectangles (so one sparse plane does not borrow another's coverage), or the whole image.
//!
//! Finally every level is dilated: texels with alpha 0 take the mean colour of their covered
//! neighbours, wave after wave (16 waves, then the mean covered colour), so bilinear filtering at
//! a cut-out's edge blends towards the right colour instead of black.

use std::sync::LazyLock;

/// An RGBA8 image and its mips, each level top row first.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MipChain {
    /// Level 0's width and height in texels.
    pub size: [u32; 2],
    /// Level M is [`mip_size`]`(size, M)`, 4 bytes per texel.
    pub levels: Vec<Vec<u8>>,
}

impl MipChain {
    /// Levels held, level 0 included.
    pub fn mip_count(&self) -> u32 {
        self.levels.len() as u32
    }

    /// Level `level`'s width and height in texels.
    pub fn level_size(&self, level: u32) -> [u32; 2] {
        mip_size(self.size, level)
    }
}

/// Level `level`'s size: halved per level, never below 1 (also for levels of 32 and more, which a
/// plain shift would overflow).
pub fn mip_size(size: [u32; 2], level: u32) -> [u32; 2] {
    size.map(|s| s.checked_shr(level).unwrap_or(0).max(1))
}

/// A rectangle of texels at level 0.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TexelRect {
    /// Left edge, in texels from the image's left.
    pub x: u32,
    /// Top edge, in texels from the image's top row.
    pub y: u32,
    /// Texels across, from `x` rightwards.
    pub width: u32,
    /// Texels down, from `y`.
    pub height: u32,
}

impl TexelRect {
    /// The texels of level `level` this rectangle touches.
    fn at_level(self, level: u32, size: [u32; 2]) -> TexelRect {
        let scale = 1u32 << level;
        let (x0, y0) = (self.x / scale, self.y / scale);
        let x1 = (self.x + self.width).div_ceil(scale).min(size[0]);
        let y1 = (self.y + self.height).div_ceil(scale).min(size[1]);
        TexelRect { x: x0, y: y0, width: x1.saturating_sub(x0), height: y1.saturating_sub(y0) }
    }

    fn texels(self, width: u32) -> impl Iterator<Item = usize> {
        (self.y..self.y + self.height)
            .flat_map(move |y| (self.x..self.x + self.width).map(move |x| (y * width + x) as usize))
    }
}

static SRGB_TO_LINEAR: LazyLock<[f32; 256]> = LazyLock::new(|| {
    std::array::from_fn(|i| {
        let c = i as f32 / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    })
});

fn linear_to_srgb(c: f32) -> u8 {
    let c = c.clamp(0.0, 1.0);
    let s = if c <= 0.003_130_8 { c * 12.92 } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (s * 255.0).round() as u8
}

/// `level0` (RGBA8 sRGB, straight alpha, `size`) with `mip_count` levels in all (at least 1).
/// With `alpha_cutoff`, the coverage of each of `regions` (the whole image when empty) is kept
/// across levels.
pub fn build_mip_chain(
    mut level0: Vec<u8>,
    size: [u32; 2],
    mip_count: u32,
    alpha_cutoff: Option<f32>,
    regions: &[TexelRect],
) -> MipChain {
    let whole = [TexelRect { x: 0, y: 0, width: size[0], height: size[1] }];
    let regions = if regions.is_empty() { &whole[..] } else { regions };
    let linear = |c: u8| SRGB_TO_LINEAR[c as usize];
    let mut current: Vec<[f32; 4]> = level0
        .chunks_exact(4)
        .map(|t| [linear(t[0]), linear(t[1]), linear(t[2]), f32::from(t[3]) / 255.0])
        .collect();
    let targets: Vec<f32> = match alpha_cutoff {
        Some(cutoff) => {
            let alpha: Vec<f32> = current.iter().map(|t| t[3]).collect();
            regions.iter().map(|r| coverage(&alpha, size[0], *r, cutoff, 1.0)).collect()
        }
        None => Vec::new(),
    };
    dilate(&mut level0, size);
    let mut levels = vec![level0];
    for level in 1..mip_count.max(1) {
        let (from, to) = (mip_size(size, level - 1), mip_size(size, level));
        current = downsample(&current, from, to);
        let mut alpha: Vec<f32> = current.iter().map(|t| t[3]).collect();
        if let Some(cutoff) = alpha_cutoff {
            for (region, &target) in regions.iter().zip(&targets) {
                let r = region.at_level(level, to);
                let scale = coverage_scale(&alpha, to[0], r, cutoff, target);
                for i in r.texels(to[0]) {
                    alpha[i] = (alpha[i] * scale).min(1.0);
                }
            }
        }
        let mut texels: Vec<u8> = current
            .iter()
            .zip(&alpha)
            .flat_map(|(t, &a)| {
                [linear_to_srgb(t[0]), linear_to_srgb(t[1]), linear_to_srgb(t[2]), (a * 255.0).round() as u8]
            })
            .collect();
        dilate(&mut texels, to);
        levels.push(texels);
    }
    MipChain { size, levels }
}

/// The 2 × 2 box filter (clamped at odd edges), alpha-weighted in colour.
fn downsample(texels: &[[f32; 4]], from: [u32; 2], to: [u32; 2]) -> Vec<[f32; 4]> {
    let mut out = Vec::with_capacity((to[0] * to[1]) as usize);
    for y in 0..to[1] {
        for x in 0..to[0] {
            let (mut sum, mut plain, mut alpha) = ([0.0f32; 3], [0.0f32; 3], 0.0f32);
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let sx = (2 * x + dx).min(from[0] - 1);
                let sy = (2 * y + dy).min(from[1] - 1);
                let t = texels[(sy * from[0] + sx) as usize];
                for k in 0..3 {
                    sum[k] += t[k] * t[3];
                    plain[k] += t[k];
                }
                alpha += t[3];
            }
            let rgb = if alpha > 0.0 { sum.map(|s| s / alpha) } else { plain.map(|s| s / 4.0) };
            out.push([rgb[0], rgb[1], rgb[2], alpha / 4.0]);
        }
    }
    out
}

/// The fraction of `region`'s texels whose alpha, times `scale` (clamped to 1), passes `cutoff`.
fn coverage(alpha: &[f32], width: u32, region: TexelRect, cutoff: f32, scale: f32) -> f32 {
    let count = region.width as usize * region.height as usize;
    if count == 0 {
        return 0.0;
    }
    let passing = region.texels(width).filter(|&i| (alpha[i] * scale).min(1.0) >= cutoff).count();
    passing as f32 / count as f32
}

/// The alpha scale that brings `region`'s coverage closest to `target` (1 when it has none).
fn coverage_scale(alpha: &[f32], width: u32, region: TexelRect, cutoff: f32, target: f32) -> f32 {
    if target <= 0.0 || region.width == 0 || region.height == 0 {
        return 1.0;
    }
    let (mut lo, mut hi) = (0.0f32, 64.0f32);
    for _ in 0..20 {
        let mid = 0.5 * (lo + hi);
        if coverage(alpha, width, region, cutoff, mid) < target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi
}

/// Gives every texel with alpha 0 the mean colour of its nearest covered neighbours.
fn dilate(texels: &mut [u8], size: [u32; 2]) {
    const WAVES: usize = 16;
    let (w, h) = (size[0] as i64, size[1] as i64);
    let mut filled: Vec<bool> = texels.chunks_exact(4).map(|t| t[3] > 0).collect();
    let covered = filled.iter().filter(|&&f| f).count();
    if covered == 0 || covered == filled.len() {
        return;
    }
    let mut mean = [0u64; 3];
    for t in texels.chunks_exact(4).filter(|t| t[3] > 0) {
        for k in 0..3 {
            mean[k] += u64::from(t[k]);
        }
    }
    let mean = mean.map(|m| (m / covered as u64) as u8);
    let neighbours = |i: usize| {
        let (x, y) = (i as i64 % w, i as i64 / w);
        (-1..=1i64)
            .flat_map(move |dy| (-1..=1i64).map(move |dx| (x + dx, y + dy)))
            .filter(move |&(nx, ny)| (nx, ny) != (x, y) && nx >= 0 && ny >= 0 && nx < w && ny < h)
            .map(move |(nx, ny)| (ny * w + nx) as usize)
    };
    let mut frontier: Vec<usize> =
        (0..filled.len()).filter(|&i| !filled[i] && neighbours(i).any(|n| filled[n])).collect();
    for _ in 0..WAVES {
        if frontier.is_empty() {
            break;
        }
        let colours: Vec<[u8; 3]> = frontier
            .iter()
            .map(|&i| {
                let (mut sum, mut n) = ([0u32; 3], 0u32);
                for j in neighbours(i).filter(|&j| filled[j]) {
                    for k in 0..3 {
                        sum[k] += u32::from(texels[4 * j + k]);
                    }
                    n += 1;
                }
                sum.map(|s| (s / n.max(1)) as u8)
            })
            .collect();
        for (&i, c) in frontier.iter().zip(&colours) {
            texels[4 * i..4 * i + 3].copy_from_slice(c);
            filled[i] = true;
        }
        let mut next: Vec<usize> =
            frontier.iter().flat_map(|&i| neighbours(i)).filter(|&j| !filled[j]).collect();
        next.sort_unstable();
        next.dedup();
        frontier = next;
    }
    for (i, t) in texels.chunks_exact_mut(4).enumerate() {
        if !filled[i] {
            t[..3].copy_from_slice(&mean);
        }
    }
}
