//! Block-compressed imagery (BC1, BC7): the same synthetic world stored three ways renders alike,
//! each cache slot holds the blocks as stored (a quarter, an eighth of RGBA8's bytes), and the
//! fallback that decodes blocks on load (adapters without BC sampling) draws what sampling the
//! blocks draws.
#![allow(clippy::unwrap_used, reason = "tests")]

use terramp::config::ImageryBlocks;
use terramp::dataset::{Dataset, ImageryFormat};
use terramp::synth::SynthParams;
use terramp_testkit::camera::over_fraction;
use terramp_testkit::images::{differing_pixels, psnr};
use terramp_testkit::{ground_settings, renderer, settled_colour, synth_dataset_with};

const SIZE: u32 = 256;

fn dataset(imagery_format: ImageryFormat) -> std::path::PathBuf {
    synth_dataset_with(&SynthParams { size: SIZE, seed: 4, imagery_format, ..Default::default() })
}

/// The ground from low over the dataset (level-0 tiles, texel-sized detail) and from high above
/// (coarse levels, mips), with the caches' format and one slot's bytes.
fn views(dir: &std::path::Path, decode: bool) -> (Vec<image::RgbaImage>, wgpu::TextureFormat, usize) {
    let mut settings = ground_settings(320, 180);
    settings.imagery.blocks = if decode { ImageryBlocks::Decode } else { ImageryBlocks::Sample };
    let mut r = renderer(dir, settings);
    let images = [([0.4, 0.4], 120.0, -20.0), ([0.5, 0.1], 2500.0, -40.0)]
        .map(|(at, above_m, pitch)| {
            let camera = over_fraction(&r, at, above_m, 30.0, pitch);
            settled_colour(&mut r, &camera)
        })
        .to_vec();
    let cache = r.imagery_cache();
    (images, cache.format(), cache.tile_bytes())
}

#[test]
fn block_imagery_renders_close_to_rgba8_and_its_decoded_fallback_like_the_blocks() {
    let (plain, plain_format, plain_slot) = views(&dataset(ImageryFormat::Rgba8), false);
    assert_eq!(plain_format, wgpu::TextureFormat::Rgba8UnormSrgb);
    for (format, floor_db, shrink) in [(ImageryFormat::Bc7, 45.0, 4), (ImageryFormat::Bc1, 36.0, 8)] {
        let dir = dataset(format);
        let layer = Dataset::open(&dir).unwrap().imagery.unwrap();
        assert_eq!(layer.block_format, Some(format));
        let (blocks, cache_format, slot) = views(&dir, false);
        assert_eq!(cache_format, format.texture_format(), "lavapipe samples BC blocks");
        // Each mip in whole blocks: within 1 % of the plain slot over `shrink`.
        assert_eq!(slot as u64, format.tile_bytes(&layer.pyramid, layer.mips));
        assert!((slot * shrink) as f64 / plain_slot as f64 - 1.0 < 0.01, "{format}: {slot} vs {plain_slot}");
        for (view, (b, p)) in blocks.iter().zip(&plain).enumerate() {
            let db = psnr(b, p);
            assert!(db >= floor_db, "{format} view {view}: {db:.1} dB against rgba8");
            assert!(differing_pixels(b, p) > 0, "{format} view {view} is lossless: were blocks drawn?");
        }
        let (decoded, decoded_format, decoded_slot) = views(&dir, true);
        assert_eq!((decoded_format, decoded_slot), (plain_format, plain_slot));
        for (view, (d, b)) in decoded.iter().zip(&blocks).enumerate() {
            // The texels decode alike (BC7's decoding is exact by its specification, BC1's nearly);
            // a sampler may still round a block format's sRGB conversion and filtering
            // differently, by a level (lavapipe does).
            let worst =
                d.pixels().zip(b.pixels()).flat_map(|(x, y)| (0..3).map(move |c| x[c].abs_diff(y[c]))).max();
            let allowed = 1;
            assert!(worst <= Some(allowed), "{format} view {view}: decoded on load differs by {worst:?}");
        }
    }
}
