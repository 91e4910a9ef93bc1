//! How it works: the Tile Load Map (pass 1, Amara et al. 2007 § 4.2) tells the CPU, per cell of
//! a regular grid over the ground, whether the view needs it and at which levels. The grid is a
//! set of camera-centred rings (clipmap-like, so one layout serves a 15 km dataset and a planet):
//! ring k has `cells`² cells of edge `cell_m · 2^k`, and its origin snaps to *two* of its cells,
//! so that ring k − 1's square is exactly a block of ring-k cells (those write 0: ring k − 1
//! speaks for them) and a cell of ring k is always the same square of ground, its global address
//! (k, gx, gy) covering [gx · c_k, (gx + 1) · c_k] × [gy · c_k, (gy + 1) · c_k] of grid space.
//! Only as many rings as cover the dataset from the camera are used (at most `max_rings`).
//!
//! `TlmLayout` is that geometry, in f64, shared by the GPU pass, its CPU twin and the CPU
//! analysis. Each frame the CPU turns it into per-column and per-row `TlmSpan`s (extent clamped to
//! the dataset and relative to the camera, height tiles overlapped, inside/covered flags): all
//! the large-coordinate and floor/ceil work happens here in f64, and the shader only combines a
//! column with a row. The shader (`shaders/tile_load_map.wgsl`) then culls the cell's box (its
//! extent × the union of its height tiles' ranges) against the frustum and the depth pyramid,
//! and derives the imagery, terrain and radial levels from its nearest and farthest points.

use glam::{DMat4, DVec3};
use thiserror::Error;
use wgpu::util::DeviceExt;

use crate::camera::{Camera, CameraError};
use crate::config::{ImagerySettings, Settings, TlmSettings};
use crate::dataset::{Dataset, TileId};
use crate::gpu::gpu_types::{TlmCell, TlmRing, TlmSpan, TlmUniforms};
use crate::gpu::{Gpu, GpuError};
use crate::passes::depth_pyramid::DepthPyramid;
use crate::shaders::{self, MAX_LEVELS};
use crate::terrain::select::Lods;

mod layout;
use layout::height_level;
pub use layout::{CellAddress, TlmLayout};

/// Workgroup edge of the TLM dispatch (handed to WGSL through the prelude).
pub const TLM_WORKGROUP: u32 = 8;
/// Rings the uniforms have room for (`tlm.max_rings` is at most this).
pub const TLM_MAX_RINGS: u32 = 16;
/// `TlmSpan::flags`: the column (row) overlaps the dataset.
pub const TLM_SPAN_INSIDE: u32 = 1;
/// `TlmSpan::flags`: the column (row) lies within the inner ring's; a cell whose column and row
/// both do is covered by the inner ring.
pub const TLM_SPAN_COVERED: u32 = 2;

#[derive(Debug, Error)]
pub enum TlmError {
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error("the TLM supports at most {MAX_LEVELS} height levels; this dataset has {0}")]
    TooManyLevels(u32),
    #[error(
        "the layout has {rings} rings of {cells}² cells; the pass was built for {max_rings} of {pass_cells}²"
    )]
    LayoutMismatch { rings: u32, cells: u32, max_rings: u32, pass_cells: u32 },
}

/// Height ranges of every height tile, in `Pyramid::tile_index` order: the pass's per-dataset input.
/// Each is the union of the pack's conservative range (every level-0 sample under the tile) over the
/// tile and its eight neighbours: a coarse mesh near a tile's edge interpolates towards samples of
/// the neighbour, and the box must hold that surface too. A tile whose range cannot be read gets
/// the dataset's whole range.
pub fn height_tile_ranges(dataset: &Dataset) -> Vec<[f32; 2]> {
    let pyramid = &dataset.height.pyramid;
    let whole = [dataset.manifest.height.min_m, dataset.manifest.height.max_m];
    let own: Vec<[f32; 2]> = pyramid.tiles().map(|id| dataset.height_range(id).unwrap_or(whole)).collect();
    pyramid
        .tiles()
        .map(|id| {
            let [nx, ny] = pyramid.tiles_at(id.level);
            let mut range = [f32::INFINITY, f32::NEG_INFINITY];
            for y in id.y.saturating_sub(1)..=(id.y + 1).min(ny - 1) {
                for x in id.x.saturating_sub(1)..=(id.x + 1).min(nx - 1) {
                    let index = pyramid.tile_index(TileId::new(id.level, x, y)).unwrap_or_default() as usize;
                    range = [range[0].min(own[index][0]), range[1].max(own[index][1])];
                }
            }
            range
        })
        .collect()
}

/// The imagery layer as the TLM sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TlmImagery {
    /// Texel edge at level 0, metres.
    pub texel_m: f64,
    pub levels: u32,
    /// `imagery.lod_bias`, log2 texels.
    pub lod_bias: f64,
}

