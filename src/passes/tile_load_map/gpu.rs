//! The Tile Load Map's GPU half: the pipeline and binding table (built once), the bind group over
//! a dataset's height ranges and the depth pyramid, the frame's upload and the recorded dispatch.

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension};

use crate::config::Settings;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::gpu_types::{TlmCell, TlmSpan, TlmUniforms};
use crate::gpu::layout::{TLM_MAX_RINGS, TLM_WORKGROUP};
use crate::gpu::readback::read_values;
use crate::gpu::resources::{buffer, buffer_init, compute_pipeline, pipeline_layout};
use crate::gpu::shaders::{HASH, WgslSource};
use crate::gpu::{Gpu, GpuError};
use crate::passes::depth_pyramid::gpu::DepthPyramid;

use super::TlmError;
use super::frame::{TlmFrame, TlmInputs};

/// The Tile Load Map's shader.
pub const SHADER: WgslSource =
    WgslSource { name: "tile_load_map", parts: &[HASH, include_str!("../../../shaders/tile_load_map.wgsl")] };

/// The pass's bindings. The per-frame constants are a storage buffer, not a uniform one: see the
/// note in the shader.
pub const BINDINGS: BindingTable<5> = BindingTable {
    label: "tile load map",
    bindings: [
        Binding::storage::<TlmUniforms>(0, "u", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<TlmSpan>(1, "spans", Stage::COMPUTE, Access::Read),
        Binding::storage_array::<[f32; 2]>(2, "height_ranges_m", Stage::COMPUTE, Access::Read),
        Binding::texture(
            3,
            "hiz",
            Stage::COMPUTE,
            TextureSampleType::Float { filterable: false },
            TextureViewDimension::D2,
        ),
        Binding::storage_array::<TlmCell>(4, "cells_out", Stage::COMPUTE, Access::ReadWrite),
    ],
};

/// The pass's bind group over one dataset's height ranges and one depth pyramid.
pub struct TlmBindings {
    bind_group: wgpu::BindGroup,
    _height_ranges: wgpu::Buffer,
}

/// Pass 1 on the GPU: its pipeline, binding table and buffers, sized for `tlm.max_rings` rings of
/// `tlm.cells`² cells, built once in `new`; each frame `prepare` uploads the uniforms and spans and
/// `encode` records the dispatch.
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
    /// Builds the pipeline and the uniform, span and output buffers for the largest layout the
    /// `[tlm]` settings allow (built once; a frame's layout may use fewer rings).
    pub fn new(device: &wgpu::Device, settings: &Settings) -> Self {
        let (cells, max_rings) = (settings.tlm.cells, settings.tlm.max_rings.clamp(1, TLM_MAX_RINGS));
        let module = SHADER.module(device);
        let layout = BINDINGS.layout(device);
        let pipeline_layout = pipeline_layout(device, "tile load map", &[&layout]);
        let pipeline = compute_pipeline(device, "tile load map", &pipeline_layout, &module, "main");
        use wgpu::BufferUsages as U;
        let uniforms =
            buffer(device, "tlm uniforms", size_of::<TlmUniforms>() as u64, U::STORAGE | U::COPY_DST);
        let spans_bytes = u64::from(max_rings * 2 * cells) * size_of::<TlmSpan>() as u64;
        let spans = buffer(device, "tlm spans", spans_bytes, U::STORAGE | U::COPY_DST);
        let output_bytes = u64::from(max_rings * cells * cells) * size_of::<TlmCell>() as u64;
        let output = buffer(device, "tlm cells", output_bytes, U::STORAGE | U::COPY_SRC);
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
        // A binding may not be empty: a dataset without ranges still gets one (never read) entry.
        let ranges = if height_ranges_m.is_empty() { &[[0.0f32; 2]][..] } else { height_ranges_m };
        let height_ranges = buffer_init(
            device,
            "tlm height ranges",
            bytemuck::cast_slice(ranges),
            wgpu::BufferUsages::STORAGE,
        );
        let bind_group = BINDINGS.bind_group(
            device,
            &self.layout,
            [
                self.uniforms.as_entire_binding(),
                self.spans.as_entire_binding(),
                height_ranges.as_entire_binding(),
                wgpu::BindingResource::TextureView(hiz.view()),
                self.output.as_entire_binding(),
            ],
        );
        TlmBindings { bind_group, _height_ranges: height_ranges }
    }

    /// Builds the frame's uniforms and spans and uploads them; returns them (the twin reads the same).
    pub fn prepare(&self, queue: &crate::gpu::Queue, inputs: &TlmInputs) -> Result<TlmFrame, TlmError> {
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
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bindings: &TlmBindings,
        frame: &TlmFrame,
        counting: Counting<'_>,
    ) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("tile load map"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &bindings.bind_group, &[]);
        let groups = self.cells.div_ceil(TLM_WORKGROUP);
        counting.begin(&mut pass, Part::Whole);
        counting.dispatch(&mut pass, [groups, groups, frame.uniforms.rings]);
        counting.end(&mut pass);
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
        read_values(gpu, &self.output, frame.cell_count() as u64)
    }
}
