//! How it works: a partition writes whole subtrees, each from one read of its source. For a
//! subtree rooted at level `k`, the texels each level must hold are found top down: at level `l`,
//! the bordered windows of the subtree's tiles, and the window one level up reduces from (twice
//! its extent, plus one). Level 0's rectangle is read from the source in one window; each level
//! above is reduced from the one below over its rectangle, with `write_layer`'s clamping and
//! reduction rule; every tile is then cut from its level's image exactly as `write_layer` cuts
//! it from the source or from the tiles below. Only two levels are held at once.

use std::path::Path;

use indicatif::ProgressBar;
use rayon::prelude::*;

use super::{PartSlots, Split};
use crate::dataset::layer_writer::made_tile;
use crate::dataset::lcc::{LccCoding, LccTiles, lcc_pyramid};
use crate::dataset::pack::PackWriter;
use crate::dataset::{LayerError, LayerSpec, Pyramid, Texel, TileId, Window};

/// Rows of level 0 read from the source at once, on any thread.
const BAND_ROWS: u32 = 128;

/// An inclusive rectangle of one level's texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Rect {
    lo: [i64; 2],
    hi: [i64; 2],
}

impl Rect {
    /// The rectangle as a source window.
    pub(super) fn window(self) -> Window {
        Window {
            x0: self.lo[0] as u32,
            y0: self.lo[1] as u32,
            width: self.width() as u32,
            height: (self.hi[1] - self.lo[1] + 1) as u32,
        }
    }

    fn width(&self) -> usize {
        (self.hi[0] - self.lo[0] + 1) as usize
    }

    pub(super) fn union(self, other: Rect) -> Rect {
        Rect {
            lo: [0, 1].map(|a| self.lo[a].min(other.lo[a])),
            hi: [0, 1].map(|a| self.hi[a].max(other.hi[a])),
        }
    }
}

/// A level's texels over a rectangle, row by row, south first.
struct Image<T> {
    rect: Rect,
    texels: Vec<T>,
}

impl<T: Copy> Image<T> {
    fn at(&self, x: i64, y: i64) -> T {
        let (rect, width) = (&self.rect, self.rect.width());
        self.texels[(y - rect.lo[1]) as usize * width + (x - rect.lo[0]) as usize]
    }
}

/// The rectangle of each level, 0 to the split level, that `root`'s subtree reads.
pub(super) fn needed_rects(pyramid: &Pyramid, split: &Split, root: TileId) -> Vec<Rect> {
    let extent = i64::from(pyramid.tile_extent());
    let mut rects = Vec::with_capacity(split.level as usize + 1);
    for level in (0..=split.level).rev() {
        let tiles = split.subtree_at(root, level);
        let (first, last) = (tiles[0], tiles[tiles.len() - 1]);
        let last_texel = pyramid.size_at(level).map(|n| i64::from(n) - 1);
        let (lo, hi) = (pyramid.tile_origin(first), pyramid.tile_origin(last));
        let mut rect = Rect {
            lo: [0, 1].map(|a| lo[a].clamp(0, last_texel[a])),
            hi: [0, 1].map(|a| (hi[a] + extent - 1).clamp(0, last_texel[a])),
        };
        if let Some(above) = rects.last() {
            let Rect { lo, hi } = *above;
            let read = Rect { lo: lo.map(|v| 2 * v), hi: [0, 1].map(|a| (2 * hi[a] + 1).min(last_texel[a])) };
            rect = rect.union(read);
        }
        rects.push(rect);
    }
    rects.reverse();
    rects
}

