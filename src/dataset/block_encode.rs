//! How it works: turns an imagery pack of RGBA8 tiles into one of BC1 or BC7 blocks
//! (`ImageryFormat`), tile by tile on every thread, placed in the pack's order (the same input
//! gives the same bytes). Builds write the plain pack first, because every coarser level and mip
//! is reduced from the plain texels beneath it (blocks would compound their error level after
//! level); the blocks are made last, once, from the finished plain pack.
//!
//! The encoder is Intel's ISPC texture compressor (`intel_tex_2`: maintained bindings with the
//! kernels prebuilt for Linux, macOS and Windows, no ISPC needed to build; its BC7 is among the
//! best of the fast encoders, and it runs on the CPU, so a build needs no GPU). Each mip is
//! padded to whole blocks by repeating its last column and row: the padding is never sampled (a
//! mip's texture coordinates end at its own edge) and repeating keeps the edge blocks' endpoints
//! fitted to the texels that are. BC1 keeps coverage as one bit: a block with texels of alpha
//! below a half is re-indexed in BC1's three-colour mode (its endpoints as the encoder fitted
//! them), those texels transparent black, the others the nearest of the three colours; the ground
//! shader divides a filtered BC1 colour by its alpha (`IMAGERY_PUNCHED`).

use std::path::Path;

use indicatif::ProgressBar;

use super::imagery_format::ImageryFormat;
use super::layer_writer::{LayerError, level_ids};
use super::manifest::CellLayer;
use super::pack::{Codec, Pack, PackError, PackWriter, Predictor};
use super::pyramid::Pyramid;
use super::staging::Staging;

// intel_tex_2's prebuilt kernels carry C++ (its ASTC encoder, linked in with the rest) but do not
// name the C++ runtime: without this, a binary that links nothing else of C++ (`terramp-data` built
// alone) fails to link.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[link(name = "stdc++")]
unsafe extern "C" {}
#[cfg(target_os = "macos")]
#[link(name = "c++")]
unsafe extern "C" {}

/// How a block pack stores its tiles: zstd with no predictor (blocks look like noise to a
/// predictor; zstd still finds the repeated endpoints of flat ground).
const BLOCK_CODEC: Codec = Codec::Zstd(Predictor::None);

/// BC7's settings for a tile: opaque tiles spend no bits on alpha. ISPC's "very fast" profile:
/// on single tiles of the synthetic and nc imagery, close to its "basic" profile at a fraction of
/// its time, while "ultra fast" lost clearly more (compared once, in code not kept; no setting
/// selects another profile: docs/building.md, "Block-compressed imagery").
fn bc7_settings(opaque: bool) -> intel_tex_2::bc7::EncodeSettings {
    if opaque {
        intel_tex_2::bc7::opaque_very_fast_settings()
    } else {
        intel_tex_2::bc7::alpha_very_fast_settings()
    }
}

/// Turns the plain imagery pack `layer` names in `staging` into `format`'s blocks (nothing to do
/// for `Rgba8`), under the same name, and records the format in `layer`.
pub fn encode_staged_imagery(
    staging: &Staging,
    layer: &mut CellLayer,
    format: ImageryFormat,
    progress: &ProgressBar,
) -> Result<(), LayerError> {
    if format == ImageryFormat::Rgba8 {
        return Ok(());
    }
    let (plain, blocks) = (staging.path(&layer.pack), staging.path(&format!(".{}.blocks", layer.pack)));
    encode_imagery_pack(&plain, &blocks, &layer.pyramid, layer.mips, format, progress)?;
    std::fs::rename(&blocks, &plain).map_err(|source| PackError::Io { path: plain.clone(), source })?;
    layer.format = format.name().to_owned();
    Ok(())
}

/// Writes `plain` (an RGBA8 imagery pack of `pyramid` with `mips` mips) as `format`'s blocks into
/// a new pack at `out`, one progress step a tile.
pub fn encode_imagery_pack(
    plain: &Path,
    out: &Path,
    pyramid: &Pyramid,
    mips: u32,
    format: ImageryFormat,
    progress: &ProgressBar,
) -> Result<(), LayerError> {
    let source = Pack::open(plain)?;
    let writer =
        PackWriter::create(out, format.tile_bytes(pyramid, mips), pyramid.tile_count(), BLOCK_CODEC)?;
    progress.set_length(pyramid.tile_count());
    for level in 0..pyramid.levels {
        writer.write_ordered(&level_ids(pyramid, level), |&id| -> Result<_, LayerError> {
            let index = pyramid.tile_index(id).unwrap_or_default();
            let blocks = encode_tile(format, pyramid, mips, &source.tile(index)?);
            progress.inc(1);
            Ok((index, blocks, None))
        })?;
    }
    writer.finish()?;
    Ok(())
}

