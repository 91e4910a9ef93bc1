//! How it works: builds one layer's pack tile by tile, so memory stays flat however large the input.
//!
//! Level 0 tiles are cut from a *source*: a function that returns any in-range window of the
//! level-0 grid (GDAL reads for real data, a noise function for synthetic data). Windows that
//! reach past the layer's edge are completed by replicating the edge texel. Each coarser level is
//! then derived from the level below it as already written in the pack (read back through the
//! page cache, never held whole), by one `Reduce` rule per layer: heights are decimated so that a
//! coarse sample equals the fine sample at the same place (which is what keeps LOD seams exact),
//! imagery is box-filtered. A tile's mips are reduced from its own bordered mip 0, with the same
//! rule, so mips and coarser levels agree. Land cover is not reduced at all: `crate::dataset::lcc` writes
//! its lossless 3-level quadtree, cutting its source windows with the same `read_replicated`.

use std::path::Path;

use indicatif::ProgressBar;
use rayon::prelude::*;
use thiserror::Error;

use super::pack::{PackError, PackWriter};
use super::pyramid::{Pyramid, Sampling, TileId};
use super::{CELL_TILE_TEXELS, HEIGHT_BORDER, HEIGHT_TILE_CELLS, IMAGERY_BORDER, IMAGERY_MIPS};
use crate::dataset::lcc::LccError;

/// How a texel of level `l + 1` is made from the 2 × 2 texels of level `l` beneath it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduce {
    /// Keep the texel that shares the coarse texel's position (vertex-centred heights, masks).
    Decimate,
    /// Average (imagery).
    Mean,
}

/// A texel type a pack can store.
pub trait Texel: bytemuck::Pod + Send + Sync {
    /// One texel of the coarser level (or mip) from the 2 × 2 texels beneath it by `rule`,
    /// `block[dx + 2·dy]` the one at offset (dx, dy).
    fn reduce(rule: Reduce, block: [Self; 4]) -> Self;

    /// The value range recorded in the pack index for a tile of these texels, if the type has one.
    fn range(_texels: &[Self]) -> Option<[f32; 2]> {
        None
    }
}

impl Texel for f32 {
    fn range(texels: &[f32]) -> Option<[f32; 2]> {
        let range =
            texels.iter().fold([f32::INFINITY, f32::NEG_INFINITY], |[lo, hi], &v| [lo.min(v), hi.max(v)]);
        (range[0] <= range[1]).then_some(range)
    }

    fn reduce(rule: Reduce, block: [f32; 4]) -> f32 {
        match rule {
            Reduce::Decimate => block[0],
            Reduce::Mean => block.iter().sum::<f32>() * 0.25,
        }
    }
}

impl Texel for u8 {
    fn reduce(rule: Reduce, block: [u8; 4]) -> u8 {
        match rule {
            Reduce::Decimate => block[0],
            Reduce::Mean => ((block.iter().map(|&v| u32::from(v)).sum::<u32>() + 2) / 4) as u8,
        }
    }
}

impl Texel for [u8; 4] {
    fn reduce(rule: Reduce, block: [[u8; 4]; 4]) -> [u8; 4] {
        std::array::from_fn(|c| u8::reduce(rule, block.map(|texel| texel[c])))
    }
}

/// An in-range window of a layer's level-0 grid: texels `x0..x0 + width`, `y0..y0 + height`
/// (grid space: y grows north). Sources return texels row by row, southernmost row first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Window {
    /// Westmost texel column of the window.
    pub x0: u32,
    /// Southmost texel row of the window.
    pub y0: u32,
    /// Texel columns, west to east.
    pub width: u32,
    /// Texel rows, south to north.
    pub height: u32,
}

