//! How it works: pass 3, seed selection (Amara et al. 2007 § 4.4). The CPU hands the GPU the
//! ring-0 cells the latest Tile Load Map found visible within the radial LOD range, each with its
//! pattern and land-cover level; `shaders/seed_select.wgsl` checks every seed of every such cell
//! (one invocation per seed) and appends the survivors to a fixed-capacity record buffer, with
//! counters of what was checked, culled (and why) and what overflowed. Each workgroup writes its
//! survivors in rank order, each with its draw group in a parallel key buffer, and where it put
//! them in its own entry of a block table (`SeedBlock`), which compaction (`passes/compact.rs`)
//! reads in order: the table, not the atomics, fixes the order in which seeds are drawn.
//!
//! `SeedFrame::new` is the CPU half, in f64: it turns each cell's corner into an integer texel and
//! a remainder in every layer's own grid (height samples, level-1 land-cover texels, level-0
//! imagery texels) and pre-divides every length, so the shader (and its twin,
//! `reference/seed_select.rs`) only adds and multiplies small f32 numbers. The patterns and the
//! species tables are uploaded once, in `new`.

use glam::DVec3;
use wgpu::util::DeviceExt;

use crate::camera::{Camera, CameraError};
use crate::config::Settings;
use crate::dataset::{Dataset, Pyramid, TileId};
use crate::gpu::gpu_types::{SeedBlock, SeedCell, SeedCounters, SeedRecord, SeedSpecies, SeedUniforms};
use crate::gpu::{Gpu, GpuError};
use crate::seeds::patterns::SeedPatterns;
use crate::seeds::{MAX_SEED_CELLS, SeedTables, block_capacity, max_cells, workgroups_per_cell};
use crate::shaders::{self, MAX_LEVELS};
use crate::streaming::TileCache;

/// A ring-0 TLM cell whose seeds are wanted: its global address, pattern and radial LOD.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SeedCellRef {
    pub address: [i64; 2],
    pub pattern: u32,
    pub radial_lod: u32,
}

/// What a frame's seed selection needs from the CPU.
pub struct SeedInputs<'a> {
    pub settings: &'a Settings,
    pub dataset: &'a Dataset,
    pub camera: &'a Camera,
    /// Camera position in grid space, metres.
    pub camera_grid_m: DVec3,
    pub viewport_px: [u32; 2],
    pub cells: &'a [SeedCellRef],
    /// Ranks worth checking (`SeedTables::active_ranks`).
    pub active_ranks: u32,
}

/// One frame's uniforms and cells: what the shader reads, and what the twin replays.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedFrame {
    pub uniforms: SeedUniforms,
    pub cells: Vec<SeedCell>,
    /// Cells beyond `seeds::max_cells` (the farthest in the TLM's order) that were left out.
    pub cells_dropped: usize,
}

/// Everything pass 3 wrote in a frame, read back (or replayed by the twin).
#[derive(Debug, Clone, PartialEq)]
pub struct SeedOutput {
    /// The record buffer's filled part (`min(selected, capacity)` records), and each record's
    /// draw group (`seeds::seed_group`).
    pub records: Vec<SeedRecord>,
    pub keys: Vec<u32>,
    /// One entry per workgroup, cell by cell (`SeedFrame::blocks`).
    pub blocks: Vec<SeedBlock>,
    pub counters: SeedCounters,
}

impl SeedOutput {
    /// The records block by block in table order: cell by cell, rank by rank, as the twin lists
    /// them (when nothing overflowed), whatever order the blocks landed in.
    pub fn in_block_order(&self) -> Vec<SeedRecord> {
        self.blocks
            .iter()
            .flat_map(|b| &self.records[b.offset as usize..(b.offset + b.count) as usize])
            .copied()
            .collect()
    }
}

/// Page-table addressing of a pyramid's levels: first entry, tiles along x and y.
fn level_table<const N: usize>(pyramid: &Pyramid) -> [[u32; 4]; N] {
    let mut table = [[0; 4]; N];
    for level in 0..pyramid.levels.min(N as u32) {
        let [nx, ny] = pyramid.tiles_at(level);
        let first = pyramid.tile_index(TileId::new(level, 0, 0)).unwrap_or_default() as u32;
        table[level as usize] = [first, nx, ny, 0];
    }
    table
}

/// `value` (≥ 0 or not) as an integer part and a remainder in [0, 1) that f32 can carry.
fn split(value: f64) -> (i32, f32) {
    let whole = value.floor();
    let frac = (value - whole) as f32;
    // A remainder a hair below 1 rounds to 1.0 in f32: carry it.
    if frac >= 1.0 { (whole as i32 + 1, 0.0) } else { (whole as i32, frac) }
}

