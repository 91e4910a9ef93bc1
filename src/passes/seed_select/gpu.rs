//! Pass 3's GPU half: the pipelines and binding table (built once), the patterns and species
//! tables uploaded once, the frame's upload and the recorded dispatches (the selection, `settle`,
//! and the selection again, indirectly, which runs only when the records overflowed: see
//! `shaders/seed_select_blocks.wgsl`), and blocking readbacks for tests.

use wgpu::{ShaderStages as Stage, TextureSampleType as Sample, TextureViewDimension as Dim};

use crate::camera::CameraError;
use crate::config::Settings;
use crate::earth::gpu::EARTH;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::gpu_types::{
    SeedBlock, SeedCell, SeedClass, SeedCounters, SeedRecord, SeedSettle, SeedSpecies, SeedUniforms,
};
use crate::gpu::readback::read_values;
use crate::gpu::resources::{buffer, buffer_init, compute_pipeline, pipeline_layout};
use crate::gpu::shaders::{BLOCKS, HASH, LANDCOVER, SEED_RECORD, TERRAIN_SURFACE, WgslSource};
use crate::gpu::{Gpu, GpuError};
use crate::seeds::patterns::SeedPatterns;
use crate::seeds::{MAX_SEED_CELLS, SeedTables, block_capacity, workgroups_per_cell};
use crate::streaming::TileCache;

use super::frame::{SeedFrame, SeedInputs, SeedOutput};
use super::march::BLOCKS_PER_TILE;

/// Pass 3's shader.
pub const SHADER: WgslSource = WgslSource {
    name: "seed_select",
    parts: &[
        HASH,
        BLOCKS,
        EARTH,
        SEED_RECORD,
        TERRAIN_SURFACE,
        LANDCOVER,
        include_str!("../../../shaders/seed_select.wgsl"),
        include_str!("../../../shaders/seed_select_imagery.wgsl"),
        include_str!("../../../shaders/seed_select_march.wgsl"),
        include_str!("../../../shaders/seed_select_blocks.wgsl"),
    ],
};

