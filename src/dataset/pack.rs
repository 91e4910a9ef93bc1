//! How it works: a pack is one file holding every tile of one layer, memory-mapped at run time.
//!
//! All tiles of a layer have the same payload size (uncompressed texels, all mips), so tile `i`
//! lives at `data_offset + i * tile_bytes`: finding a tile is O(1) and needs no index walk. A small
//! index after the header stores each tile's CRC-32 and whether it was written; readers verify the
//! header, the file length and a tile's checksum before handing its bytes out, so a truncated or
//! bit-flipped pack is an error that names the file and the tile, never garbage on screen.
//!
//! Each index entry also carries the tile's value range (two f32, NaN when the layer has none):
//! for heights, a conservative min/max of every level-0 sample under the tile, so culling can bound
//! a tile's relief in O(1) without reading it. The index is checksummed in the header.
//!
//! Layout (little-endian): 64-byte header | `tile_count` × 16-byte index entries (crc, state,
//! range min, range max) | padding to 4 KiB | tiles.

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use memmap2::Mmap;
use thiserror::Error;

const MAGIC: &[u8; 8] = b"TRMPPACK";
/// Version of the pack layout in the header; `Pack::open` refuses any other, so an old pack is
/// rebuilt, never misread.
pub const PACK_VERSION: u32 = 2;
const HEADER_BYTES: u64 = 64;
const INDEX_ENTRY_BYTES: u64 = 16;
const DATA_ALIGN: u64 = 4096;
/// Index entry state of a tile that the builder wrote.
const TILE_PRESENT: u32 = 1;

/// Why a pack could not be written or opened, or could not hand out a tile.
#[derive(Debug, Error)]
pub enum PackError {
    /// Creating, sizing, mapping, reading or writing the pack file failed.
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
        "{path}: pack format version {found}, this build reads version {PACK_VERSION}; rebuild the dataset"
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
    /// A tile's payload fails its CRC-32 when read: that tile alone is unusable.
    #[error("{path}: tile {index} is corrupt (checksum mismatch)")]
    Corrupt {
        /// The pack file.
        path: PathBuf,
        /// The tile's position in the pack (`Pyramid::tile_index`).
        index: u64,
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
    tile_bytes: u64,
    tile_count: u64,
    index_crc: u32,
}

impl Header {
    fn data_offset(&self) -> u64 {
        (HEADER_BYTES + self.tile_count * INDEX_ENTRY_BYTES).next_multiple_of(DATA_ALIGN)
    }

    fn file_bytes(&self) -> u64 {
        self.data_offset() + self.tile_count * self.tile_bytes
    }

    fn encode(&self) -> [u8; HEADER_BYTES as usize] {
        let mut bytes = [0u8; HEADER_BYTES as usize];
        bytes[0..8].copy_from_slice(MAGIC);
        bytes[8..12].copy_from_slice(&PACK_VERSION.to_le_bytes());
        bytes[16..24].copy_from_slice(&self.tile_bytes.to_le_bytes());
        bytes[24..32].copy_from_slice(&self.tile_count.to_le_bytes());
        bytes[32..36].copy_from_slice(&self.index_crc.to_le_bytes());
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
        if version != PACK_VERSION {
            return Err(PackError::Version { path: path.to_owned(), found: version });
        }
        Ok(Header { tile_bytes: u64_at(16), tile_count: u64_at(24), index_crc: u32_at(32) })
    }
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> PackError + '_ {
    move |source| PackError::Io { path: path.to_owned(), source }
}

/// Writes a pack's tiles in any order, from any number of threads.
pub struct PackWriter {
    file: File,
    path: PathBuf,
    header: Header,
    /// Per tile: `present << 32 | crc`, filled as tiles land; written out by `finish`.
    index: Vec<AtomicU64>,
    /// Per tile: the value range as two f32 bit patterns (`max << 32 | min`).
    ranges: Vec<AtomicU64>,
}

const NO_RANGE: [f32; 2] = [f32::NAN, f32::NAN];

fn pack_range([min, max]: [f32; 2]) -> u64 {
    u64::from(max.to_bits()) << 32 | u64::from(min.to_bits())
}

fn unpack_range(bits: u64) -> Option<[f32; 2]> {
    let range = [f32::from_bits(bits as u32), f32::from_bits((bits >> 32) as u32)];
    (!range[0].is_nan()).then_some(range)
}

impl PackWriter {
    /// Creates (or truncates) the pack at `path`, sized for `tile_count` tiles of `tile_bytes`
    /// bytes each, every tile unwritten until `write_tile`.
    pub fn create(path: &Path, tile_bytes: u64, tile_count: u64) -> Result<Self, PackError> {
        let header = Header { tile_bytes, tile_count, index_crc: 0 };
        let file = File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)
            .map_err(io(path))?;
        file.set_len(header.file_bytes()).map_err(io(path))?;
        let index = (0..tile_count).map(|_| AtomicU64::new(0)).collect();
        let ranges = (0..tile_count).map(|_| AtomicU64::new(pack_range(NO_RANGE))).collect();
        Ok(Self { file, path: path.to_owned(), header, index, ranges })
    }