/// A tile's payload in `format` from its RGBA8 texels (all `mips`, as a plain pack stores them).
pub fn encode_tile(format: ImageryFormat, pyramid: &Pyramid, mips: u32, texels: &[u8]) -> Vec<u8> {
    if format == ImageryFormat::Rgba8 {
        return texels.to_vec();
    }
    let opaque = texels.chunks_exact(4).all(|t| t[3] == u8::MAX);
    let mut blocks = Vec::with_capacity(format.tile_bytes(pyramid, mips) as usize);
    let mut offset = 0;
    for mip in 0..mips {
        let extent = pyramid.mip_extent(mip) as usize;
        let layout = format.mip_layout(pyramid, mip);
        let padded =
            padded_mip(&texels[offset..offset + extent * extent * 4], extent, layout.copy_extent as usize);
        let surface = intel_tex_2::RgbaSurface {
            data: &padded,
            width: layout.copy_extent,
            height: layout.copy_extent,
            stride: layout.copy_extent * 4,
        };
        let start = blocks.len();
        blocks.resize(start + layout.bytes(), 0);
        match format {
            ImageryFormat::Bc1 => {
                intel_tex_2::bc1::compress_blocks_into(&surface, &mut blocks[start..]);
                if !opaque {
                    punch_holes(&mut blocks[start..], &padded, layout.copy_extent as usize);
                }
            }
            _ => {
                intel_tex_2::bc7::compress_blocks_into(&bc7_settings(opaque), &surface, &mut blocks[start..])
            }
        }
        offset += extent * extent * 4;
    }
    blocks
}

/// Alpha below which a BC1 texel is a hole (transparent black).
const BC1_HOLE_ALPHA: u8 = 128;

/// Re-indexes the BC1 `blocks` of the `width`² RGBA8 `texels` whose blocks hold holes in BC1's
/// three-colour mode: endpoints ordered so that the first is not above the second (what selects the
/// mode), holes index 3, every other texel the nearest of the endpoints and their midpoint.
fn punch_holes(blocks: &mut [u8], texels: &[u8], width: usize) {
    let blocks_x = width / 4;
    for (k, block) in blocks.chunks_exact_mut(8).enumerate() {
        let (bx, by) = (4 * (k % blocks_x), 4 * (k / blocks_x));
        let texel = |i: usize| &texels[4 * ((by + i / 4) * width + bx + i % 4)..][..4];
        if (0..16).all(|i| texel(i)[3] >= BC1_HOLE_ALPHA) {
            continue;
        }
        let ends = [u16::from_le_bytes([block[0], block[1]]), u16::from_le_bytes([block[2], block[3]])];
        let (low, high) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
        let (c0, c1) = (rgb565(low), rgb565(high));
        let palette = [c0, c1, std::array::from_fn(|c| (c0[c] + c1[c]) / 2)];
        let mut indices = 0u32;
        for i in 0..16 {
            let t = texel(i);
            let index = if t[3] < BC1_HOLE_ALPHA {
                3
            } else {
                let distance = |p: &[i32; 3]| (0..3).map(|c| (p[c] - i32::from(t[c])).pow(2)).sum::<i32>();
                (0..3).min_by_key(|&j| distance(&palette[j])).unwrap_or(0) as u32
            };
            indices |= index << (2 * i);
        }
        block[..2].copy_from_slice(&low.to_le_bytes());
        block[2..4].copy_from_slice(&high.to_le_bytes());
        block[4..].copy_from_slice(&indices.to_le_bytes());
    }
}

/// An RGB565 endpoint's colour in 8-bit channels, as decoders expand it (bits repeated).
fn rgb565(v: u16) -> [i32; 3] {
    let (r, g, b) = (i32::from(v >> 11), i32::from((v >> 5) & 63), i32::from(v & 31));
    [(r << 3) | (r >> 2), (g << 2) | (g >> 4), (b << 3) | (b >> 2)]
}

