//! How it works: a straight descent (issue 43), and how much each patch of ground changes colour
//! from one frame to the next. The camera keeps its x, y, heading and pitch and sinks from its
//! height above the ground below it to `bottom_m`, each frame `1 − step` of the last's height. Two
//! renderers of one dataset follow it, the amplified one (the settings as given) and the
//! photograph's (`photograph_settings`), each settled at every height, so streaming is done and
//! what changes is what the representations do with distance, not what has not loaded yet.
//!
//! The patches are fixed on the ground, not on the screen (the screen's blocks slide over the
//! ground as the camera sinks): square blocks of level-0 imagery texels, keyed by the terrain
//! point each pixel shows (`keys`), their edge the smallest power of two of texels that covers at
//! least `BLOCK_PX` × `BLOCK_PX` pixels at the higher frame of each pair. A block is compared
//! between frames `k` and `k + 1` when it lies wholly inside both (none of its pixels on a frame's
//! border) and has `BLOCK_PX²` pixels or more in both. Per block, three CIEDE2000 of mean colours
//! (linear light, as `measure`):
//! - the **amplified** frame's change: what a viewer sees;
//! - the **photograph** frame's change: the imagery's own (its filtering and mip levels, pixels
//!   crossing the block's edges), the floor any frame shares;
//! - the amplification's **own** change: frame `k + 1` against frame `k + 1`'s photograph plus
//!   frame `k`'s departure from its photograph (`A₁` against `P₁ + A₀ − P₀`, in linear light), which
//!   the photograph's own change does not move.

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;
use serde::Serialize;

use super::colour::{delta_e_2000, lab_of_linear, linear_table};
use super::measure::{BLOCK_PX, NO_TEXEL, PixelKeys, Sums, key_texel, linear_at, texel_key};
use super::{PhotoError, measured_settings, photograph_settings, pixel_keys};
use crate::camera::Camera;
use crate::config::Settings;
use crate::dataset::Dataset;
use crate::frame::Renderer;
use crate::gpu::Gpu;

/// A straight descent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Descent {
    /// The first frame's camera (its height is where the descent starts).
    pub top: Camera,
    /// Height above the ground below the camera where it ends, metres.
    pub bottom_m: f64,
    /// Each frame's height above that ground is `1 − step` of the last's (0.02: 2 %).
    pub step: f64,
}

/// One pair of consecutive frames.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PairFigures {
    /// The two frames' heights above the ground below the camera, metres.
    pub height_m: [f64; 2],
    /// The blocks' edge, level-0 imagery texels.
    pub block_texels: u32,
    /// Blocks compared.
    pub blocks: usize,
    /// The largest CIEDE2000 of a block's change in the amplified frames (`None` without blocks).
    pub amplified: Option<f64>,
    /// In the photograph frames.
    pub photograph: Option<f64>,
    /// The amplification's own.
    pub own: Option<f64>,
    /// Where the block of the largest own change lies in the later frame: its pixels' centroid.
    pub own_at_px: Option<[u32; 2]>,
}

/// A descent measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DescentFigures {
    /// Frames rendered (each twice: amplified and photograph).
    pub frames: usize,
    /// Every pair, top first.
    pub pairs: Vec<PairFigures>,
}

