//! How it works: the terrain pass draws the CDLOD nodes chosen by `select` as instances of one
//! grid mesh, displaced in the vertex shader by the height tiles of the height cache and shaded
//! with imagery through the imagery cache's page table (`shaders/terrain.wgsl`). Its depth is a
//! reversed-Z Depth32Float target that later passes read.
//!
//! The grid's index buffer is laid out quadrant by quadrant, so a node of which the parent draws
//! only some quadrants (CDLOD's partial nodes) costs one instanced draw per quadrant: instances
//! are grouped by quadrant and each group is drawn with that quadrant's index range.

pub mod select;

use std::ops::Range;

use wgpu::util::DeviceExt;

use crate::config::Settings;
use crate::gpu::gpu_types::{TerrainNode, TerrainUniforms};
use crate::shaders;
use crate::streaming::TileCache;

pub const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
/// Node instances one frame can draw.
pub const MAX_NODES: u32 = 16384;

pub struct TerrainPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    nodes: wgpu::Buffer,
    indices: wgpu::Buffer,
    quadrant_indices: [Range<u32>; 4],
    sampler: wgpu::Sampler,
}

/// Node instances of one frame, grouped by quadrant.
#[derive(Default)]
pub struct NodeBatches {
    pub by_quadrant: [Vec<TerrainNode>; 4],
}

impl NodeBatches {
    pub fn len(&self) -> usize {
        self.by_quadrant.iter().map(Vec::len).sum()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Instance ranges of each quadrant's draw, as uploaded.
pub struct PreparedNodes {
    ranges: [Range<u32>; 4],
}

impl TerrainPass {
    /// `software`: the adapter is a CPU rasteriser (decides automatic anisotropy).
    pub fn new(device: &wgpu::Device, settings: &Settings, software: bool) -> Self {
        let module = shaders::module(device, "terrain");
        let entry =
            |binding, ty, visibility| wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None };
        let both = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let array_of = |sample_type| wgpu::BindingType::Texture {
            sample_type,
            view_dimension: wgpu::TextureViewDimension::D2Array,
            multisampled: false,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("terrain"),
            entries: &[
                entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    both,
                ),
                entry(1, storage, wgpu::ShaderStages::VERTEX),
                entry(
                    2,
                    array_of(wgpu::TextureSampleType::Float { filterable: false }),
                    wgpu::ShaderStages::VERTEX,
                ),
                entry(
                    3,
                    array_of(wgpu::TextureSampleType::Float { filterable: true }),
                    wgpu::ShaderStages::FRAGMENT,
                ),
                entry(
                    4,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    wgpu::ShaderStages::FRAGMENT,
                ),
                entry(5, storage, wgpu::ShaderStages::FRAGMENT),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("terrain"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("terrain"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(COLOUR_FORMAT.into())],
            }),
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
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("terrain uniforms"),
            size: size_of::<TerrainUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let nodes = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("terrain nodes"),
            size: u64::from(MAX_NODES) * size_of::<TerrainNode>() as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (index_data, quadrant_indices) = grid_indices(settings.terrain.node_cells);
        let indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("terrain grid"),
            contents: bytemuck::cast_slice(&index_data),
            usage: wgpu::BufferUsages::INDEX,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("imagery"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            anisotropy_clamp: settings.imagery.anisotropy_on(software),
            ..Default::default()
        });
        Self { pipeline, layout, uniforms, nodes, indices, quadrant_indices, sampler }
    }

    /// The bind group over the caches; the caches are fixed for a renderer's life, so is this.
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        heights: &TileCache,
        imagery: &TileCache,
    ) -> wgpu::BindGroup {
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("terrain"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: self.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: self.nodes.as_entire_binding() },
                wgpu::BindGroupEntry {
                    binding: 2,
                    resource: wgpu::BindingResource::TextureView(&heights.view),
                },
                wgpu::BindGroupEntry {
                    binding: 3,
                    resource: wgpu::BindingResource::TextureView(&imagery.view),
                },
                wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(&self.sampler) },
                wgpu::BindGroupEntry { binding: 5, resource: imagery.page_table.as_entire_binding() },
            ],
        })
    }

    /// Uploads the frame's uniforms and node instances (at most `MAX_NODES`; the rest are dropped,
    /// coarse quadrants last, and counted by the caller).
    pub fn prepare(
        &self,
        queue: &wgpu::Queue,
        uniforms: &TerrainUniforms,
        batches: &NodeBatches,
    ) -> PreparedNodes {
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
        let mut all = Vec::with_capacity(batches.len());
        let ranges = batches.by_quadrant.each_ref().map(|nodes| {
            let start = all.len().min(MAX_NODES as usize);
            all.extend_from_slice(&nodes[..nodes.len().min(MAX_NODES as usize - start)]);
            start as u32..all.len() as u32
        });
        if !all.is_empty() {
            queue.write_buffer(&self.nodes, 0, bytemuck::cast_slice(&all));
        }
        PreparedNodes { ranges }
    }

    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        clear_linear: [f64; 3],
        nodes: &PreparedNodes,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("terrain"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color {
                        r: clear_linear[0],
                        g: clear_linear[1],
                        b: clear_linear[2],
                        a: 1.0,
                    }),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                // Reversed-Z: 0 is infinitely far.
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (indices, instances) in self.quadrant_indices.iter().zip(&nodes.ranges) {
            if !instances.is_empty() {
                pass.draw_indexed(indices.clone(), 0, instances.clone());
            }
        }
    }
}

/// Triangles of a `cells`² grid of `(cells + 1)²` vertices, quadrant by quadrant (south-west,
/// south-east, north-west, north-east), counter-clockwise seen from above; with each quadrant's
/// index range. Diagonals alternate so the mesh has no directional bias.
pub fn grid_indices(cells: u32) -> (Vec<u32>, [Range<u32>; 4]) {
    let row = cells + 1;
    let half = cells / 2;
    let mut indices = Vec::with_capacity((cells * cells * 6) as usize);
    let ranges = [(0, 0), (half, 0), (0, half), (half, half)].map(|(x0, y0)| {
        let start = indices.len() as u32;
        for y in y0..y0 + half {
            for x in x0..x0 + half {
                let (sw, se, nw, ne) =
                    (y * row + x, y * row + x + 1, (y + 1) * row + x, (y + 1) * row + x + 1);
                if (x + y) % 2 == 0 {
                    indices.extend_from_slice(&[sw, se, ne, sw, ne, nw]);
                } else {
                    indices.extend_from_slice(&[sw, se, nw, se, ne, nw]);
                }
            }
        }
        start..indices.len() as u32
    });
    (indices, ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_quadrants_cover_every_cell_once() {
        let (indices, ranges) = grid_indices(8);
        assert_eq!(indices.len(), 8 * 8 * 6);
        assert_eq!(ranges.iter().map(|r| r.len()).sum::<usize>(), indices.len());
        assert!(indices.iter().all(|&i| i < 81));
        // Counter-clockwise from above (+z): positive signed area for every triangle.
        for t in indices.chunks(3) {
            let p = t.iter().map(|&i| ((i % 9) as i32, (i / 9) as i32)).collect::<Vec<_>>();
            let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
            assert!(area > 0, "{t:?}");
        }
    }
}