impl SeedFrame {
    pub fn new(inputs: &SeedInputs) -> Result<Self, CameraError> {
        let (s, dataset, camera) = (inputs.settings, inputs.dataset, inputs.camera);
        let [width, height] = inputs.viewport_px;
        let clip = camera.clip_from_view(width, height)? * camera.view_from_world();
        let rows = clip.transpose();
        // A side plane is `w ∓ x ≥ 0`: a sphere reaches it within `r · |row_w ∓ row_x|` (xyz).
        let row_len = |r: glam::DVec4| {
            let (plus, minus) = ((rows.w_axis + r).truncate(), (rows.w_axis - r).truncate());
            plus.length().max(minus.length()) as f32
        };
        let manifest = &dataset.manifest;
        let spacing_m = manifest.height.spacing_m;
        let half_spacing = 0.5 * spacing_m;
        let cell_m = s.tlm.cell_m;
        let seeds = &s.seeds;
        let mut u = SeedUniforms {
            clip_from_view_world: clip.as_mat4().to_cols_array_2d(),
            camera_z_m: inputs.camera_grid_m.z as f32,
            near_m: camera.near_m as f32,
            frustum_epsilon: seeds.frustum_epsilon as f32,
            no_fuse: 0,
            clip_row_len: [row_len(rows.x_axis), row_len(rows.y_axis)],
            screen_px: [width, height],
            occlusion_tolerance_m: seeds.occlusion_tolerance_m as f32,
            occlusion_tolerance_per_m: (seeds.occlusion_tolerance_per_km / 1000.0) as f32,
            inv_reference_height_m: (1.0 / seeds.reference_height_m) as f32,
            sink_fraction: seeds.sink_fraction as f32,
            radial_lod_m: crate::seeds::lod_reach_m(s).map(|r| r as f32),
            cell_in_samples: (cell_m / spacing_m) as f32,
            cell_in_lcc_texels: 0.0,
            cell_in_imagery_texels: 0.0,
            ground_radius_texels: 0.0,
            inv_spacing_m: (1.0 / spacing_m) as f32,
            seeds_per_pattern: seeds.seeds_per_pattern,
            capacity: seeds.capacity,
            seed: s.tlm.seed,
            height_size: dataset.height.pyramid.size,
            height_level_count: dataset.height.pyramid.levels.min(MAX_LEVELS),
            lcc_sub_bits: 0,
            lcc_size: [0; 2],
            imagery_level_count: 0,
            cell_m: cell_m as f32,
            imagery_size: [0; 2],
            ndc_per_px: [(2.0 / f64::from(width)) as f32, (2.0 / f64::from(height)) as f32],
            camera_sample: [0; 2],
            camera_sample_frac: [0.0; 2],
            refine_max_steps: seeds.occlusion_refine_steps,
            active_ranks: inputs.active_ranks.min(seeds.seeds_per_pattern),
            _pad: [0; 2],
            height_levels: level_table(&dataset.height.pyramid),
            lcc_levels: [[0; 4]; 4],
            imagery_levels: [[0; 4]; MAX_LEVELS as usize],
        };
        // Level-1 land-cover texels are twice the level-0 ones (the level that duplicates them).
        let lcc_texel_m = match (&dataset.landcover, &manifest.landcover) {
            (Some(layer), Some(meta)) => {
                let texel_m = 2.0 * meta.layer.texel_m;
                u.cell_in_lcc_texels = (cell_m / texel_m) as f32;
                u.lcc_sub_bits = meta.coding.sub_bits();
                u.lcc_size = layer.pyramid.size_at(1);
                u.lcc_levels = level_table(&layer.pyramid);
                Some(texel_m)
            }
            _ => None,
        };
        let imagery_texel_m = match (&dataset.imagery, &manifest.imagery) {
            (Some(layer), Some(meta)) => {
                u.cell_in_imagery_texels = (cell_m / meta.texel_m) as f32;
                u.ground_radius_texels = (seeds.ground_colour_radius_m / meta.texel_m) as f32;
                u.imagery_level_count = layer.pyramid.levels.min(MAX_LEVELS);
                u.imagery_size = layer.pyramid.size;
                u.imagery_levels = level_table(&layer.pyramid);
                Some(meta.texel_m)
            }
            _ => None,
        };
        let camera_xy = [inputs.camera_grid_m.x, inputs.camera_grid_m.y];
        let (cx, cy) = (split(camera_xy[0] / spacing_m), split(camera_xy[1] / spacing_m));
        (u.camera_sample, u.camera_sample_frac) = ([cx.0, cy.0], [cx.1, cy.1]);
        let kept = inputs.cells.len().min(max_cells(u.active_ranks) as usize);
        let cells = inputs.cells[..kept]
            .iter()
            .map(|c| {
                let corner = c.address.map(|g| g as f64 * cell_m);
                let in_grid = |texel_m: f64, offset_m: f64| {
                    let (x, y) =
                        (split((corner[0] + offset_m) / texel_m), split((corner[1] + offset_m) / texel_m));
                    ([x.0, y.0], [x.1, y.1])
                };
                let (height_sample, height_frac) = in_grid(spacing_m, 0.0);
                let (lcc_texel, lcc_frac) =
                    lcc_texel_m.map_or(([0; 2], [0.0; 2]), |t| in_grid(t, half_spacing));
                let (imagery_texel, imagery_frac) =
                    imagery_texel_m.map_or(([0; 2], [0.0; 2]), |t| in_grid(t, half_spacing));
                SeedCell {
                    rel_m: [(corner[0] - camera_xy[0]) as f32, (corner[1] - camera_xy[1]) as f32],
                    address: c.address.map(|g| g.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32),
                    height_sample,
                    height_frac,
                    lcc_texel,
                    lcc_frac,
                    imagery_texel,
                    imagery_frac,
                    pattern: c.pattern,
                    lcc_level: c.radial_lod.min(crate::lcc::LCC_LEVELS - 1),
                    _pad: [0; 2],
                }
            })
            .collect();
        Ok(Self { uniforms: u, cells, cells_dropped: inputs.cells.len() - kept })
    }

