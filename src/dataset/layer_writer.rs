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
use thiserror::Error;

use super::pack::{Codec, MadeTile, PackError, PackWriter, Predictor};
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

    /// How a pack stores tiles of these texels (losslessly, `pack::codec`).
    fn codec() -> Codec;
}

impl Texel for f32 {
    fn codec() -> Codec {
        Codec::Zstd(Predictor::Grid32)
    }

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
    fn codec() -> Codec {
        Codec::Zstd(Predictor::Planes(1))
    }

    fn reduce(rule: Reduce, block: [u8; 4]) -> u8 {
        match rule {
            Reduce::Decimate => block[0],
            Reduce::Mean => ((block.iter().map(|&v| u32::from(v)).sum::<u32>() + 2) / 4) as u8,
        }
    }
}

impl Texel for [u8; 4] {
    fn codec() -> Codec {
        Codec::Zstd(Predictor::Planes(4))
    }

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
    /// A partitioned build's part pack is not the one its plan expects.
    #[error("{}: {message}", path.display())]
    Parts {
        /// The part pack.
        path: std::path::PathBuf,
        /// What is wrong with it.
        message: String,
    },
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
    let writer = PackWriter::create(path, spec.tile_bytes::<T>(), pyramid.tile_count(), T::codec())?;
    progress.set_length(pyramid.tile_count());
    writer.write_ordered(&level_ids(pyramid, 0), |&id| -> Result<_, LayerError> {
        let (origin, extent) = (pyramid.tile_origin(id), pyramid.tile_extent());
        let mip0 = read_replicated(spec.name, pyramid.size, &source, origin, extent)?;
        progress.inc(1);
        Ok(made_tile(spec, pyramid.tile_index(id).unwrap_or_default(), mip0, None))
    })?;
    for level in 1..pyramid.levels {
        write_reduced_level::<T>(spec, &writer, level, progress)?;
    }
    writer.finish()?;
    Ok(())
}

/// Every tile of `level`, row by row: the order a pack places them in.
pub(crate) fn level_ids(pyramid: &Pyramid, level: u32) -> Vec<TileId> {
    let [nx, ny] = pyramid.tiles_at(level);
    (0..ny).flat_map(|y| (0..nx).map(move |x| TileId::new(level, x, y))).collect()
}