impl TlmImagery {
    /// `dataset`'s imagery as the TLM sees it, with the imagery settings' bias; `None` without.
    pub fn of(dataset: &Dataset, settings: &ImagerySettings) -> Option<Self> {
        dataset.manifest.imagery.as_ref().map(|i| Self {
            texel_m: i.texel_m,
            levels: i.pyramid.levels,
            lod_bias: settings.lod_bias,
        })
    }
}

/// What one frame's TLM is computed from.
pub struct TlmInputs<'a> {
    pub settings: &'a TlmSettings,
    pub layout: &'a TlmLayout,
    pub camera: &'a Camera,
    /// Camera position in grid space (CRS position − `Manifest::origin_m`), metres.
    pub camera_grid_m: DVec3,
    /// The depth target's size, pixels.
    pub viewport_px: [u32; 2],
    /// The terrain's LODs this frame (ranges, height pyramid and spacing).
    pub lods: &'a Lods,
    pub imagery: Option<TlmImagery>,
    pub hiz_mips: u32,
}

/// One frame's TLM inputs as the GPU (and the twin) read them.
#[derive(Debug, Clone)]
pub struct TlmFrame {
    pub uniforms: TlmUniforms,
    pub spans: Vec<TlmSpan>,
}

impl TlmFrame {
    pub fn new(inputs: &TlmInputs) -> Result<Self, TlmError> {
        let (camera, layout, lods, s) = (inputs.camera, inputs.layout, inputs.lods, inputs.settings);
        let [width, height] = inputs.viewport_px;
        let clip: DMat4 = camera.clip_from_view(width, height)? * camera.view_from_world();
        let levels = lods.pyramid.levels;
        if levels > MAX_LEVELS || lods.range_m.len() > MAX_LEVELS as usize {
            return Err(TlmError::TooManyLevels(levels));
        }
        // Gribb & Hartmann, as `camera::Frustum` (no far plane: it is at infinity).
        let m = clip.transpose();
        let (x, y, z, w) = (m.x_axis, m.y_axis, m.z_axis, m.w_axis);
        let planes = [w + x, w - x, w + y, w - y, w - z]
            .map(|p| (p / p.truncate().length().max(1e-300)).as_vec4().to_array());
        let mut u = TlmUniforms {
            clip_from_view_world: clip.as_mat4().to_cols_array_2d(),
            frustum_planes: planes,
            camera_z_m: inputs.camera_grid_m.z as f32,
            near_m: camera.near_m as f32,
            occlusion_tolerance_m: s.occlusion_tolerance_m as f32,
            imagery_scale_sq: 0.0,
            radial_lod_sq_m2: [0, 1, 2, 3]
                .map(|k| s.radial_lod_m.get(k).map_or(f32::INFINITY, |r| (r * r) as f32)),
            screen_px: [width, height],
            ndc_per_px: [(2.0 / f64::from(width)) as f32, (2.0 / f64::from(height)) as f32],
            hiz_mips: inputs.hiz_mips,
            imagery_levels: 0,
            height_lod_count: lods.range_m.len() as u32,
            rings: layout.rings,
            cells: layout.cells,
            patterns: s.patterns.max(1),
            seed: s.seed,
            no_fuse: 0,
            height_lod_range_m: [[0.0; 4]; MAX_LEVELS as usize / 4],
            height_levels: [[0; 4]; MAX_LEVELS as usize],
            rings_info: [TlmRing::default(); TLM_MAX_RINGS as usize],
        };
        if let Some(imagery) = inputs.imagery {
            let scale = camera.metres_per_pixel(1.0, height) * imagery.lod_bias.exp2() / imagery.texel_m;
            u.imagery_scale_sq = (scale * scale) as f32;
            u.imagery_levels = imagery.levels;
        }
        for (m, range) in lods.range_m.iter().enumerate() {
            u.height_lod_range_m[m / 4][m % 4] = *range as f32;
        }
        for level in 0..levels {
            let [nx, ny] = lods.pyramid.tiles_at(level);
            let first = lods.pyramid.tile_index(TileId::new(level, 0, 0)).unwrap_or_default() as u32;
            u.height_levels[level as usize] = [first, nx, ny, 0];
        }
        for ring in 0..layout.rings {
            let origin = layout.origin_cell[ring as usize];
            u.rings_info[ring as usize] = TlmRing {
                // Beyond i32 the cells are far outside any dataset (culled); only ring 0 hashes it.
                origin_cell: origin.map(|g| g.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32),
                height_level: height_level(&lods.pyramid, lods.spacing_m, layout.ring_cell_m(ring)),
                _pad: 0,
            };
        }
        let spans = layout.spans(&lods.pyramid, lods.spacing_m, inputs.camera_grid_m);
        Ok(Self { uniforms: u, spans })
    }

    pub fn cell_count(&self) -> usize {
        (self.uniforms.rings * self.uniforms.cells * self.uniforms.cells) as usize
    }

    /// Bytes of the TLM buffer this frame fills (what the readback copies).
    pub fn output_bytes(&self) -> u64 {
        (self.cell_count() * size_of::<TlmCell>()) as u64
    }
}

