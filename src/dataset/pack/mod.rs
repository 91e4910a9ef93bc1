//! How it works: a pack is one file holding every tile of one layer.
//!
//! Every tile of a layer has the same payload (its texels, all mips), stored as the pack's codec
//! says (`codec`: as it is, or losslessly compressed by zstd after a predictor). An index after
//! the header gives each tile's place and stored length, so finding a tile is O(1), and its CRC-32
//! over the *stored* bytes, checked before they are decoded; the decoded payload must have the
//! pack's tile size. Readers verify the header, the file length and the index checksum at open, so
//! a truncated or bit-flipped pack is an error that names the file and the tile, never garbage on
//! screen.
//!
//! Each index entry also carries the tile's value range (two f32, NaN when the layer has none):
//! for heights, a conservative min/max of every level-0 sample under the tile, so culling can bound
//! a tile's relief in O(1) without reading it. The index is checksummed in the header.
//!
//! Reading (`Pack`): the header and the whole index are read into memory at open (32 bytes a
//! tile), and each tile's stored bytes with one positioned read (`pread`) when it is asked for,
//! never through a memory mapping. A viewer runs for hours over packs that another tool may
//! truncate or rewrite in place meanwhile (`cp` or `rsync --inplace` over them; the builder's own
//! publishing is an atomic rename, which leaves an open file intact); a mapping of a file cut
//! short raises SIGBUS at the first touch of a page past its end, and a signal handler cannot
//! tell which read it broke. A positioned read comes back short instead, and a rewritten tile
//! fails its checksum: either is `PackError::Changed` for that tile when the file's length,
//! status-change time or header differs from open's. The cost is one copy of the stored bytes
//! per tile (the codec decodes into a new buffer anyway); `benches/tile_reads.rs` times it
//! against a mapping (docs/streaming.md has the figures).
//!
//! Layout (little-endian): 64-byte header (magic, version, codec, tile bytes, tile count, index
//! checksum, data bytes, header checksum) | `tile_count` × 32-byte index entries (offset, stored
//! length, crc, state, range) | padding to 4 KiB | the stored tiles, each at a 16-byte boundary,
//! in the order they were written. Version 2 packs (raw tiles at fixed places, 16-byte entries)
//! are still read.

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};

use thiserror::Error;

mod codec;
mod writer;

pub use codec::{Codec, Predictor};
pub use writer::{MadeTile, PackWriter};

const MAGIC: &[u8; 8] = b"TRMPPACK";
/// Version of the pack layout written; `Pack::open` reads it and `LEGACY_VERSION`, and refuses any
/// other, so an old pack is rebuilt, never misread.
pub const PACK_VERSION: u32 = 3;
/// The layout before codecs: raw tiles at fixed places.
const LEGACY_VERSION: u32 = 2;
const HEADER_BYTES: u64 = 64;
const DATA_ALIGN: u64 = 4096;
/// Stored tiles start at multiples of this (part of the layout).
const TILE_ALIGN: u64 = 16;
/// Index entry state of a tile that the builder wrote.
const TILE_PRESENT: u32 = 1;