/// Why a layer's pack could not be written.
#[derive(Debug, Error)]
pub enum LayerError {
    /// Creating, writing, reading back or finishing the pack failed.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// The source could not deliver a window (e.g. a failed GDAL read).
    #[error("reading {layer} window {window:?}: {message}")]
    Source {
        /// The layer being written, e.g. "height".
        layer: &'static str,
        /// The window asked of the source, in texels of its grid.
        window: Window,
        /// The source's own message.
        message: String,
    },
    /// The source returned another number of texels than the window holds.
    #[error("{layer}: source returned {actual} texels for window {window:?}, expected {expected}")]
    SourceSize {
        /// The layer being written, e.g. "height".
        layer: &'static str,
        /// The window asked of the source, in texels of its grid.
        window: Window,
        /// Texels in the window, `width × height`.
        expected: usize,
        /// Texels the source returned.
        actual: usize,
    },
    /// The land cover's LCC coding is invalid, or the source gave a code outside its palette.
    #[error(transparent)]
    Lcc(#[from] LccError),
}

/// What is stored for one layer.
#[derive(Debug, Clone, Copy)]
pub struct LayerSpec {
    /// The layer's name in progress and error messages, e.g. "height".
    pub name: &'static str,
    /// The layer's tile quadtree, which numbers the pack's tiles.
    pub pyramid: Pyramid,
    /// Mip levels stored in each tile (1 = mip 0 only).
    pub mips: u32,
    /// How coarser levels and mips are made from the texels beneath them.
    pub reduce: Reduce,
}

impl LayerSpec {
    /// Heights: vertex samples in f32 metres, decimated so coarse samples are fine ones.
    pub fn heights(size: [u32; 2]) -> Self {
        let pyramid = Pyramid::new(size, HEIGHT_TILE_CELLS, HEIGHT_BORDER, Sampling::Vertex);
        Self { name: "height", pyramid, mips: 1, reduce: Reduce::Decimate }
    }

    /// The heights' validity mask: the heights' pyramid, one u8 per sample, decimated alike.
    pub fn valid_mask(size: [u32; 2]) -> Self {
        Self { name: "valid mask", ..Self::heights(size) }
    }

    /// Imagery: RGBA8 sRGB texels with their mips and borders, box-filtered.
    pub fn imagery(size: [u32; 2]) -> Self {
        let pyramid = Pyramid::new(size, CELL_TILE_TEXELS, IMAGERY_BORDER, Sampling::Cell);
        Self { name: "imagery", pyramid, mips: IMAGERY_MIPS, reduce: Reduce::Mean }
    }

    /// Texels of one stored tile, every mip included (`mip_extent(m)`² each).
    pub fn tile_texels(&self) -> usize {
        (0..self.mips).map(|m| (self.pyramid.mip_extent(m) as usize).pow(2)).sum()
    }