/// Level 0 over `rect`, read from the source in bands of rows on every thread (a source's texel
/// is the same whichever window reads it).
fn read_level0<T: Texel, S>(name: &'static str, source: &S, rect: Rect) -> Result<Image<T>, LayerError>
where
    S: Fn(Window) -> Result<Vec<T>, String> + Sync,
{
    let whole = rect.window();
    let bands: Vec<Window> = (0..whole.height.div_ceil(BAND_ROWS))
        .map(|b| Window {
            y0: whole.y0 + b * BAND_ROWS,
            height: BAND_ROWS.min(whole.height - b * BAND_ROWS),
            ..whole
        })
        .collect();
    let bands = bands
        .into_par_iter()
        .map(|window| {
            let texels =
                source(window).map_err(|message| LayerError::Source { layer: name, window, message })?;
            let expected = window.width as usize * window.height as usize;
            if texels.len() != expected {
                return Err(LayerError::SourceSize { layer: name, window, expected, actual: texels.len() });
            }
            Ok(texels)
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Image { rect, texels: bands.concat() })
}

/// Level `level` over `rect`, reduced from the level below (which covers what it reads).
fn reduce_image<T: Texel>(spec: &LayerSpec, below: &Image<T>, level: u32, rect: Rect) -> Image<T> {
    let size_below = spec.pyramid.size_at(level - 1).map(|n| i64::from(n) - 1);
    let at = |x: i64, y: i64| below.at(x.min(size_below[0]), y.min(size_below[1]));
    let texels = (rect.lo[1]..=rect.hi[1])
        .into_par_iter()
        .flat_map_iter(|y| {
            (rect.lo[0]..=rect.hi[0]).map(move |x| {
                let (x, y) = (2 * x, 2 * y);
                T::reduce(spec.reduce, [at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)])
            })
        })
        .collect();
    Image { rect, texels }
}

/// Mip 0 of tile `id`, cut from its level's image with the edge replicated beyond the layer.
fn cut_tile<T: Texel>(pyramid: &Pyramid, image: &Image<T>, id: TileId) -> Vec<T> {
    let extent = i64::from(pyramid.tile_extent());
    let last_texel = pyramid.size_at(id.level).map(|n| i64::from(n) - 1);
    let [x0, y0] = pyramid.tile_origin(id);
    let mut out = Vec::with_capacity((extent * extent) as usize);
    for j in 0..extent {
        let y = (y0 + j).clamp(0, last_texel[1]);
        out.extend((0..extent).map(|i| image.at((x0 + i).clamp(0, last_texel[0]), y)));
    }
    out
}

/// Writes partition `part` of `spec`'s layer, as `split` cuts it, into the part pack at `path`:
/// every tile of its subtrees with `write_layer`'s payload and the tile's own value range.
pub fn write_layer_part<T, S>(
    path: &Path,
    spec: &LayerSpec,
    split: &Split,
    part: u32,
    source: S,
    progress: &ProgressBar,
) -> Result<(), LayerError>
where
    T: Texel,
    S: Fn(Window) -> Result<Vec<T>, String> + Sync,
{
    let pyramid = &spec.pyramid;
    let slots = PartSlots::new(pyramid, &split.tiles(part));
    let writer = PackWriter::create(path, spec.tile_bytes::<T>(), slots.len(), T::codec())?;
    progress.set_length(slots.len());
    for root in split.roots(part) {
        let rects = needed_rects(pyramid, split, root);
        let mut image = read_level0(spec.name, &source, rects[0])?;
        for level in 0..=split.level {
            if level > 0 {
                image = reduce_image(spec, &image, level, rects[level as usize]);
            }
            writer.write_ordered(&split.subtree_at(root, level), |&id| -> Result<_, LayerError> {
                // The tile's own range: those of the tiles it was reduced from join at the merge.
                let slot = pyramid.tile_index(id).and_then(|global| slots.slot(global));
                progress.inc(1);
                Ok(made_tile(spec, slot.unwrap_or(u64::MAX), cut_tile(pyramid, &image, id), None))
            })?;
        }
    }
    writer.finish()?;
    Ok(())
}

/// Writes partition `part` of a land-cover layer (`write_lcc_layer`'s arguments) into the part
/// pack at `path`. Its subtrees need nothing beyond themselves: the land cover has no border, a
/// level-0 tile is cut from its level-1 parent and a level-2 tile packs its level-1 children.
pub fn write_lcc_part<S>(
    path: &Path,
    source_size: [u32; 2],
    coding: &LccCoding,
    split: &Split,
    part: u32,
    source: S,
    progress: &ProgressBar,
) -> Result<(), LayerError>
where
    S: Fn(Window) -> Result<Vec<u8>, String> + Sync,
{
    let tiles = LccTiles::new(source_size, coding)?;
    let pyramid = lcc_pyramid(source_size);
    let slots = PartSlots::new(&pyramid, &split.tiles(part));
    let writer = tiles.create(path, slots.len())?;
    progress.set_length(slots.len());
    let roots = split.roots(part);
    for level in LccTiles::LEVEL_ORDER.into_iter().filter(|&level| level <= split.level) {
        let ids = roots.iter().flat_map(|&root| split.subtree_at(root, level)).collect();
        let slot = |id: TileId| pyramid.tile_index(id).and_then(|global| slots.slot(global));
        tiles.write_level(&writer, level, ids, slot, &source, progress)?;
    }
    writer.finish()?;
    Ok(())
}
