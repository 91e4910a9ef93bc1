//! Compaction's GPU half: the four pipelines over one binding table (built once), the draw
//! templates, the run's constants and the recorded dispatches, and blocking readbacks for tests.

use wgpu::ShaderStages as Stage;

use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::gpu_types::{CompactParams, SeedBlock, SeedDrawArgs};
use crate::gpu::layout::{COMPACT_CHUNK, SEED_DRAWS, SEED_GROUPS};
use crate::gpu::readback::read_values;
use crate::gpu::resources::{buffer, compute_pipeline, pipeline_layout};
use crate::gpu::shaders::{BLOCKS, WgslSource};
use crate::gpu::{Gpu, GpuError};

use super::frame::{CompactLimits, Compacted};
use super::{CompactError, MAX_COMPACT_BLOCKS};

/// Compaction's shader.
pub const SHADER: WgslSource =
    WgslSource { name: "compact", parts: &[BLOCKS, include_str!("../../../shaders/compact.wgsl")] };

/// The draws, as the shader declares them: `SEED_DRAWS` of them.
type Draws = [SeedDrawArgs; SEED_DRAWS as usize];

/// Compaction's bindings (its constants are a storage buffer: see `tile_load_map.wgsl`).
pub const BINDINGS: BindingTable<7> = BindingTable {
    label: "compact",
    bindings: [
        Binding::storage::<CompactParams>(0, "params", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<SeedBlock>(1, "blocks", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<u32>(2, "keys", Stage::COMPUTE, Access::Read),
        Binding::storage::<Draws>(3, "templates", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<u32>(4, "chunk_counts", Stage::COMPUTE, Access::ReadWrite),
        Binding::storage::<Draws>(5, "args", Stage::COMPUTE, Access::ReadWrite),
        Binding::storage_array::<u32>(6, "order", Stage::COMPUTE, Access::ReadWrite),
    ],
};

/// The buffers compaction reads: pass 3's block table and keys (or a test's).
pub struct CompactInputs<'a> {
    /// Pass 3's block table: one `SeedBlock` (offset, count in the record buffer) per workgroup.
    pub blocks: &'a wgpu::Buffer,
    /// Each record's draw group (species × `SEED_LODS` + radial LOD), parallel to the records.
    pub keys: &'a wgpu::Buffer,
}

/// Pass 4a on the GPU: pipelines, binding table and buffers built once in `new`; each frame `prepare`
/// writes the run's constants and `encode` records its four dispatches.
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
        let module = SHADER.module(device);
        let layout = BINDINGS.layout(device);
        let pipeline_layout = pipeline_layout(device, "compact", &[&layout]);
        let pipeline =
            |entry_point| compute_pipeline(device, entry_point, &pipeline_layout, &module, entry_point);
        let buffer = |label, size: u64, usage| buffer(device, label, size, usage);
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
        BINDINGS.bind_group(
            device,
            &self.layout,
            [
                self.params.as_entire_binding(),
                inputs.blocks.as_entire_binding(),
                inputs.keys.as_entire_binding(),
                self.templates.as_entire_binding(),
                self.chunk_counts.as_entire_binding(),
                self.args.as_entire_binding(),
                self.order.as_entire_binding(),
            ],
        )
    }

    /// Sets the mesh fields of each draw (`index_count`, `first_index`, `base_vertex`; the rest
    /// is ignored), draw by draw from 0 (`SEED_DRAWS`: the groups', then their cross-fades');
    /// draws beyond `templates` keep theirs.
    pub fn set_templates(&mut self, queue: &crate::gpu::Queue, templates: &[SeedDrawArgs]) {
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
    pub fn prepare(&self, queue: &crate::gpu::Queue, blocks: u32) -> Result<CompactParams, CompactError> {
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
        counting: Counting<'_>,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("compact"),
            timestamp_writes: None,
        });
        pass.set_bind_group(0, bind_group, &[]);
        counting.begin(&mut pass, Part::Whole);
        let steps = [
            (&self.reduce, params.chunks),
            (&self.scan, SEED_GROUPS),
            (&self.finish, 1),
            (&self.scatter, params.chunks),
        ];
        for (pipeline, workgroups) in steps {
            if workgroups > 0 {
                pass.set_pipeline(pipeline);
                counting.dispatch(&mut pass, [workgroups, 1, 1]);
            }
        }
        counting.end(&mut pass);
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

    /// What the pass was sized for in `new`: the most blocks `prepare` takes, and the length of
    /// the permutation.
    pub fn limits(&self) -> CompactLimits {
        self.limits
    }

    /// Reads the last run's draw arguments and permutation back, waiting for the GPU: for tests
    /// and tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu) -> Result<Compacted, GpuError> {
        let args = read_values(gpu, &self.args, SEED_DRAWS.into())?;
        let mut out = Compacted { order: Vec::new(), args };
        let drawn = (out.drawn() as u64).min(self.limits.records.into());
        out.order = read_values(gpu, &self.order, drawn)?;
        Ok(out)
    }
}