    /// Seeds this frame checks.
    pub fn checked(&self) -> u64 {
        self.cells.len() as u64 * u64::from(self.uniforms.active_ranks)
    }

    /// Entries of the block table this frame writes: one per workgroup, cell by cell.
    pub fn blocks(&self) -> u32 {
        self.cells.len() as u32 * workgroups_per_cell(self.uniforms.active_ranks)
    }
}

pub struct SeedSelectPass {
    pipeline: wgpu::ComputePipeline,
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
    capacity: u32,
    block_capacity: u32,
}

/// The caches and depth pass 3 reads.
pub struct SeedSources<'a> {
    pub heights: &'a TileCache,
    pub landcover: &'a TileCache,
    pub imagery: &'a TileCache,
    pub depth: &'a wgpu::TextureView,
}

impl SeedSelectPass {
    /// Builds the pipeline and uploads the patterns and tables, which a renderer keeps for life.
    pub fn new(
        device: &wgpu::Device,
        settings: &Settings,
        patterns: &SeedPatterns,
        tables: &SeedTables,
    ) -> Self {
        let module = shaders::module(device, "seed_select");
        let entry = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let storage = |read_only| wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let array = |sample_type| wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let float = wgpu::TextureSampleType::Float { filterable: false };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("seed select"),
            entries: &[
                entry(0, storage(true)),
                entry(1, storage(true)),
                entry(2, storage(true)),
                entry(3, storage(true)),
                entry(4, storage(true)),
                entry(5, storage(true)),
                entry(6, array(float)),
                entry(7, storage(true)),
                entry(8, array(wgpu::TextureSampleType::Uint)),
                entry(9, storage(true)),
                entry(10, array(float)),
                entry(
                    11,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Depth,
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(12, storage(false)),
                entry(13, storage(false)),
                entry(14, storage(false)),
                entry(15, storage(false)),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("seed select"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("seed select"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let storage_usage = wgpu::BufferUsages::STORAGE;
        let empty = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let init = |label, contents: &[u8]| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: storage_usage,
            })
        };
        let copy_dst = wgpu::BufferUsages::COPY_DST;
        let capacity = settings.seeds.capacity;
        let block_capacity = block_capacity(settings.seeds.seeds_per_pattern);
        let output = storage_usage | wgpu::BufferUsages::COPY_SRC;
        // A binding may not be empty: a table without species still gets one (never read) entry.
        let no_species = [SeedSpecies::default()];
        let species: &[u8] =
            bytemuck::cast_slice(if tables.species.is_empty() { &no_species[..] } else { &tables.species });
        Self {
            pipeline,
            layout,
            uniforms: empty("seed uniforms", size_of::<SeedUniforms>() as u64, storage_usage | copy_dst),
            cells: empty(
                "seed cells",
                u64::from(MAX_SEED_CELLS) * size_of::<SeedCell>() as u64,
                storage_usage | copy_dst,
            ),
            patterns: init("seed patterns", bytemuck::cast_slice(&patterns.positions_unit)),
            species: init("seed species", species),
            classes: init("seed classes", bytemuck::cast_slice(&tables.classes)),
            records: empty(
                "seed records",
                u64::from(capacity.max(1)) * size_of::<SeedRecord>() as u64,
                output,
            ),
            counters: empty(
                "seed counters",
                size_of::<SeedCounters>() as u64,
                storage_usage | copy_dst | wgpu::BufferUsages::COPY_SRC,
            ),
            keys: empty("seed keys", u64::from(capacity.max(1)) * 4, output),
            blocks: empty("seed blocks", u64::from(block_capacity) * size_of::<SeedBlock>() as u64, output),
            capacity,
            block_capacity,
        }
    }

    /// The bind group over a renderer's caches and depth target (fixed for its life).
    pub fn bind_group(&self, device: &wgpu::Device, sources: &SeedSources) -> wgpu::BindGroup {
        fn buffer(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: buffer.as_entire_binding() }
        }
        fn texture(binding: u32, view: &wgpu::TextureView) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry { binding, resource: wgpu::BindingResource::TextureView(view) }
        }
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("seed select"),
            layout: &self.layout,
            entries: &[
                buffer(0, &self.uniforms),
                buffer(1, &self.cells),
                buffer(2, &self.patterns),
                buffer(3, &self.species),
                buffer(4, &self.classes),
                buffer(5, &sources.heights.page_table),
                texture(6, &sources.heights.view),
                buffer(7, &sources.landcover.page_table),
                texture(8, &sources.landcover.view),
                buffer(9, &sources.imagery.page_table),
                texture(10, &sources.imagery.view),
                texture(11, sources.depth),
                buffer(12, &self.records),
                buffer(13, &self.counters),
                buffer(14, &self.keys),
                buffer(15, &self.blocks),
            ],
        })
    }

    /// Builds the frame's uniforms and cells and uploads them; returns them (the twin reads the same).
    pub fn prepare(&self, queue: &wgpu::Queue, inputs: &SeedInputs) -> Result<SeedFrame, CameraError> {
        let frame = SeedFrame::new(inputs)?;
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&frame.uniforms));
        if !frame.cells.is_empty() {
            queue.write_buffer(&self.cells, 0, bytemuck::cast_slice(&frame.cells));
        }
        Ok(frame)
    }

    /// Records the pass: counters cleared, then one invocation per seed of every cell.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        frame: &SeedFrame,
    ) {
        encoder.clear_buffer(&self.counters, 0, None);
        if frame.cells.is_empty() {
            return;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("seed select"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(
            workgroups_per_cell(frame.uniforms.active_ranks),
            frame.cells.len() as u32,
            1,
        );
    }

    /// The record buffer (`capacity` records; a frame fills `min(selected, capacity)`).
    pub fn records(&self) -> &wgpu::Buffer {
        &self.records
    }

    /// The counters (`SeedCounters`), cleared at the start of each frame's pass.
    pub fn counters(&self) -> &wgpu::Buffer {
        &self.counters
    }

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

    pub fn block_capacity(&self) -> u32 {
        self.block_capacity
    }

    /// Reads the last frame's records and counters back, waiting for the GPU: for tests and
    /// tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu) -> Result<(Vec<SeedRecord>, SeedCounters), GpuError> {
        let counters = self.read_counters(gpu)?;
        let kept = counters.selected.min(self.capacity);
        let bytes = super::read_buffer(gpu, &self.records, u64::from(kept) * size_of::<SeedRecord>() as u64)?;
        Ok((bytemuck::pod_collect_to_vec(&bytes), counters))
    }

    /// Reads everything the last frame of `frame` wrote (records, keys, block table, counters),
    /// waiting for the GPU: for tests and tools.
    pub fn read_output(&self, gpu: &Gpu, frame: &SeedFrame) -> Result<SeedOutput, GpuError> {
        let (records, counters) = self.read_back(gpu)?;
        let keys = super::read_buffer(gpu, &self.keys, records.len() as u64 * 4)?;
        let blocks = u64::from(frame.blocks().min(self.block_capacity)) * size_of::<SeedBlock>() as u64;
        let blocks = super::read_buffer(gpu, &self.blocks, blocks)?;
        Ok(SeedOutput {
            records,
            keys: bytemuck::pod_collect_to_vec(&keys),
            blocks: bytemuck::pod_collect_to_vec(&blocks),
            counters,
        })
    }

    fn read_counters(&self, gpu: &Gpu) -> Result<SeedCounters, GpuError> {
        let bytes = super::read_buffer(gpu, &self.counters, size_of::<SeedCounters>() as u64)?;
        Ok(bytemuck::pod_read_unaligned(&bytes))
    }
}
