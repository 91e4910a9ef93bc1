//! How it works: the amplified frame against the photograph frame, pixel for pixel of one camera,
//! on the CPU. Both come as sRGB bytes and are decoded to linear light first; every mean is taken
//! there, then turned to CIELAB and compared by CIEDE2000 (`colour`). Three groupings:
//! - **imagery texel footprints**: the pixels whose terrain point falls in one level-0 imagery
//!   texel (`PixelKeys::texel`). A footprint counts when it has `MIN_PIXELS_PER_TEXEL` pixels or
//!   more and at least half of them wooded; its mean colour in each frame is what the
//!   photograph says of that texel and what the amplified frame makes of it. Within it the spread
//!   (standard deviation) of the frame's luminance is its detail: a flat paint of the photograph's
//!   colour has none.
//! - **blocks** of `BLOCK_PX` × `BLOCK_PX` pixels (full blocks only), for far views where a texel
//!   is a pixel or less and footprints do not form: a block counts when at least half its pixels
//!   are wooded.
//! - **changed share**: of the wooded pixels, those whose bytes differ between the frames.
//! - **edges** (filled in by `measure_view`, which has the seeds): whether the trees' edges
//!   follow the land cover's cells (`edges`).
//!
//! A grouping with nothing counted has no ΔE figures (`None`), rather than a 0 that would read as
//! a perfect match.

use std::collections::BTreeMap;

use image::RgbaImage;
use serde::Serialize;

use super::PhotoError;
use super::colour::{Lab, delta_e_2000, lab_of_linear, linear_table, luminance};
use super::edges::Edges;
use crate::reference::worst::worst;

/// A pixel whose terrain point lies in no imagery texel: sky, or beyond the imagery.
pub const NO_TEXEL: u64 = u64::MAX;

/// Fewest pixels a texel footprint needs to count. A footprint of one to three pixels is mostly
/// edge (pixels half in a neighbouring texel) and its mean is one pixel's colour: it says nothing
/// about the texel, and the spread of luminance inside it is no measure of detail. Four is a
/// texel at least 2 × 2 pixels on screen; at nc's 7 m imagery texels that is within about 1.5 km
/// of a 640-pixel, 60° view looking down.
pub const MIN_PIXELS_PER_TEXEL: usize = 4;

/// Edge of the pixel blocks, pixels: 5 × 5 keeps a block near a few texels in the far views
/// (where a texel is about a pixel) and small against the forest stands it averages.
pub const BLOCK_PX: u32 = 5;

/// The level-0 imagery texel (column, row) as a key of `PixelKeys::texel`.
pub fn texel_key(texel: [u32; 2]) -> u64 {
    (u64::from(texel[1]) << 32) | u64::from(texel[0])
}

/// The texel (column, row) of a `texel_key`.
pub fn key_texel(key: u64) -> [u32; 2] {
    [(key & 0xffff_ffff) as u32, (key >> 32) as u32]
}

/// Pixel `i`'s RGB of sRGB `image` in linear light, by `table` (`colour::linear_table`).
pub(super) fn linear_at(image: &RgbaImage, i: usize, table: &[f64; 256]) -> [f64; 3] {
    let p = &image.as_raw()[4 * i..4 * i + 3];
    [table[p[0] as usize], table[p[1] as usize], table[p[2] as usize]]
}

/// What each pixel of a view stands on, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct PixelKeys {
    /// The frames' size, pixels.
    pub size_px: [u32; 2],
    /// Per pixel, the level-0 imagery texel its terrain point falls in (`texel_key`), or `NO_TEXEL`.
    pub texel: Vec<u64>,
    /// Per pixel, whether the land cover there grows trees (`keys`).
    pub wooded: Vec<bool>,
    /// Per pixel, the bilinear share of tree-growing cells around its terrain point (0 to 1).
    pub wooded_fraction: Vec<f32>,
    /// Per pixel, whether the four cells around its terrain point all grow seeds: seed selection
    /// dithers the class edges between such cells, and keeps the others (shores, the data's
    /// edge) on the land cover's cells.
    pub seeded_around: Vec<bool>,
    /// Per pixel, the horizontal area of ground it shows, m² (0 for the sky).
    pub ground_area_m2: Vec<f32>,
    /// Per pixel, the horizontal distance from the camera to its terrain point, m (infinite for
    /// the sky).
    pub ground_distance_m: Vec<f32>,
    /// Per pixel, the view depth of its terrain point, m (infinite for the sky).
    pub ground_depth_m: Vec<f32>,
}

/// CIEDE2000 over a grouping's members.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct DeltaE {
    /// The mean.
    pub mean: f64,
    /// The 95th percentile, nearest rank (always a member's value).
    pub p95: f64,
    /// The largest.
    pub max: f64,
}

