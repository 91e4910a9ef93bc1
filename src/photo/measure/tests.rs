#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use super::*;
use crate::photo::colour::srgb_to_linear;

/// Figures of a few uniform colours are sums of a few hundred equal f64: exact to far below this.
const EXACT: f64 = 1e-9;

/// A `w` × `h` frame whose pixel (x, y) is `colour(x, y)` (sRGB bytes, opaque).
fn frame(w: u32, h: u32, colour: impl Fn(u32, u32) -> [u8; 3]) -> RgbaImage {
    RgbaImage::from_fn(w, h, |x, y| {
        let [r, g, b] = colour(x, y);
        image::Rgba([r, g, b, 255])
    })
}

/// Keys of a `w` × `h` view over texels `texel_px` pixels wide, every pixel wooded.
fn grid_keys(w: u32, h: u32, texel_px: u32) -> PixelKeys {
    let texel = (0..h).flat_map(|y| (0..w).map(move |x| texel_key([x / texel_px, y / texel_px]))).collect();
    PixelKeys::forest([w, h], texel)
}

fn lab_of_bytes(rgb: [u8; 3]) -> Lab {
    lab_of_linear(rgb.map(srgb_to_linear))
}

#[test]
fn a_frame_against_itself_is_zero_everywhere() {
    let photo = frame(20, 20, |x, y| [(x * 12) as u8, (y * 12) as u8, 90]);
    let figures = measure(&photo, &photo, &grid_keys(20, 20, 4)).unwrap();
    assert_eq!(figures.texels.counted, 25);
    assert_eq!(figures.blocks.counted, 16);
    assert_eq!(figures.texels.delta_e.unwrap().max, 0.0);
    assert_eq!(figures.blocks.delta_e.unwrap().max, 0.0);
    assert_eq!((figures.wooded_px, figures.changed_px, figures.changed_share), (400, 0, Some(0.0)));
    assert_eq!(figures.texels.amplified_mean_l, figures.texels.photograph_mean_l);
}

#[test]
fn a_uniform_colour_change_is_its_own_ciede2000() {
    // Two colours a forest shows: the reference computed from the bytes alone, not by `measure`.
    let (photo_rgb, frame_rgb) = ([62, 84, 40], [31, 52, 22]);
    let photo = frame(10, 10, |_, _| photo_rgb);
    let amplified = frame(10, 10, |_, _| frame_rgb);
    let want = delta_e_2000(lab_of_bytes(photo_rgb), lab_of_bytes(frame_rgb));
    assert!(want > 5.0, "the control must be a visible change: {want}");
    let figures = measure(&amplified, &photo, &grid_keys(10, 10, 5)).unwrap();
    for de in [figures.texels.delta_e.unwrap(), figures.blocks.delta_e.unwrap()] {
        for got in [de.mean, de.p95, de.max] {
            assert!((got - want).abs() < EXACT, "{got} against {want}");
        }
    }
    let l = figures.texels.amplified_mean_l.unwrap();
    assert!((l - lab_of_bytes(frame_rgb).l).abs() < EXACT);
    assert_eq!(figures.changed_share, Some(1.0));
}

#[test]
fn means_are_taken_in_linear_light() {
    // A footprint of black and white pixels half and half is, in linear light, grey 0.5: sRGB 188,
    // not the 128 of a mean of bytes (which would be ΔE00 of about 20 from it).
    let amplified = frame(2, 2, |x, _| if x == 0 { [0; 3] } else { [255; 3] });
    let photograph = frame(2, 2, |_, _| [188; 3]);
    let figures = measure(&amplified, &photograph, &grid_keys(2, 2, 2)).unwrap();
    assert_eq!(figures.texels.counted, 1);
    let de = figures.texels.delta_e.unwrap().mean;
    // 188 is linear 0.5029: within a byte of 0.5.
    assert!(de < 0.3, "{de}");
    // The control: against the mean of the bytes, far off.
    let bytes = measure(&amplified, &frame(2, 2, |_, _| [128; 3]), &grid_keys(2, 2, 2)).unwrap();
    assert!(bytes.texels.delta_e.unwrap().mean > 15.0);
    // Detail: luminance 0 and 1 about a mean of 0.5 spread by exactly 0.5; the flat frame none.
    assert!((figures.texels.amplified_detail_y.unwrap() - 0.5).abs() < 1e-6);
    assert!(figures.texels.photograph_detail_y.unwrap() < EXACT);
}

#[test]
fn footprints_count_only_with_enough_pixels_mostly_wooded() {
    // Texel 0: 4 pixels, 2 wooded (counts); texel 1: 4 pixels, 1 wooded (does not); texel 2:
    // 3 pixels, all wooded (too few); the last pixel is sky.
    let texel = [0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, NO_TEXEL]
        .map(|t| if t == NO_TEXEL { t } else { texel_key([t as u32, 0]) });
    let wooded = [true, true, false, false, true, false, false, false, true, true, true, false];
    let keys = PixelKeys { wooded: wooded.to_vec(), ..PixelKeys::forest([12, 1], texel.to_vec()) };
    let photo = frame(12, 1, |_, _| [50, 70, 30]);
    let amplified = frame(12, 1, |x, _| if x == 0 { [20, 30, 10] } else { [50, 70, 30] });
    let figures = measure(&amplified, &photo, &keys).unwrap();
    assert_eq!(figures.texels.counted, 1);
    assert!(figures.texels.delta_e.unwrap().mean > 1.0);
    // Too small for one 5 × 5 block: no block figures, not a perfect 0.
    assert_eq!((figures.blocks.counted, figures.blocks.delta_e), (0, None));
    assert_eq!((figures.wooded_px, figures.changed_px), (6, 1));
}

#[test]
fn blocks_need_half_their_pixels_wooded() {
    let photo = frame(10, 5, |_, _| [40, 60, 30]);
    let mut keys = grid_keys(10, 5, 1);
    // The left block keeps 13 of 25 wooded (counts), the right 12 (does not).
    for (i, v) in keys.wooded.iter_mut().enumerate() {
        let (x, y) = (i % 10, i / 10);
        *v = if x < 5 { y * 5 + x < 13 } else { y * 5 + (x - 5) < 12 };
    }
    let figures = measure(&photo, &photo, &keys).unwrap();
    assert_eq!(figures.blocks.counted, 1);
}

#[test]
fn p95_is_a_nearest_rank_member() {
    let values: Vec<f64> = (1..=100).map(f64::from).collect();
    let de = DeltaE::of(&values).unwrap().unwrap();
    assert_eq!((de.mean, de.p95, de.max), (50.5, 95.0, 100.0));
    assert_eq!(DeltaE::of(&[3.0]).unwrap().unwrap().p95, 3.0);
    assert_eq!(DeltaE::of(&[]).unwrap(), None);
    assert!(matches!(DeltaE::of(&[1.0, f64::NAN]), Err(PhotoError::NotFinite(_))));
}

#[test]
fn frames_of_other_sizes_are_refused() {
    let photo = frame(10, 10, |_, _| [0; 3]);
    let other = frame(10, 9, |_, _| [0; 3]);
    assert!(matches!(measure(&other, &photo, &grid_keys(10, 10, 2)), Err(PhotoError::Size { .. })));
    assert!(matches!(measure(&photo, &photo, &grid_keys(10, 9, 2)), Err(PhotoError::Size { .. })));
}