/// Pass 3's bindings: the frame's constants and cells (a storage buffer, not a uniform one: see
/// `tile_load_map.wgsl`), the patterns and tables, the three caches and the terrain depth it reads,
/// what it writes, and the tops the occlusion march leaps by (`march`): per height tile, and per
/// block of each resident tile (the height cache's summary).
pub const BINDINGS: BindingTable<18> = BindingTable {
    label: "seed select",
    bindings: [
        Binding::storage::<SeedUniforms>(0, "u", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<SeedCell>(1, "cells", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<[f32; 2]>(2, "patterns", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<SeedSpecies>(3, "species_table", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<SeedClass>(4, "class_table", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<u32>(5, "height_page_table", Stage::COMPUTE, Access::Read),
        Binding::texture(
            6,
            "height_tiles",
            Stage::COMPUTE,
            Sample::Float { filterable: false },
            Dim::D2Array,
        ),
        Binding::storage_array::<u32>(7, "lcc_page_table", Stage::COMPUTE, Access::Read),
        Binding::texture(8, "lcc_tiles", Stage::COMPUTE, Sample::Uint, Dim::D2Array),
        Binding::storage_array::<u32>(9, "imagery_page_table", Stage::COMPUTE, Access::Read),
        Binding::texture(
            10,
            "imagery_tiles",
            Stage::COMPUTE,
            Sample::Float { filterable: false },
            Dim::D2Array,
        ),
        Binding::texture(11, "depth", Stage::COMPUTE, Sample::Depth, Dim::D2),
        Binding::storage_array::<SeedRecord>(12, "records", Stage::COMPUTE, Access::ReadWrite),
        Binding::storage::<SeedCounters>(13, "counters", Stage::COMPUTE, Access::ReadWrite),
        Binding::storage_array::<u32>(14, "keys", Stage::COMPUTE, Access::ReadWrite),
        Binding::storage_array::<SeedBlock>(15, "blocks", Stage::COMPUTE, Access::ReadWrite),
        Binding::storage_array::<f32>(16, "height_tile_max_m", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<f32>(17, "height_block_max_m", Stage::COMPUTE, Access::Read),
    ],
};

/// `settle`'s group 1: the second round's indirect dispatch, which it writes. Not in `BINDINGS`:
/// bound for that round, it could not also be its indirect argument.
pub const SETTLE_BINDINGS: BindingTable<1> = BindingTable {
    label: "seed select settle",
    bindings: [Binding::storage::<SeedSettle>(0, "settled", Stage::COMPUTE, Access::ReadWrite)],
};

/// Pass 3 on the GPU: pipeline, binding table, patterns, species tables and output buffers built once
/// in `new`; each frame `prepare` uploads the uniforms and cells and `encode` records the dispatch.
pub struct SeedSelectPass {
    pipeline: wgpu::ComputePipeline,
    settle: wgpu::ComputePipeline,
    settle_group: wgpu::BindGroup,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    cells: wgpu::Buffer,
    patterns: wgpu::Buffer,
    species: wgpu::Buffer,
    classes: wgpu::Buffer,
    records: wgpu::Buffer,
    counters: wgpu::Buffer,
    keys: wgpu::Buffer,
    blocks: wgpu::Buffer,
    height_tile_max: wgpu::Buffer,
    settled: wgpu::Buffer,
    capacity: u32,
    block_capacity: u32,
}

/// The caches and depth pass 3 reads.
pub struct SeedSources<'a> {
    /// The height cache: page table and tiles the seeds' ground heights and slopes are read from.
    pub heights: &'a TileCache,
    /// The land-cover cache: the classes that choose each seed's species.
    pub landcover: &'a TileCache,
    /// The imagery cache: the ground colour each seed takes on.
    pub imagery: &'a TileCache,
    /// The terrain's reversed-Z depth target, for the occlusion test.
    pub depth: &'a wgpu::TextureView,
}

impl SeedSelectPass {
    /// Builds the pipeline and uploads the patterns and tables and the dataset's
    /// `height_tile_max_m` (`march::height_tile_max_m`), which a renderer keeps for life.
    pub fn new(
        device: &wgpu::Device,
        settings: &Settings,
        patterns: &SeedPatterns,
        tables: &SeedTables,
        height_tile_max_m: &[f32],
    ) -> Self {
        let module = SHADER.module(device);
        let layout = BINDINGS.layout(device);
        let main_layout = pipeline_layout(device, "seed select", &[&layout]);
        let pipeline = compute_pipeline(device, "seed select", &main_layout, &module, "main");
        // `settle` sees the pass's bindings and, in group 1, the second round's dispatch.
        let settle_layout = SETTLE_BINDINGS.layout(device);
        let both = pipeline_layout(device, "seed select settle", &[&layout, &settle_layout]);
        let settle = compute_pipeline(device, "seed select settle", &both, &module, "settle");
        use wgpu::BufferUsages as U;
        let settled = buffer(device, "seed settle", size_of::<SeedSettle>() as u64, U::STORAGE | U::INDIRECT);
        let settle_group = SETTLE_BINDINGS.bind_group(device, &settle_layout, [settled.as_entire_binding()]);
        let empty = |label, size: u64, usage| buffer(device, label, size, usage);
        let init = |label, contents: &[u8]| buffer_init(device, label, contents, U::STORAGE);
        let capacity = settings.seeds.capacity;
        let block_capacity = block_capacity(settings.seeds.seeds_per_pattern);
        let output = U::STORAGE | U::COPY_SRC;
        // A binding may not be empty: a table without species still gets one (never read) entry.
        let no_species = [SeedSpecies::default()];
        let species: &[u8] =
            bytemuck::cast_slice(if tables.species.is_empty() { &no_species[..] } else { &tables.species });
        let records_bytes = u64::from(capacity.max(1)) * size_of::<SeedRecord>() as u64;
        let cells_bytes = u64::from(MAX_SEED_CELLS) * size_of::<SeedCell>() as u64;
        let blocks_bytes = u64::from(block_capacity) * size_of::<SeedBlock>() as u64;
        Self {
            pipeline,
            settle,
            settle_group,
            layout,
            uniforms: empty("seed uniforms", size_of::<SeedUniforms>() as u64, U::STORAGE | U::COPY_DST),
            cells: empty("seed cells", cells_bytes, U::STORAGE | U::COPY_DST),
            patterns: init("seed patterns", bytemuck::cast_slice(&patterns.positions_unit)),
            species: init("seed species", species),
            classes: init("seed classes", bytemuck::cast_slice(&tables.classes)),
            records: empty("seed records", records_bytes, output),
            counters: empty("seed counters", size_of::<SeedCounters>() as u64, output | U::COPY_DST),
            keys: empty("seed keys", u64::from(capacity.max(1)) * 4, output),
            blocks: empty("seed blocks", blocks_bytes, output),
            height_tile_max: init(
                "seed height tile max",
                // A binding may not be empty; a top of +∞ is never leapt over.
                bytemuck::cast_slice(if height_tile_max_m.is_empty() {
                    &[f32::INFINITY][..]
                } else {
                    height_tile_max_m
                }),
            ),
            settled,
            capacity,
            block_capacity,
        }
    }

    /// The bind group over a renderer's caches and depth target (fixed for its life). A height
    /// cache without block tops (`march::BLOCK_TOPS`) gets tops of +∞: the march visits its blocks.
    pub fn bind_group(&self, device: &wgpu::Device, sources: &SeedSources) -> wgpu::BindGroup {
        use wgpu::BindingResource::TextureView as View;
        let never_leap;
        let block_tops = match sources.heights.summary_buffer() {
            Some(buffer) => buffer,
            None => {
                let tops = vec![f32::INFINITY; sources.heights.slot_count() as usize * BLOCKS_PER_TILE];
                never_leap = buffer_init(
                    device,
                    "seed block tops",
                    bytemuck::cast_slice(&tops),
                    wgpu::BufferUsages::STORAGE,
                );
                &never_leap
            }
        };
        BINDINGS.bind_group(
            device,
            &self.layout,
            [
                self.uniforms.as_entire_binding(),
                self.cells.as_entire_binding(),
                self.patterns.as_entire_binding(),
                self.species.as_entire_binding(),
                self.classes.as_entire_binding(),
                sources.heights.page_table.as_entire_binding(),
                View(&sources.heights.view),
                sources.landcover.page_table.as_entire_binding(),
                View(&sources.landcover.view),
                sources.imagery.page_table.as_entire_binding(),
                View(&sources.imagery.view),
                View(sources.depth),
                self.records.as_entire_binding(),
                self.counters.as_entire_binding(),
                self.keys.as_entire_binding(),
                self.blocks.as_entire_binding(),
                self.height_tile_max.as_entire_binding(),
                block_tops.as_entire_binding(),
            ],
        )
    }

    /// Builds the frame's uniforms and cells and uploads them; returns them (the twin reads the same).
    pub fn prepare(&self, queue: &crate::gpu::Queue, inputs: &SeedInputs) -> Result<SeedFrame, CameraError> {
        let frame = SeedFrame::new(inputs)?;
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&frame.uniforms));
        if !frame.cells.is_empty() {
            queue.write_buffer(&self.cells, 0, bytemuck::cast_slice(&frame.cells));
        }
        Ok(frame)
    }

    /// Records the pass: counters cleared, one invocation per seed of every cell, `settle`, and the
    /// second round (dispatched by `settle`: no workgroups unless the records overflowed).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        frame: &SeedFrame,
        counting: Counting<'_>,
    ) {
        encoder.clear_buffer(&self.counters, 0, None);
        if frame.cells.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("seed select"),
            timestamp_writes: None,
        });
        counting.begin(&mut pass, Part::Whole);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        let workgroups = [workgroups_per_cell(frame.uniforms.active_ranks), frame.cells.len() as u32, 1];
        counting.dispatch(&mut pass, workgroups);
        pass.set_pipeline(&self.settle);
        pass.set_bind_group(1, &self.settle_group, &[]);
        counting.dispatch(&mut pass, [1, 1, 1]);
        pass.set_pipeline(&self.pipeline);
        counting.dispatch_indirect(&mut pass, &self.settled, 0);
        counting.end(&mut pass);
    }

    /// The record buffer (`capacity` records; a frame fills `min(selected, capacity)`).
    pub fn records(&self) -> &wgpu::Buffer {
        &self.records
    }

    /// The counters (`SeedCounters`), cleared at the start of each frame's pass.
    pub fn counters(&self) -> &wgpu::Buffer {
        &self.counters
    }

    /// Records the record buffer holds (`seeds.capacity`); survivors beyond it count as overflow.
    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Each record's draw group (`capacity` entries, filled as the records are).
    pub fn keys(&self) -> &wgpu::Buffer {
        &self.keys
    }

    /// The block table (`block_capacity` entries; a frame writes `SeedFrame::blocks` of them).
    pub fn blocks(&self) -> &wgpu::Buffer {
        &self.blocks
    }

    /// Entries of the block table (`seeds::block_capacity` for `seeds.seeds_per_pattern`).
    pub fn block_capacity(&self) -> u32 {
        self.block_capacity
    }

    /// Reads the last frame's records and counters back, waiting for the GPU: for tests and
    /// tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu) -> Result<(Vec<SeedRecord>, SeedCounters), GpuError> {
        let counters = self.read_counters(gpu)?;
        let kept = counters.selected.min(self.capacity);
        Ok((read_values(gpu, &self.records, kept.into())?, counters))
    }

    /// Reads everything the last frame of `frame` wrote (records, keys, block table, counters),
    /// waiting for the GPU: for tests and tools.
    pub fn read_output(&self, gpu: &Gpu, frame: &SeedFrame) -> Result<SeedOutput, GpuError> {
        let (records, counters) = self.read_back(gpu)?;
        let keys = read_values(gpu, &self.keys, records.len() as u64)?;
        let blocks = read_values(gpu, &self.blocks, frame.blocks().min(self.block_capacity).into())?;
        Ok(SeedOutput { records, keys, blocks, counters })
    }

    fn read_counters(&self, gpu: &Gpu) -> Result<SeedCounters, GpuError> {
        let counters: Vec<SeedCounters> = read_values(gpu, &self.counters, 1)?;
        counters.first().copied().ok_or_else(|| GpuError::Validation("no seed counters read back".into()))
    }
}