/// Why a pack could not be written or opened, or could not hand out a tile.
#[derive(Debug, Error)]
pub enum PackError {
    /// Creating, sizing, reading or writing the pack file failed.
    #[error("{path}: {source}")]
    Io {
        /// The pack file.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// The file is too short for a header, or its magic or header checksum is wrong: not a pack,
    /// or one whose header is damaged.
    #[error("{path}: not a terramp pack (bad magic or header checksum)")]
    NotAPack {
        /// The file opened as a pack.
        path: PathBuf,
    },
    /// The header's layout version is not `PACK_VERSION`: the dataset must be rebuilt.
    #[error(
        "{path}: pack format version {found}, this build reads versions {LEGACY_VERSION} and {PACK_VERSION}; rebuild the dataset"
    )]
    Version {
        /// The pack file.
        path: PathBuf,
        /// The version the header declares.
        found: u32,
    },
    /// At open, the file is shorter than its header's tile count and tile size imply (a build or
    /// a copy cut short).
    #[error("{path}: truncated: {actual} bytes, the header promises {expected}")]
    Truncated {
        /// The pack file.
        path: PathBuf,
        /// File length the header implies, bytes.
        expected: u64,
        /// File length on disk, bytes.
        actual: u64,
    },
    /// At open, the tile index fails the checksum stored in the header.
    #[error("{path}: the tile index is corrupt (checksum mismatch)")]
    CorruptIndex {
        /// The pack file.
        path: PathBuf,
    },
    /// A tile's stored bytes fail their CRC-32, lie outside the data, or do not decode to the
    /// pack's tile size: that tile alone is unusable.
    #[error("{path}: tile {index} is corrupt (checksum mismatch, or it does not decode)")]
    Corrupt {
        /// The pack file.
        path: PathBuf,
        /// The tile's position in the pack (`Pyramid::tile_index`).
        index: u64,
    },
    /// A tile could not be read as the index read at open describes it (cut short, or failing its
    /// checksum), and the file is no longer the one opened: truncated or rewritten in place since
    /// (a `cp` or `rsync --inplace` over it). The tiles read before stand.
    #[error(
        "{path}: tile {index} cannot be read: the file changed on disk since it was opened (truncated or rewritten in place); open the dataset again"
    )]
    Changed {
        /// The pack file.
        path: PathBuf,
        /// The tile's position in the pack (`Pyramid::tile_index`).
        index: u64,
    },
    /// A tile decodes to a value outside the range its index entry records (a height, or a
    /// land-cover palette index): damage that its checksum did not see. `LayerPack` checks this.
    #[error("{path}: tile {index} decodes to {value}, outside its recorded range {min} to {max}")]
    OutsideRange {
        /// The pack file.
        path: PathBuf,
        /// The tile's position in the pack (`Pyramid::tile_index`).
        index: u64,
        /// The first value found outside.
        value: f32,
        /// The range's lower end.
        min: f32,
        /// The range's upper end.
        max: f32,
    },
    /// A tile the builder never wrote is read, from a pack or back through `PackWriter::read_tile`.
    #[error("{path}: tile {index} was never written")]
    Missing {
        /// The pack file.
        path: PathBuf,
        /// The tile's position in the pack (`Pyramid::tile_index`).
        index: u64,
    },
    /// A tile past the pack's tile count is asked for, or a `TileId` outside the layer's pyramid.
    #[error("{path}: tile {index} is out of range (the pack holds {count})")]
    OutOfRange {
        /// The pack file.
        path: PathBuf,
        /// The position asked for; `u64::MAX` for a `TileId` outside the pyramid.
        index: u64,
        /// Tiles the pack holds.
        count: u64,
    },
    /// A payload given to `PackWriter::write_tile` is not the pack's tile size.
    #[error("{path}: tile payload is {actual} bytes, the pack stores {expected}")]
    PayloadSize {
        /// The pack file.
        path: PathBuf,
        /// Bytes per tile the pack stores.
        expected: u64,
        /// Bytes of the payload given.
        actual: u64,
    },
    /// A tile of a layer the dataset does not have is asked for (land cover in a dataset without).
    #[error("{path}: the dataset has no {layer} layer")]
    NoLayer {
        /// The dataset folder.
        path: PathBuf,
        /// The missing layer's name for the message, e.g. "land-cover".
        layer: &'static str,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Header {
    version: u32,
    codec: Codec,
    tile_bytes: u64,
    tile_count: u64,
    index_crc: u32,
    /// Bytes of the stored tiles (version 3; implied by the tile size in version 2).
    data_bytes: u64,
}

impl Header {
    fn entry_bytes(&self) -> u64 {
        if self.version == LEGACY_VERSION { 16 } else { 32 }
    }

    fn index_range(&self) -> std::ops::Range<usize> {
        HEADER_BYTES as usize..(HEADER_BYTES + self.tile_count * self.entry_bytes()) as usize
    }

    fn data_offset(&self) -> u64 {
        (HEADER_BYTES + self.tile_count * self.entry_bytes()).next_multiple_of(DATA_ALIGN)
    }

