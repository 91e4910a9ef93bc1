//! The terrain pass's GPU half: the pipeline and binding table (built once), the frame's uploads
//! (`prepare`) and the recorded draw (`encode`), and the mesh draw the ground pass repeats.

use std::ops::Range;

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension};

use crate::config::Settings;
use crate::earth::gpu::EARTH;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::gpu_types::{EarthNode, TerrainNode, TerrainUniforms};
use crate::gpu::resources::{buffer, buffer_init, pipeline_layout};
use crate::gpu::shaders::{TERRAIN_MESH, WgslSource};
use crate::passes::DEPTH_FORMAT;
use crate::streaming::TileCache;

use super::frame::{NodeBatches, grid_indices};

/// Node instances one frame can draw.
pub const MAX_NODES: u32 = 16384;

/// The terrain pass's shader (the mesh alone: depth only).
pub const SHADER: WgslSource = WgslSource {
    name: "terrain",
    parts: &[TERRAIN_MESH, EARTH, include_str!("../../../shaders/terrain.wgsl")],
};

/// The bind group both terrain passes use: uniforms, nodes and the height cache (the mesh), then
/// the imagery cache with its sampler and page table (the ground's shading), and the nodes' Earth
/// mappings (the mesh).
pub const BINDINGS: BindingTable<7> = BindingTable {
    label: "terrain",
    bindings: [
        Binding::uniform::<TerrainUniforms>(0, "u", Stage::VERTEX_FRAGMENT),
        // The texcells' silhouettes read the ground under their rays in the fragment stage.
        Binding::storage_array::<TerrainNode>(1, "nodes", Stage::VERTEX_FRAGMENT, Access::Read),
        Binding::texture(
            2,
            "height_tiles",
            Stage::VERTEX_FRAGMENT,
            TextureSampleType::Float { filterable: false },
            TextureViewDimension::D2Array,
        ),
        Binding::texture(
            3,
            "imagery_tiles",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: true },
            TextureViewDimension::D2Array,
        ),
        Binding::sampler(4, "imagery_sampler", Stage::FRAGMENT, wgpu::SamplerBindingType::Filtering),
        Binding::storage_array::<u32>(5, "imagery_page_table", Stage::FRAGMENT, Access::Read),
        // The texcells' silhouettes turn their rays into their node's frame in the fragment stage.
        Binding::storage_array::<EarthNode>(6, "node_earth", Stage::VERTEX_FRAGMENT, Access::Read),
    ],
};

/// Pass 0 on the GPU: depth-only pipeline, binding table, grid index buffer and node buffer built once
/// in `new`; each frame `prepare` uploads uniforms and instances and `encode` records the depth draw.
pub struct TerrainPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    nodes: wgpu::Buffer,
    node_earth: wgpu::Buffer,
    indices: wgpu::Buffer,
    quadrant_indices: [Range<u32>; 4],
}

/// Everything a pass needs to draw this frame's terrain mesh.
#[derive(Clone, Copy)]
pub struct MeshDraw<'a> {
    /// The pass owning the grid's index buffer and its quadrant ranges.
    pub terrain: &'a TerrainPass,
    /// The terrain bind group (`BINDINGS`) over the height and imagery caches.
    pub bind_group: &'a wgpu::BindGroup,
    /// This frame's uploaded instance ranges, quadrant by quadrant.
    pub nodes: &'a PreparedNodes,
}

impl MeshDraw<'_> {
    /// Draws the node instances with the pipeline already set on `pass`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, counting: Counting<'_>) {
        self.terrain.draw_mesh(pass, self.bind_group, self.nodes, counting);
    }
}

/// Instance ranges of each quadrant's draw, as uploaded.
#[derive(Debug, Clone)]
pub struct PreparedNodes {
    ranges: [Range<u32>; 4],
}

impl PreparedNodes {
    /// The node buffer index of quadrant `q`'s `i`-th instance (`NodeBatches::by_quadrant[q][i]`),
    /// or `None` when it did not fit.
    pub fn instance(&self, q: usize, i: usize) -> Option<u32> {
        let range = self.ranges.get(q)?;
        let index = range.start.checked_add(u32::try_from(i).ok()?)?;
        (index < range.end).then_some(index)
    }
}

