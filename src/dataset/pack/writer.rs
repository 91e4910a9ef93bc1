//! How it works: tiles arrive in any order from any number of threads. Each is encoded by the
//! pack's codec on its own thread, then given the next free place in the data region (an atomic
//! bump of the end, rounded to `TILE_ALIGN`) and written there, so threads never wait on one
//! another; its place, stored length, checksum and range go into atomics that `finish` writes out
//! as the index, with the header last. Places then depend on which thread finished first;
//! `write_ordered` makes tiles on every thread but places them in the order given, a chunk at a
//! time, so the same input gives the same file, byte for byte, in bounded memory. A tile written earlier can be read back (the builder
//! derives coarse levels from fine ones) through the page cache, not a mapping, so the builder's
//! resident memory stays flat.

use std::fs::File;
use std::os::unix::fs::FileExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use super::{
    Codec, HEADER_BYTES, Header, PACK_VERSION, PackError, TILE_ALIGN, TILE_PRESENT, io, unpack_range,
};

const NO_RANGE: [f32; 2] = [f32::NAN, f32::NAN];

/// Tiles `write_ordered` makes at once per thread before placing them: enough to keep every thread
/// busy across a chunk's slowest tile, few enough that the stored tiles held stay small.
const ORDERED_CHUNK_PER_THREAD: usize = 8;

/// A tile made for `write_ordered`: its index, payload and value range.
pub type MadeTile = (u64, Vec<u8>, Option<[f32; 2]>);

fn pack_range([min, max]: [f32; 2]) -> u64 {
    u64::from(max.to_bits()) << 32 | u64::from(min.to_bits())
}

/// Writes a pack's tiles in any order, from any number of threads.
pub struct PackWriter {
    file: File,
    path: PathBuf,
    header: Header,
    /// Per tile: `present << 32 | crc`, filled as tiles land.
    index: Vec<AtomicU64>,
    /// Per tile: where its stored bytes start (from the data's start) and how many there are.
    places: Vec<[AtomicU64; 2]>,
    /// Per tile: the value range as two f32 bit patterns (`max << 32 | min`).
    ranges: Vec<AtomicU64>,
    /// End of the data written so far, from the data's start.
    end: AtomicU64,
}

