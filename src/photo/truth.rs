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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photo::measure::texel_key;

    /// An 8 × 8 frame of texels 4 × 4 pixels, its pixels' linear greys from `f(x, y)`.
    fn frame(f: impl Fn(u32, u32) -> f64) -> (RgbaImage, PixelKeys) {
        let image = RgbaImage::from_fn(8, 8, |x, y| {
            let v = encode_srgb(f(x, y) as f32);
            image::Rgba([v, v, v, 255])
        });
        let texel = (0..64u32).map(|i| texel_key([i % 8 / 4, i / 8 / 4])).collect();
        (image, PixelKeys::forest([8, 8], texel))
    }

    #[test]
    fn grey_is_the_luminance_in_srgb() {
        let colours = RgbaImage::from_fn(3, 1, |x, _| {
            let [r, g, b] = [[0, 0, 0], [255, 255, 255], [0, 255, 0]][x as usize];
            image::Rgba([r, g, b, 255])
        });
        let g = grey(&colours);
        assert_eq!([g.get_pixel(0, 0).0, g.get_pixel(1, 0).0], [[0, 0, 0, 255], [255, 255, 255, 255]]);
        // Pure green's luminance is its weight in CIE Y.
        let v = encode_srgb(0.715_152_2);
        assert_eq!(g.get_pixel(2, 0).0, [v, v, v, 255]);
    }

    #[test]
    fn detail_ignores_each_footprint_s_brightness_and_a_flat_paint_has_none() {
        let pattern = |x: u32, y: u32| 0.05 + 0.1 * f64::from((x * 3 + y * 5) % 4);
        let (a, keys) = frame(pattern);
        // The same pattern, each footprint made brighter or darker by its own factor.
        let (b, _) = frame(|x, y| pattern(x, y) * [0.5, 2.0, 1.5, 0.8][(x / 4 + 2 * (y / 4)) as usize]);
        let (da, db) = (detail(&a, &keys), detail(&b, &keys));
        let most = da.as_raw().iter().zip(db.as_raw()).map(|(p, q)| p.abs_diff(*q)).max().unwrap();
        assert!(most <= 2, "the bytes' rounding only: {most}");
        let (flat, _) = frame(|x, y| [0.1, 0.3, 0.02, 0.6][(x / 4 + 2 * (y / 4)) as usize]);
        let mid = encode_srgb(MID_GREY_Y as f32);
        assert!(detail(&flat, &keys).pixels().all(|p| p[0].abs_diff(mid) <= 1));
        assert!(da.pixels().any(|p| p[0].abs_diff(mid) > 20), "the pattern's detail shows");
    }

    #[cfg(feature = "flip")]
    #[test]
    fn a_frame_against_itself_is_zero_over_the_band_and_the_band_is_its_near_pixels() {
        let (a, mut keys) = frame(|x, y| 0.05 + 0.1 * f64::from((x + y) % 3));
        for (i, d) in keys.ground_depth_m.iter_mut().enumerate() {
            *d = if i < 24 { 100.0 } else { 900.0 };
        }
        let same = truth_flip(&a, &a, &keys, 800.0).unwrap();
        assert_eq!(
            (same.pixels, same.colour, same.luminance, same.detail),
            (24, Some(0.0), Some(0.0), Some(0.0))
        );
        let (b, _) = frame(|x, y| 0.4 + 0.1 * f64::from((x + 2 * y) % 3));
        let other = truth_flip(&a, &b, &keys, 800.0).unwrap();
        assert!(other.colour.unwrap() > 0.05 && other.luminance.unwrap() > 0.05, "{other:?}");
        assert_eq!(truth_flip(&a, &a, &keys, 50.0).unwrap().colour, None, "no pixels, no figure");
    }
}