impl DescentFigures {
    /// The largest of `figure` over all pairs, with the pair's index.
    pub fn largest(&self, figure: impl Fn(&PairFigures) -> Option<f64>) -> Option<(usize, f64)> {
        self.pairs
            .iter()
            .enumerate()
            .filter_map(|(i, p)| figure(p).map(|v| (i, v)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// What a frame of the descent leaves for the next.
struct Frame {
    height_m: f64,
    amplified: image::RgbaImage,
    photograph: image::RgbaImage,
    keys: PixelKeys,
}

impl Descent {
    /// The cameras of the descent, top first (the last no lower than `bottom_m`); an error when
    /// the top is not above the bottom or the step is not within (0, 1).
    pub fn cameras(&self, dataset: &Dataset) -> Result<Vec<(f64, Camera)>, PhotoError> {
        let o = dataset.manifest.origin_m;
        let p = self.top.position_m;
        let ground_m = dataset.height_at(p.x - o[0], p.y - o[1], 0).map_err(PhotoError::Pack)?;
        let top_m = p.z - ground_m;
        if !(self.step > 0.0 && self.step < 1.0 && self.bottom_m > 0.0 && top_m > self.bottom_m) {
            return Err(PhotoError::Descent { top_m, bottom_m: self.bottom_m, step: self.step });
        }
        let mut cameras = Vec::new();
        let mut height_m = top_m;
        while height_m >= self.bottom_m {
            let mut camera = self.top;
            camera.position_m = DVec3::new(p.x, p.y, ground_m + height_m);
            cameras.push((height_m, camera));
            height_m *= 1.0 - self.step;
        }
        Ok(cameras)
    }
}

/// Renders `descent` over `dataset` with `settings` (amplified) and `photograph_settings`, at
/// scene time `time_s`, comparing each frame with the last; `progress(done, of)` after each frame.
pub fn descend(
    gpu: &Gpu,
    dataset: Arc<Dataset>,
    settings: &Settings,
    descent: &Descent,
    time_s: f64,
    progress: &mut dyn FnMut(usize, usize),
) -> Result<DescentFigures, PhotoError> {
    let cameras = descent.cameras(&dataset)?;
    let renderer = |settings: Settings| -> Result<Renderer, PhotoError> {
        let mut r = Renderer::new(gpu.clone(), Arc::clone(&dataset), settings)?;
        r.set_time_s(time_s);
        Ok(r)
    };
    let settings = &measured_settings(settings);
    let (mut amplified, mut photo) = (renderer(settings.clone())?, renderer(photograph_settings(settings))?);
    let texel_m = dataset.manifest.imagery.as_ref().map_or(1.0, |i| i.texel_m);
    let (mut last, mut pairs): (Option<Frame>, Vec<PairFigures>) = (None, Vec::new());
    for (k, (height_m, camera)) in cameras.iter().enumerate() {
        amplified.render_resolved(camera)?;
        photo.render_resolved(camera)?;
        let frame = Frame {
            height_m: *height_m,
            amplified: amplified.read_colour()?,
            photograph: photo.read_colour()?,
            keys: pixel_keys(&photo, camera)?,
        };
        if let Some(before) = &last {
            let render = &settings.render;
            let metres_per_px = camera.metres_per_pixel(before.height_m, render.height);
            let block_texels = (f64::from(BLOCK_PX) * metres_per_px / texel_m).ceil().max(1.0) as u32;
            pairs.push(compare(before, &frame, block_texels.next_power_of_two()));
        }
        last = Some(frame);
        progress(k + 1, cameras.len());
    }
    Ok(DescentFigures { frames: cameras.len(), pairs })
}

/// A block's pixels in one frame: their sums (`measure::Sums`), the sum of their columns and
/// rows, and whether any lies on the frame's border.
#[derive(Debug, Default, Clone, Copy)]
struct BlockSums {
    sums: Sums,
    at_px: [u64; 2],
    on_border: bool,
}

/// Per block of `block_texels` level-0 texels (by its corner texel), the frame's sums.
fn block_sums(frame: &Frame, block_texels: u32) -> HashMap<u64, BlockSums> {
    let table = linear_table();
    let [w, h] = frame.keys.size_px;
    let mut blocks: HashMap<u64, BlockSums> = HashMap::new();
    for (i, &key) in frame.keys.texel.iter().enumerate() {
        if key == NO_TEXEL {
            continue;
        }
        let s = blocks.entry(texel_key(key_texel(key).map(|t| t / block_texels))).or_default();
        let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
        s.on_border |= x == 0 || y == 0 || x + 1 == w || y + 1 == h;
        s.at_px[0] += u64::from(x);
        s.at_px[1] += u64::from(y);
        s.sums.add(linear_at(&frame.amplified, i, &table), linear_at(&frame.photograph, i, &table), false);
    }
    blocks
}

/// The pair's figures over the blocks both frames show whole.
fn compare(before: &Frame, after: &Frame, block_texels: u32) -> PairFigures {
    let (b0, b1) = (block_sums(before, block_texels), block_sums(after, block_texels));
    let least = (BLOCK_PX * BLOCK_PX) as usize;
    let de = |a: [f64; 3], b: [f64; 3]| delta_e_2000(lab_of_linear(a), lab_of_linear(b));
    let (mut blocks, mut largest, mut own_at_px) = (0, [None::<f64>; 3], None);
    for (key, s0) in &b0 {
        let Some(s1) = b1.get(key) else { continue };
        if s0.on_border || s1.on_border || s0.sums.pixels < least || s1.sums.pixels < least {
            continue;
        }
        let ((a0, p0), (a1, p1)) = (s0.sums.means(), s1.sums.means());
        let carried: [f64; 3] = std::array::from_fn(|c| (p1[c] + a0[c] - p0[c]).max(0.0));
        let own = de(carried, a1);
        if largest[2].is_none_or(|v| own > v) {
            own_at_px = Some(s1.at_px.map(|v| (v / s1.sums.pixels as u64) as u32));
        }
        for (slot, value) in largest.iter_mut().zip([de(a0, a1), de(p0, p1), own]) {
            *slot = Some(slot.map_or(value, |v: f64| v.max(value)));
        }
        blocks += 1;
    }
    PairFigures {
        height_m: [before.height_m, after.height_m],
        block_texels,
        blocks,
        amplified: largest[0],
        photograph: largest[1],
        own: largest[2],
        own_at_px,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 25 × 25 frame of greys, its texels 5 × 5 pixels (a 5 × 5 grid of texels).
    fn frame(amplified: impl Fn(u32, u32) -> u8, photograph: impl Fn(u32, u32) -> u8) -> Frame {
        let n = 25;
        let grey = |f: &dyn Fn(u32, u32) -> u8| {
            image::RgbaImage::from_fn(n, n, |x, y| {
                let v = f(x, y);
                image::Rgba([v, v, v, 255])
            })
        };
        let texel = (0..n * n).map(|i| texel_key([i % n / 5, i / n / 5])).collect();
        let keys = PixelKeys::forest([n, n], texel);
        Frame { height_m: 100.0, amplified: grey(&amplified), photograph: grey(&photograph), keys }
    }

    #[test]
    fn a_change_of_the_photograph_alone_is_none_of_the_amplification_s() {
        // The amplified frame 0.02 brighter than the photograph in linear light in both frames,
        // the photograph brighter in the second.
        let linear = linear_table();
        let brighter = |byte: u8| crate::texcell::pyramid::encode_srgb((linear[byte as usize] + 0.02) as f32);
        let before = frame(|_, _| brighter(50), |_, _| 50);
        let after = frame(|_, _| brighter(70), |_, _| 70);
        // Blocks of 2 × 2 texels (10 × 10 pixels): only the one wholly inside counts.
        let pair = compare(&before, &after, 2);
        assert_eq!(pair.blocks, 1, "{pair:?}");
        assert!(pair.amplified.unwrap() > 3.0 && pair.photograph.unwrap() > 3.0, "{pair:?}");
        // Within the bytes' rounding.
        assert!(pair.own.unwrap() < 0.5, "{pair:?}");
    }

    #[test]
    fn a_block_that_pops_is_found_and_placed() {
        let before = frame(|_, _| 50, |_, _| 50);
        // Texel (1, 1) (pixels 5 to 9) turns brighter in the amplified frame only.
        let pops = |x: u32, y: u32| if (5..10).contains(&x) && (5..10).contains(&y) { 90 } else { 50 };
        let pair = compare(&before, &frame(pops, |_, _| 50), 1);
        // Texels (1..=3, 1..=3) lie wholly inside: 9 blocks.
        assert_eq!(pair.blocks, 9, "{pair:?}");
        assert_eq!(pair.photograph, Some(0.0));
        assert!(pair.own.unwrap() > 10.0 && pair.own == pair.amplified, "{pair:?}");
        assert_eq!(pair.own_at_px, Some([7, 7]));
    }

    #[cfg(feature = "synth")]
    #[test]
    fn a_descent_must_go_down() {
        use crate::synth::{SynthParams, synthesize};
        let dir = std::env::temp_dir().join(format!("terramp-descent-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        synthesize(&dir, &SynthParams { size: 64, seed: 1, ..Default::default() }, false).unwrap();
        let dataset = Dataset::open(&dir).unwrap();
        let o = dataset.manifest.origin_m;
        let ground_m = dataset.height_at(0.0, 0.0, 0).unwrap();
        let position_m = DVec3::new(o[0], o[1], ground_m + 1000.0);
        let top =
            Camera { position_m, yaw_deg: 0.0, pitch_deg: -89.0, roll_deg: 0.0, fov_deg: 60.0, near_m: 0.1 };
        let cameras = Descent { top, bottom_m: 500.0, step: 0.1 }.cameras(&dataset).unwrap();
        let heights: Vec<f64> = cameras.iter().map(|(h, _)| *h).collect();
        assert_eq!(heights.len(), 7, "1000 m to 531 m by 10 %: {heights:?}");
        assert!((heights[6] - 1000.0 * 0.9f64.powi(6)).abs() < 1e-6);
        for (bottom_m, step) in [(1000.0, 0.1), (2000.0, 0.1), (0.0, 0.1), (500.0, 0.0), (500.0, 1.0)] {
            let e = Descent { top, bottom_m, step }.cameras(&dataset).unwrap_err();
            assert!(matches!(e, PhotoError::Descent { .. }), "{e}");
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