/// The pass's bind group over one dataset's height ranges and one depth pyramid.
pub struct TlmBindings {
    bind_group: wgpu::BindGroup,
    _height_ranges: wgpu::Buffer,
}

pub struct TileLoadMapPass {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    spans: wgpu::Buffer,
    output: wgpu::Buffer,
    cells: u32,
    max_rings: u32,
}

impl TileLoadMapPass {
    pub fn new(device: &wgpu::Device, settings: &Settings) -> Self {
        let (cells, max_rings) = (settings.tlm.cells, settings.tlm.max_rings.clamp(1, TLM_MAX_RINGS));
        let module = shaders::module(device, "tile_load_map");
        let buffer = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        };
        let read_only = wgpu::BufferBindingType::Storage { read_only: true };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("tile load map"),
            entries: &[
                // The per-frame constants are a storage buffer: see the note in the shader.
                buffer(0, read_only),
                buffer(1, read_only),
                buffer(2, read_only),
                wgpu::BindGroupLayoutEntry {
                    binding: 3,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: false },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                buffer(4, wgpu::BufferBindingType::Storage { read_only: false }),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("tile load map"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("tile load map"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("main"),
            compilation_options: Default::default(),
            cache: None,
        });
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size,
                usage,
                mapped_at_creation: false,
            })
        };
        let copy_dst = wgpu::BufferUsages::COPY_DST;
        let uniforms =
            buffer("tlm uniforms", size_of::<TlmUniforms>() as u64, wgpu::BufferUsages::STORAGE | copy_dst);
        let spans_bytes = u64::from(max_rings * 2 * cells) * size_of::<TlmSpan>() as u64;
        let spans = buffer("tlm spans", spans_bytes, wgpu::BufferUsages::STORAGE | copy_dst);
        let output_bytes = u64::from(max_rings * cells * cells) * size_of::<TlmCell>() as u64;
        let output =
            buffer("tlm cells", output_bytes, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
        Self { pipeline, layout, uniforms, spans, output, cells, max_rings }
    }

    /// The bind group over a dataset's height ranges (`height_tile_ranges`) and the depth
    /// pyramid; both are fixed for a renderer's life, so is this.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        height_ranges_m: &[[f32; 2]],
        hiz: &DepthPyramid,
    ) -> TlmBindings {
        let ranges = if height_ranges_m.is_empty() { &[[0.0f32; 2]][..] } else { height_ranges_m };
        let height_ranges = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("tlm height ranges"),
            contents: bytemuck::cast_slice(ranges),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let entry = |binding, resource| wgpu::BindGroupEntry { binding, resource };
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("tile load map"),
            layout: &self.layout,
            entries: &[
                entry(0, self.uniforms.as_entire_binding()),
                entry(1, self.spans.as_entire_binding()),
                entry(2, height_ranges.as_entire_binding()),
                entry(3, wgpu::BindingResource::TextureView(hiz.view())),
                entry(4, self.output.as_entire_binding()),
            ],
        });
        TlmBindings { bind_group, _height_ranges: height_ranges }
    }

    /// Builds the frame's uniforms and spans and uploads them; returns them (the twin reads the same).
    pub fn prepare(&self, queue: &wgpu::Queue, inputs: &TlmInputs) -> Result<TlmFrame, TlmError> {
        let layout = inputs.layout;
        if layout.cells != self.cells || layout.rings > self.max_rings {
            return Err(TlmError::LayoutMismatch {
                rings: layout.rings,
                cells: layout.cells,
                max_rings: self.max_rings,
                pass_cells: self.cells,
            });
        }
        let frame = TlmFrame::new(inputs)?;
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&frame.uniforms));
        queue.write_buffer(&self.spans, 0, bytemuck::cast_slice(&frame.spans));
        Ok(frame)
    }

    /// Records the pass: one invocation per cell of the frame's rings.
    pub fn encode(&self, encoder: &mut wgpu::CommandEncoder, bindings: &TlmBindings, frame: &TlmFrame) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("tile load map"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bindings.bind_group, &[]);
        let groups = self.cells.div_ceil(TLM_WORKGROUP);
        pass.dispatch_workgroups(groups, groups, frame.uniforms.rings);
    }

    /// The TLM buffer (`max_rings · cells²` cells; a frame fills `frame.output_bytes()`).
    pub fn output(&self) -> &wgpu::Buffer {
        &self.output
    }

    /// Bytes of the whole output buffer: the capacity a readback ring needs.
    pub fn capacity_bytes(&self) -> u64 {
        self.output.size()
    }

    /// Reads the frame's cells back, waiting for the GPU: for tests and tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu, frame: &TlmFrame) -> Result<Vec<TlmCell>, GpuError> {
        Ok(bytemuck::pod_collect_to_vec(&super::read_buffer(gpu, &self.output, frame.output_bytes())?))
    }
}