    /// Payload bytes of one stored tile of `T` texels, mips included: the pack's tile size.
    pub fn tile_bytes<T: Texel>(&self) -> u64 {
        (self.tile_texels() * size_of::<T>()) as u64
    }
}

/// Writes every tile of `spec` into the pack at `path`, level 0 from `source`.
pub fn write_layer<T, S>(
    path: &Path,
    spec: &LayerSpec,
    source: S,
    progress: &ProgressBar,
) -> Result<(), LayerError>
where
    T: Texel,
    S: Fn(Window) -> Result<Vec<T>, String> + Sync,
{
    let pyramid = &spec.pyramid;
    debug_assert!(pyramid.tile_extent().is_multiple_of(1 << (spec.mips - 1)), "mips must halve exactly");
    let writer = PackWriter::create(path, spec.tile_bytes::<T>(), pyramid.tile_count())?;
    progress.set_length(pyramid.tile_count());
    for level in 0..pyramid.levels {
        let [nx, ny] = pyramid.tiles_at(level);
        let ids: Vec<TileId> = (0..ny).flat_map(|y| (0..nx).map(move |x| TileId::new(level, x, y))).collect();
        ids.par_iter().try_for_each(|&id| -> Result<(), LayerError> {
            let extent = pyramid.tile_extent();
            let [x0, y0] = pyramid.tile_origin(id);
            // A coarse tile's range also spans the finer tiles it was reduced from, so it bounds
            // every level-0 value beneath it, not only its own (decimated) samples.
            let (mip0, range_below) = if level == 0 {
                (read_replicated(spec.name, spec.pyramid.size, &source, [x0, y0], extent)?, None)
            } else {
                reduce_level_below(spec, &writer, id)?
            };
            let range = union(T::range(&mip0), range_below);
            let payload = with_mips(spec, mip0);
            let index = pyramid.tile_index(id).unwrap_or_default();
            writer.write_tile(index, bytemuck::cast_slice(&payload), range)?;
            progress.inc(1);
            Ok(())
        })?;
    }
    writer.finish()?;
    Ok(())
}

/// The `extent`² window at `origin` of a source grid of `size` texels (`layer` names it in
/// errors), south row first, edge-replicated beyond the grid.
pub(crate) fn read_replicated<T, S>(
    layer: &'static str,
    size: [u32; 2],
    source: &S,
    [x0, y0]: [i64; 2],
    extent: u32,
) -> Result<Vec<T>, LayerError>
where
    T: bytemuck::Pod,
    S: Fn(Window) -> Result<Vec<T>, String>,
{
    let size = size.map(i64::from);
    let clamp = |v: i64, axis: usize| v.clamp(0, size[axis] - 1);
    let (lo, hi) = (
        [clamp(x0, 0), clamp(y0, 1)],
        [clamp(x0 + i64::from(extent) - 1, 0), clamp(y0 + i64::from(extent) - 1, 1)],
    );
    let window = Window {
        x0: lo[0] as u32,
        y0: lo[1] as u32,
        width: (hi[0] - lo[0] + 1) as u32,
        height: (hi[1] - lo[1] + 1) as u32,
    };
    let texels = source(window).map_err(|message| LayerError::Source { layer, window, message })?;
    let expected = window.width as usize * window.height as usize;
    if texels.len() != expected {
        return Err(LayerError::SourceSize { layer, window, expected, actual: texels.len() });
    }
    let extent = extent as usize;
    let mut out = Vec::with_capacity(extent * extent);
    for j in 0..extent as i64 {
        let row = (clamp(y0 + j, 1) - lo[1]) as usize * window.width as usize;
        out.extend((0..extent as i64).map(|i| texels[row + (clamp(x0 + i, 0) - lo[0]) as usize]));
    }
    Ok(out)
}

fn union(a: Option<[f32; 2]>, b: Option<[f32; 2]>) -> Option<[f32; 2]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([a[0].min(b[0]), a[1].max(b[1])]),
        (a, b) => a.or(b),
    }
}

/// Mip 0 of tile `id` (level ≥ 1), reduced from the level below as written in the pack, with the
/// union of the ranges of the tiles it read.
fn reduce_level_below<T: Texel>(
    spec: &LayerSpec,
    writer: &PackWriter,
    id: TileId,
) -> Result<(Vec<T>, Option<[f32; 2]>), LayerError> {
    let pyramid = &spec.pyramid;
    let below = id.level - 1;
    let size_below = pyramid.size_at(below).map(i64::from);
    let extent = pyramid.tile_extent() as i64;
    let [x0, y0] = pyramid.tile_origin(id);
    // The level-below window this tile reads: 2 × (extent + 1) texels from 2 × origin, clamped.
    let lo = [2 * x0, 2 * y0].map(|v| v.max(0));
    let hi = [0, 1].map(|a| (2 * [x0, y0][a] + 2 * extent - 1).min(size_below[a] - 1));
    let (window, range) = read_written_window::<T>(spec, writer, below, lo, hi)?;
    let width = (hi[0] - lo[0] + 1) as usize;
    let at = |x: i64, y: i64| {
        let (x, y) = (x.clamp(0, size_below[0] - 1), y.clamp(0, size_below[1] - 1));
        window[(y - lo[1]) as usize * width + (x - lo[0]) as usize]
    };
    let size = pyramid.size_at(id.level).map(i64::from);
    let mut out = Vec::with_capacity((extent * extent) as usize);
    for j in 0..extent {
        let y = (y0 + j).clamp(0, size[1] - 1);
        for i in 0..extent {
            let x = (x0 + i).clamp(0, size[0] - 1);
            let block =
                [at(2 * x, 2 * y), at(2 * x + 1, 2 * y), at(2 * x, 2 * y + 1), at(2 * x + 1, 2 * y + 1)];
            out.push(T::reduce(spec.reduce, block));
        }
    }
    Ok((out, range))
}

