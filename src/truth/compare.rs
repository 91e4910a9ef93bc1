//! How it works: a frame's error against its ground truth, for the whole frame and per distance
//! band, so each representation is judged where it is drawn. A pixel's distance is that of the
//! nearest of its truth samples (reversed-Z: the largest depth), so a tree in front of far terrain
//! counts in the tree's band; the sky is in no band, only in the whole frame. Bands come from the
//! settings measured (`bands`): the mesh reach, each billboard cloud's reach, the texcells out to
//! their reach or the truth's, whichever is nearer (beyond the truth's reach it grows no tree to
//! judge them by), then beyond the last (reaches are those of a seed of
//! `seeds.reference_height_m`; smaller seeds switch sooner).
//!
//! Per region also the **forest cover** (`Cover`), when the frame's own ground is given: the
//! truth's forest pixels (at least half their samples on a seed) against the frame's drawn pixels
//! (those its seeds and texcells change from its ground by `DRAWN_MIN_LEVELS` or more), so that a
//! representation is judged on where it puts forest (recall: the truth's forest it covers;
//! precision: its cover that lies on the truth's forest) apart from how it colours it; and how
//! bright each draws its forest (the mean sRGB level of the truth's forest pixels in the truth, of
//! the drawn pixels in the frame), so that representations meeting at a band's edge are judged on
//! their colour against the same reference, not against each other.
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
    ImageMetricError, capped_psnr_db, flip_map, psnr_of_mse, squared_errors, ssim_map,
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

/// The bands of `settings` judged against a truth whose seeds grow to `truth_reach_m`: up to each
/// `draw_seeds.reach_m`, the texcells (when drawn) to the nearer of their reach and the truth's,
/// then beyond the last.
pub fn bands(settings: &Settings, truth_reach_m: f64) -> Vec<Band> {
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
    let texcells_to_m = settings.texcells.reach_m.min(truth_reach_m);
    if settings.texcells.enabled() && texcells_to_m > from_m {
        out.push(Band { name: "texcells".into(), from_m, to_m: texcells_to_m });
        from_m = texcells_to_m;
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
    /// Where the frame puts forest against where the truth has it (`None`: no ground given).
    pub cover: Option<Cover>,
}

/// A frame pixel counts as drawn (seeds or texcells on it) when one of its channels differs from
/// the frame's own ground by this many 8-bit levels or more: above rounding and dither noise.
pub const DRAWN_MIN_LEVELS: u8 = 3;

/// Forest cover in a region: the truth's forest pixels, the frame's drawn ones, and both; and the
/// sums of their levels, for their mean brightness.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Cover {
    /// Pixels at least half of whose truth samples show a seed.
    pub truth_px: u64,
    /// Pixels the frame's seeds and texcells change from its ground (`DRAWN_MIN_LEVELS`).
    pub drawn_px: u64,
    /// Pixels both.
    pub both_px: u64,
    /// Over the truth's forest pixels, the sum of the truth's mean level of R, G and B (sRGB,
    /// 0–255).
    pub truth_level_sum: f64,
    /// Over the frame's drawn pixels, the sum of the frame's mean level of R, G and B.
    pub drawn_level_sum: f64,
}

impl Cover {
    /// Share of the truth's forest pixels the frame covers, % (NaN without any).
    pub fn recall_pct(&self) -> f64 {
        100.0 * self.both_px as f64 / self.truth_px as f64
    }

    /// Share of the frame's drawn pixels that lie on the truth's forest, % (NaN without any).
    pub fn precision_pct(&self) -> f64 {
        100.0 * self.both_px as f64 / self.drawn_px as f64
    }

    /// How bright the frame draws its forest against the truth's forest: the ratio of their mean
    /// levels (1: alike; NaN without either).
    pub fn brightness_ratio(&self) -> f64 {
        (self.drawn_level_sum / self.drawn_px as f64) / (self.truth_level_sum / self.truth_px as f64)
    }

    fn add(&mut self, other: &Cover) {
        self.truth_px += other.truth_px;
        self.drawn_px += other.drawn_px;
        self.both_px += other.both_px;
        self.truth_level_sum += other.truth_level_sum;
        self.drawn_level_sum += other.drawn_level_sum;
    }
}

