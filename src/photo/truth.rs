//! How it works: the amplified frame against a ground truth of the same view (`terramp truth`,
//! perhaps by another build: "today's truth" of issue 43), in FLIP (`reference::image_metrics::flip_map`)
//! over the pixels whose terrain lies within the mesh band (`draw_seeds.reach_m[0]`, view depth),
//! in colour and in **luminance only**: both images turned to grey (CIE Y of their linear light,
//! encoded back to sRGB) before FLIP, so that a forest recoloured to follow its photograph is
//! judged on its light and shade and not on its hue; and in **detail** only: each grey image's
//! luminance divided by its mean over the imagery texel footprint it lies in (`keys`; pixels
//! without one keep their own) and set to mid grey's (0.18) before encoding, so that a forest made
//! as dark as its photograph is judged on its shading, gaps and crowns and not on its brightness.
//! A flat paint of the imagery's colour has no detail and FLIP sees it; so does a forest with
//! fewer trees.

use std::collections::HashMap;

use image::RgbaImage;
use serde::Serialize;

#[cfg(feature = "flip")]
use super::PhotoError;
use super::colour::{linear_table, luminance};
use super::measure::{NO_TEXEL, PixelKeys};
use crate::texcell::pyramid::encode_srgb;

/// FLIP of the amplified frame against a truth over the mesh band.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TruthFlip {
    /// The band's far edge, metres of view depth.
    pub mesh_reach_m: f64,
    /// Pixels whose terrain lies nearer.
    pub pixels: usize,
    /// Mean FLIP over them, in colour (`None` without pixels).
    pub colour: Option<f64>,
    /// Mean FLIP over them, both images in grey.
    pub luminance: Option<f64>,
    /// Mean FLIP over them, both images in grey over their footprints' means.
    pub detail: Option<f64>,
}

/// Mid grey's luminance, where `detail` puts every footprint's mean.
const MID_GREY_Y: f64 = 0.18;

/// Each pixel's CIE Y in linear light.
fn luminances(image: &RgbaImage) -> Vec<f64> {
    let table = linear_table();
    image.pixels().map(|p| luminance([p[0], p[1], p[2]].map(|v| table[v as usize]))).collect()
}

/// `y` (one per pixel of `like`) as a grey sRGB image the size of `like`.
fn grey_image(like: &RgbaImage, y: &[f64]) -> RgbaImage {
    let mut out = like.clone();
    for (p, &y) in out.pixels_mut().zip(y) {
        let byte = encode_srgb(y as f32);
        p.0 = [byte, byte, byte, p[3]];
    }
    out
}

/// `image` in grey: each pixel's CIE Y in linear light, encoded to sRGB, in R, G and B.
pub fn grey(image: &RgbaImage) -> RgbaImage {
    grey_image(image, &luminances(image))
}

/// `image`'s detail in grey: each pixel's Y over the mean Y of its footprint (`keys.texel`), times
/// `MID_GREY_Y`; a pixel without a footprint, or in a black one, is mid grey.
pub fn detail(image: &RgbaImage, keys: &PixelKeys) -> RgbaImage {
    let y = luminances(image);
    let mut sums: HashMap<u64, (f64, u32)> = HashMap::new();
    for (&key, &v) in keys.texel.iter().zip(&y) {
        let s = sums.entry(key).or_default();
        s.0 += v;
        s.1 += 1;
    }
    let relative: Vec<f64> = keys
        .texel
        .iter()
        .zip(&y)
        .map(|(key, &v)| match sums.get(key) {
            Some(&(sum, n)) if *key != NO_TEXEL && sum > 0.0 => MID_GREY_Y * v * f64::from(n) / sum,
            _ => MID_GREY_Y,
        })
        .collect();
    grey_image(image, &relative)
}

/// `amplified` against `truth` (same size) over the pixels `keys` puts within `mesh_reach_m`.
#[cfg(feature = "flip")]
pub fn truth_flip(
    amplified: &RgbaImage,
    truth: &RgbaImage,
    keys: &PixelKeys,
    mesh_reach_m: f64,
) -> Result<TruthFlip, PhotoError> {
    use crate::reference::image_metrics::flip_map;
    let map = |a: &RgbaImage, b: &RgbaImage| flip_map(a, b).map_err(PhotoError::Truth);
    let (colour, luminance) = (map(truth, amplified)?, map(&grey(truth), &grey(amplified))?);
    let detail = map(&detail(truth, keys), &detail(amplified, keys))?;
    let near: Vec<usize> = (0..keys.ground_depth_m.len())
        .filter(|&i| f64::from(keys.ground_depth_m[i]) < mesh_reach_m)
        .collect();
    let mean = |values: &[f32]| {
        (!near.is_empty())
            .then(|| near.iter().map(|&i| f64::from(values[i])).sum::<f64>() / near.len() as f64)
    };
    Ok(TruthFlip {
        mesh_reach_m,
        pixels: near.len(),
        colour: mean(&colour),
        luminance: mean(&luminance),
        detail: mean(&detail),
    })
}
