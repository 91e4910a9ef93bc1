//! The photograph measure (`terramp::photo`) end to end on a small synthetic dataset with the
//! shared models baked, one view looking down over its forest at 160 × 160:
//! - the photograph frame against itself: ΔE 0 and nothing changed;
//! - the amplified frame (trees drawn) against it: some wooded pixels changed, finite ΔE;
//! - a control frame, the photograph's linear colour scaled by a known factor: the block figures
//!   are the CIEDE2000 of the scaled block means, computed here from the photograph's own pixels
//!   (not from the measure's output);
//! - a flat paint of each counted texel footprint with the photograph's mean there: no detail,
//!   ΔE within the rounding of a mean to bytes;
//! - the colour follow-up: the trees' block means near the photograph's, and far in the models'
//!   own colours (the control).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::sync::Arc;

use glam::DVec3;
use image::RgbaImage;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::photo::colour::{delta_e_2000, lab_of_linear, linear_table};
use terramp::photo::measure::{BLOCK_PX, MIN_PIXELS_PER_TEXEL, NO_TEXEL, PixelKeys};
use terramp::photo::{measure, measure_view};
use terramp_testkit::{camera, gpu, nc_impostors, nc_table_with, small_settings, synth_dataset};

const IMAGE_PX: u32 = 160;
/// The linear factor of the control frame: half the light, a change anyone sees (about 10 ΔE00).
const DIM_FACTOR: f64 = 0.5;
/// The control frame is rounded to sRGB bytes and the prediction is not: a byte step is at most
/// about 0.8 ΔE00 in the dark greens of a forest, half of it in rounding, and a block's 25
/// roundings mostly cancel in its mean. 0.2 is above that and far below what a factor 10 % off
/// changes (the check below).
const DIM_TOLERANCE: f64 = 0.2;
/// A flat footprint's luminance spread: its pixels' equal values less their mean, which a sum of
/// equal f64 divided by their count meets to within rounding.
const NO_DETAIL: f64 = 1e-12;
/// A flat paint rounds each footprint's linear mean to sRGB bytes, half a byte step per channel at
/// most: a few tenths of a ΔE00 in the darkest footprints (L* near 10, where a byte moves a* and b*
/// most), about 0.15 on average over a forest's footprints. The mean stays under 0.3.
const FLAT_TOLERANCE: f64 = 0.3;
/// The followed forest's blocks against the photograph's, mean CIEDE2000: issue 43's bound for
/// nc from 3 km. The crowns' own detail within a block (leaves, shading, gaps) and the model's
/// mean taken over every foliage triangle (leaves hiding leaves are not modelled) leave a little:
/// 2.09 measured here (lavapipe, 2026-12-06), from 250 m where the meshes are near.
const FOLLOWED_MAX_MEAN: f64 = 3.0;
/// ... and the models' own colours (the control), far from the synthetic imagery's: 26.89
/// measured; a third of it is still far outside the bound above.
const OWN_MIN_MEAN: f64 = 10.0;
/// The measure and this test sum the same values in other orders: f64 rounding only.
const SUM_ORDER: f64 = 1e-9;

fn srgb_byte(linear: f64) -> u8 {
    let c = if linear <= 0.0031308 { linear * 12.92 } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 };
    (c.clamp(0.0, 1.0) * 255.0).round() as u8
}

fn map_linear(image: &RgbaImage, f: impl Fn(usize, [f64; 3]) -> [f64; 3]) -> RgbaImage {
    let table = linear_table();
    let mut out = image.clone();
    for (i, p) in out.pixels_mut().enumerate() {
        let rgb = f(i, [0, 1, 2].map(|c| table[p[c] as usize]));
        for c in 0..3 {
            p[c] = srgb_byte(rgb[c]);
        }
    }
    out
}

