//! How it works: a frame's error against its ground truth, for the whole frame and per distance
//! band, so each representation is judged where it is drawn. A pixel's distance is that of the
//! nearest of its truth samples (reversed-Z: the largest depth), so a tree in front of far terrain
//! counts in the tree's band; the sky is in no band, only in the whole frame. Bands come from the
//! settings measured (`bands`): the mesh reach, each billboard cloud's reach, then beyond the last
//! (reaches are those of a seed of `seeds.reference_height_m`; smaller seeds switch sooner).
//!
//! Three errors, each from one whole-frame map averaged over the band's pixels:
//! - **PSNR**: the mean squared error over R, G and B (`image_metrics::squared_errors`);
//! - **SSIM**: the luma SSIM map (`image_metrics::ssim_map`), each window counted at its centre;
//! - **FLIP** (LDR-FLIP, Andersson et al. 2020): NVIDIA's reference implementation through the
//!   `nv-flip` bindings (gfx-rs; wgpu's own image tests use them), at its default 67 pixels per
//!   degree (a 0.7 m viewing distance from a 24-inch 4K screen). It models what a viewer sees
//!   flipping between the two images (colour and edge differences weighed by the eye's contrast
//!   sensitivity), which PSNR and SSIM do not: 0 is no visible difference, 1 the largest.

use serde::Serialize;

use super::Truth;
use crate::config::Settings;
use crate::reference::image_metrics::{
    ImageMetricError, capped_psnr_db, psnr_of_mse, squared_errors, ssim_map,
};

/// A distance band, metres from the camera.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Band {
    /// What is drawn there ("meshes", "clouds 1", …, "beyond").
    pub name: String,
    /// Nearest distance, metres.
    pub from_m: f64,
    /// Farthest distance (excluded), metres; infinite for the last.
    pub to_m: f64,
}

/// The bands of `settings`: up to each `draw_seeds.reach_m`, then beyond the last.
pub fn bands(settings: &Settings) -> Vec<Band> {
    let mut out = Vec::new();
    let mut from_m = 0.0;
    for (lod, &to_m) in settings.draw_seeds.reach_m.iter().enumerate() {
        if to_m <= from_m {
            continue;
        }
        let name = if lod == 0 { "meshes".to_owned() } else { format!("clouds {lod}") };
        out.push(Band { name, from_m, to_m });
        from_m = to_m;
    }
    out.push(Band { name: "beyond".into(), from_m, to_m: f64::INFINITY });
    out
}

/// One region's errors.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RegionError {
    /// The band (the whole frame: 0 to ∞, sky included).
    pub band: Band,
    /// Its pixels.
    pub pixels: u64,
    /// Mean squared error over R, G and B, in 8-bit steps squared (NaN without pixels).
    pub mse: f64,
    /// PSNR over its pixels, dB (capped at `PSNR_CAP_DB`; NaN without pixels).
    pub psnr_db: f64,
    /// Mean SSIM of the windows centred in it (NaN without any).
    pub ssim: f64,
    /// Mean FLIP error of its pixels (NaN without pixels).
    pub flip: f64,
}

/// A frame against its truth: the whole frame, then each band.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameError {
    /// The whole frame.
    pub frame: RegionError,
    /// Each band, nearest first.
    pub bands: Vec<RegionError>,
}

/// The distance of each pixel of `truth`, metres (∞ for the sky): its nearest sample's.
pub fn pixel_distances_m(truth: &Truth, near_m: f64) -> Vec<f64> {
    let [w, h] = truth.size_px;
    let ss = truth.supersample as usize;
    let row = w as usize * ss;
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h as usize {
        for x in 0..w as usize {
            let nearest = (0..ss)
                .flat_map(|sy| (0..ss).map(move |sx| (y * ss + sy) * row + x * ss + sx))
                .map(|i| truth.depth.get(i).copied().unwrap_or(0.0))
                .fold(0.0f32, f32::max);
            out.push(if nearest > 0.0 { near_m / f64::from(nearest) } else { f64::INFINITY });
        }
    }
    out
}

