//! How it works: the LCC pack is written level 1 first, each tile cut from the source (its codes
//! turned into palette indices); level 0 repeats each level-1 index on its 2 × 2 children and
//! level 2 packs four into a word, both from level 1 as written in the pack, read back through the
//! page cache. `LccTiles` writes any set of tiles of one level into any pack (a slot per tile), so
//! the whole layer (`write_lcc_layer`), a partition's subtrees and the merge share every rule.

use std::path::Path;

use indicatif::ProgressBar;

use super::{LAYER_NAME, LCC_SOURCE_LEVEL, LccCoding, LccError, lcc_pyramid};
use crate::dataset::layer_writer::read_replicated;
// Bit-packed codes: no predictor helps them.
use crate::dataset::pack::{Codec, PackError, PackWriter, Predictor};
use crate::dataset::{LayerError, Pyramid, TileId, Window};

/// A word type the LCC pack can store.
trait LccWord: bytemuck::Pod + Send + Sync + Into<u32> {
    /// `value` in this word; the caller made sure it fits.
    fn narrow(value: u32) -> Self;
}

macro_rules! lcc_word {
    ($($word:ty),*) => {$(
        impl LccWord for $word {
            fn narrow(value: u32) -> Self {
                value as $word
            }
        }
    )*};
}
lcc_word!(u8, u16, u32);

/// Writes the 3-level LCC pack at `path` from `source`, the codes of the level-1 grid of
/// `source_size` texels (south row first). Every code must be in `coding`'s palette. Returns the
/// layer's pyramid.
pub fn write_lcc_layer<S>(
    path: &Path,
    source_size: [u32; 2],
    coding: &LccCoding,
    source: S,
    progress: &ProgressBar,
) -> Result<Pyramid, LayerError>
where
    S: Fn(Window) -> Result<Vec<u8>, String> + Sync,
{
    let tiles = LccTiles::new(source_size, coding)?;
    let pyramid = lcc_pyramid(source_size);
    let writer = tiles.create(path, pyramid.tile_count())?;
    progress.set_length(pyramid.tile_count());
    for level in LccTiles::LEVEL_ORDER {
        let [nx, ny] = pyramid.tiles_at(level);
        let ids = (0..ny).flat_map(|y| (0..nx).map(move |x| TileId::new(level, x, y))).collect();
        tiles.write_level(&writer, level, ids, |id| pyramid.tile_index(id), &source, progress)?;
    }
    writer.finish()?;
    Ok(pyramid)
}

/// The tiles of one LCC layer: how each level's are made, into any pack.
pub(crate) struct LccTiles<'a> {
    pyramid: Pyramid,
    coding: &'a LccCoding,
    /// The palette index of every source code the palette holds.
    index_of: [Option<u32>; 256],
}

impl<'a> LccTiles<'a> {
    /// The order levels are written in: level 1 from the source, then the two derived from it.
    pub(crate) const LEVEL_ORDER: [u32; 3] = [LCC_SOURCE_LEVEL, 0, 2];

    /// The tiles of the layer over a level-1 grid of `source_size` texels, coded by `coding`.
    pub(crate) fn new(source_size: [u32; 2], coding: &'a LccCoding) -> Result<Self, LayerError> {
        coding.validate()?;
        let mut index_of = [None; 256];
        for (entry, &code) in coding.palette.iter().enumerate() {
            index_of[usize::from(code)] = Some(entry as u32 + 1);
        }
        Ok(Self { pyramid: lcc_pyramid(source_size), coding, index_of })
    }

    /// Payload bytes of one tile.
    pub(crate) fn tile_bytes(&self) -> u64 {
        (self.pyramid.tile_extent() as usize).pow(2) as u64 * self.coding.word_bytes() as u64
    }

    /// Creates (or truncates) a pack at `path` for `tile_count` of these tiles.
    pub(crate) fn create(&self, path: &Path, tile_count: u64) -> Result<PackWriter, PackError> {
        PackWriter::create(path, self.tile_bytes(), tile_count, Codec::Zstd(Predictor::None))
    }

    /// Makes the tiles `ids` of `level` into `writer`, each at its `slot`; level 1 is cut from
    /// `source`, levels 0 and 2 read level 1 back from `writer` through the same slots (and read
    /// no source).
    pub(crate) fn write_level<S>(
        &self,
        writer: &PackWriter,
        level: u32,
        ids: Vec<TileId>,
        slot: impl Fn(TileId) -> Option<u64> + Sync,
        source: &S,
        progress: &ProgressBar,
    ) -> Result<(), LayerError>
    where
        S: Fn(Window) -> Result<Vec<u8>, String> + Sync,
    {
        match self.coding.word_bits {
            8 => self.write_words::<u8, S>(writer, level, &ids, &slot, source, progress),
            16 => self.write_words::<u16, S>(writer, level, &ids, &slot, source, progress),
            _ => self.write_words::<u32, S>(writer, level, &ids, &slot, source, progress),
        }
    }

