//! How it works: the terrain pass (pass 0) draws the CDLOD nodes chosen by `select` as instances
//! of one grid mesh, displaced in the vertex shader by the height tiles of the height cache
//! (`shaders/shared/terrain_mesh.wgsl`), into a reversed-Z Depth32Float target only: the depth
//! the Tile Load Map culls against before anything is shaded. The ground pass
//! (`passes::ground`) then draws the same instances again, at depth-equal, to shade them; this
//! module owns what both share: the bind group, the node instances and the mesh draw.
//!
//! The grid's index buffer is laid out quadrant by quadrant, so a node of which the parent draws
//! only some quadrants (CDLOD's partial nodes) costs one instanced draw per quadrant: instances
//! are grouped by quadrant and each group is drawn with that quadrant's index range.

pub mod select;

use std::ops::Range;

use glam::DVec3;
use wgpu::util::DeviceExt;

use crate::config::Settings;
use crate::dataset::{Dataset, TileId};
use crate::gpu::gpu_types::{TerrainNode, TerrainUniforms};
use crate::shaders;
use crate::shaders::MAX_LEVELS;
use crate::streaming::TileCache;
use select::{Lods, NodeId, Selected};

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

/// Everything a pass needs to draw this frame's terrain mesh.
#[derive(Clone, Copy)]
pub struct MeshDraw<'a> {
    pub terrain: &'a TerrainPass,
    pub bind_group: &'a wgpu::BindGroup,
    pub nodes: &'a PreparedNodes,
}

impl MeshDraw<'_> {
    /// Draws the node instances with the pipeline already set on `pass`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.terrain.draw_mesh(pass, self.bind_group, self.nodes);
    }
}

/// Instance ranges of each quadrant's draw, as uploaded.
#[derive(Debug, Clone)]
pub struct PreparedNodes {
    ranges: [Range<u32>; 4],
}

impl TerrainPass {
    pub fn new(device: &wgpu::Device, settings: &Settings) -> Self {
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
            fragment: None,
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
        Self { pipeline, layout, uniforms, nodes, indices, quadrant_indices }
    }

    /// The bind group over the caches; the caches are fixed for a renderer's life, so is this.
    /// The bind group both terrain passes use: uniforms, nodes, the height cache (mesh), and the
    /// imagery cache with its page table and sampler (ground shading).
    pub fn bind_group(
        &self,
        device: &wgpu::Device,
        heights: &TileCache,
        imagery: &TileCache,
        imagery_sampler: &wgpu::Sampler,
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
                wgpu::BindGroupEntry {
                    binding: 4,
                    resource: wgpu::BindingResource::Sampler(imagery_sampler),
                },
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

    /// The layout of `bind_group`, for the passes that draw this mesh.
    pub fn bind_group_layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }

    /// Pass 0: the mesh into a cleared depth target, nothing else.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        depth: &wgpu::TextureView,
        nodes: &PreparedNodes,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("terrain"),
            color_attachments: &[],
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
        self.draw_mesh(&mut pass, bind_group, nodes);
    }

    /// Draws this frame's node instances with the pipeline already set on `pass`.
    pub fn draw_mesh(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        bind_group: &wgpu::BindGroup,
        nodes: &PreparedNodes,
    ) {
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (indices, instances) in self.quadrant_indices.iter().zip(&nodes.ranges) {
            if !instances.is_empty() {
                pass.draw_indexed(indices.clone(), 0, instances.clone());
            }
        }
    }
}