    /// The length the header implies; `None` past u64 (a damaged or forged header).
    fn file_bytes(&self) -> Option<u64> {
        let index_end = self.tile_count.checked_mul(self.entry_bytes())?.checked_add(HEADER_BYTES)?;
        index_end.checked_next_multiple_of(DATA_ALIGN)?.checked_add(self.data_bytes)
    }

    fn encode(&self) -> [u8; HEADER_BYTES as usize] {
        let mut bytes = [0u8; HEADER_BYTES as usize];
        bytes[0..8].copy_from_slice(MAGIC);
        bytes[8..12].copy_from_slice(&self.version.to_le_bytes());
        bytes[12..16].copy_from_slice(&self.codec.word().to_le_bytes());
        bytes[16..24].copy_from_slice(&self.tile_bytes.to_le_bytes());
        bytes[24..32].copy_from_slice(&self.tile_count.to_le_bytes());
        bytes[32..36].copy_from_slice(&self.index_crc.to_le_bytes());
        bytes[40..48].copy_from_slice(&self.data_bytes.to_le_bytes());
        let crc = crc32fast::hash(&bytes[0..60]);
        bytes[60..64].copy_from_slice(&crc.to_le_bytes());
        bytes
    }

    fn decode(bytes: &[u8], path: &Path) -> Result<Header, PackError> {
        let not_a_pack = || PackError::NotAPack { path: path.to_owned() };
        if bytes.len() < HEADER_BYTES as usize || &bytes[0..8] != MAGIC {
            return Err(not_a_pack());
        }
        let u32_at = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap_or([0; 4]));
        let u64_at = |at: usize| u64::from_le_bytes(bytes[at..at + 8].try_into().unwrap_or([0; 8]));
        if crc32fast::hash(&bytes[0..60]) != u32_at(60) {
            return Err(not_a_pack());
        }
        let version = u32_at(8);
        let (tile_bytes, tile_count) = (u64_at(16), u64_at(24));
        let (codec, data_bytes) = match version {
            PACK_VERSION => (Codec::from_word(u32_at(12)), u64_at(40)),
            LEGACY_VERSION => (Some(Codec::Raw), tile_count.saturating_mul(tile_bytes)),
            found => return Err(PackError::Version { path: path.to_owned(), found }),
        };
        // A codec this build does not know is a newer pack's: as good as another version.
        let codec = codec.ok_or(PackError::Version { path: path.to_owned(), found: version })?;
        Ok(Header { version, codec, tile_bytes, tile_count, index_crc: u32_at(32), data_bytes })
    }
}

/// A tile's value range from its two f32 bit patterns (`max << 32 | min`); NaN: none.
fn unpack_range(bits: u64) -> Option<[f32; 2]> {
    let range = [f32::from_bits(bits as u32), f32::from_bits((bits >> 32) as u32)];
    (!range[0].is_nan()).then_some(range)
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> PackError + '_ {
    move |source| PackError::Io { path: path.to_owned(), source }
}

/// A pack open for reading: its header and tile index read into memory at open, its tiles read
/// from the file with positioned reads when asked for.
pub struct Pack {
    file: File,
    path: PathBuf,
    header: Header,
    /// The tile index as the file held it at open (`tile_count` entries), checksum verified.
    index: Vec<u8>,
    /// The file as it was at open: a failed read of a file no longer like it is `Changed`.
    opened: Stamp,
}

/// What changes when a file's contents change in place: its length, its status-change time (a
/// write moves it, and no tool can set it back, unlike the modification time `rsync` restores;
/// but it moves by the kernel's clock tick, a few milliseconds) and its header (another pack's
/// has other data lengths and index checksums, whenever it was written).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stamp {
    bytes: u64,
    changed_s: i64,
    changed_ns: i64,
    header: [u8; HEADER_BYTES as usize],
}

impl Stamp {
    /// The file's stamp now.
    fn of(file: &File) -> std::io::Result<Self> {
        use std::os::unix::fs::MetadataExt;
        let meta = file.metadata()?;
        let mut header = [0u8; HEADER_BYTES as usize];
        match file.read_exact_at(&mut header, 0) {
            Ok(()) => {}
            // Shorter than a header: zeros, which are no pack's magic.
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => header = [0; HEADER_BYTES as usize],
            Err(e) => return Err(e),
        }
        Ok(Self { bytes: meta.len(), changed_s: meta.ctime(), changed_ns: meta.ctime_nsec(), header })
    }
}

