//! How it works: one layer's pack with the pyramid that numbers its tiles (`LayerPack`): a tile
//! is read from the pack (its stored bytes checked against their CRC-32, then decoded by the
//! pack's codec), and the last few tiles read are kept (`RecentTiles`): tools and twins read
//! texel by texel, mostly from the same few tiles.

use std::collections::VecDeque;
use std::path::Path;
use std::sync::{Arc, Mutex};

use super::pack::{Pack, PackError};
use super::{DatasetError, ImageryFormat, LayerSpec, Pyramid, Reduce, TileId};

/// Tiles a layer keeps for the next reads (decoded): tools and twins read texel by
/// texel, mostly from the same few tiles.
const RECENT_TILES_KEPT: usize = 16;

/// The latest few tiles read, newest last, by pack index.
#[derive(Default)]
struct RecentTiles(Mutex<VecDeque<(u64, Arc<[u8]>)>>);

impl RecentTiles {
    fn get(&self, index: u64) -> Option<Arc<[u8]>> {
        let tiles = self.0.lock().ok()?;
        tiles.iter().find(|(i, _)| *i == index).map(|(_, bytes)| Arc::clone(bytes))
    }

    fn keep(&self, index: u64, bytes: &Arc<[u8]>) {
        if let Ok(mut tiles) = self.0.lock() {
            if tiles.len() == RECENT_TILES_KEPT {
                tiles.pop_front();
            }
            tiles.push_back((index, Arc::clone(bytes)));
        }
    }
}

/// One layer's pack with the pyramid that addresses it.
pub struct LayerPack {
    /// The tile quadtree that numbers the pack's tiles, as the manifest gives it.
    pub pyramid: Pyramid,
    /// Mips stored per tile: the imagery's count, 1 for heights, the mask and land cover.
    pub mips: u32,
    /// How the texels are stored when in blocks (block-compressed imagery); `None` when plain.
    pub block_format: Option<ImageryFormat>,
    pack: Pack,
    /// The latest payloads read and decoded.
    recent: RecentTiles,
    /// The latest tiles decoded from blocks into plain texels (block formats only).
    plain: RecentTiles,
}

impl LayerPack {
    /// The pack `file` in `dir`, checked to hold a tile of `tile_bytes` for every tile of `pyramid`.
    pub(super) fn open(
        dir: &Path,
        file: &str,
        pyramid: Pyramid,
        mips: u32,
        tile_bytes: u64,
        block_format: Option<ImageryFormat>,
    ) -> Result<Self, DatasetError> {
        let pack = Pack::open(&dir.join(file))?;
        if pack.tile_count() != pyramid.tile_count() || pack.tile_bytes() != tile_bytes {
            return Err(DatasetError::PackShape {
                path: pack.path().to_owned(),
                found: pack.tile_count(),
                found_bytes: pack.tile_bytes(),
                expected: pyramid.tile_count(),
                expected_bytes: tile_bytes,
            });
        }
        Ok(Self {
            pyramid,
            mips,
            block_format,
            pack,
            recent: RecentTiles::default(),
            plain: RecentTiles::default(),
        })
    }

    /// A pack of plain texels of `texel_bytes` each, `mips` mips a tile.
    pub(super) fn open_plain(
        dir: &Path,
        file: &str,
        pyramid: Pyramid,
        mips: u32,
        texel_bytes: usize,
    ) -> Result<Self, DatasetError> {
        let spec = LayerSpec { name: "", pyramid, mips, reduce: Reduce::Decimate };
        Self::open(dir, file, pyramid, mips, (spec.tile_texels() * texel_bytes) as u64, None)
    }

    /// The layer's pack: its codec and sizes.
    pub fn pack(&self) -> &Pack {
        &self.pack
    }

    /// The tile's value range from the pack index (heights: conservative min/max of every
    /// level-0 sample under the tile), without reading the tile.
    pub fn tile_range(&self, id: TileId) -> Result<Option<[f32; 2]>, PackError> {
        self.pack.tile_range(self.index_of(id)?)
    }

    fn index_of(&self, id: TileId) -> Result<u64, PackError> {
        self.pyramid.tile_index(id).ok_or_else(|| PackError::OutOfRange {
            path: self.pack.path().to_owned(),
            index: u64::MAX,
            count: self.pack.tile_count(),
        })
    }

    /// The tile's payload (all mips) as stored, checksum verified and decoded (the last
    /// `RECENT_TILES_KEPT` are kept for the next reads).
    pub fn tile_bytes(&self, id: TileId) -> Result<Arc<[u8]>, PackError> {
        let index = self.index_of(id)?;
        if let Some(bytes) = self.recent.get(index) {
            return Ok(bytes);
        }
        let bytes: Arc<[u8]> = self.pack.tile(index)?.into();
        self.recent.keep(index, &bytes);
        Ok(bytes)
    }

    /// The tile's texels (all mips, each `mip_extent`² texels): the payload itself when stored
    /// plain, else decoded from its blocks into RGBA8 (the last few are kept for the next reads).
    pub fn tile_texels(&self, id: TileId) -> Result<Arc<[u8]>, PackError> {
        let Some(format) = self.block_format else { return self.tile_bytes(id) };
        let index = self.index_of(id)?;
        if let Some(texels) = self.plain.get(index) {
            return Ok(texels);
        }
        let texels: Arc<[u8]> = format.decode_tile(&self.pyramid, self.mips, &self.tile_bytes(id)?).into();
        self.plain.keep(index, &texels);
        Ok(texels)
    }
}

/// A little-endian word of 1, 2 or 4 bytes, widened.
pub(super) fn word_of(bytes: &[u8]) -> u32 {
    bytes.iter().rev().fold(0, |word, &b| word << 8 | u32::from(b))
}