/// Each block's mean linear colour in `image`, for the blocks at least half wooded.
fn block_means(image: &RgbaImage, keys: &PixelKeys) -> Vec<[f64; 3]> {
    let table = linear_table();
    let [w, h] = keys.size_px;
    let mut means = Vec::new();
    for by in 0..h / BLOCK_PX {
        for bx in 0..w / BLOCK_PX {
            let (mut sum, mut wooded) = ([0.0; 3], 0);
            for y in by * BLOCK_PX..(by + 1) * BLOCK_PX {
                for x in bx * BLOCK_PX..(bx + 1) * BLOCK_PX {
                    let p = image.get_pixel(x, y);
                    for c in 0..3 {
                        sum[c] += table[p[c] as usize];
                    }
                    wooded += usize::from(keys.wooded[(y * w + x) as usize]);
                }
            }
            if 2 * wooded >= (BLOCK_PX * BLOCK_PX) as usize {
                means.push(sum.map(|s| s / f64::from(BLOCK_PX * BLOCK_PX)));
            }
        }
    }
    means
}

/// The synthetic dataset with the shared models' trees, and a view 250 m over its centre looking
/// down at 60° over its forest (`None` without the shared models).
fn forest_view() -> Option<(Arc<Dataset>, Settings, Camera)> {
    let impostors = nc_impostors()?;
    let dir = synth_dataset(300, 7);
    let dataset = Arc::new(Dataset::open(&dir).unwrap());
    let mut settings = small_settings(IMAGE_PX, IMAGE_PX);
    settings.draw_seeds.impostors = impostors.display().to_string();
    let [w, h] = dataset.manifest.extent_m();
    let (x, y) = (0.5 * w, 0.5 * h);
    let ground_m = dataset.height_at(x, y, 0).unwrap();
    let o = dataset.manifest.origin_m;
    let pose = camera::looking(DVec3::new(x + o[0], y + o[1], ground_m + 250.0), 0.0, -60.0);
    Some((dataset, settings, pose))
}

#[test]
fn the_measure_sees_trees_a_brightness_change_and_no_detail_in_a_flat_paint() {
    let Some((dataset, settings, pose)) = forest_view() else { return };
    let view = measure_view(&gpu(), Arc::clone(&dataset), &settings, &pose, 0.0, None).unwrap();
    let (photo, keys, figures) = (&view.photograph, &view.keys, &view.figures);
    let pixels = (IMAGE_PX * IMAGE_PX) as usize;
    let wooded = keys.wooded.iter().filter(|&&v| v).count();
    assert!(wooded > pixels / 4, "the view must be mostly forest: {wooded} of {pixels} wooded");
    assert!(keys.texel.iter().all(|&t| t != NO_TEXEL), "looking down, every pixel shows imagery");
    assert!(figures.texels.counted > 20 && figures.blocks.counted > 100, "{figures:?}");

    // The photograph against itself.
    let same = measure(photo, photo, keys).unwrap();
    assert_eq!((same.texels.delta_e.unwrap().max, same.blocks.delta_e.unwrap().max), (0.0, 0.0));
    assert_eq!(same.changed_share, Some(0.0));

    // The trees: pixels changed, figures finite (what they are is the measure's to report).
    let trees = figures.blocks.delta_e.unwrap();
    assert!(figures.changed_share.unwrap() > 0.05, "{figures:?}");
    assert!(trees.mean.is_finite() && trees.mean > 0.0 && trees.max.is_finite(), "{trees:?}");

    // The control: every pixel at DIM_FACTOR of its light. The prediction: this test's own block
    // means of the photograph, scaled, through Lab.
    let dim = map_linear(photo, |_, rgb| rgb.map(|c| c * DIM_FACTOR));
    let predicted = |factor: f64| {
        let des: Vec<f64> = block_means(photo, keys)
            .iter()
            .map(|m| delta_e_2000(lab_of_linear(*m), lab_of_linear(m.map(|c| c * factor))))
            .collect();
        des.iter().sum::<f64>() / des.len() as f64
    };
    let measured = measure(&dim, photo, keys).unwrap().blocks.delta_e.unwrap().mean;
    let want = predicted(DIM_FACTOR);
    assert!(want > 5.0, "the control must be a visible change: {want}");
    assert!(
        (measured - want).abs() < DIM_TOLERANCE,
        "dimmed ×{DIM_FACTOR}: measured {measured}, predicted {want}"
    );
    let off = predicted(DIM_FACTOR * 1.1);
    assert!((measured - off).abs() > DIM_TOLERANCE, "the tolerance must tell a factor 10 % off: {off}");

    // A flat paint of each footprint of MIN_PIXELS_PER_TEXEL or more with the photograph's mean
    // there (this test's own means). What is left of ΔE is the rounding of each mean to bytes,
    // predicted footprint by footprint for those the measure counts (mostly wooded).
    let table = linear_table();
    let mut sums: std::collections::HashMap<u64, ([f64; 3], usize, usize)> = Default::default();
    for (i, p) in photo.pixels().enumerate() {
        let s = sums.entry(keys.texel[i]).or_default();
        for c in 0..3 {
            s.0[c] += table[p[c] as usize];
        }
        s.1 += 1;
        s.2 += usize::from(keys.wooded[i]);
    }
    let mean_of = |(sum, n, _): &([f64; 3], usize, usize)| sum.map(|s| s / *n as f64);
    let flat = map_linear(photo, |i, rgb| match sums.get(&keys.texel[i]) {
        Some(s) if s.1 >= MIN_PIXELS_PER_TEXEL => mean_of(s),
        _ => rgb,
    });
    let rounding: Vec<f64> = sums
        .iter()
        .filter(|(key, s)| **key != NO_TEXEL && s.1 >= MIN_PIXELS_PER_TEXEL && 2 * s.2 >= s.1)
        .map(|(_, s)| {
            let mean = mean_of(s);
            let painted = mean.map(|c| table[srgb_byte(c) as usize]);
            delta_e_2000(lab_of_linear(mean), lab_of_linear(painted))
        })
        .collect();
    let predicted = rounding.iter().sum::<f64>() / rounding.len() as f64;
    let painted = measure(&flat, photo, keys).unwrap();
    assert!(painted.texels.amplified_detail_y.unwrap() < NO_DETAIL, "{:?}", painted.texels);
    assert!(
        painted.texels.photograph_detail_y.unwrap() > 100.0 * NO_DETAIL,
        "the photograph has detail to lose"
    );
    assert!(figures.texels.amplified_detail_y.unwrap() > 100.0 * NO_DETAIL, "the trees have detail");
    let de = painted.texels.delta_e.unwrap();
    assert_eq!(painted.texels.counted, rounding.len());
    assert!(
        (de.mean - predicted).abs() < SUM_ORDER,
        "flat paint: measured {de:?}, predicted mean {predicted}"
    );
    assert!(de.mean < FLAT_TOLERANCE, "{de:?}");
    assert!(measure(&dim, photo, keys).unwrap().texels.delta_e.unwrap().mean > FLAT_TOLERANCE);
}