/// Damage done to a tile's stored bytes as they are read: fault injection's corrupt reads
/// (`Pack::tile_damaged`, `[faults]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Damage {
    /// Byte `at` (modulo their length) flipped after the checksum was made, as a disk's or a
    /// network's error would: the checksum catches it.
    Caught {
        /// Which stored byte is flipped.
        at: usize,
    },
    /// Byte `at` (modulo their length) flipped before the checksum was made, so it matches: the
    /// codec, and the layer's checks after it, meet the damage.
    Unseen {
        /// Which stored byte is flipped.
        at: usize,
    },
}

/// One tile's index entry, decoded.
struct Entry {
    /// Where its stored bytes start, from the start of the data.
    offset: u64,
    stored_bytes: u64,
    crc: u32,
    state: u32,
    range: u64,
}

impl Pack {
    /// Opens the pack at `path` and reads and checks its header, version, length and tile index
    /// (its checksum); tiles are read, and checked, when asked for.
    pub fn open(path: &Path) -> Result<Self, PackError> {
        let file = File::open(path).map_err(io(path))?;
        // Taken first: a change while the index is read shows at the next failed read.
        let opened = Stamp::of(&file).map_err(io(path))?;
        let actual = opened.bytes;
        let header = Header::decode(&opened.header, path)?;
        let expected = header.file_bytes();
        if expected.is_none_or(|e| actual < e) {
            return Err(PackError::Truncated {
                path: path.to_owned(),
                expected: expected.unwrap_or(u64::MAX),
                actual,
            });
        }
        // No larger than the file, checked above.
        let range = header.index_range();
        let mut index = vec![0u8; range.len()];
        file.read_exact_at(&mut index, range.start as u64).map_err(io(path))?;
        if crc32fast::hash(&index) != header.index_crc {
            return Err(PackError::CorruptIndex { path: path.to_owned() });
        }
        Ok(Self { file, path: path.to_owned(), header, index, opened })
    }

    /// The pack file, for messages.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Payload bytes of every tile, all mips included (as decoded, whatever the codec).
    pub fn tile_bytes(&self) -> u64 {
        self.header.tile_bytes
    }

    /// Tiles the pack holds, all levels together.
    pub fn tile_count(&self) -> u64 {
        self.header.tile_count
    }

    /// How the tiles are stored.
    pub fn codec(&self) -> Codec {
        self.header.codec
    }

    /// Tile `index`'s index entry, or the error for a tile the pack does not hold.
    fn entry(&self, index: u64) -> Result<Entry, PackError> {
        let h = &self.header;
        if index >= h.tile_count {
            return Err(PackError::OutOfRange { path: self.path.clone(), index, count: h.tile_count });
        }
        let at = (index * h.entry_bytes()) as usize;
        let e = &self.index[at..at + h.entry_bytes() as usize];
        let u32_at = |i: usize| u32::from_le_bytes(e[i..i + 4].try_into().unwrap_or([0; 4]));
        let u64_at = |i: usize| u64::from_le_bytes(e[i..i + 8].try_into().unwrap_or([0xff; 8]));
        Ok(if h.version == LEGACY_VERSION {
            let (offset, stored_bytes) = (index * h.tile_bytes, h.tile_bytes);
            Entry { offset, stored_bytes, crc: u32_at(0), state: u32_at(4), range: u64_at(8) }
        } else {
            let (offset, stored_bytes) = (u64_at(0), u64::from(u32_at(8)));
            Entry { offset, stored_bytes, crc: u32_at(12), state: u32_at(16), range: u64_at(24) }
        })
    }

    /// Where tile `index`'s stored bytes lie in the file (for tools that inspect or damage packs).
    pub fn stored_span(&self, index: u64) -> Result<std::ops::Range<u64>, PackError> {
        let entry = self.entry(index)?;
        let start = self.header.data_offset().checked_add(entry.offset);
        let end = start.and_then(|start| start.checked_add(entry.stored_bytes));
        match (start, end) {
            (Some(start), Some(end)) => Ok(start..end),
            _ => Err(PackError::Corrupt { path: self.path.clone(), index }),
        }
    }