impl TerrainPass {
    /// Builds the depth-only pipeline, the uniform and node buffers (`MAX_NODES`) and the index
    /// buffer of the `terrain.node_cells`² grid, once for a renderer's life.
    pub fn new(device: &wgpu::Device, settings: &Settings) -> Self {
        let module = SHADER.module(device);
        let layout = BINDINGS.layout(device);
        let pipeline_layout = pipeline_layout(device, "terrain", &[&layout]);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("terrain"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: None,
            // Back faces are culled, here and in the ground pass. Seen from above, a heightfield
            // shows none, and drawing them (measured) closed no hole a consistent rasteriser opens:
            // where the morph shrinks triangles to slivers, one that snaps backwards lies over front
            // faces, and unculled it won the depth test on nc and was shaded from its sliver's
            // derivatives (a stray bright pixel), and this pass took longer (a build not kept,
            // docs/RELIABILITY.md). Lavapipe is not
            // consistent: it culls in floating point but rasterises in fixed point, and drops one
            // sliver its rasteriser finds front-facing, one sky pixel in the 100 frames of
            // `tests/streaming_faults.rs`'s control.
            primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        use wgpu::BufferUsages as U;
        let uniforms =
            buffer(device, "terrain uniforms", size_of::<TerrainUniforms>() as u64, U::UNIFORM | U::COPY_DST);
        let nodes_bytes = u64::from(MAX_NODES) * size_of::<TerrainNode>() as u64;
        let nodes = buffer(device, "terrain nodes", nodes_bytes, U::STORAGE | U::COPY_DST);
        let earth_bytes = u64::from(MAX_NODES) * size_of::<EarthNode>() as u64;
        let node_earth = buffer(device, "terrain nodes' earth", earth_bytes, U::STORAGE | U::COPY_DST);
        let (index_data, quadrant_indices) = grid_indices(settings.terrain.node_cells);
        let indices = buffer_init(device, "terrain grid", bytemuck::cast_slice(&index_data), U::INDEX);
        Self { pipeline, layout, uniforms, nodes, node_earth, indices, quadrant_indices }
    }

    /// The bind group both terrain passes use (`BINDINGS`) over the height and imagery caches;
    /// the caches are fixed for a renderer's life, so is this.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        heights: &TileCache,
        imagery: &TileCache,
        imagery_sampler: &wgpu::Sampler,
    ) -> wgpu::BindGroup {
        use wgpu::BindingResource as R;
        BINDINGS.bind_group(
            device,
            &self.layout,
            [
                self.uniforms.as_entire_binding(),
                self.nodes.as_entire_binding(),
                R::TextureView(&heights.view),
                R::TextureView(&imagery.view),
                R::Sampler(imagery_sampler),
                imagery.page_table.as_entire_binding(),
                self.node_earth.as_entire_binding(),
            ],
        )
    }

    /// Uploads the frame's uniforms and node instances with their Earth mappings (at most
    /// `MAX_NODES`; the rest are dropped, coarse quadrants last, and counted by the caller).
    pub fn prepare(
        &self,
        queue: &crate::gpu::Queue,
        uniforms: &TerrainUniforms,
        batches: &NodeBatches,
    ) -> PreparedNodes {
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
        let (mut all, mut earth) = (Vec::with_capacity(batches.len()), Vec::with_capacity(batches.len()));
        let ranges = std::array::from_fn(|q| {
            let start = all.len().min(MAX_NODES as usize);
            let kept = batches.by_quadrant[q].len().min(MAX_NODES as usize - start);
            all.extend_from_slice(&batches.by_quadrant[q][..kept]);
            earth.extend_from_slice(&batches.earth[q][..kept]);
            start as u32..all.len() as u32
        });
        if !all.is_empty() {
            queue.write_buffer(&self.nodes, 0, bytemuck::cast_slice(&all));
            queue.write_buffer(&self.node_earth, 0, bytemuck::cast_slice(&earth));
        }
        PreparedNodes { ranges }
    }

    /// The layout of `bind_group`, for the passes that draw this mesh.
    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// Pass 0: the mesh into the depth target, cleared unless `keep_depth` (a host's geometry is
    /// in it), nothing else; counted through `counting`.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        (depth, keep_depth): (&wgpu::TextureView, bool),
        nodes: &PreparedNodes,
        counting: Counting<'_>,
    ) {
        // Reversed-Z: 0 is infinitely far. Kept where a host's geometry is in it already.
        let load = if keep_depth { wgpu::LoadOp::Load } else { wgpu::LoadOp::Clear(0.0) };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("terrain"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        counting.begin(&mut pass, Part::Whole);
        self.draw_mesh(&mut pass, bind_group, nodes, counting);
        counting.end(&mut pass);
    }

    /// Draws this frame's node instances with the pipeline already set on `pass`.
    pub fn draw_mesh(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        bind_group: &wgpu::BindGroup,
        nodes: &PreparedNodes,
        counting: Counting<'_>,
    ) {
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (indices, instances) in self.quadrant_indices.iter().zip(&nodes.ranges) {
            if !instances.is_empty() {
                counting.draw_indexed(pass, indices.clone(), 0, instances.clone());
            }
        }
    }
}