/// One value per pixel of `truth` (row by row), from the indices of its samples.
fn per_pixel<T>(truth: &Truth, of_samples: impl Fn(&mut dyn Iterator<Item = usize>) -> T) -> Vec<T> {
    let [w, h] = truth.size_px;
    let ss = truth.supersample as usize;
    let row = w as usize * ss;
    let mut out = Vec::with_capacity((w * h) as usize);
    for y in 0..h as usize {
        for x in 0..w as usize {
            let mut samples = (0..ss).flat_map(|sy| (0..ss).map(move |sx| (y * ss + sy) * row + x * ss + sx));
            out.push(of_samples(&mut samples));
        }
    }
    out
}

/// Per pixel of `truth`: whether at least half its samples show a seed.
pub fn truth_forest(truth: &Truth) -> Vec<bool> {
    let ss = truth.supersample as usize;
    per_pixel(truth, |samples| {
        let on_seeds = samples.filter(|&i| truth.seed_ids.get(i).is_some_and(|&id| id != 0)).count();
        2 * on_seeds >= ss * ss
    })
}

/// Per pixel: whether `frame` differs from `ground` by `DRAWN_MIN_LEVELS` or more in a channel.
pub fn drawn(frame: &image::RgbaImage, ground: &image::RgbaImage) -> Result<Vec<bool>, ImageMetricError> {
    if frame.dimensions() != ground.dimensions() {
        return Err(ImageMetricError::SizeMismatch { a: frame.dimensions(), b: ground.dimensions() });
    }
    Ok(frame
        .pixels()
        .zip(ground.pixels())
        .map(|(f, g)| (0..3).any(|c| f[c].abs_diff(g[c]) >= DRAWN_MIN_LEVELS))
        .collect())
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
    per_pixel(truth, |samples| {
        let nearest = samples.map(|i| truth.depth.get(i).copied().unwrap_or(0.0)).fold(0.0f32, f32::max);
        if nearest > 0.0 { near_m / f64::from(nearest) } else { f64::INFINITY }
    })
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
            cover: regions.iter().try_fold(Cover::default(), |mut sum, r| {
                sum.add(r.cover.as_ref()?);
                Some(sum)
            }),
        }
    };
    Some(FrameError {
        frame: pooled(errors.iter().map(|e| &e.frame).collect()),
        bands: (0..first.bands.len())
            .map(|b| pooled(errors.iter().filter_map(|e| e.bands.get(b)).collect()))
            .collect(),
    })
}