    /// The tile's value range (heights: conservative min/max of the level-0 samples under it), or
    /// `None` for layers without one. Verified with the index at `open`; no payload is read.
    pub fn tile_range(&self, index: u64) -> Result<Option<[f32; 2]>, PackError> {
        Ok(unpack_range(self.entry(index)?.range))
    }

    /// Tile `index`'s stored bytes as the file holds them now, and the checksum the index gives
    /// them, after checking that it was written and that they lie within the data. The read is
    /// positioned (`pread`): a file cut short since `open` is an error here, where a mapping of
    /// it would have raised SIGBUS.
    fn read_place(&self, index: u64) -> Result<(Vec<u8>, u32), PackError> {
        let entry = self.entry(index)?;
        if entry.state != TILE_PRESENT {
            return Err(PackError::Missing { path: self.path.clone(), index });
        }
        let end = entry.offset.checked_add(entry.stored_bytes).filter(|&end| end <= self.header.data_bytes);
        end.ok_or_else(|| PackError::Corrupt { path: self.path.clone(), index })?;
        // At most the data's length, which `open` found within the file.
        let mut stored = vec![0; entry.stored_bytes as usize];
        let at = self.header.data_offset() + entry.offset;
        match self.file.read_exact_at(&mut stored, at) {
            Ok(()) => Ok((stored, entry.crc)),
            Err(source) => Err(self.changed_or(index, PackError::Io { path: self.path.clone(), source })),
        }
    }

    /// `Changed` when the file is no longer the one opened, else `error`: why a read failed.
    fn changed_or(&self, index: u64, error: PackError) -> PackError {
        match Stamp::of(&self.file) {
            Ok(now) if now != self.opened => PackError::Changed { path: self.path.clone(), index },
            _ => error,
        }
    }

    /// `stored` if it holds checksum `crc`.
    fn checked(&self, index: u64, stored: Vec<u8>, crc: u32) -> Result<Vec<u8>, PackError> {
        if crc32fast::hash(&stored) != crc {
            return Err(self.changed_or(index, PackError::Corrupt { path: self.path.clone(), index }));
        }
        Ok(stored)
    }

    /// The tile's stored bytes (as its codec wrote them), read from the file, after checking that
    /// it was written and that they hold their checksum (the partitioned build's merge copies
    /// packs this way, never decoding).
    pub fn read_stored(&self, index: u64) -> Result<Vec<u8>, PackError> {
        let (stored, crc) = self.read_place(index)?;
        self.checked(index, stored, crc)
    }

    /// The tile's payload, read from the file, after checking that it was written and that its
    /// stored bytes hold their checksum, decoded as the pack's codec says.
    pub fn tile(&self, index: u64) -> Result<Vec<u8>, PackError> {
        self.payload(index, self.read_stored(index)?)
    }

    /// The tile as `tile` would give it had its stored bytes been damaged as `damage` says
    /// (fault injection's corrupt reads), through the same checks.
    pub fn tile_damaged(&self, index: u64, damage: Damage) -> Result<Vec<u8>, PackError> {
        let (mut stored, mut crc) = self.read_place(index)?;
        let (Damage::Caught { at } | Damage::Unseen { at }) = damage;
        let len = stored.len().max(1);
        if let Some(byte) = stored.get_mut(at % len) {
            *byte ^= 0xa5;
        }
        if matches!(damage, Damage::Unseen { .. }) {
            crc = crc32fast::hash(&stored);
        }
        let stored = self.checked(index, stored, crc)?;
        self.payload(index, stored)
    }

    /// A tile's payload from its checked stored bytes.
    fn payload(&self, index: u64, stored: Vec<u8>) -> Result<Vec<u8>, PackError> {
        match self.header.codec {
            Codec::Raw if stored.len() as u64 == self.header.tile_bytes => Ok(stored),
            codec => codec
                .decode(&stored, self.header.tile_bytes as usize)
                .ok_or_else(|| PackError::Corrupt { path: self.path.clone(), index }),
        }
    }
}

#[cfg(test)]
mod tests;