    /// The pack file being written, for messages.
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn check_index(&self, index: u64) -> Result<(), PackError> {
        if index >= self.header.tile_count {
            return Err(PackError::OutOfRange {
                path: self.path.clone(),
                index,
                count: self.header.tile_count,
            });
        }
        Ok(())
    }

    fn tile_offset(&self, index: u64) -> u64 {
        self.header.data_offset() + index * self.header.tile_bytes
    }

    /// Writes tile `index`; `range` is its value range, if the layer has one.
    pub fn write_tile(&self, index: u64, payload: &[u8], range: Option<[f32; 2]>) -> Result<(), PackError> {
        self.check_index(index)?;
        if payload.len() as u64 != self.header.tile_bytes {
            return Err(PackError::PayloadSize {
                path: self.path.clone(),
                expected: self.header.tile_bytes,
                actual: payload.len() as u64,
            });
        }
        self.file.write_all_at(payload, self.tile_offset(index)).map_err(io(&self.path))?;
        let entry = u64::from(TILE_PRESENT) << 32 | u64::from(crc32fast::hash(payload));
        self.ranges[index as usize].store(pack_range(range.unwrap_or(NO_RANGE)), Ordering::Release);
        self.index[index as usize].store(entry, Ordering::Release);
        Ok(())
    }

    /// The range recorded for a tile written earlier.
    pub fn tile_range(&self, index: u64) -> Result<Option<[f32; 2]>, PackError> {
        self.check_index(index)?;
        Ok(unpack_range(self.ranges[index as usize].load(Ordering::Acquire)))
    }

    /// Reads back a tile written earlier (the builder derives coarse levels from fine ones).
    /// Goes through the page cache, not a mapping, so the builder's resident memory stays flat.
    pub fn read_tile(&self, index: u64) -> Result<Vec<u8>, PackError> {
        self.check_index(index)?;
        if self.index[index as usize].load(Ordering::Acquire) >> 32 != u64::from(TILE_PRESENT) {
            return Err(PackError::Missing { path: self.path.clone(), index });
        }
        let mut payload = vec![0u8; self.header.tile_bytes as usize];
        self.file.read_exact_at(&mut payload, self.tile_offset(index)).map_err(io(&self.path))?;
        Ok(payload)
    }

    /// Writes the index and header, and flushes the file to disk.
    pub fn finish(self) -> Result<(), PackError> {
        let mut index = Vec::with_capacity(self.index.len() * INDEX_ENTRY_BYTES as usize);
        for (entry, range) in self.index.iter().zip(&self.ranges) {
            let (entry, range) = (entry.load(Ordering::Acquire), range.load(Ordering::Acquire));
            index.extend_from_slice(&(entry as u32).to_le_bytes());
            index.extend_from_slice(&((entry >> 32) as u32).to_le_bytes());
            index.extend_from_slice(&range.to_le_bytes());
        }
        self.file.write_all_at(&index, HEADER_BYTES).map_err(io(&self.path))?;
        let header = Header { index_crc: crc32fast::hash(&index), ..self.header };
        self.file.write_all_at(&header.encode(), 0).map_err(io(&self.path))?;
        self.file.sync_all().map_err(io(&self.path))
    }
}

/// A memory-mapped pack, read-only.
pub struct Pack {
    map: Mmap,
    path: PathBuf,
    header: Header,
}

impl Pack {
    /// Maps the pack at `path` read-only and checks its header, version, length and index checksum;
    /// tile payloads are checked when read.
    pub fn open(path: &Path) -> Result<Self, PackError> {
        let file = File::open(path).map_err(io(path))?;
        // SAFETY: packs are written once by the builder and never modified in place; a dataset is
        // replaced by an atomic rename, which leaves this mapping's inode intact.
        let map = unsafe { Mmap::map(&file) }.map_err(io(path))?;
        let header = Header::decode(&map, path)?;
        let actual = map.len() as u64;
        if actual < header.file_bytes() {
            return Err(PackError::Truncated {
                path: path.to_owned(),
                expected: header.file_bytes(),
                actual,
            });
        }
        let index =
            &map[HEADER_BYTES as usize..(HEADER_BYTES + header.tile_count * INDEX_ENTRY_BYTES) as usize];
        if crc32fast::hash(index) != header.index_crc {
            return Err(PackError::CorruptIndex { path: path.to_owned() });
        }
        Ok(Self { map, path: path.to_owned(), header })
    }

    /// The mapped pack file, for messages.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Payload bytes of every tile, all mips included.
    pub fn tile_bytes(&self) -> u64 {
        self.header.tile_bytes
    }