/// `frame` against `truth`'s image, whole and per band of `bands`; with the frame's own `ground`
/// (the same view without seeds or texcells), each region's forest cover too.
pub fn frame_error(
    truth: &Truth,
    near_m: f64,
    frame: &image::RgbaImage,
    ground: Option<&image::RgbaImage>,
    bands: &[Band],
) -> Result<FrameError, ImageMetricError> {
    let reference = &truth.colour;
    let squared = squared_errors(reference, frame)?;
    let ssim = ssim_map(reference, frame)?;
    let flip = flip_map(reference, frame)?;
    let distance = pixel_distances_m(truth, near_m);
    let forest = ground.map(|ground| Ok::<_, ImageMetricError>((truth_forest(truth), drawn(frame, ground)?)));
    let forest = forest.transpose()?;
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
            cover: forest.as_ref().map(|(truth, drawn)| {
                let count = |f: &dyn Fn(usize) -> bool| pixels.iter().filter(|&&i| f(i)).count() as u64;
                let level_sum = |image: &image::RgbaImage, f: &dyn Fn(usize) -> bool| {
                    let level = |i: usize| {
                        image.as_raw()[4 * i..4 * i + 3].iter().map(|&v| f64::from(v)).sum::<f64>() / 3.0
                    };
                    pixels.iter().filter(|&&i| f(i)).map(|&i| level(i)).sum()
                };
                Cover {
                    truth_px: count(&|i| truth[i]),
                    drawn_px: count(&|i| drawn[i]),
                    both_px: count(&|i| truth[i] && drawn[i]),
                    truth_level_sum: level_sum(reference, &|i| truth[i]),
                    drawn_level_sum: level_sum(frame, &|i| drawn[i]),
                }
            }),
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
            cover: None,
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
        let names = |settings: &Settings, truth_reach_m| -> Vec<(String, f64, f64)> {
            bands(settings, truth_reach_m).into_iter().map(|b| (b.name, b.from_m, b.to_m)).collect()
        };
        let clouds = [
            ("meshes".into(), 0.0, 100.0),
            ("clouds 1".into(), 100.0, 700.0),
            ("clouds 3".into(), 700.0, 3000.0),
        ];
        // Texcells out to the truth's reach (8 km), nearer than theirs (12 km).
        settings.texcells.reach_m = 12000.0;
        let with: Vec<_> = clouds
            .iter()
            .cloned()
            .chain([("texcells".into(), 3000.0, 8000.0), ("beyond".into(), 8000.0, f64::INFINITY)])
            .collect();
        assert_eq!(names(&settings, 8000.0), with);
        // A truth no farther than the clouds judges no texcells; without texcells there are none.
        let without: Vec<_> =
            clouds.iter().cloned().chain([("beyond".into(), 3000.0, f64::INFINITY)]).collect();
        assert_eq!(names(&settings, 3000.0), without);
        settings.texcells.reach_m = 0.0;
        assert_eq!(names(&settings, 8000.0), without);
    }

    #[test]
    fn cover_counts_the_truths_forest_against_the_frames_drawn_pixels() {
        let mut truth = truth();
        // Truth forest: the left half of the middle third, at 3 of 4 samples (one at 1 of 4 is not).
        let (w, ss) = (32usize, 2usize);
        for y in 8..16 {
            for x in 0..16 {
                for (sy, sx) in [(0, 0), (0, 1), (1, 0)] {
                    truth.seed_ids[(y * ss + sy) * w * ss + x * ss + sx] = 1;
                }
            }
            truth.seed_ids[(y * ss) * w * ss + 20 * ss] = 1;
            // One colour over the middle third, so that the levels are known: a mean of 90.
            for x in 0..w as u32 {
                truth.colour.put_pixel(x, y as u32, image::Rgba([60, 120, 90, 255]));
            }
        }
        // The frame draws the middle third's columns 8..24: half on the truth's forest.
        let ground = truth.colour.clone();
        let mut frame = ground.clone();
        for y in 8..16 {
            for x in 8..24 {
                frame.get_pixel_mut(x, y).0[0] ^= 0x40;
            }
        }
        // Two levels is below the drawn threshold.
        frame.get_pixel_mut(0, 20).0[1] = frame.get_pixel(0, 20).0[1].saturating_add(2).min(253);
        let bands = [Band { name: "all".into(), from_m: 0.0, to_m: f64::INFINITY }];
        let e = frame_error(&truth, 0.1, &frame, Some(&ground), &bands).unwrap();
        let cover = e.bands[0].cover.unwrap();
        // Drawn pixels are (60 ^ 0x40, 120, 90): a mean of 334 / 3 against the truth's 90.
        let (truth_px, drawn_px) = (8 * 16, 8 * 16);
        let levels = (90.0 * truth_px as f64, 334.0 / 3.0 * drawn_px as f64);
        assert_eq!((cover.truth_px, cover.drawn_px, cover.both_px), (truth_px, drawn_px, 8 * 8));
        assert!(
            (cover.truth_level_sum - levels.0).abs() < 1e-9
                && (cover.drawn_level_sum - levels.1).abs() < 1e-6
        );
        assert_eq!((cover.recall_pct(), cover.precision_pct()), (50.0, 50.0));
        assert!((cover.brightness_ratio() - 334.0 / 270.0).abs() < 1e-12, "{}", cover.brightness_ratio());
        assert!(frame_error(&truth, 0.1, &frame, None, &bands).unwrap().bands[0].cover.is_none());
        // Pooled, the counts add up.
        let pooled = pool(&[e.clone(), e]).unwrap();
        let pooled = pooled.bands[0].cover.unwrap();
        assert_eq!(pooled.both_px, 2 * 8 * 8);
        assert!((pooled.brightness_ratio() - cover.brightness_ratio()).abs() < 1e-12);
    }

    #[test]
    fn an_error_counts_in_the_band_it_is_drawn_in_only() {
        let truth = truth();
        let bands = [
            Band { name: "near".into(), from_m: 0.0, to_m: 100.0 },
            Band { name: "far".into(), from_m: 100.0, to_m: f64::INFINITY },
        ];
        let same = frame_error(&truth, 0.1, &truth.colour, None, &bands).unwrap();
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
        let e = frame_error(&truth, 0.1, &frame, None, &bands).unwrap();
        let (near, far) = (&e.bands[0], &e.bands[1]);
        assert!(near.psnr_db < 20.0 && near.flip > 0.1 && near.ssim < 0.95, "{near:?}");
        assert_eq!(far.psnr_db, 100.0);
        assert!(far.flip < near.flip / 4.0, "FLIP spreads a little across the edge only: {far:?}");
        assert!(e.frame.psnr_db > near.psnr_db && e.frame.flip < near.flip);
    }
}