/// Texels `lo..=hi` of `level`, gathered from the interiors of the tiles already written, with the
/// union of those tiles' ranges.
fn read_written_window<T: Texel>(
    spec: &LayerSpec,
    writer: &PackWriter,
    level: u32,
    lo: [i64; 2],
    hi: [i64; 2],
) -> Result<(Vec<T>, Option<[f32; 2]>), LayerError> {
    let pyramid = &spec.pyramid;
    let (tile, border, extent) =
        (i64::from(pyramid.tile), i64::from(pyramid.border), pyramid.tile_extent() as usize);
    let tiles = pyramid.tiles_at(level).map(i64::from);
    let width = (hi[0] - lo[0] + 1) as usize;
    let mut window = vec![T::zeroed(); width * (hi[1] - lo[1] + 1) as usize];
    let mut range = None;
    let tile_of = |v: i64, axis: usize| (v / tile).min(tiles[axis] - 1);
    for ty in tile_of(lo[1], 1)..=tile_of(hi[1], 1) {
        for tx in tile_of(lo[0], 0)..=tile_of(hi[0], 0) {
            let id = TileId::new(level, tx as u32, ty as u32);
            let index = pyramid.tile_index(id).unwrap_or_default();
            let bytes = writer.read_tile(index)?;
            range = union(range, writer.tile_range(index)?);
            let texels: &[T] = bytemuck::cast_slice(&bytes[..extent * extent * size_of::<T>()]);
            // The texels this tile owns: its interior; the last tile also owns the rest of the axis.
            let own_lo = [tx * tile, ty * tile];
            let own_hi =
                [0, 1].map(|a| if [tx, ty][a] == tiles[a] - 1 { hi[a] } else { own_lo[a] + tile - 1 });
            for y in own_lo[1].max(lo[1])..=own_hi[1].min(hi[1]) {
                let src_row = (y - own_lo[1] + border) as usize * extent;
                for x in own_lo[0].max(lo[0])..=own_hi[0].min(hi[0]) {
                    window[(y - lo[1]) as usize * width + (x - lo[0]) as usize] =
                        texels[src_row + (x - own_lo[0] + border) as usize];
                }
            }
        }
    }
    Ok((window, range))
}

/// Mip 0 followed by its reductions, as stored in a tile payload.
fn with_mips<T: Texel>(spec: &LayerSpec, mip0: Vec<T>) -> Vec<T> {
    let mut payload = Vec::with_capacity(spec.tile_texels());
    payload.extend_from_slice(&mip0);
    let mut previous = mip0;
    for mip in 1..spec.mips {
        let (extent, below) =
            (spec.pyramid.mip_extent(mip) as usize, spec.pyramid.mip_extent(mip - 1) as usize);
        let at = |x: usize, y: usize| previous[y * below + x];
        let next: Vec<T> = (0..extent * extent)
            .map(|k| {
                let (x, y) = (2 * (k % extent), 2 * (k / extent));
                T::reduce(spec.reduce, [at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)])
            })
            .collect();
        payload.extend_from_slice(&next);
        previous = next;
    }
    payload
}
