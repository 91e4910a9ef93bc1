//! How it works: the image errors the speed trade is measured with, between two same-sized sRGB
//! images (8 bits per channel, alpha ignored); FLIP's map (with the `flip` feature) is NVIDIA's
//! reference implementation, described where the trade pools it (`truth::compare`).
//!
//! - **PSNR** over the R, G and B channels: 10·log10(255² / MSE), the MSE taken over every channel
//!   of every pixel. Identical images have an infinite PSNR; `capped_psnr_db` clamps it to
//!   `PSNR_CAP_DB` for tables and JSON (which has no infinity).
//! - **SSIM** (Wang, Bovik, Sheikh & Simoncelli 2004) on luma (Rec. 601 weights on the 8-bit sRGB
//!   values, as MATLAB's `ssim` on `rgb2gray`), with the paper's standard choices: an 11 × 11
//!   Gaussian window of σ = 1.5 (normalised), K1 = 0.01, K2 = 0.03, L = 255, so C1 = (K1·L)² and
//!   C2 = (K2·L)². Local means, variances and the covariance are Gaussian-weighted moments
//!   (E\[x²\] − E\[x\]², computed in f64 by a separable filter), over the "valid" window positions only
//!   (no padding), and the index is the mean of the SSIM map. Identical images give exactly 1.

use thiserror::Error;

/// What `capped_psnr_db` reports for identical images (and any PSNR above it). A single 8-bit
/// step in one channel of a 1280 × 720 image is already 112 dB: 100 dB means "no visible
/// difference at all", and keeps the figure a finite number.
pub const PSNR_CAP_DB: f64 = 100.0;

/// Side of the SSIM window, pixels, and its Gaussian's standard deviation.
pub const SSIM_WINDOW_PX: usize = 11;
/// Standard deviation of the SSIM window's Gaussian weights, pixels.
pub const SSIM_SIGMA_PX: f64 = 1.5;
const SSIM_C1: f64 = (0.01 * 255.0) * (0.01 * 255.0);
const SSIM_C2: f64 = (0.03 * 255.0) * (0.03 * 255.0);

/// Why two images could not be compared.
#[derive(Debug, Error, PartialEq, Eq)]
pub enum ImageMetricError {
    /// The two images differ in width or height.
    #[error("images of different sizes: {a:?} and {b:?}")]
    SizeMismatch {
        /// The first image's (width, height), pixels.
        a: (u32, u32),
        /// The second image's (width, height), pixels.
        b: (u32, u32),
    },
    /// SSIM was asked of images narrower or shorter than its window (`SSIM_WINDOW_PX`).
    #[error("SSIM needs images of at least {SSIM_WINDOW_PX} × {SSIM_WINDOW_PX} pixels; got {0:?}")]
    TooSmall((u32, u32)),
}

fn same_size(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<(), ImageMetricError> {
    if a.dimensions() != b.dimensions() {
        return Err(ImageMetricError::SizeMismatch { a: a.dimensions(), b: b.dimensions() });
    }
    Ok(())
}

/// Mean squared error over the R, G and B channels, in 8-bit steps squared.
pub fn mse(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<f64, ImageMetricError> {
    same_size(a, b)?;
    let samples = 3 * u64::from(a.width()) * u64::from(a.height());
    let squared: f64 = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2)))
        .sum();
    Ok(squared / samples.max(1) as f64)
}

/// The PSNR of a mean squared error (in 8-bit steps squared), dB: infinite for 0.
pub fn psnr_of_mse(mse: f64) -> f64 {
    if mse <= 0.0 { f64::INFINITY } else { 10.0 * (255.0f64 * 255.0 / mse).log10() }
}

/// Peak signal-to-noise ratio over R, G and B, dB; infinite for identical images.
pub fn psnr_db(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<f64, ImageMetricError> {
    Ok(psnr_of_mse(mse(a, b)?))
}

/// A PSNR clamped to `PSNR_CAP_DB`, for reports.
pub fn capped_psnr_db(db: f64) -> f64 {
    db.min(PSNR_CAP_DB)
}

/// Rec. 601 luma of each pixel, row by row, on the 8-bit values.
fn luma(image: &image::RgbaImage) -> Vec<f64> {
    image
        .pixels()
        .map(|p| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]))
        .collect()
}

/// The normalised 1D Gaussian the 2D window is the outer product of.
fn gaussian_1d() -> [f64; SSIM_WINDOW_PX] {
    let half = (SSIM_WINDOW_PX / 2) as f64;
    let mut w = [0.0; SSIM_WINDOW_PX];
    for (i, v) in w.iter_mut().enumerate() {
        let d = i as f64 - half;
        *v = (-d * d / (2.0 * SSIM_SIGMA_PX * SSIM_SIGMA_PX)).exp();
    }
    let sum: f64 = w.iter().sum();
    w.map(|v| v / sum)
}

