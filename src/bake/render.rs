//! How it works: the offscreen half of baking, on whatever adapter `crate::gpu::Gpu` opens (Mesa
//! lavapipe included). A model's mesh and materials are uploaded once ([`Baker::upload`]); each
//! LOD's atlas is then one render pass into an RGBA8 sRGB texture cleared to transparent, with a
//! depth buffer: per plane, the viewport and scissor are its atlas rectangle and one instanced
//! draw per material (instance = plane, which picks its matrix) draws the triangles the fit gave
//! it. `shaders/bake/billboard.wgsl` samples the base colour, cuts alpha-masked materials out at
//! their cutoff and writes opaque texels, so alpha is coverage. The atlas is read back for the
//! CPU to build its mips.

use std::ops::Range;

use bytemuck::{Pod, Zeroable};
use glam::Mat4;
use thiserror::Error;
use wgpu::util::DeviceExt;

use crate::gpu::{Gpu, GpuError};
use crate::impostor::{AlphaMode, Mesh, MeshVertex, MipChain, TexelRect};

/// Why an atlas could not be rendered.
#[derive(Debug, Error)]
pub enum RenderError {
    /// The atlas is wider than the adapter's largest 2D texture.
    #[error("an atlas of {atlas} texels exceeds the adapter's limit of {limit}")]
    TooLarge {
        /// The atlas's width and height in texels.
        atlas: u32,
        /// The adapter's `max_texture_dimension_2d`, in texels.
        limit: u32,
    },
    /// No plane of the LOD has a triangle to draw on it.
    #[error("no triangle to draw")]
    NothingToDraw,
    /// Copying the rendered atlas back to the CPU failed.
    #[error("reading the atlas back: {0}")]
    Readback(#[source] GpuError),
    /// The GPU reported an error (a validation error, say) while rendering the atlas.
    #[error("baking an atlas: {0}")]
    Gpu(#[source] GpuError),
}

const ATLAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Twin of `BakeMaterial` in `shaders/bake/billboard.wgsl`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
struct BakeMaterial {
    base_color_factor: [f32; 4],
    alpha_cutoff: f32,
    masked: u32,
    pad: [u32; 2],
}

/// One plane to draw: where it lands and what is drawn on it.
pub struct PlaneDraw {
    /// Clip space of the plane's rectangle (x, y in [−1, 1], depth in [0, 1]) from model space.
    pub clip_from_model: Mat4,
    pub rect: TexelRect,
    /// Triangles of the mesh (triangle t is indices 3t..3t+3).
    pub triangles: Vec<u32>,
}

pub struct Baker {
    pipeline: wgpu::RenderPipeline,
    planes_layout: wgpu::BindGroupLayout,
    material_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
}

/// A model's mesh on the GPU.
pub struct UploadedMesh {
    vertices: wgpu::Buffer,
    /// Per material: its bind group.
    materials: Vec<wgpu::BindGroup>,
}

impl Baker {
    pub fn new(gpu: &Gpu) -> Self {
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("bake billboard"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/bake/billboard.wgsl").into()),
        });
        let entry =
            |binding, visibility, ty| wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None };
        let buffer = |ty| wgpu::BindingType::Buffer { ty, has_dynamic_offset: false, min_binding_size: None };
        let planes_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake planes"),
            entries: &[entry(
                0,
                wgpu::ShaderStages::VERTEX,
                buffer(wgpu::BufferBindingType::Storage { read_only: true }),
            )],
        });
        let material_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("bake material"),
            entries: &[
                entry(0, wgpu::ShaderStages::FRAGMENT, buffer(wgpu::BufferBindingType::Uniform)),
                entry(
                    1,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                ),
                entry(
                    2,
                    wgpu::ShaderStages::FRAGMENT,
                    wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                ),
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("bake"),
            bind_group_layouts: &[Some(&planes_layout), Some(&material_layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("bake billboard"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: size_of::<MeshVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
                })],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(ATLAS_FORMAT.into())],
            }),
            // Leaves are two-sided and a plane sees whichever side faces it.
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("bake base colour"),
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        Self { pipeline, planes_layout, material_layout, sampler }
    }

    /// Uploads `mesh`'s vertices and its materials' textures.
    pub fn upload(&self, gpu: &Gpu, mesh: &Mesh) -> UploadedMesh {
        let device = &gpu.device;
        let vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bake vertices"),
            contents: bytemuck::cast_slice(&mesh.vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let white = MipChain { size: [1, 1], levels: vec![vec![255; 4]] };
        let materials = mesh
            .materials
            .iter()
            .map(|m| {
                let texture = upload_texture(gpu, m.texture.as_ref().unwrap_or(&white));
                let uniform = BakeMaterial {
                    base_color_factor: m.base_color_factor,
                    alpha_cutoff: m.alpha_cutoff,
                    masked: u32::from(m.alpha_mode == AlphaMode::Mask),
                    pad: [0; 2],
                };
                let uniform = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                    label: Some("bake material"),
                    contents: bytemuck::bytes_of(&uniform),
                    usage: wgpu::BufferUsages::UNIFORM,
                });
                let view = texture.create_view(&Default::default());
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("bake material"),
                    layout: &self.material_layout,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                        wgpu::BindGroupEntry {
                            binding: 1,
                            resource: wgpu::BindingResource::TextureView(&view),
                        },
                        wgpu::BindGroupEntry {
                            binding: 2,
                            resource: wgpu::BindingResource::Sampler(&self.sampler),
                        },
                    ],
                })
            })
            .collect();
        UploadedMesh { vertices, materials }
    }

    /// Renders `planes` of `mesh` into an `atlas` × `atlas` image: RGBA8 sRGB, top row first.
    pub fn render_atlas(
        &self,
        gpu: &Gpu,
        mesh: &Mesh,
        uploaded: &UploadedMesh,
        planes: &[PlaneDraw],
        atlas: u32,
    ) -> Result<Vec<u8>, RenderError> {
        let device = &gpu.device;
        let limit = device.limits().max_texture_dimension_2d;
        if atlas > limit {
            return Err(RenderError::TooLarge { atlas, limit });
        }
        // Indices grouped by plane, then material: one draw each.
        let mut indices: Vec<u32> = Vec::new();
        let mut draws: Vec<(u32, u32, Range<u32>)> = Vec::new();
        for (p, plane) in planes.iter().enumerate() {
            for material in 0..mesh.materials.len() as u32 {
                let start = indices.len() as u32;
                for &t in &plane.triangles {
                    if mesh.material_of_triangle(t as usize) == Some(material) {
                        indices.extend_from_slice(&mesh.indices[3 * t as usize..3 * t as usize + 3]);
                    }
                }
                if indices.len() as u32 > start {
                    draws.push((p as u32, material, start..indices.len() as u32));
                }
            }
        }
        if indices.is_empty() {
            return Err(RenderError::NothingToDraw);
        }
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bake indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        let matrices: Vec<[f32; 16]> = planes.iter().map(|p| p.clip_from_model.to_cols_array()).collect();
        let matrix_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bake planes"),
            contents: bytemuck::cast_slice(&matrices),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let planes_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake planes"),
            layout: &self.planes_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: matrix_buffer.as_entire_binding() }],
        });
        self.render_into(gpu, [atlas, atlas], |pass| {
            pass.set_bind_group(0, &planes_group, &[]);
            pass.set_vertex_buffer(0, uploaded.vertices.slice(..));
            pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            for (p, material, range) in draws {
                let r = planes[p as usize].rect;
                pass.set_viewport(r.x as f32, r.y as f32, r.width as f32, r.height as f32, 0.0, 1.0);
                pass.set_scissor_rect(r.x, r.y, r.width, r.height);
                pass.set_bind_group(1, &uploaded.materials[material as usize], &[]);
                pass.draw_indexed(range, 0, p..p + 1);
            }
        })
    }
}

