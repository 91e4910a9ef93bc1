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

use thiserror::Error;

use crate::config::Settings;
use crate::gpu::gpu_types::{CompactParams, SeedDrawArgs};
use crate::gpu::{Gpu, GpuError};
use crate::seeds::{SEED_DRAWS, SEED_GROUPS, SEED_WORKGROUP, block_capacity};
use crate::shaders;

/// Blocks per chunk: the workgroup of `reduce` and `scatter`, one lane per block, whose block ×
/// group table of counts (`COMPACT_CHUNK × SEED_GROUPS` words) fits WebGPU's 16 KiB of workgroup
/// memory.
pub const COMPACT_CHUNK: u32 = 64;
/// Invocations of the `scan` workgroup (one per group), each summing a run of chunks.
pub const COMPACT_WORKGROUP: u32 = 256;
/// Blocks one compaction takes at most (chunks are dispatched along one dimension).
pub const MAX_COMPACT_BLOCKS: u32 = 65535 * COMPACT_CHUNK;

const _: () = assert!(SEED_GROUPS <= COMPACT_CHUNK, "a lane per group sums or scans a column");
const _: () = assert!(COMPACT_CHUNK * SEED_GROUPS * 4 <= 16384, "the chunk's table fits workgroup memory");

#[derive(Debug, Error)]
pub enum CompactError {
    #[error("{blocks} blocks: one compaction takes at most {max} (`seeds.seeds_per_pattern` too large?)")]
    TooManyBlocks { blocks: u64, max: u64 },
    #[error("compaction's {what} needs {bytes} bytes; one buffer binding holds at most {max} here")]
    TooLarge { what: &'static str, bytes: u64, max: u64 },
    #[error(
        "block {block}: {count} records at {offset} reach beyond the {records} keys, or beyond {SEED_WORKGROUP} a block"
    )]
    BadBlock { block: usize, offset: u32, count: u32, records: usize },
    #[error(transparent)]
    Gpu(#[from] GpuError),
}

/// What a compaction pass is sized for: block-table entries and records.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CompactLimits {
    pub blocks: u32,
    pub records: u32,
}

impl From<&Settings> for CompactLimits {
    fn from(settings: &Settings) -> Self {
        Self { blocks: block_capacity(settings.seeds.seeds_per_pattern), records: settings.seeds.capacity }
    }
}

/// What compaction wrote (GPU readback or CPU twin).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Compacted {
    /// Draw slot → record index, groups one after the other (`drawn()` slots).
    pub order: Vec<u32>,
    /// `SEED_DRAWS` indirect draws: one per group, then each group's cross-fade draw.
    pub args: Vec<SeedDrawArgs>,
}

impl Compacted {
    /// Slots filled: the records of every group.
    pub fn drawn(&self) -> usize {
        self.args.iter().take(SEED_GROUPS as usize).map(|a| a.instance_count as usize).sum()
    }

    /// The records in draw order, from the record buffer `order` indexes.
    pub fn gather<T: Copy>(&self, records: &[T]) -> Vec<T> {
        self.order.iter().map(|&i| records[i as usize]).collect()
    }
}

/// The buffers compaction reads: pass 3's block table and keys (or a test's).
pub struct CompactInputs<'a> {
    pub blocks: &'a wgpu::Buffer,
    pub keys: &'a wgpu::Buffer,
}

pub struct CompactPass {
    reduce: wgpu::ComputePipeline,
    scan: wgpu::ComputePipeline,
    finish: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    templates: wgpu::Buffer,
    chunk_counts: wgpu::Buffer,
    args: wgpu::Buffer,
    order: wgpu::Buffer,
    /// What `templates` holds, for the twin.
    template_copy: Vec<SeedDrawArgs>,
    limits: CompactLimits,
}