/// The FLIP error map of `test` against `reference` (sRGB, alpha ignored), one value per pixel.
pub fn flip_map(reference: &image::RgbaImage, test: &image::RgbaImage) -> Result<Vec<f32>, ImageMetricError> {
    if reference.dimensions() != test.dimensions() {
        return Err(ImageMetricError::SizeMismatch { a: reference.dimensions(), b: test.dimensions() });
    }
    let rgb = |image: &image::RgbaImage| {
        let bytes: Vec<u8> = image.pixels().flat_map(|p| [p[0], p[1], p[2]]).collect();
        nv_flip::FlipImageRgb8::with_data(image.width(), image.height(), &bytes)
    };
    Ok(nv_flip::flip(rgb(reference), rgb(test), nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec())
}

/// Several views' errors as one: squared errors, SSIM windows and FLIP pooled over all their
/// pixels (bands matched by position; an empty band adds nothing).
pub fn pool(errors: &[FrameError]) -> Option<FrameError> {
    let first = errors.first()?;
    let pooled = |regions: Vec<&RegionError>| {
        let kept: Vec<&&RegionError> = regions.iter().filter(|r| r.pixels > 0).collect();
        let pixels: u64 = kept.iter().map(|r| r.pixels).sum();
        // Weighted by pixels; a region without a figure (a band too thin for an SSIM window)
        // is left out of that figure's mean.
        let mean = |f: &dyn Fn(&RegionError) -> f64| {
            let with: Vec<(f64, f64)> =
                kept.iter().map(|r| (f(r), r.pixels as f64)).filter(|(v, _)| v.is_finite()).collect();
            with.iter().map(|(v, n)| v * n).sum::<f64>() / with.iter().map(|(_, n)| n).sum::<f64>()
        };
        let mse = mean(&|r| r.mse);
        RegionError {
            band: regions[0].band.clone(),
            pixels,
            mse,
            psnr_db: if pixels == 0 { f64::NAN } else { capped_psnr_db(psnr_of_mse(mse)) },
            ssim: mean(&|r| r.ssim),
            flip: mean(&|r| r.flip),
        }
    };
    Some(FrameError {
        frame: pooled(errors.iter().map(|e| &e.frame).collect()),
        bands: (0..first.bands.len())
            .map(|b| pooled(errors.iter().filter_map(|e| e.bands.get(b)).collect()))
            .collect(),
    })
}

/// `frame` against `truth`'s image, whole and per band of `bands`.
pub fn frame_error(
    truth: &Truth,
    near_m: f64,
    frame: &image::RgbaImage,
    bands: &[Band],
) -> Result<FrameError, ImageMetricError> {
    let reference = &truth.colour;
    let squared = squared_errors(reference, frame)?;
    let ssim = ssim_map(reference, frame)?;
    let flip = flip_map(reference, frame)?;
    let distance = pixel_distances_m(truth, near_m);
    let width = reference.width() as usize;
    let region = |band: Band, within: &dyn Fn(f64) -> bool| {
        let pixels: Vec<usize> = (0..distance.len()).filter(|&i| within(distance[i])).collect();
        let n = pixels.len() as f64;
        let mse = pixels.iter().map(|&i| squared[i]).sum::<f64>() / n;
        let windows: Vec<f64> = (0..ssim.values.len())
            .filter(|&k| {
                let (x, y) = (k % ssim.width + ssim.offset_px, k / ssim.width + ssim.offset_px);
                within(distance[y * width + x])
            })
            .map(|k| ssim.values[k])
            .collect();
        RegionError {
            band,
            pixels: pixels.len() as u64,
            mse,
            psnr_db: if pixels.is_empty() { f64::NAN } else { capped_psnr_db(psnr_of_mse(mse)) },
            ssim: windows.iter().sum::<f64>() / windows.len() as f64,
            flip: pixels.iter().map(|&i| f64::from(flip[i])).sum::<f64>() / n,
        }
    };
    let whole = Band { name: "frame".into(), from_m: 0.0, to_m: f64::INFINITY };
    Ok(FrameError {
        frame: region(whole, &|_| true),
        bands: bands
            .iter()
            .map(|b| region(b.clone(), &|d: f64| d >= b.from_m && d < b.to_m && d.is_finite()))
            .collect(),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A frame error with two bands, each half the frame, for reports' tests.
    pub fn error(psnr_db: f64, ssim: f64, flip: f64) -> FrameError {
        let region = |name: &str, from_m, to_m, pixels| RegionError {
            band: Band { name: name.into(), from_m, to_m },
            pixels,
            mse: 1.0,
            psnr_db,
            ssim,
            flip,
        };
        FrameError {
            frame: region("frame", 0.0, f64::INFINITY, 200),
            bands: vec![region("meshes", 0.0, 100.0, 100), region("beyond", 100.0, f64::INFINITY, 100)],
        }
    }
    use crate::reference::oracle::OracleCounts;

    /// A 32 × 24 truth at 2² samples: the top third sky, the middle third 2 km away, the bottom
    /// third 50 m away; a textured image so SSIM and FLIP see structure.
    fn truth() -> Truth {
        let (w, h, ss) = (32u32, 24u32, 2u32);
        let near_m = 0.1;
        let depth = (0..(w * ss) * (h * ss))
            .map(|i| match i / (w * ss) / (8 * ss) {
                0 => 0.0,
                1 => (near_m / 2000.0) as f32,
                _ => (near_m / 50.0) as f32,
            })
            .collect();
        let colour = image::RgbaImage::from_fn(w, h, |x, y| {
            let v = ((x * 37 + y * 11) % 200) as u8;
            image::Rgba([v, 255 - v, (v / 2).wrapping_add(40), 255])
        });
        Truth {
            size_px: [w, h],
            supersample: ss,
            ground: colour.clone(),
            colour,
            seed_ids: vec![0; (w * ss * h * ss) as usize],
            depth,
            seeds: Vec::new(),
            samples: Vec::new(),
            counts: OracleCounts::default(),
        }
    }

    #[test]
    fn bands_follow_the_reaches_and_end_beyond_the_last() {
        let mut settings = Settings::default();
        settings.draw_seeds.reach_m = [100.0, 700.0, 700.0, 3000.0];
        let names: Vec<(String, f64, f64)> =
            bands(&settings).into_iter().map(|b| (b.name, b.from_m, b.to_m)).collect();
        assert_eq!(
            names,
            [
                ("meshes".into(), 0.0, 100.0),
                ("clouds 1".into(), 100.0, 700.0),
                ("clouds 3".into(), 700.0, 3000.0),
                ("beyond".into(), 3000.0, f64::INFINITY)
            ]
        );
    }

    #[test]
    fn an_error_counts_in_the_band_it_is_drawn_in_only() {
        let truth = truth();
        let bands = [
            Band { name: "near".into(), from_m: 0.0, to_m: 100.0 },
            Band { name: "far".into(), from_m: 100.0, to_m: f64::INFINITY },
        ];
        let same = frame_error(&truth, 0.1, &truth.colour, &bands).unwrap();
        for r in std::iter::once(&same.frame).chain(&same.bands) {
            assert_eq!((r.psnr_db, r.ssim, r.flip), (100.0, 1.0, 0.0), "{r:?}");
        }
        assert_eq!(same.bands.iter().map(|b| b.pixels).collect::<Vec<_>>(), [8 * 32, 8 * 32]);
        // Darken the near third: the near band's errors, not the far one's.
        let mut frame = truth.colour.clone();
        for y in 16..24 {
            for x in 0..32 {
                frame.get_pixel_mut(x, y).0[1] /= 2;
            }
        }
        let e = frame_error(&truth, 0.1, &frame, &bands).unwrap();
        let (near, far) = (&e.bands[0], &e.bands[1]);
        assert!(near.psnr_db < 20.0 && near.flip > 0.1 && near.ssim < 0.95, "{near:?}");
        assert_eq!(far.psnr_db, 100.0);
        assert!(far.flip < near.flip / 4.0, "FLIP spreads a little across the edge only: {far:?}");
        assert!(e.frame.psnr_db > near.psnr_db && e.frame.flip < near.flip);
    }
}
