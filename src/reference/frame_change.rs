//! How it works: how much a frame changes from the one before, the measure of popping. Both
//! frames are cut into aligned 4 × 4 blocks (the period of pass 4's ordered dither: a cross-fade
//! flips single pixels inside a block and leaves its mean almost still, a pop changes the whole
//! block at once) and each block's change is the difference of its mean luma (Rec. 709 weights
//! on the 8-bit sRGB values, in levels of 255). A flight's figure per pair of consecutive frames
//! is its largest block change. Motion alone changes blocks too (an edge sweeping across one), so
//! a frame sequence is judged against the ground truth along the same flight: `popping` is, pair
//! by pair, how much the largest block change exceeds the truth's, at its worst. What exceeds it
//! is every temporal artefact the truth (supersampled, every tile resident, every seed a mesh)
//! does not have: LOD switches and seeds appearing, tiles streaming in, and the shimmer of
//! single-sampled alpha-tested foliage. A slow flight keeps motion's own changes small.

use super::image_metrics::ImageMetricError;

/// Side of a block, pixels.
pub const BLOCK_PX: u32 = 4;

/// The luma of an 8-bit sRGB pixel, in levels of 255 (Rec. 709 weights on the encoded values).
fn luma(p: &image::Rgba<u8>) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

/// The change of every whole 4 × 4 block's mean luma from `a` to `b`, levels of 255 (absolute),
/// row by row; a partial block at the right or bottom edge is left out.
pub fn block_changes(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<Vec<f64>, ImageMetricError> {
    if a.dimensions() != b.dimensions() {
        return Err(ImageMetricError::SizeMismatch { a: a.dimensions(), b: b.dimensions() });
    }
    let (w, h) = a.dimensions();
    let mut out = Vec::with_capacity(((w / BLOCK_PX) * (h / BLOCK_PX)) as usize);
    for by in 0..h / BLOCK_PX {
        for bx in 0..w / BLOCK_PX {
            let mut sum = 0.0;
            for k in 0..BLOCK_PX * BLOCK_PX {
                let (x, y) = (BLOCK_PX * bx + k % BLOCK_PX, BLOCK_PX * by + k / BLOCK_PX);
                sum += luma(b.get_pixel(x, y)) - luma(a.get_pixel(x, y));
            }
            out.push((sum / f64::from(BLOCK_PX * BLOCK_PX)).abs());
        }
    }
    Ok(out)
}

/// The largest block change from `a` to `b`, levels of 255 (0 for images without a whole block).
pub fn largest_block_change(a: &image::RgbaImage, b: &image::RgbaImage) -> Result<f64, ImageMetricError> {
    Ok(block_changes(a, b)?.into_iter().fold(0.0, f64::max))
}

/// The largest block change of each pair of consecutive frames, in order.
pub fn largest_changes(frames: &[image::RgbaImage]) -> Result<Vec<f64>, ImageMetricError> {
    frames.windows(2).map(|f| largest_block_change(&f[0], &f[1])).collect()
}

/// A flight's popping against the truth's along the same poses, levels of 255.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Popping {
    /// Pairs of consecutive frames compared.
    pub pairs: u32,
    /// The largest block change of the frames, over all pairs.
    pub largest: f64,
    /// The same of the truth's frames.
    pub truth_largest: f64,
    /// The largest excess, over the pairs, of the frames' largest block change over the truth's
    /// (pair by pair); 0 or below when nothing changes more than motion does in the truth.
    pub popping: f64,
}

impl Popping {
    /// `frames` against `truth` (the same poses, in flight order).
    pub fn of(frames: &[image::RgbaImage], truth: &[image::RgbaImage]) -> Result<Self, ImageMetricError> {
        let (ours, theirs) = (largest_changes(frames)?, largest_changes(truth)?);
        let pairs = ours.len().min(theirs.len());
        let max = |v: &[f64]| v.iter().copied().fold(0.0, f64::max);
        let popping = ours.iter().zip(&theirs).map(|(o, t)| o - t).fold(f64::NEG_INFINITY, f64::max);
        Ok(Self {
            pairs: pairs as u32,
            largest: max(&ours[..pairs]),
            truth_largest: max(&theirs[..pairs]),
            popping: if pairs == 0 { 0.0 } else { popping },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grey(w: u32, h: u32, level: u8) -> image::RgbaImage {
        image::RgbaImage::from_pixel(w, h, image::Rgba([level, level, level, 255]))
    }

    #[test]
    fn a_pop_changes_its_block_a_dither_flip_barely() {
        let a = grey(12, 8, 100);
        // One whole block goes from 100 to 180: a pop of 80 levels.
        let mut popped = a.clone();
        for y in 4..8 {
            for x in 4..8 {
                popped.put_pixel(x, y, image::Rgba([180, 180, 180, 255]));
            }
        }
        let changes = block_changes(&a, &popped).unwrap();
        assert_eq!(changes.len(), 6);
        assert!((changes[4] - 80.0).abs() < 1e-9 && changes.iter().filter(|c| **c > 0.0).count() == 1);
        // One pixel flips by 80: its block's mean moves by 5.
        let mut flipped = a.clone();
        flipped.put_pixel(1, 1, image::Rgba([180, 180, 180, 255]));
        assert!((largest_block_change(&a, &flipped).unwrap() - 5.0).abs() < 1e-9);
        // Pure red weighs 0.2126 of its level.
        let red = image::RgbaImage::from_pixel(4, 4, image::Rgba([255, 0, 0, 255]));
        let black = grey(4, 4, 0);
        assert!((largest_block_change(&black, &red).unwrap() - 0.2126 * 255.0).abs() < 1e-9);
        assert!(block_changes(&a, &grey(8, 8, 0)).is_err());
    }

    #[test]
    fn popping_is_the_worst_excess_over_the_truth_pair_by_pair() {
        let frames: Vec<_> = [100, 110, 110, 150].map(|l| grey(8, 8, l)).into();
        let truth: Vec<_> = [100, 130, 130, 140].map(|l| grey(8, 8, l)).into();
        let p = Popping::of(&frames, &truth).unwrap();
        // Pairs: ours 10, 0, 40; the truth's 30, 0, 10; excess -20, 0, 30.
        assert_eq!(p.pairs, 3);
        assert!((p.largest - 40.0).abs() < 1e-9 && (p.truth_largest - 30.0).abs() < 1e-9);
        assert!((p.popping - 30.0).abs() < 1e-9, "{p:?}");
        // A flight as steady as its truth does not pop.
        let steady = Popping::of(&truth, &truth).unwrap();
        assert_eq!(steady.popping, 0.0);
        assert_eq!(Popping::of(&frames[..1], &truth[..1]).unwrap().popping, 0.0);
    }
}