impl CompactPass {
    /// Builds the four pipelines and the buffers for up to `limits`; templates start empty (no
    /// mesh: every draw has 0 indices).
    pub fn new(device: &wgpu::Device, limits: CompactLimits) -> Result<Self, CompactError> {
        if limits.blocks > MAX_COMPACT_BLOCKS {
            return Err(CompactError::TooManyBlocks {
                blocks: limits.blocks.into(),
                max: MAX_COMPACT_BLOCKS.into(),
            });
        }
        let max = device.limits().max_storage_buffer_binding_size;
        let chunk_bytes =
            u64::from(limits.blocks.div_ceil(COMPACT_CHUNK).max(1)) * u64::from(SEED_GROUPS) * 4;
        let order_bytes = u64::from(limits.records.max(1)) * 4;
        for (what, bytes) in [("chunk table", chunk_bytes), ("permutation", order_bytes)] {
            if bytes > max {
                return Err(CompactError::TooLarge { what, bytes, max });
            }
        }
        let module = shaders::module(device, "compact");
        let entry = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("compact"),
            entries: &[
                entry(0, true),
                entry(1, true),
                entry(2, true),
                entry(3, true),
                entry(4, false),
                entry(5, false),
                entry(6, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("compact"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = |entry_point| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        use wgpu::BufferUsages as U;
        let draws_bytes = u64::from(SEED_DRAWS) * size_of::<SeedDrawArgs>() as u64;
        Ok(Self {
            reduce: pipeline("reduce"),
            scan: pipeline("scan"),
            finish: pipeline("finish"),
            scatter: pipeline("scatter"),
            layout,
            params: buffer("compact params", size_of::<CompactParams>() as u64, U::STORAGE | U::COPY_DST),
            templates: buffer("seed draw templates", draws_bytes, U::STORAGE | U::COPY_DST),
            chunk_counts: buffer("compact chunk counts", chunk_bytes, U::STORAGE),
            args: buffer("seed draw args", draws_bytes, U::STORAGE | U::INDIRECT | U::COPY_SRC),
            order: buffer("seed draw order", order_bytes, U::STORAGE | U::COPY_SRC),
            template_copy: vec![SeedDrawArgs::default(); SEED_DRAWS as usize],
            limits,
        })
    }

    /// The bind group over `inputs` (fixed for a renderer's life).
    pub fn bind_group(&self, device: &wgpu::Device, inputs: &CompactInputs) -> wgpu::BindGroup {
        let buffers = [
            &self.params,
            inputs.blocks,
            inputs.keys,
            &self.templates,
            &self.chunk_counts,
            &self.args,
            &self.order,
        ];
        let entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(binding, buffer)| wgpu::BindGroupEntry {
                binding: binding as u32,
                resource: buffer.as_entire_binding(),
            })
            .collect();
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("compact"),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Sets the mesh fields of each draw (`index_count`, `first_index`, `base_vertex`; the rest
    /// is ignored), draw by draw from 0 (`SEED_DRAWS`: the groups', then their cross-fades');
    /// draws beyond `templates` keep theirs.
    pub fn set_templates(&mut self, queue: &wgpu::Queue, templates: &[SeedDrawArgs]) {
        let n = templates.len().min(SEED_DRAWS as usize);
        if n > 0 {
            self.template_copy[..n].copy_from_slice(&templates[..n]);
            queue.write_buffer(&self.templates, 0, bytemuck::cast_slice(&templates[..n]));
        }
    }

    /// The templates the draws are filled from (`SEED_DRAWS`).
    pub fn templates(&self) -> &[SeedDrawArgs] {
        &self.template_copy
    }

    /// Writes the run's constants: compact the first `blocks` entries of the block table.
    pub fn prepare(&self, queue: &wgpu::Queue, blocks: u32) -> Result<CompactParams, CompactError> {
        if blocks > self.limits.blocks {
            return Err(CompactError::TooManyBlocks {
                blocks: blocks.into(),
                max: self.limits.blocks.into(),
            });
        }
        let params = CompactParams { blocks, chunks: blocks.div_ceil(COMPACT_CHUNK), _pad: [0; 2] };
        queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        Ok(params)
    }

    /// Records the four steps (reduce, scan, finish, scatter) in one compute pass; wgpu orders
    /// them, as each writes what the next reads.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        params: &CompactParams,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("compact"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, bind_group, &[]);
        let steps = [
            (&self.reduce, params.chunks),
            (&self.scan, SEED_GROUPS),
            (&self.finish, 1),
            (&self.scatter, params.chunks),
        ];
        for (pipeline, workgroups) in steps {
            if workgroups > 0 {
                pass.set_pipeline(pipeline);
                pass.dispatch_workgroups(workgroups, 1, 1);
            }
        }
    }

    /// The permutation, draw slot → record index (`limits.records` entries; a run fills the
    /// first `Σ instance_count`).
    pub fn order(&self) -> &wgpu::Buffer {
        &self.order
    }

    /// `SEED_DRAWS` indirect draws (`SeedDrawArgs`), usable with `draw_indexed_indirect`.
    pub fn draw_args(&self) -> &wgpu::Buffer {
        &self.args
    }

    pub fn limits(&self) -> CompactLimits {
        self.limits
    }

    /// Reads the last run's draw arguments and permutation back, waiting for the GPU: for tests
    /// and tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu) -> Result<Compacted, GpuError> {
        let args_bytes = u64::from(SEED_DRAWS) * size_of::<SeedDrawArgs>() as u64;
        let args = bytemuck::pod_collect_to_vec(&super::read_buffer(gpu, &self.args, args_bytes)?);
        let mut out = Compacted { order: Vec::new(), args };
        let drawn = (out.drawn() as u64).min(self.limits.records.into());
        out.order = bytemuck::pod_collect_to_vec(&super::read_buffer(gpu, &self.order, drawn * 4)?);
        Ok(out)
    }
}