    fn write_words<W: LccWord, S>(
        &self,
        writer: &PackWriter,
        level: u32,
        ids: &[TileId],
        slot: &(impl Fn(TileId) -> Option<u64> + Sync),
        source: &S,
        progress: &ProgressBar,
    ) -> Result<(), LayerError>
    where
        S: Fn(Window) -> Result<Vec<u8>, String> + Sync,
    {
        let pyramid = &self.pyramid;
        let extent = pyramid.tile_extent();
        writer.write_ordered(ids, |&id| -> Result<_, LayerError> {
            let [x0, y0] = [id.x, id.y].map(|t| t * pyramid.tile);
            let words: Vec<u32> = match level {
                0 => {
                    let fine = self.level1_block::<W>(writer, slot, [x0 / 2, y0 / 2], extent / 2)?;
                    let half = (extent / 2) as usize;
                    (0..extent as usize)
                        .flat_map(|j| (0..extent as usize).map(move |i| (i, j)))
                        .map(|(i, j)| fine[(j / 2) * half + i / 2])
                        .collect()
                }
                1 => {
                    let (origin, size) = ([x0, y0].map(i64::from), pyramid.size_at(LCC_SOURCE_LEVEL));
                    let codes = read_replicated(LAYER_NAME, size, source, origin, extent)?;
                    codes
                        .into_iter()
                        .map(|c| self.index_of[usize::from(c)].ok_or(LccError::NotInPalette { code: c }))
                        .collect::<Result<_, _>>()?
                }
                _ => self.level2_words::<W>(writer, slot, id)?,
            };
            let range = self.index_range(level, &words);
            let payload: Vec<W> = words.into_iter().map(W::narrow).collect();
            progress.inc(1);
            Ok((slot(id).unwrap_or(u64::MAX), bytemuck::cast_slice(&payload).to_vec(), range))
        })
    }

    /// The words of level-2 tile `id`, each packing the 4 level-1 texels it covers; beyond the
    /// layer, the edge word repeats.
    fn level2_words<W: LccWord>(
        &self,
        writer: &PackWriter,
        slot: &impl Fn(TileId) -> Option<u64>,
        id: TileId,
    ) -> Result<Vec<u32>, LayerError> {
        let pyramid = &self.pyramid;
        let (extent, size) = (pyramid.tile_extent(), pyramid.size_at(2));
        let [x0, y0] = [id.x, id.y].map(|t| t * pyramid.tile);
        let fine = self.level1_block::<W>(writer, slot, [2 * x0, 2 * y0], 2 * extent)?;
        let fine_extent = 2 * extent as usize;
        let mut words = Vec::with_capacity((extent as usize).pow(2));
        for j in 0..extent {
            let y = (y0 + j).min(size[1] - 1) - y0;
            for i in 0..extent {
                let x = (x0 + i).min(size[0] - 1) - x0;
                let child =
                    |dx: u32, dy: u32| fine[(2 * y + dy) as usize * fine_extent + (2 * x + dx) as usize];
                words.push(self.coding.pack([child(0, 0), child(1, 0), child(0, 1), child(1, 1)]));
            }
        }
        Ok(words)
    }

    /// Level-1 indices of the `extent`² block at `origin`, clamped to the layer, gathered from the
    /// level-1 tiles already written.
    fn level1_block<W: LccWord>(
        &self,
        writer: &PackWriter,
        slot: &impl Fn(TileId) -> Option<u64>,
        origin: [u32; 2],
        extent: u32,
    ) -> Result<Vec<u32>, LayerError> {
        let pyramid = &self.pyramid;
        let (size, tile) = (pyramid.size_at(LCC_SOURCE_LEVEL), pyramid.tile);
        let clamp = |v: u32, axis: usize| v.min(size[axis] - 1);
        let first = [0, 1].map(|a| clamp(origin[a], a) / tile);
        let last = [0, 1].map(|a| clamp(origin[a] + extent - 1, a) / tile);
        let mut tiles = Vec::new();
        for ty in first[1]..=last[1] {
            for tx in first[0]..=last[0] {
                let index = slot(TileId::new(LCC_SOURCE_LEVEL, tx, ty)).unwrap_or(u64::MAX);
                let words: Vec<W> = bytemuck::pod_collect_to_vec(&writer.read_tile(index)?);
                tiles.push(words);
            }
        }
        let across = (last[0] - first[0] + 1) as usize;
        let mut block = Vec::with_capacity((extent as usize).pow(2));
        for j in 0..extent {
            let y = clamp(origin[1] + j, 1);
            for i in 0..extent {
                let x = clamp(origin[0] + i, 0);
                let (tx, ty) = ((x / tile - first[0]) as usize, (y / tile - first[1]) as usize);
                // Land-cover tiles have no border: a tile's words are its `tile`² texels.
                let local = ((y % tile) * tile + x % tile) as usize;
                block.push(tiles[ty * across + tx][local].into());
            }
        }
        Ok(block)
    }

    /// The pack index range of a tile: min and max palette index under it.
    fn index_range(&self, level: u32, words: &[u32]) -> Option<[f32; 2]> {
        let sub_codes = if level < 2 { 1 } else { 4 };
        let indices = words.iter().flat_map(|&w| (0..sub_codes).map(move |k| (w, [k & 1, k >> 1])));
        let [lo, hi] = indices
            .map(|(word, q)| self.coding.decode(level, word, q))
            .fold([u32::MAX, 0], |[lo, hi], v| [lo.min(v), hi.max(v)]);
        (lo <= hi).then_some([lo as f32, hi as f32])
    }
}