/// The colour follow-up on the GPU (`draw_seeds::from_above`, the texcells' sample mean): on the
/// same view, the trees' block means against the photograph's, with the follow-up (the default)
/// and without it (every species' and the texcells' `ground_blend` 0: the models' own colours,
/// the control). Following, the forest's local means are the photograph's within
/// `FOLLOWED_MAX_MEAN`; in their own colours they are not, by far; and the trees still change
/// pixels (detail kept, not a paint of the ground).
#[test]
fn the_trees_follow_the_photograph_s_local_mean() {
    let Some((dataset, settings, pose)) = forest_view() else { return };
    let followed = measure_view(&gpu(), Arc::clone(&dataset), &settings, &pose, 0.0, None).unwrap();
    let mut own = settings.clone();
    own.seeds.class_table = nc_table_with("photo-own-colours", "ground_blend = 0.0").display().to_string();
    own.texcells.ground_blend = 0.0;
    let own = measure_view(&gpu(), Arc::clone(&dataset), &own, &pose, 0.0, None).unwrap();
    let (f, o) = (followed.figures.blocks.delta_e.unwrap(), own.figures.blocks.delta_e.unwrap());
    println!(
        "blocks' CIEDE2000 against the photograph: followed {:.2} mean, {:.2} p95; own colours {:.2}, {:.2}; \
         changed share {:.3} and {:.3}",
        f.mean,
        f.p95,
        o.mean,
        o.p95,
        followed.figures.changed_share.unwrap(),
        own.figures.changed_share.unwrap()
    );
    assert!(followed.figures.changed_share.unwrap() > 0.05, "the trees must still be drawn");
    assert!(f.mean <= FOLLOWED_MAX_MEAN, "followed: {f:?}");
    assert!(o.mean >= OWN_MIN_MEAN, "the control (own colours) must fail the bound: {o:?}");
}
