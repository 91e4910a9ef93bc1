//! How it works: pass 4a, compaction (DESIGN § "The frame", step 4). Pass 3 leaves its survivors
//! in blocks: workgroup w of the frame wrote its kept seeds, in rank order, at a place of the
//! record buffer its one atomic found, with each record's draw group (species × `SEED_LODS` +
//! radial LOD) in a parallel key buffer, and noted where in entry w of the block table. Where the
//! blocks landed varies from run to run; the table's order does not. `shaders/compact.wgsl` turns
//! that into one instanced draw per group: a permutation `order` (draw slot → record index) in
//! which group g holds slots `[first_instance, first_instance + instance_count)`, its records in
//! table order, and the indirect draw arguments (`SeedDrawArgs`, wgpu's `DrawIndexedIndirectArgs`
//! layout; mesh fields from templates the draw pass uploads with `set_templates`), twice: each
//! group's own draw, then (`SEED_DRAWS`) the same instances with the next LOD's geometry, for the
//! cross-fade of the seeds in the outer band of their LOD.
//!
//! It is a reduce-then-scan over chunks of `COMPACT_CHUNK` blocks: count each group per chunk,
//! scan each group's counts over the chunks in order, place the groups one after the other, then
//! scatter: one lane per block walks its records in order, each to its group's next slot (group
//! start + the chunks before + the chunk's blocks before + the block's records before). No atomic
//! is used, so the output equals its CPU twin (`reference/compact.rs`) bit for bit and is the
//! same in every run. Writing a permutation rather than copying records keeps the pass to 4 bytes
//! per record each way (no 48-byte record is read or written; the draw pass reads
//! `records[order[instance]]`), so 16 M seeds fit WebGPU's guaranteed 128 MiB binding. The CPU
//! never reads any of it in a frame; `read_back` is for tests and tools.
//!
//! `frame` is the CPU half (its limits, and the result as CPU data, which the twin
//! `reference::compact` also produces); `gpu` the four pipelines, binding table and dispatches.

pub mod frame;
pub mod gpu;

use thiserror::Error;

use crate::gpu::GpuError;
use crate::gpu::layout::SEED_WORKGROUP;

/// Blocks one compaction takes at most (chunks are dispatched along one dimension).
pub const MAX_COMPACT_BLOCKS: u32 = 65535 * crate::gpu::layout::COMPACT_CHUNK;

/// Why a compaction pass could not be built or run, or its CPU twin refused its input.
#[derive(Debug, Error)]
pub enum CompactError {
    /// The pass is built for more blocks than one dispatch dimension reaches (`new`), or a run asks
    /// for more blocks than it was built for (`prepare`).
    #[error("{blocks} blocks: one compaction takes at most {max} (`seeds.seeds_per_pattern` too large?)")]
    TooManyBlocks {
        /// Block-table entries asked for.
        blocks: u64,
        /// The most it takes: `MAX_COMPACT_BLOCKS` in `new`, the built limits in `prepare`.
        max: u64,
    },
    /// In `new`: a buffer of the pass exceeds the device's `max_storage_buffer_binding_size`.
    #[error("compaction's {what} needs {bytes} bytes; one buffer binding holds at most {max} here")]
    TooLarge {
        /// Which buffer: the chunk table or the permutation.
        what: &'static str,
        /// Bytes it needs.
        bytes: u64,
        /// The largest storage binding the device allows, in bytes.
        max: u64,
    },
    /// In the CPU twin: a block reaches beyond the keys or holds more than a workgroup's records,
    /// which the GPU would not read.
    #[error(
        "block {block}: {count} records at {offset} reach beyond the {records} keys, or beyond {SEED_WORKGROUP} a block"
    )]
    BadBlock {
        /// Its index in the block table.
        block: usize,
        /// Its first record, as an index into the record buffer.
        offset: u32,
        /// Records it claims.
        count: u32,
        /// Keys given: the records there are.
        records: usize,
    },
    /// The GPU failed underneath (device, validation or readback).
    #[error(transparent)]
    Gpu(#[from] GpuError),
}