impl PackWriter {
    /// Creates (or truncates) the pack at `path` for `tile_count` tiles of `tile_bytes` bytes
    /// each, stored by `codec`, every tile unwritten until `write_tile`.
    pub fn create(path: &Path, tile_bytes: u64, tile_count: u64, codec: Codec) -> Result<Self, PackError> {
        let header =
            Header { version: PACK_VERSION, codec, tile_bytes, tile_count, index_crc: 0, data_bytes: 0 };
        let file = File::options()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(path)
            .map_err(io(path))?;
        file.set_len(header.data_offset()).map_err(io(path))?;
        let atomics = |value: u64| (0..tile_count).map(|_| AtomicU64::new(value)).collect();
        let places = (0..tile_count).map(|_| [AtomicU64::new(0), AtomicU64::new(0)]).collect();
        Ok(Self {
            file,
            path: path.to_owned(),
            header,
            index: atomics(0),
            places,
            ranges: atomics(pack_range(NO_RANGE)),
            end: AtomicU64::new(0),
        })
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

    fn check_payload(&self, payload: &[u8]) -> Result<(), PackError> {
        if payload.len() as u64 != self.header.tile_bytes {
            return Err(PackError::PayloadSize {
                path: self.path.clone(),
                expected: self.header.tile_bytes,
                actual: payload.len() as u64,
            });
        }
        Ok(())
    }

    /// Writes tile `index`; `range` is its value range, if the layer has one.
    pub fn write_tile(&self, index: u64, payload: &[u8], range: Option<[f32; 2]>) -> Result<(), PackError> {
        self.check_index(index)?;
        self.check_payload(payload)?;
        let stored = self.header.codec.encode(payload, &self.path)?;
        self.place(index, &stored, range)
    }

    /// Makes a tile for every item with `make` on rayon's threads, and places them in the order of
    /// `items`, so that the file does not depend on the threads' timing.
    pub fn write_ordered<T: Sync, E: From<PackError> + Send>(
        &self,
        items: &[T],
        make: impl Fn(&T) -> Result<MadeTile, E> + Sync,
    ) -> Result<(), E> {
        let chunk = ORDERED_CHUNK_PER_THREAD * rayon::current_num_threads().max(1);
        for items in items.chunks(chunk) {
            let stored = items
                .par_iter()
                .map(|item| {
                    let (index, payload, range) = make(item)?;
                    self.check_index(index)?;
                    self.check_payload(&payload)?;
                    Ok((index, self.header.codec.encode(&payload, &self.path)?, range))
                })
                .collect::<Result<Vec<_>, E>>()?;
            for (index, stored, range) in stored {
                self.place(index, &stored, range)?;
            }
        }
        Ok(())
    }

    /// Places tile `index` as `stored`, bytes another pack of the same codec and tile size stored
    /// (a partitioned build's merge copies them without decoding).
    pub(crate) fn place_stored(
        &self,
        index: u64,
        stored: &[u8],
        range: Option<[f32; 2]>,
    ) -> Result<(), PackError> {
        self.check_index(index)?;
        self.place(index, stored, range)
    }

    /// Puts tile `index`'s `stored` bytes at the end of the data and records them.
    fn place(&self, index: u64, stored: &[u8], range: Option<[f32; 2]>) -> Result<(), PackError> {
        let length = stored.len() as u64;
        let offset = self.end.fetch_add(length.next_multiple_of(TILE_ALIGN), Ordering::AcqRel);
        self.file.write_all_at(stored, self.header.data_offset() + offset).map_err(io(&self.path))?;
        let i = index as usize;
        self.places[i][0].store(offset, Ordering::Release);
        self.places[i][1].store(length, Ordering::Release);
        self.ranges[i].store(pack_range(range.unwrap_or(NO_RANGE)), Ordering::Release);
        let entry = u64::from(TILE_PRESENT) << 32 | u64::from(crc32fast::hash(stored));
        self.index[i].store(entry, Ordering::Release);
        Ok(())
    }

    /// The range recorded for a tile written earlier.
    pub fn tile_range(&self, index: u64) -> Result<Option<[f32; 2]>, PackError> {
        self.check_index(index)?;
        Ok(unpack_range(self.ranges[index as usize].load(Ordering::Acquire)))
    }

    /// Reads back a tile written earlier, decoded.
    pub fn read_tile(&self, index: u64) -> Result<Vec<u8>, PackError> {
        self.check_index(index)?;
        let i = index as usize;
        if self.index[i].load(Ordering::Acquire) >> 32 != u64::from(TILE_PRESENT) {
            return Err(PackError::Missing { path: self.path.clone(), index });
        }
        let [offset, length] = [0, 1].map(|k| self.places[i][k].load(Ordering::Acquire));
        let mut stored = vec![0u8; length as usize];
        self.file.read_exact_at(&mut stored, self.header.data_offset() + offset).map_err(io(&self.path))?;
        self.header
            .codec
            .decode(&stored, self.header.tile_bytes as usize)
            .ok_or(PackError::Corrupt { path: self.path.clone(), index })
    }

    /// Writes the index and header, and flushes the file to disk.
    pub fn finish(self) -> Result<(), PackError> {
        let mut index = Vec::with_capacity(self.index.len() * self.header.entry_bytes() as usize);
        for ((entry, place), range) in self.index.iter().zip(&self.places).zip(&self.ranges) {
            let entry = entry.load(Ordering::Acquire);
            let [offset, length] = [0, 1].map(|k| place[k].load(Ordering::Acquire));
            index.extend_from_slice(&offset.to_le_bytes());
            index.extend_from_slice(&(length as u32).to_le_bytes());
            index.extend_from_slice(&(entry as u32).to_le_bytes());
            index.extend_from_slice(&((entry >> 32) as u32).to_le_bytes());
            index.extend_from_slice(&0u32.to_le_bytes());
            index.extend_from_slice(&range.load(Ordering::Acquire).to_le_bytes());
        }
        let data_bytes = self.end.load(Ordering::Acquire);
        self.file.set_len(self.header.data_offset() + data_bytes).map_err(io(&self.path))?;
        self.file.write_all_at(&index, HEADER_BYTES).map_err(io(&self.path))?;
        let header = Header { index_crc: crc32fast::hash(&index), data_bytes, ..self.header };
        self.file.write_all_at(&header.encode(), 0).map_err(io(&self.path))?;
        self.file.sync_all().map_err(io(&self.path))
    }
}