/// The terrain passes' uniforms for a camera at `camera_grid_m` (grid space) with `clip` the
/// clip-from-camera-relative-world matrix; `sky_linear` is also the haze colour.
pub fn terrain_uniforms(
    dataset: &Dataset,
    settings: &Settings,
    camera_grid_m: DVec3,
    clip: glam::Mat4,
    sky_linear: [f64; 3],
) -> TerrainUniforms {
    let r = &settings.render;
    let manifest = &dataset.manifest;
    let (azimuth, elevation) = (r.sun_azimuth_deg.to_radians(), r.sun_elevation_deg.to_radians());
    let sun = DVec3::new(azimuth.sin() * elevation.cos(), azimuth.cos() * elevation.cos(), elevation.sin());
    let half_spacing = 0.5 * manifest.height.spacing_m;
    let mut uniforms = TerrainUniforms {
        clip_from_view_world: clip.to_cols_array_2d(),
        sun_dir: sun.as_vec3().extend(0.0).to_array(),
        haze: [
            sky_linear[0] as f32,
            sky_linear[1] as f32,
            sky_linear[2] as f32,
            r.haze_half_distance_m as f32,
        ],
        camera_grid_m: camera_grid_m.as_vec3().extend(0.0).to_array(),
        height_range_m: [manifest.height.min_m, manifest.height.max_m],
        node_cells: settings.terrain.node_cells,
        has_imagery: u32::from(dataset.imagery.is_some()),
        imagery_frame: [0.0; 4],
        imagery_levels: [[0; 4]; MAX_LEVELS as usize],
        imagery_level_count: 1,
        _pad: [0; 3],
    };
    if let (Some(layer), Some(meta)) = (&dataset.imagery, &manifest.imagery) {
        let p = &layer.pyramid;
        uniforms.imagery_frame = [
            -half_spacing as f32,
            -half_spacing as f32,
            meta.texel_m as f32,
            settings.imagery.lod_bias as f32,
        ];
        for level in 0..p.levels {
            let [nx, ny] = p.tiles_at(level);
            let first = p.tile_index(TileId::new(level, 0, 0)).unwrap_or_default() as u32;
            uniforms.imagery_levels[level as usize] = [first, nx, ny, 0];
        }
        uniforms.imagery_level_count = p.levels;
    }
    uniforms
}

/// The instances drawing `selected` from a camera at `camera_grid_m` (grid space). A node reads its
/// own height tile, or while that streams in, its finest resident ancestor; a node with neither
/// (only before the pinned levels load) is dropped and counted. `bounds` gives node height ranges
/// (the skirt depth). Nodes on the dataset's boundary hang their skirts down to `floor_m`, the
/// dataset's lowest ground (the shader stops every skirt a cell below it): seen from outside, from
/// below the edge's ground, the terrain is then a solid block, not a shell showing its underside.
pub fn node_batches(
    lods: &Lods,
    selected: &[Selected],
    camera_grid_m: DVec3,
    heights: &TileCache,
    floor_m: f32,
    bounds: &mut dyn FnMut(NodeId) -> [f32; 2],
) -> (NodeBatches, usize) {
    let mut batches = NodeBatches::default();
    let mut dropped = 0;
    for s in selected {
        let Some((source, slot)) = heights.resident_ancestor(lods.tile_of(s.node)) else {
            dropped += 1;
            continue;
        };
        let size = lods.node_m(s.node.lod);
        let cell_m = size / f64::from(lods.cells);
        let [low_m, high_m] = bounds(s.node);
        let (steps, inside) = (lods.steps(s.node.lod), lods.cells_inside(s.node));
        let start = [s.node.x, s.node.y].map(|n| n * lods.cells);
        let boundary = (0..2).any(|a| start[a] == 0 || start[a] + inside[a] >= steps[a]);
        let low_m = if boundary { low_m.min(floor_m) } else { low_m };
        let lod = s.node.lod as usize;
        let node = TerrainNode {
            // Subtracted in f64: the GPU only sees offsets from the camera.
            origin_rel_m: [
                (f64::from(s.node.x) * size - camera_grid_m.x) as f32,
                (f64::from(s.node.y) * size - camera_grid_m.y) as f32,
            ],
            cell_m: cell_m as f32,
            height_slot: slot,
            sample_offset: lods.sample_offset_in(s.node, source),
            morph_start_m: lods.morph_start_m[lod].min(f64::from(f32::MAX)) as f32,
            morph_end_m: lods.range_m[lod].min(f64::from(f32::MAX)) as f32,
            cells_inside: lods.cells_inside(s.node).map(|c| c as f32),
            sample_step: 1.0 / (1u32 << (source.level - s.node.lod)) as f32,
            // Deep enough to close any seam against a neighbour reading another level.
            skirt_m: (f64::from(high_m - low_m) + cell_m) as f32,
        };
        for (q, quadrant) in batches.by_quadrant.iter_mut().enumerate() {
            if s.quadrants & (1 << q) != 0 {
                quadrant.push(node);
            }
        }
    }
    (batches, dropped)
}