/// Writes every tile of `level` (≥ 1) into `writer`, reduced from the level below as written
/// there. A coarse tile's range also spans the finer tiles it was reduced from, so it bounds every
/// level-0 value beneath it, not only its own (decimated) samples.
pub(crate) fn write_reduced_level<T: Texel>(
    spec: &LayerSpec,
    writer: &PackWriter,
    level: u32,
    progress: &ProgressBar,
) -> Result<(), LayerError> {
    let pyramid = &spec.pyramid;
    writer.write_ordered(&level_ids(pyramid, level), |&id| -> Result<_, LayerError> {
        let mip0 = reduce_level_below::<T>(spec, writer, id)?;
        let below = range_below(pyramid, writer, id)?;
        progress.inc(1);
        Ok(made_tile(spec, pyramid.tile_index(id).unwrap_or_default(), mip0, below))
    })
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

pub(crate) fn union(a: Option<[f32; 2]>, b: Option<[f32; 2]>) -> Option<[f32; 2]> {
    match (a, b) {
        (Some(a), Some(b)) => Some([a[0].min(b[0]), a[1].max(b[1])]),
        (a, b) => a.or(b),
    }
}

/// The level-below window tile `id` (level ≥ 1) reduces from: 2 × extent texels from 2 × its
/// origin, clamped to the level.
fn window_below(pyramid: &Pyramid, id: TileId) -> ([i64; 2], [i64; 2]) {
    let size_below = pyramid.size_at(id.level - 1).map(i64::from);
    let extent = i64::from(pyramid.tile_extent());
    let origin = pyramid.tile_origin(id);
    let lo = origin.map(|v| (2 * v).max(0));
    let hi = [0, 1].map(|a| (2 * origin[a] + 2 * extent - 1).min(size_below[a] - 1));
    (lo, hi)
}

/// The tiles of the level below whose texels tile `id` (level ≥ 1) reduces from, row by row: those
/// whose owned texels (its interior; the last tile of an axis owns the rest) meet its window.
fn tiles_below(pyramid: &Pyramid, id: TileId) -> impl Iterator<Item = TileId> {
    let (lo, hi) = window_below(pyramid, id);
    let (level, tile) = (id.level - 1, i64::from(pyramid.tile));
    let tiles = pyramid.tiles_at(level).map(i64::from);
    let tile_of = move |v: i64, axis: usize| (v / tile).min(tiles[axis] - 1);
    (tile_of(lo[1], 1)..=tile_of(hi[1], 1)).flat_map(move |ty| {
        (tile_of(lo[0], 0)..=tile_of(hi[0], 0)).map(move |tx| TileId::new(level, tx as u32, ty as u32))
    })
}

/// The union of the ranges of the tiles `id` (level ≥ 1) is reduced from, as written in `writer`.
pub(crate) fn range_below(
    pyramid: &Pyramid,
    writer: &PackWriter,
    id: TileId,
) -> Result<Option<[f32; 2]>, LayerError> {
    let mut range = None;
    for below in tiles_below(pyramid, id) {
        range = union(range, writer.tile_range(pyramid.tile_index(below).unwrap_or_default())?);
    }
    Ok(range)
}

/// Mip 0 of tile `id` (level ≥ 1), reduced from the level below as written in the pack.
fn reduce_level_below<T: Texel>(
    spec: &LayerSpec,
    writer: &PackWriter,
    id: TileId,
) -> Result<Vec<T>, LayerError> {
    let pyramid = &spec.pyramid;
    let size_below = pyramid.size_at(id.level - 1).map(i64::from);
    let extent = pyramid.tile_extent() as i64;
    let [x0, y0] = pyramid.tile_origin(id);
    let (lo, hi) = window_below(pyramid, id);
    let window = read_written_window::<T>(spec, writer, id, lo, hi)?;
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
    Ok(out)
}

/// Texels `lo..=hi` of the level below tile `id`, gathered from the interiors of the tiles already
/// written there.
fn read_written_window<T: Texel>(
    spec: &LayerSpec,
    writer: &PackWriter,
    id: TileId,
    lo: [i64; 2],
    hi: [i64; 2],
) -> Result<Vec<T>, LayerError> {
    let pyramid = &spec.pyramid;
    let (tile, border, extent) =
        (i64::from(pyramid.tile), i64::from(pyramid.border), pyramid.tile_extent() as usize);
    let tiles = pyramid.tiles_at(id.level - 1).map(i64::from);
    let width = (hi[0] - lo[0] + 1) as usize;
    let mut window = vec![T::zeroed(); width * (hi[1] - lo[1] + 1) as usize];
    for below in tiles_below(pyramid, id) {
        let bytes = writer.read_tile(pyramid.tile_index(below).unwrap_or_default())?;
        let texels: &[T] = bytemuck::cast_slice(&bytes[..extent * extent * size_of::<T>()]);
        let (tx, ty) = (i64::from(below.x), i64::from(below.y));
        // The texels this tile owns: its interior; the last tile also owns the rest of the axis.
        let own_lo = [tx * tile, ty * tile];
        let own_hi = [0, 1].map(|a| if [tx, ty][a] == tiles[a] - 1 { hi[a] } else { own_lo[a] + tile - 1 });
        for y in own_lo[1].max(lo[1])..=own_hi[1].min(hi[1]) {
            let src_row = (y - own_lo[1] + border) as usize * extent;
            for x in own_lo[0].max(lo[0])..=own_hi[0].min(hi[0]) {
                window[(y - lo[1]) as usize * width + (x - lo[0]) as usize] =
                    texels[src_row + (x - own_lo[0] + border) as usize];
            }
        }
    }
    Ok(window)
}

/// The tile to place at `index` from its mip 0: the payload with its mips, and as range its own
/// texels' with `below`, the ranges of the tiles it was reduced from.
pub(crate) fn made_tile<T: Texel>(
    spec: &LayerSpec,
    index: u64,
    mip0: Vec<T>,
    below: Option<[f32; 2]>,
) -> MadeTile {
    let range = union(T::range(&mip0), below);
    let payload = with_mips(spec, mip0);
    (index, bytemuck::cast_slice(&payload).to_vec(), range)
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