/// One mesh drawn many times into one image: per instance, its clip space from model space and
/// the rectangle it lands in (its whole mesh each time).
pub struct Instances<'a> {
    pub mesh: &'a Mesh,
    pub uploaded: &'a UploadedMesh,
    /// Sorted by rectangle, so that each rectangle's instances draw together.
    pub instances: Vec<(Mat4, TexelRect)>,
}

impl Baker {
    /// Renders every batch's instances into one `size` image, RGBA8 sRGB cleared to transparent,
    /// depth-tested across batches (the nearest surface of any mesh wins).
    pub fn render_instances(
        &self,
        gpu: &Gpu,
        batches: &[Instances],
        size: [u32; 2],
    ) -> Result<Vec<u8>, RenderError> {
        let device = &gpu.device;
        let limit = device.limits().max_texture_dimension_2d;
        if size[0].max(size[1]) > limit {
            return Err(RenderError::TooLarge { atlas: size[0].max(size[1]), limit });
        }
        let matrices: Vec<[f32; 16]> =
            batches.iter().flat_map(|b| b.instances.iter().map(|(m, _)| m.to_cols_array())).collect();
        if matrices.is_empty() {
            return Err(RenderError::NothingToDraw);
        }
        let matrix_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bake instances"),
            contents: bytemuck::cast_slice(&matrices),
            usage: wgpu::BufferUsages::STORAGE,
        });
        let planes_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("bake instances"),
            layout: &self.planes_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: matrix_buffer.as_entire_binding() }],
        });
        // Every batch's indices in one buffer; a mesh's are grouped by material already (its
        // submeshes): one draw per material and rectangle.
        let mut indices: Vec<u32> = Vec::new();
        let mut ranges: Vec<Vec<(u32, Range<u32>)>> = Vec::new();
        for b in batches {
            let base = indices.len() as u32;
            indices.extend_from_slice(&b.mesh.indices);
            let submeshes = b.mesh.submeshes.iter().filter(|m| m.index_count > 0);
            ranges.push(
                submeshes
                    .map(|m| (m.material, base + m.first_index..base + m.first_index + m.index_count))
                    .collect(),
            );
        }
        let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("bake indices"),
            contents: bytemuck::cast_slice(&indices),
            usage: wgpu::BufferUsages::INDEX,
        });
        self.render_into(gpu, size, |pass| {
            pass.set_bind_group(0, &planes_group, &[]);
            pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
            let mut first = 0u32;
            for (b, per_material) in batches.iter().zip(&ranges) {
                pass.set_vertex_buffer(0, b.uploaded.vertices.slice(..));
                let mut i = 0;
                while i < b.instances.len() {
                    let rect = b.instances[i].1;
                    let run = b.instances[i..].iter().take_while(|(_, r)| *r == rect).count();
                    let r = rect;
                    pass.set_viewport(r.x as f32, r.y as f32, r.width as f32, r.height as f32, 0.0, 1.0);
                    pass.set_scissor_rect(r.x, r.y, r.width, r.height);
                    let instances = first + i as u32..first + (i + run) as u32;
                    for (material, range) in per_material {
                        pass.set_bind_group(1, &b.uploaded.materials[*material as usize], &[]);
                        pass.draw_indexed(range.clone(), 0, instances.clone());
                    }
                    i += run;
                }
                first += b.instances.len() as u32;
            }
        })
    }

    /// One render pass over a `size` colour target (RGBA8 sRGB, cleared to transparent) and a depth
    /// target, with the bake pipeline set; `record` draws; the colour is read back.
    fn render_into(
        &self,
        gpu: &Gpu,
        size: [u32; 2],
        record: impl FnOnce(&mut wgpu::RenderPass),
    ) -> Result<Vec<u8>, RenderError> {
        let device = &gpu.device;
        let target = |format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some("bake target"),
                size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let colour =
            target(ATLAS_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC);
        let depth = target(DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let (colour_view, depth_view) =
            (colour.create_view(&Default::default()), depth.create_view(&Default::default()));
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("bake"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour_view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            pass.set_pipeline(&self.pipeline);
            record(&mut pass);
        }
        gpu.queue.submit([encoder.finish()]);
        let texels = crate::gpu::readback::read_texture(gpu, &colour, wgpu::TextureAspect::All, 4)
            .map_err(RenderError::Readback)?;
        gpu.check().map_err(RenderError::Gpu)?;
        Ok(texels)
    }
}

/// A texture with every level of `chain` (RGBA8 sRGB).
fn upload_texture(gpu: &Gpu, chain: &MipChain) -> wgpu::Texture {
    let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
        label: Some("bake base colour"),
        size: wgpu::Extent3d { width: chain.size[0], height: chain.size[1], depth_or_array_layers: 1 },
        mip_level_count: chain.mip_count(),
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: ATLAS_FORMAT,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (m, level) in chain.levels.iter().enumerate() {
        let [w, h] = chain.level_size(m as u32);
        gpu.queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: m as u32,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            level,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(h) },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
    }
    texture
}
