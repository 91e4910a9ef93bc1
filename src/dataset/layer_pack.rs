//! How it works: one layer's pack with the pyramid that numbers its tiles (`LayerPack`), and what
//! a tile must hold beyond its checksum. A tile is read from the pack (its stored bytes checked
//! against their CRC-32, then decoded by the pack's codec), then, where the layer records a value
//! range per tile in the pack's index, every value is checked to lie within it: each height sample
//! (which also refuses NaN and infinities), each land-cover palette index (levels 0 and 1: the
//! word; level 2: each of its four sub-codes). The checksum catches damage on the way from the
//! disk; the range catches what decodes anyway from damage the checksum cannot see (made before
//! it, as `faults.damage` injects), so no pass meets a non-finite height, a height outside the
//! bounds culling takes from the index, or a palette index the tile does not hold. Imagery and
//! the validity mask record no range: damaged texels that decode are shown as they decode.
//!
//! The last few tiles read are kept (`RecentTiles`): tools and twins read texel by texel, mostly
//! from the same few tiles.

use std::collections::VecDeque;
use std::path::Path;
use std::sync::{Arc, Mutex};

use super::lcc::{LCC_PACKED_LEVEL, LccCoding};
use super::pack::{Damage, Pack, PackError};
use super::{DatasetError, ImageryFormat, LayerSpec, Pyramid, Reduce, TileId};

/// Tiles a layer keeps for the next reads (decoded, checked): tools and twins read texel by
/// texel, mostly from the same few tiles.
const RECENT_TILES_KEPT: usize = 16;

/// What a layer's tiles are checked for beyond their checksum.
#[derive(Debug, Clone)]
pub enum ValueCheck {
    /// Nothing (imagery, the validity mask: no range is recorded).
    None,
    /// `f32` samples, each within its tile's recorded range.
    Heights,
    /// LCC words read through this coding, each palette index within its tile's recorded range.
    Landcover(LccCoding),
}

impl ValueCheck {
    /// The first value of tile `id`'s `payload` outside `[min, max]` (NaN is outside any range).
    fn outside(&self, id: TileId, payload: &[u8], [min, max]: [f32; 2]) -> Option<f32> {
        let within = |v: &f32| min <= *v && *v <= max;
        match self {
            Self::None => None,
            Self::Heights => payload
                .chunks_exact(4)
                .map(|w| f32::from_le_bytes([w[0], w[1], w[2], w[3]]))
                .find(|v| !within(v)),
            Self::Landcover(coding) => {
                let sub_codes = if id.level < LCC_PACKED_LEVEL { 1 } else { 4 };
                payload
                    .chunks_exact(coding.word_bytes())
                    .map(word_of)
                    .flat_map(|word| {
                        (0..sub_codes)
                            .map(move |k: u32| coding.decode(id.level, word, [k & 1, k >> 1]) as f32)
                    })
                    .find(|v| !within(v))
            }
        }
    }
}

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
    /// What each tile is checked for after it decodes.
    check: ValueCheck,
    /// The latest payloads read, decoded and checked.
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
            check: ValueCheck::None,
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

    /// The layer with its tiles checked by `check` after they decode.
    pub(super) fn with_check(self, check: ValueCheck) -> Self {
        Self { check, ..self }
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

    /// The tile's payload (all mips) as stored, checksum verified, decoded and checked against
    /// its recorded range (the last `RECENT_TILES_KEPT` are kept for the next reads).
    pub fn tile_bytes(&self, id: TileId) -> Result<Arc<[u8]>, PackError> {
        let index = self.index_of(id)?;
        if let Some(bytes) = self.recent.get(index) {
            return Ok(bytes);
        }
        let bytes = self.checked(id, index, self.pack.tile(index)?)?;
        self.recent.keep(index, &bytes);
        Ok(bytes)
    }

    /// The tile as `tile_bytes` gives it had its stored bytes been damaged as `damage` says, through
    /// the same checks; never kept. Fault injection's corrupt reads (`[faults]`).
    pub fn tile_damaged(&self, id: TileId, damage: Damage) -> Result<Arc<[u8]>, PackError> {
        let index = self.index_of(id)?;
        self.checked(id, index, self.pack.tile_damaged(index, damage)?)
    }

    /// `payload` if every value lies within the tile's recorded range (or the layer has none).
    fn checked(&self, id: TileId, index: u64, payload: Vec<u8>) -> Result<Arc<[u8]>, PackError> {
        if let Some([min, max]) = self.pack.tile_range(index)?
            && let Some(value) = self.check.outside(id, &payload, [min, max])
        {
            return Err(PackError::OutsideRange {
                path: self.pack.path().to_owned(),
                index,
                value,
                min,
                max,
            });
        }
        Ok(payload.into())
    }

    /// The tile's texels (all mips, each `mip_extent`² texels): the payload itself when stored
    /// plain, else decoded from its blocks into RGBA8 (the last few are kept for the next reads).
    pub fn tile_texels(&self, id: TileId) -> Result<Arc<[u8]>, PackError> {
        if self.block_format.is_none() {
            return self.tile_bytes(id);
        }
        let index = self.index_of(id)?;
        if let Some(texels) = self.plain.get(index) {
            return Ok(texels);
        }
        let texels = self.texels_of(self.tile_bytes(id)?);
        self.plain.keep(index, &texels);
        Ok(texels)
    }

    /// The texels of a payload of this layer: itself when stored plain, else its blocks decoded.
    pub fn texels_of(&self, payload: Arc<[u8]>) -> Arc<[u8]> {
        match self.block_format {
            Some(format) => format.decode_tile(&self.pyramid, self.mips, &payload).into(),
            None => payload,
        }
    }
}