/// A square mip of `extent` RGBA8 texels grown to `padded` by repeating its last column and row.
fn padded_mip(texels: &[u8], extent: usize, padded: usize) -> Vec<u8> {
    if padded == extent {
        return texels.to_vec();
    }
    let mut out = Vec::with_capacity(padded * padded * 4);
    for y in 0..padded {
        let row = &texels[y.min(extent - 1) * extent * 4..][..extent * 4];
        out.extend_from_slice(row);
        let last = &row[(extent - 1) * 4..];
        for _ in extent..padded {
            out.extend_from_slice(last);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::LayerSpec;

    /// A tile of smooth colour with some detail, all mips, as a plain pack stores it.
    fn plain_tile(spec: &LayerSpec, alpha: impl Fn(usize, usize) -> u8) -> Vec<u8> {
        let mut texels = Vec::new();
        for mip in 0..spec.mips {
            let extent = spec.pyramid.mip_extent(mip) as usize;
            for y in 0..extent {
                for x in 0..extent {
                    let (u, v) = ((x << mip) as f32, (y << mip) as f32);
                    let r = 120.0 + 60.0 * (u * 0.05).sin();
                    let g = 100.0 + 50.0 * (v * 0.07).cos();
                    let b = 80.0 + 30.0 * ((u + v) * 0.02).sin();
                    texels.extend_from_slice(&[r as u8, g as u8, b as u8, alpha(x << mip, y << mip)]);
                }
            }
        }
        texels
    }

    fn psnr(a: &[u8], b: &[u8]) -> f64 {
        let mse = a.iter().zip(b).map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2)).sum::<f64>()
            / a.len() as f64;
        10.0 * (255.0f64.powi(2) / mse.max(1e-12)).log10()
    }

    #[test]
    fn blocks_decode_close_to_the_plain_tile_in_every_mip_padded_one_included() {
        let spec = LayerSpec::imagery([512, 512]);
        let plain = plain_tile(&spec, |_, _| 255);
        for (format, floor_db) in [(ImageryFormat::Bc1, 27.0), (ImageryFormat::Bc7, 34.0)] {
            let blocks = encode_tile(format, &spec.pyramid, spec.mips, &plain);
            assert_eq!(blocks.len() as u64, format.tile_bytes(&spec.pyramid, spec.mips));
            let decoded = format.decode_tile(&spec.pyramid, spec.mips, &blocks);
            assert_eq!(decoded.len(), plain.len());
            let mut offset = 0;
            for mip in 0..spec.mips {
                let bytes = (spec.pyramid.mip_extent(mip) as usize).pow(2) * 4;
                let db = psnr(&plain[offset..offset + bytes], &decoded[offset..offset + bytes]);
                assert!(db > floor_db, "{format} mip {mip}: {db:.1} dB");
                offset += bytes;
            }
        }
    }

    #[test]
    fn both_block_formats_keep_the_holes_in_coverage() {
        let spec = LayerSpec::imagery([512, 512]);
        // A hole whose edge crosses blocks (x < 101, y < 41).
        let holed = plain_tile(&spec, |x, y| if x < 101 && y < 41 { 0 } else { 255 });
        let extent = spec.pyramid.mip_extent(0) as usize;
        for format in [ImageryFormat::Bc7, ImageryFormat::Bc1] {
            let blocks = encode_tile(format, &spec.pyramid, spec.mips, &holed);
            let decoded = format.decode_tile(&spec.pyramid, spec.mips, &blocks);
            for (x, y) in [(0, 0), (100, 40), (101, 40), (100, 41), (300, 300)] {
                let (texel, plain) =
                    (&decoded[4 * (y * extent + x)..][..4], &holed[4 * (y * extent + x)..][..4]);
                assert_eq!(texel[3], plain[3], "{format} alpha at ({x}, {y})");
                if plain[3] == 255 {
                    let error = (0..3).map(|c| texel[c].abs_diff(plain[c])).max().unwrap();
                    assert!(error <= 24, "{format} at ({x}, {y}): {texel:?} for {plain:?}");
                } else if format == ImageryFormat::Bc1 {
                    assert_eq!(texel, [0, 0, 0, 0], "a BC1 hole is transparent black");
                }
            }
        }
    }

    #[test]
    fn padding_repeats_the_last_column_and_row() {
        let texels: Vec<u8> = (0..4u8).flat_map(|k| [k, k, k, 255]).collect();
        let padded = padded_mip(&texels, 2, 4);
        let reds: Vec<u8> = padded.chunks_exact(4).map(|t| t[0]).collect();
        assert_eq!(reds, [0, 1, 1, 1, 2, 3, 3, 3, 2, 3, 3, 3, 2, 3, 3, 3]);
    }
}