    /// Tiles the pack holds, all levels together.
    pub fn tile_count(&self) -> u64 {
        self.header.tile_count
    }

    /// Tile `index`'s index entry, or the error for a tile the pack does not hold.
    fn entry(&self, index: u64) -> Result<&[u8], PackError> {
        if index >= self.header.tile_count {
            return Err(PackError::OutOfRange {
                path: self.path.clone(),
                index,
                count: self.header.tile_count,
            });
        }
        let at = (HEADER_BYTES + index * INDEX_ENTRY_BYTES) as usize;
        Ok(&self.map[at..at + INDEX_ENTRY_BYTES as usize])
    }

    /// The tile's value range (heights: conservative min/max of the level-0 samples under it), or
    /// `None` for layers without one. Verified with the index at `open`; no payload is read.
    pub fn tile_range(&self, index: u64) -> Result<Option<[f32; 2]>, PackError> {
        let entry = self.entry(index)?;
        Ok(unpack_range(u64::from_le_bytes(entry[8..16].try_into().unwrap_or([0xff; 8]))))
    }

    /// The tile's payload, after checking that it was written and that its checksum holds.
    pub fn tile(&self, index: u64) -> Result<&[u8], PackError> {
        let entry = self.entry(index)?;
        let crc = u32::from_le_bytes([entry[0], entry[1], entry[2], entry[3]]);
        let state = u32::from_le_bytes([entry[4], entry[5], entry[6], entry[7]]);
        if state != TILE_PRESENT {
            return Err(PackError::Missing { path: self.path.clone(), index });
        }
        let start = (self.header.data_offset() + index * self.header.tile_bytes) as usize;
        let payload = &self.map[start..start + self.header.tile_bytes as usize];
        if crc32fast::hash(payload) != crc {
            return Err(PackError::Corrupt { path: self.path.clone(), index });
        }
        Ok(payload)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp_path(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("terramp-pack-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join("layer.pack")
    }

    fn written_pack(name: &str) -> PathBuf {
        let path = temp_path(name);
        let writer = PackWriter::create(&path, 16, 3).unwrap();
        for i in (0..3).rev() {
            writer.write_tile(i, &[i as u8; 16], Some([i as f32, 10.0 + i as f32])).unwrap();
        }
        assert_eq!(writer.read_tile(1).unwrap(), vec![1u8; 16]);
        writer.finish().unwrap();
        path
    }

    #[test]
    fn round_trip_in_any_order() {
        let path = written_pack("roundtrip");
        let pack = Pack::open(&path).unwrap();
        assert_eq!((pack.tile_count(), pack.tile_bytes()), (3, 16));
        for i in 0..3 {
            assert_eq!(pack.tile(i).unwrap(), &[i as u8; 16]);
        }
        assert!(matches!(pack.tile(3), Err(PackError::OutOfRange { .. })));
        assert_eq!(pack.tile_range(2).unwrap(), Some([2.0, 12.0]));
    }

    #[test]
    fn flipped_byte_is_reported_for_that_tile_only() {
        let path = written_pack("corrupt");
        let mut bytes = std::fs::read(&path).unwrap();
        let last = bytes.len() - 1;
        bytes[last] ^= 0x40;
        std::fs::write(&path, &bytes).unwrap();
        let pack = Pack::open(&path).unwrap();
        assert!(pack.tile(0).is_ok());
        assert!(matches!(pack.tile(2), Err(PackError::Corrupt { index: 2, .. })));
    }

    #[test]
    fn a_damaged_index_is_refused_at_open() {
        let path = written_pack("index");
        let mut bytes = std::fs::read(&path).unwrap();
        bytes[HEADER_BYTES as usize + 9] ^= 0x01;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(Pack::open(&path), Err(PackError::CorruptIndex { .. })));
    }

    #[test]
    fn truncated_and_foreign_files_are_refused() {
        let path = written_pack("truncated");
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 5]).unwrap();
        assert!(matches!(Pack::open(&path), Err(PackError::Truncated { .. })));
        std::fs::write(&path, b"GIF89a, not a pack at all, but long enough to hold a header....").unwrap();
        assert!(matches!(Pack::open(&path), Err(PackError::NotAPack { .. })));
    }

    #[test]
    fn unwritten_tiles_are_missing_not_zero() {
        let path = temp_path("missing");
        let writer = PackWriter::create(&path, 4, 2).unwrap();
        writer.write_tile(0, &[7; 4], None).unwrap();
        assert!(matches!(writer.write_tile(0, &[7; 3], None), Err(PackError::PayloadSize { .. })));
        writer.finish().unwrap();
        let pack = Pack::open(&path).unwrap();
        assert!(matches!(pack.tile(1), Err(PackError::Missing { index: 1, .. })));
        assert_eq!(pack.tile_range(0).unwrap(), None);
    }
}