/// A little-endian word of 1, 2 or 4 bytes, widened.
pub(super) fn word_of(bytes: &[u8]) -> u32 {
    bytes.iter().rev().fold(0, |word, &b| word << 8 | u32::from(b))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn heights(values: &[f32]) -> Vec<u8> {
        bytemuck::cast_slice(values).to_vec()
    }

    #[test]
    fn heights_outside_their_range_nan_and_infinities_are_found() {
        let id = TileId::new(0, 0, 0);
        let check = ValueCheck::Heights;
        assert_eq!(check.outside(id, &heights(&[100.0, 250.0, 180.5]), [100.0, 250.0]), None);
        assert_eq!(check.outside(id, &heights(&[100.0, 250.5, 180.5]), [100.0, 250.0]), Some(250.5));
        assert_eq!(check.outside(id, &heights(&[100.0, 99.75]), [100.0, 250.0]), Some(99.75));
        assert_eq!(check.outside(id, &heights(&[f32::INFINITY]), [100.0, 250.0]), Some(f32::INFINITY));
        assert!(check.outside(id, &heights(&[120.0, f32::NAN]), [100.0, 250.0]).is_some_and(f32::is_nan));
        assert_eq!(ValueCheck::None.outside(id, &heights(&[f32::NAN]), [0.0, 1.0]), None);
    }

    #[test]
    fn land_cover_indices_outside_their_range_are_found_in_words_and_packed_sub_codes() {
        // Three codes: palette indices 1 to 3, 8-bit words, level 2 packs four 2-bit sub-codes.
        let coding = LccCoding::for_codes([11, 41, 42]).unwrap();
        assert_eq!((coding.word_bytes(), coding.sub_bits()), (1, 2));
        let check = ValueCheck::Landcover(coding.clone());
        let level1 = TileId::new(1, 0, 0);
        assert_eq!(check.outside(level1, &[1, 2, 3, 2], [1.0, 3.0]), None);
        assert_eq!(check.outside(level1, &[1, 2, 3, 2], [1.0, 2.0]), Some(3.0));
        assert_eq!(check.outside(level1, &[1, 7], [1.0, 3.0]), Some(7.0));
        let level2 = TileId::new(LCC_PACKED_LEVEL, 0, 0);
        let word = |subs: [u32; 4]| coding.pack(subs) as u8;
        assert_eq!(check.outside(level2, &[word([1, 2, 3, 1])], [1.0, 3.0]), None);
        // One sub-code out of four, the last: index 0, below the range.
        assert_eq!(check.outside(level2, &[word([1, 2, 3, 1]), word([2, 2, 2, 0])], [1.0, 3.0]), Some(0.0));
    }
}