/// `values` (width × height, row by row) filtered by the window over its valid positions only:
/// (width − 10) × (height − 10) results, row by row.
fn filter_valid(values: &[f64], width: usize, height: usize, kernel: &[f64; SSIM_WINDOW_PX]) -> Vec<f64> {
    let (out_w, out_h) = (width + 1 - SSIM_WINDOW_PX, height + 1 - SSIM_WINDOW_PX);
    let mut rows = vec![0.0; out_w * height];
    for y in 0..height {
        let row = &values[y * width..][..width];
        for x in 0..out_w {
            rows[y * out_w + x] = kernel.iter().zip(&row[x..]).map(|(k, v)| k * v).sum();
        }
    }
    let mut out = vec![0.0; out_w * out_h];
    for y in 0..out_h {
        for x in 0..out_w {
            out[y * out_w + x] = kernel.iter().enumerate().map(|(k, w)| w * rows[(y + k) * out_w + x]).sum();
        }
    }
    out
}

/// The mean structural similarity of two images' luma (1 for identical images, less otherwise).
pub fn ssim(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<f64, ImageMetricError> {
    let map = ssim_map(a, b)?;
    Ok(map.values.iter().sum::<f64>() / map.values.len() as f64)
}

/// The SSIM of every window position: `values[y * width + x]` is the window whose centre is
/// pixel (x + `offset_px`, y + `offset_px`).
#[derive(Debug, Clone, PartialEq)]
pub struct SsimMap {
    /// Window positions along x and y.
    pub width: usize,
    /// Window positions along y.
    pub height: usize,
    /// The first window's centre, pixels from the image's edges.
    pub offset_px: usize,
    /// The SSIM of each position, row by row.
    pub values: Vec<f64>,
}

/// The SSIM map of two images' luma over the valid window positions (no padding).
pub fn ssim_map(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<SsimMap, ImageMetricError> {
    same_size(a, b)?;
    let (width, height) = (a.width() as usize, a.height() as usize);
    if width < SSIM_WINDOW_PX || height < SSIM_WINDOW_PX {
        return Err(ImageMetricError::TooSmall(a.dimensions()));
    }
    let (x, y) = (luma(a), luma(b));
    let kernel = gaussian_1d();
    let filter = |v: &[f64]| filter_valid(v, width, height, &kernel);
    let products = |p: &[f64], q: &[f64]| p.iter().zip(q).map(|(p, q)| p * q).collect::<Vec<f64>>();
    let (mu_x, mu_y) = (filter(&x), filter(&y));
    let (xx, yy, xy) = (filter(&products(&x, &x)), filter(&products(&y, &y)), filter(&products(&x, &y)));
    let values = (0..mu_x.len())
        .map(|i| {
            let (mx, my) = (mu_x[i], mu_y[i]);
            let (vx, vy, cxy) = (xx[i] - mx * mx, yy[i] - my * my, xy[i] - mx * my);
            ((2.0 * mx * my + SSIM_C1) * (2.0 * cxy + SSIM_C2))
                / ((mx * mx + my * my + SSIM_C1) * (vx + vy + SSIM_C2))
        })
        .collect();
    Ok(SsimMap {
        width: width + 1 - SSIM_WINDOW_PX,
        height: height + 1 - SSIM_WINDOW_PX,
        offset_px: SSIM_WINDOW_PX / 2,
        values,
    })
}

/// Each pixel's squared error, the mean over R, G and B (what `mse` averages).
pub fn squared_errors(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<Vec<f64>, ImageMetricError> {
    same_size(a, b)?;
    Ok(a.pixels()
        .zip(b.pixels())
        .map(|(p, q)| (0..3).map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2)).sum::<f64>() / 3.0)
        .collect())
}

#[cfg(feature = "flip")]
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

#[cfg(test)]
mod tests {
    use super::*;

    fn uniform(w: u32, h: u32, rgb: [u8; 3]) -> image::RgbaImage {
        image::RgbaImage::from_pixel(w, h, image::Rgba([rgb[0], rgb[1], rgb[2], 255]))
    }

    /// A reproducible textured image (a small LCG), so the structure term matters.
    fn textured(w: u32, h: u32, seed: u32) -> image::RgbaImage {
        let mut state = seed.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        image::RgbaImage::from_fn(w, h, |x, y| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let noise = (state >> 24) as u8 / 4;
            let v = ((x * 7 + y * 3) % 64) as u8 * 2 + noise;
            image::Rgba([v, v.wrapping_add(20), 255 - v, 255])
        })
    }

    #[test]
    fn psnr_matches_hand_computed_values() {
        // Every channel one step off: MSE 1, PSNR = 20·log10(255) = 48.1308 dB.
        let a = uniform(4, 3, [10, 20, 30]);
        let b = uniform(4, 3, [11, 21, 31]);
        assert!((psnr_db(&a, &b).unwrap() - 48.130_803_608).abs() < 1e-6);
        // One channel of one pixel off by 255 in a 1 × 1 image: MSE 255²/3, PSNR = 10·log10(3).
        let (black, red) = (uniform(1, 1, [0, 0, 0]), uniform(1, 1, [255, 0, 0]));
        assert!((psnr_db(&black, &red).unwrap() - 4.771_212_547).abs() < 1e-6);
        // Alpha does not count.
        let mut c = a.clone();
        c.put_pixel(0, 0, image::Rgba([10, 20, 30, 0]));
        assert_eq!(psnr_db(&a, &c).unwrap(), f64::INFINITY);
    }

    #[test]
    fn psnr_of_an_image_against_itself_is_infinite_and_capped_for_reports() {
        let a = textured(32, 24, 1);
        let db = psnr_db(&a, &a).unwrap();
        assert_eq!(db, f64::INFINITY);
        assert_eq!(capped_psnr_db(db), PSNR_CAP_DB);
        assert_eq!(capped_psnr_db(35.0), 35.0);
        let small = uniform(3, 3, [0, 0, 0]);
        assert!(matches!(psnr_db(&a, &small), Err(ImageMetricError::SizeMismatch { .. })));
    }

    #[test]
    fn ssim_of_uniform_images_is_the_luminance_term() {
        // σ = 0 in every window: SSIM = (2ab + C1) / (a² + b² + C1), with C1 = 2.55² = 6.5025.
        let (a, b) = (uniform(16, 16, [100, 100, 100]), uniform(16, 16, [110, 110, 110]));
        let expected = (2.0 * 100.0 * 110.0 + 6.5025) / (100.0f64 * 100.0 + 110.0 * 110.0 + 6.5025);
        let got = ssim(&a, &b).unwrap();
        assert!((got - expected).abs() < 1e-9, "{got} against {expected}");
        assert!((expected - 0.995_476_444).abs() < 1e-9);
    }

    #[test]
    fn ssim_is_one_for_identical_images_and_less_for_a_shifted_one() {
        let a = textured(40, 30, 3);
        assert_eq!(ssim(&a, &a).unwrap(), 1.0);
        let shifted = image::RgbaImage::from_fn(40, 30, |x, y| *a.get_pixel((x + 1).min(39), y));
        let s = ssim(&a, &shifted).unwrap();
        assert!(s < 0.99 && s > -1.0, "{s}");
        assert!(matches!(
            ssim(&uniform(10, 40, [0; 3]), &uniform(10, 40, [0; 3])),
            Err(ImageMetricError::TooSmall(_))
        ));
    }

    #[test]
    fn separable_ssim_equals_the_direct_definition() {
        let (a, b) = (textured(14, 13, 5), textured(14, 13, 9));
        let (x, y) = (luma(&a), luma(&b));
        let g = gaussian_1d();
        let (w, h) = (14usize, 13usize);
        let mut sum = 0.0;
        let mut n = 0;
        for oy in 0..=h - SSIM_WINDOW_PX {
            for ox in 0..=w - SSIM_WINDOW_PX {
                let (mut mx, mut my, mut xx, mut yy, mut xy) = (0.0, 0.0, 0.0, 0.0, 0.0);
                for j in 0..SSIM_WINDOW_PX {
                    for i in 0..SSIM_WINDOW_PX {
                        let k = g[i] * g[j];
                        let (p, q) = (x[(oy + j) * w + ox + i], y[(oy + j) * w + ox + i]);
                        (mx, my, xx, yy, xy) =
                            (mx + k * p, my + k * q, xx + k * p * p, yy + k * q * q, xy + k * p * q);
                    }
                }
                let (vx, vy, c) = (xx - mx * mx, yy - my * my, xy - mx * my);
                sum += ((2.0 * mx * my + SSIM_C1) * (2.0 * c + SSIM_C2))
                    / ((mx * mx + my * my + SSIM_C1) * (vx + vy + SSIM_C2));
                n += 1;
            }
        }
        let direct = sum / f64::from(n);
        let got = ssim(&a, &b).unwrap();
        assert!((got - direct).abs() < 1e-12, "{got} against {direct}");
        assert!(got < 0.9, "two different textures: {got}");
    }
}