/// Triangles of a `cells`² grid ringed by skirts: `(cells + 3)²` vertices, the outer ring being
/// the skirts' lower edge. Grouped quadrant by quadrant (south-west, south-east, north-west,
/// north-east; skirts go with the quadrant they border), with each quadrant's index range. The
/// grid is counter-clockwise seen from above with alternating diagonals (no directional bias);
/// skirts are walls seen from either side, so they carry both windings.
pub fn grid_indices(cells: u32) -> (Vec<u32>, [Range<u32>; 4]) {
    let row = cells + 3;
    let half = cells / 2;
    // Ring cell 0 and inner cells 1..=half border the west (or south) half.
    let side = |c: u32| usize::from(c > half);
    let mut quadrants: [Vec<u32>; 4] = Default::default();
    for cj in 0..cells + 2 {
        for ci in 0..cells + 2 {
            let (sw, se, nw, ne) =
                (cj * row + ci, cj * row + ci + 1, (cj + 1) * row + ci, (cj + 1) * row + ci + 1);
            let t = if (ci + cj) % 2 == 0 { [sw, se, ne, sw, ne, nw] } else { [sw, se, nw, se, ne, nw] };
            let quadrant = &mut quadrants[side(cj) * 2 + side(ci)];
            quadrant.extend_from_slice(&t);
            let inner = (1..=cells).contains(&ci) && (1..=cells).contains(&cj);
            if !inner {
                quadrant.extend_from_slice(&[t[0], t[2], t[1], t[3], t[5], t[4]]);
            }
        }
    }
    let mut indices = Vec::with_capacity(quadrants.iter().map(Vec::len).sum());
    let ranges = quadrants.map(|q| {
        let start = indices.len() as u32;
        indices.extend_from_slice(&q);
        start..indices.len() as u32
    });
    (indices, ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_and_skirts_cover_every_cell_once_by_quadrant() {
        let cells = 8;
        let row = cells + 3;
        let (indices, ranges) = grid_indices(cells);
        let ring_cells = (cells + 2) * (cells + 2) - cells * cells;
        assert_eq!(indices.len() as u32, (cells * cells + 2 * ring_cells) * 6);
        assert_eq!(ranges.iter().map(|r| r.len()).sum::<usize>(), indices.len());
        assert!(indices.iter().all(|&i| i < row * row));
        // Every inner triangle is counter-clockwise from above (+z), and sits in its quadrant.
        let inner = |i: u32| (1..=cells + 1).contains(&(i % row)) && (1..=cells + 1).contains(&(i / row));
        for (q, range) in ranges.iter().enumerate() {
            for t in indices[range.start as usize..range.end as usize].chunks(3) {
                if !t.iter().all(|&i| inner(i)) {
                    continue;
                }
                let p: Vec<(i32, i32)> = t.iter().map(|&i| ((i % row) as i32, (i / row) as i32)).collect();
                let area = (p[1].0 - p[0].0) * (p[2].1 - p[0].1) - (p[2].0 - p[0].0) * (p[1].1 - p[0].1);
                assert!(area > 0, "{t:?}");
                let centre =
                    ((p[0].0 + p[1].0 + p[2].0) as f32 / 3.0, (p[0].1 + p[1].1 + p[2].1) as f32 / 3.0);
                let mid = 1.0 + (cells / 2) as f32;
                assert_eq!(q, usize::from(centre.1 > mid) * 2 + usize::from(centre.0 > mid), "{t:?}");
            }
        }
    }
}
