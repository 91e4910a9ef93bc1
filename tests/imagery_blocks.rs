//! Block-compressed imagery (BC1, BC7): the same synthetic world stored three ways renders alike,
//! each cache slot holds the blocks as stored (a quarter, an eighth of RGBA8's bytes), and the
//! fallback that decodes blocks on load (adapters without BC sampling) draws what sampling the
//! blocks draws.
#![allow(clippy::unwrap_used, reason = "tests")]

use terramp::config::ImageryBlocks;
use terramp::dataset::{Dataset, ImageryFormat};
use terramp::gpu::Gpu;
use terramp::synth::SynthParams;
use terramp_testkit::camera::over_fraction;
use terramp_testkit::images::{differing_pixels, psnr};
use terramp_testkit::{ground_settings, lavapipe_only, renderer, settled_colour, synth_dataset_with};

const SIZE: u32 = 256;

fn dataset(imagery_format: ImageryFormat) -> std::path::PathBuf {
    synth_dataset_with(&SynthParams { size: SIZE, seed: 4, imagery_format, ..Default::default() })
}

/// The ground from low over the dataset (level-0 tiles, texel-sized detail) and from high above
/// (coarse levels, mips), with the caches' format and one slot's bytes.
fn views(dir: &std::path::Path, decode: bool) -> (Vec<image::RgbaImage>, wgpu::TextureFormat, usize, Gpu) {
    let mut settings = ground_settings(320, 180);
    settings.imagery.blocks = if decode { ImageryBlocks::Decode } else { ImageryBlocks::Sample };
    // Shown as the passes wrote it: a level of a texel is a level of the frame, where a tone
    // curve steeper than 1 would widen the sampler's rounding.
    settings.display.tone_curve = terramp::config::ToneCurve::Linear;
    let mut r = renderer(dir, settings);
    let images = [([0.4, 0.4], 120.0, -20.0), ([0.5, 0.1], 2500.0, -40.0)]
        .map(|(at, above_m, pitch)| {
            let camera = over_fraction(&r, at, above_m, 30.0, pitch);
            settled_colour(&mut r, &camera)
        })
        .to_vec();
    let cache = r.imagery_cache();
    (images, cache.format(), cache.tile_bytes(), r.gpu.clone())
}

/// Bytes of a tile of `mips` mips whose mip 0 is `extent` texels square, each mip's edge halved
/// from the last's and stored in whole 4 × 4 blocks of `block_bytes` (the format's own figure:
/// 8 for BC1, 16 for BC7), its last row and column of blocks padded.
fn block_tile_bytes(extent: u32, mips: u32, block_bytes: u64) -> u64 {
    (0..mips).map(|mip| u64::from((extent >> mip).div_ceil(4)).pow(2) * block_bytes).sum()
}

#[test]
fn block_imagery_renders_close_to_rgba8_and_its_decoded_fallback_like_the_blocks() {
    let (plain, plain_format, plain_slot, gpu) = views(&dataset(ImageryFormat::Rgba8), false);
    assert_eq!(plain_format, wgpu::TextureFormat::Rgba8UnormSrgb);
    for (format, floor_db, shrink, block_bytes) in
        [(ImageryFormat::Bc7, 45.0, 4, 16), (ImageryFormat::Bc1, 36.0, 8, 8)]
    {
        let dir = dataset(format);
        let layer = Dataset::open(&dir).unwrap().imagery.unwrap();
        assert_eq!(layer.block_format, Some(format));
        let (blocks, cache_format, slot, _) = views(&dir, false);
        // An adapter with BC sampling (lavapipe has it) holds the blocks as stored.
        let bc = gpu.device.features().contains(wgpu::Features::TEXTURE_COMPRESSION_BC);
        assert!(bc, "{}: the test needs an adapter that samples BC blocks", gpu.describe());
        assert_eq!(cache_format, format.texture_format());
        // Each mip in whole blocks, by the formula; within 1 % of the plain slot over `shrink`.
        let extent = layer.pyramid.tile + 2 * layer.pyramid.border;
        assert_eq!(slot as u64, block_tile_bytes(extent, layer.mips, block_bytes), "{format}");
        assert!((slot * shrink) as f64 / plain_slot as f64 - 1.0 < 0.01, "{format}: {slot} vs {plain_slot}");
        for (view, (b, p)) in blocks.iter().zip(&plain).enumerate() {
            let db = psnr(b, p);
            assert!(db >= floor_db, "{format} view {view}: {db:.1} dB against rgba8");
            assert!(differing_pixels(b, p) > 0, "{format} view {view} is lossless: were blocks drawn?");
        }
        let (decoded, decoded_format, decoded_slot, _) = views(&dir, true);
        assert_eq!((decoded_format, decoded_slot), (plain_format, plain_slot));
        if !lavapipe_only(&gpu, &format!("{format} sampled as blocks within a level of its decoding on load"))
        {
            continue;
        }
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