impl DeltaE {
    /// The figures of `values` (`None` for none); an error names a value that is not finite.
    pub fn of(values: &[f64]) -> Result<Option<Self>, PhotoError> {
        if values.is_empty() {
            return Ok(None);
        }
        let max = worst(values.iter().copied()).map_err(|e| PhotoError::NotFinite(e.value))?;
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let rank = (0.95 * sorted.len() as f64).ceil() as usize;
        let p95 = sorted[rank.clamp(1, sorted.len()) - 1];
        Ok(Some(Self { mean: values.iter().sum::<f64>() / values.len() as f64, p95, max }))
    }
}

/// The imagery texel footprints' figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Footprints {
    /// Footprints counted: `MIN_PIXELS_PER_TEXEL` pixels or more, at least half wooded.
    pub counted: usize,
    /// CIEDE2000 between the frames' mean colours, per footprint.
    pub delta_e: Option<DeltaE>,
    /// Mean L* of the amplified frame's footprint means.
    pub amplified_mean_l: Option<f64>,
    /// Mean L* of the photograph frame's footprint means.
    pub photograph_mean_l: Option<f64>,
    /// Mean over footprints of the standard deviation of the amplified frame's luminance (CIE Y,
    /// linear, 0 to 1) within each.
    pub amplified_detail_y: Option<f64>,
    /// The same of the photograph frame (its texels magnified and filtered), for scale.
    pub photograph_detail_y: Option<f64>,
    /// Mean over footprints of the amplified frame's luminance contrast within each: its standard
    /// deviation over its mean (a footprint of black counts 0). Detail that does not scale with
    /// the footprint's brightness: a forest made darker keeps its contrast, a flat paint has none.
    pub amplified_contrast: Option<f64>,
    /// The same of the photograph frame.
    pub photograph_contrast: Option<f64>,
}

/// The pixel blocks' figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Blocks {
    /// Blocks counted: at least half their pixels wooded.
    pub counted: usize,
    /// CIEDE2000 between the frames' mean colours, per block.
    pub delta_e: Option<DeltaE>,
    /// Every counted block's ΔE, row by row, for pooling views (`DeltaE::of`).
    #[serde(skip)]
    pub values: Vec<f64>,
}

/// The amplified frame against the photograph frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PhotoFigures {
    /// The frames' size, pixels.
    pub size_px: [u32; 2],
    /// Per imagery texel footprint.
    pub texels: Footprints,
    /// Per `BLOCK_PX` block.
    pub blocks: Blocks,
    /// Pixels whose land cover grows trees.
    pub wooded_px: usize,
    /// Of those, pixels whose bytes differ between the frames.
    pub changed_px: usize,
    /// `changed_px` / `wooded_px` (`None` without wooded pixels).
    pub changed_share: Option<f64>,
    /// Whether the trees' edges follow the land cover's cells (`edges`; `None` where the
    /// amplified frame's seeds are not at hand: a frame given as an image, or no land cover).
    pub edges: Option<Edges>,
}

/// A footprint's or block's pixels, summed in linear light.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct Sums {
    pub(super) pixels: usize,
    wooded: usize,
    amplified: [f64; 3],
    photograph: [f64; 3],
}

impl Sums {
    pub(super) fn add(&mut self, amplified: [f64; 3], photograph: [f64; 3], wooded: bool) {
        self.pixels += 1;
        self.wooded += usize::from(wooded);
        for c in 0..3 {
            self.amplified[c] += amplified[c];
            self.photograph[c] += photograph[c];
        }
    }

    fn mostly_wooded(&self) -> bool {
        2 * self.wooded >= self.pixels && self.pixels > 0
    }

    /// The amplified and the photograph's mean colours, linear.
    pub(super) fn means(&self) -> ([f64; 3], [f64; 3]) {
        let n = self.pixels.max(1) as f64;
        (self.amplified.map(|v| v / n), self.photograph.map(|v| v / n))
    }

    /// The means' Labs and their CIEDE2000.
    fn compared(&self) -> (Lab, Lab, f64) {
        let (a, p) = self.means();
        let (a, p) = (lab_of_linear(a), lab_of_linear(p));
        (a, p, delta_e_2000(p, a))
    }
}

/// Measures `amplified` against `photograph` (sRGB frames of one camera) over `keys`.
pub fn measure(
    amplified: &RgbaImage,
    photograph: &RgbaImage,
    keys: &PixelKeys,
) -> Result<PhotoFigures, PhotoError> {
    let size_px = [amplified.width(), amplified.height()];
    let pixels = (size_px[0] * size_px[1]) as usize;
    if [photograph.width(), photograph.height()] != size_px
        || keys.size_px != size_px
        || keys.texel.len() != pixels
        || keys.wooded.len() != pixels
        || keys.wooded_fraction.len() != pixels
        || keys.seeded_around.len() != pixels
        || keys.ground_area_m2.len() != pixels
        || keys.ground_distance_m.len() != pixels
        || keys.ground_depth_m.len() != pixels
    {
        return Err(PhotoError::Size {
            amplified: size_px,
            photograph: [photograph.width(), photograph.height()],
            keys: keys.size_px,
        });
    }
    let table = linear_table();
    let linear = |image: &RgbaImage, i: usize| linear_at(image, i, &table);

    // Footprints: sums, then the luminance spread about each one's mean (a second pass, so a flat
    // footprint's spread is exactly 0).
    let mut texels: BTreeMap<u64, Sums> = BTreeMap::new();
    let (mut wooded_px, mut changed_px) = (0, 0);
    for i in 0..pixels {
        let wooded = keys.wooded[i];
        if wooded {
            wooded_px += 1;
            changed_px +=
                usize::from(amplified.as_raw()[4 * i..4 * i + 3] != photograph.as_raw()[4 * i..4 * i + 3]);
        }
        if keys.texel[i] != NO_TEXEL {
            texels.entry(keys.texel[i]).or_default().add(linear(amplified, i), linear(photograph, i), wooded);
        }
    }
    texels.retain(|_, s| s.pixels >= MIN_PIXELS_PER_TEXEL && s.mostly_wooded());
    let mut spread: BTreeMap<u64, [f64; 2]> = BTreeMap::new();
    for i in 0..pixels {
        let Some(sums) = texels.get(&keys.texel[i]) else { continue };
        let (a, p) = sums.means();
        let d =
            [luminance(linear(amplified, i)) - luminance(a), luminance(linear(photograph, i)) - luminance(p)];
        let s = spread.entry(keys.texel[i]).or_default();
        s[0] += d[0] * d[0];
        s[1] += d[1] * d[1];
    }
    let (mut delta_e, mut l_sums, mut detail) = (Vec::with_capacity(texels.len()), [0.0; 2], [0.0; 2]);
    let mut contrast = [0.0; 2];
    for (key, sums) in &texels {
        let (a, p, de) = sums.compared();
        delta_e.push(de);
        l_sums[0] += a.l;
        l_sums[1] += p.l;
        let s = spread.get(key).copied().unwrap_or_default();
        let std = [0, 1].map(|k| (s[k] / sums.pixels as f64).sqrt());
        let (mean_a, mean_p) = sums.means();
        for (k, mean_y) in [luminance(mean_a), luminance(mean_p)].into_iter().enumerate() {
            detail[k] += std[k];
            if mean_y > 0.0 {
                contrast[k] += std[k] / mean_y;
            }
        }
    }
    let counted = texels.len();
    let per_texel = |sum: f64| (counted > 0).then(|| sum / counted as f64);
    let footprints = Footprints {
        counted,
        delta_e: DeltaE::of(&delta_e)?,
        amplified_mean_l: per_texel(l_sums[0]),
        photograph_mean_l: per_texel(l_sums[1]),
        amplified_detail_y: per_texel(detail[0]),
        photograph_detail_y: per_texel(detail[1]),
        amplified_contrast: per_texel(contrast[0]),
        photograph_contrast: per_texel(contrast[1]),
    };

    let mut block_values = Vec::new();
    for by in 0..size_px[1] / BLOCK_PX {
        for bx in 0..size_px[0] / BLOCK_PX {
            let mut sums = Sums::default();
            for y in by * BLOCK_PX..(by + 1) * BLOCK_PX {
                for x in bx * BLOCK_PX..(bx + 1) * BLOCK_PX {
                    let i = (y * size_px[0] + x) as usize;
                    sums.add(linear(amplified, i), linear(photograph, i), keys.wooded[i]);
                }
            }
            if sums.mostly_wooded() {
                block_values.push(sums.compared().2);
            }
        }
    }
    let blocks =
        Blocks { counted: block_values.len(), delta_e: DeltaE::of(&block_values)?, values: block_values };
    Ok(PhotoFigures {
        size_px,
        texels: footprints,
        blocks,
        wooded_px,
        changed_px,
        changed_share: (wooded_px > 0).then(|| changed_px as f64 / wooded_px as f64),
        edges: None,
    })
}

#[cfg(test)]
impl PixelKeys {
    /// Keys of a `size_px` view whose pixels stand on `texel` (one key each), all wooded, inside
    /// forest (share 1, every cell seeded), each on 1 m² of ground 1 m away.
    pub(super) fn forest(size_px: [u32; 2], texel: Vec<u64>) -> Self {
        let n = texel.len();
        Self {
            size_px,
            texel,
            wooded: vec![true; n],
            wooded_fraction: vec![1.0; n],
            seeded_around: vec![true; n],
            ground_area_m2: vec![1.0; n],
            ground_distance_m: vec![1.0; n],
            ground_depth_m: vec![1.0; n],
        }
    }
}

#[cfg(test)]
mod tests;
