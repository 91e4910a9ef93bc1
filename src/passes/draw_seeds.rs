//! How it works: pass 4b, drawing the seeds (DESIGN § "The frame", step 4). Everything a species
//! looks like is uploaded once, at `new`: one vertex and one index buffer hold, species after
//! species, the billboard clouds of its impostor's three LODs (17, 8 and 2 planes for radial LODs
//! 0, 1 and 2), and one RGBA8 sRGB texture array holds every LOD's atlas, with its mips, as one
//! layer (atlases of another size are resampled to the largest, nearest texel per mip). The
//! draw group of (species, LOD) gets its index range as a compaction template (`templates`, for
//! `CompactPass::set_templates`) and its layer, alpha cutoff and model scale in a small table.
//! Species without an impostor keep a zero-index template: their seeds are selected but cost
//! nothing to draw.
//!
//! Each frame `encode` records one `draw_indexed_indirect` per group from compaction's argument
//! buffer (a group of 0 instances costs nothing). `shaders/draw_seeds.wgsl` reads an instance's
//! record through compaction's `order`, scales the model to the seed's height, turns it by the
//! seed's jitter, places it camera-relative and projects it with the terrain's matrix; it draws
//! into the colour target with the terrain depth (reversed-Z, `GreaterEqual`, depth written).
//! Fragments are alpha-tested and a seed near the outer edge of its LOD band (its radial reach,
//! scaled like pass 3's) dithers out (Bayer 4×4), so seeds thin out at the visibility radius and
//! at LOD changes instead of popping. The next LOD is not drawn fading in (pass 3 gives each seed
//! one LOD), so a LOD boundary shows as a band `fade_fraction` wide where seeds are thinner.

use std::path::{Path, PathBuf};

use thiserror::Error;
use wgpu::util::DeviceExt;

use crate::classes::Species;
use crate::config::Settings;
use crate::gpu::gpu_types::{DrawSeedsGroup, DrawSeedsUniforms, SeedDrawArgs};
use crate::impostor::{Impostor, ImpostorError, MANIFEST_FILE, PlaneVertex, mip_size};
use crate::seeds::{SEED_GROUPS, SEED_LODS};
use crate::shaders;
use crate::terrain::{COLOUR_FORMAT, DEPTH_FORMAT};
use bytemuck::Zeroable;

/// The outer part of each LOD band over which seeds dither out, as a fraction of its reach.
pub const FADE_FRACTION: f32 = 0.1;
/// How much of the ground colour under a seed it takes on.
pub const GROUND_BLEND: f32 = 0.2;

#[derive(Debug, Error)]
pub enum DrawSeedsError {
    #[error("seeds.impostors = {0:?} is not a folder (bake one with `terramp-data bake`)")]
    NoFolder(PathBuf),
    #[error(transparent)]
    Impostor(#[from] ImpostorError),
    #[error("impostor {model:?} has {lods} LODs; the seed draw needs {SEED_LODS}")]
    TooFewLods { model: String, lods: usize },
    #[error("this GPU cannot start indirect draws at an instance (INDIRECT_FIRST_INSTANCE): no seeds")]
    NoFirstInstance,
    #[error("{layers} atlas layers; this GPU holds at most {max} in a texture array")]
    TooManyLayers { layers: u32, max: u32 },
}

/// Each species' impostor (index = species index of the class table), `None` where the folder has
/// no model of that name.
pub fn load_impostors(dir: &Path, species: &[Species]) -> Result<Vec<Option<Impostor>>, DrawSeedsError> {
    if !dir.is_dir() {
        return Err(DrawSeedsError::NoFolder(dir.to_path_buf()));
    }
    let mut loaded: Vec<Option<Impostor>> = Vec::with_capacity(species.len());
    for s in species {
        let known = loaded.iter().flatten().find(|i| i.name == s.model).cloned();
        let impostor = match known {
            Some(impostor) => Some(impostor),
            None if dir.join(&s.model).join(MANIFEST_FILE).is_file() => {
                Some(crate::impostor::load(dir, &s.model)?)
            }
            None => None,
        };
        loaded.push(impostor);
    }
    Ok(loaded)
}

/// What the draw reads from the earlier passes: pass 3's records and compaction's order.
pub struct DrawSeedsInputs<'a> {
    pub records: &'a wgpu::Buffer,
    pub order: &'a wgpu::Buffer,
}

pub struct DrawSeedsPass {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    groups: wgpu::Buffer,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    atlas_view: wgpu::TextureView,
    sampler: wgpu::Sampler,
    templates: Vec<SeedDrawArgs>,
    species_drawn: usize,
    species_missing: usize,
}

/// Everything uploaded for the species: geometry, atlas layers and the group table.
struct Species3 {
    vertices: Vec<PlaneVertex>,
    indices: Vec<u32>,
    templates: Vec<SeedDrawArgs>,
    groups: Vec<DrawSeedsGroup>,
    /// Each layer's mips at the common size, in layer order.
    layers: Vec<Vec<Vec<u8>>>,
    size: u32,
    mips: u32,
}

impl DrawSeedsPass {
    /// Uploads the species' impostors (`None`: not drawn) and builds the pipeline.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        impostors: &[Option<Impostor>],
    ) -> Result<Self, DrawSeedsError> {
        if !device.features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE) {
            return Err(DrawSeedsError::NoFirstInstance);
        }
        let built = gather(impostors)?;
        let max = device.limits().max_texture_array_layers;
        let layers = built.layers.len().max(1) as u32;
        if layers > max {
            return Err(DrawSeedsError::TooManyLayers { layers, max });
        }
        let atlases = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("seed atlases"),
            size: wgpu::Extent3d { width: built.size, height: built.size, depth_or_array_layers: layers },
            mip_level_count: built.mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (layer, mips) in built.layers.iter().enumerate() {
            for (mip, texels) in mips.iter().enumerate() {
                let [w, h] = mip_size([built.size; 2], mip as u32);
                queue.write_texture(
                    wgpu::TexelCopyTextureInfo {
                        texture: &atlases,
                        mip_level: mip as u32,
                        origin: wgpu::Origin3d { x: 0, y: 0, z: layer as u32 },
                        aspect: wgpu::TextureAspect::All,
                    },
                    texels,
                    wgpu::TexelCopyBufferLayout {
                        offset: 0,
                        bytes_per_row: Some(4 * w),
                        rows_per_image: Some(h),
                    },
                    wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
                );
            }
        }
        let atlas_view = atlases.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage,
            })
        };
        // Empty buffers cannot be bound: a species-less pass keeps one zero element of each.
        let vertices: &[PlaneVertex] =
            if built.vertices.is_empty() { &[PlaneVertex::zeroed()] } else { &built.vertices };
        let indices: &[u32] = if built.indices.is_empty() { &[0] } else { &built.indices };
        let vertices = buffer("seed vertices", bytemuck::cast_slice(vertices), wgpu::BufferUsages::VERTEX);
        let indices = buffer("seed indices", bytemuck::cast_slice(indices), wgpu::BufferUsages::INDEX);
        let groups = buffer("seed groups", bytemuck::cast_slice(&built.groups), wgpu::BufferUsages::STORAGE);
        let uniforms = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("draw_seeds uniforms"),
            size: size_of::<DrawSeedsUniforms>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("seed atlases"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        let (pipeline, layout) = pipeline(device);
        let species_drawn = impostors.iter().filter(|i| i.is_some()).count();
        Ok(Self {
            pipeline,
            layout,
            uniforms,
            groups,
            vertices,
            indices,
            atlas_view,
            sampler,
            templates: built.templates,
            species_drawn,
            species_missing: impostors.len() - species_drawn,
        })
    }

    /// The per-group mesh ranges, for `CompactPass::set_templates` (`SEED_GROUPS` of them).
    pub fn templates(&self) -> &[SeedDrawArgs] {
        &self.templates
    }

    /// Species with an impostor, and species left undrawn for want of one.
    pub fn species_counts(&self) -> (usize, usize) {
        (self.species_drawn, self.species_missing)
    }

    pub fn bind_group(&self, device: &wgpu::Device, inputs: &DrawSeedsInputs) -> wgpu::BindGroup {
        let entries = [
            wgpu::BindGroupEntry { binding: 0, resource: self.uniforms.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: inputs.records.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: inputs.order.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: self.groups.as_entire_binding() },
            wgpu::BindGroupEntry {
                binding: 4,
                resource: wgpu::BindingResource::TextureView(&self.atlas_view),
            },
            wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::Sampler(&self.sampler) },
        ];
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("draw_seeds"),
            layout: &self.layout,
            entries: &entries,
        })
    }

    /// Writes the frame's constants.
    pub fn prepare(&self, queue: &wgpu::Queue, uniforms: &DrawSeedsUniforms) {
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
    }

    /// Records one indirect draw per group from `draw_args` (compaction's) into the targets.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: &wgpu::BindGroup,
        draw_args: &wgpu::Buffer,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        if self.species_drawn == 0 {
            return;
        }
        let keep = wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store };
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("draw_seeds"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: colour,
                depth_slice: None,
                resolve_target: None,
                ops: keep,
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: depth,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        let stride = size_of::<SeedDrawArgs>() as u64;
        for (group, template) in self.templates.iter().enumerate() {
            if template.index_count > 0 {
                pass.draw_indexed_indirect(draw_args, group as u64 * stride);
            }
        }
    }
}

/// The frame's constants from the settings and the terrain's matrix, sun and haze.
pub fn draw_uniforms(
    settings: &Settings,
    terrain: &crate::gpu::gpu_types::TerrainUniforms,
) -> DrawSeedsUniforms {
    let radial = &settings.tlm.radial_lod_m;
    DrawSeedsUniforms {
        clip_from_view_world: terrain.clip_from_view_world,
        sun_dir: terrain.sun_dir,
        haze: terrain.haze,
        radial_lod_m: [0, 1, 2, 3].map(|k| radial.get(k).map_or(f32::INFINITY, |r| *r as f32)),
        inv_reference_height_m: (1.0 / settings.seeds.reference_height_m) as f32,
        sink_fraction: settings.seeds.sink_fraction as f32,
        fade_fraction: FADE_FRACTION,
        ground_blend: GROUND_BLEND,
    }
}

/// Lays the species' billboard clouds and atlases out for upload.
fn gather(impostors: &[Option<Impostor>]) -> Result<Species3, DrawSeedsError> {
    let lods = SEED_LODS as usize;
    let present = || impostors.iter().flatten();
    for impostor in present() {
        if impostor.lods.len() < lods {
            return Err(DrawSeedsError::TooFewLods {
                model: impostor.name.clone(),
                lods: impostor.lods.len(),
            });
        }
    }
    let atlases = || present().flat_map(|i| i.lods[..lods].iter().map(|l| &l.atlas));
    let size = atlases().map(|a| a.size[0].max(a.size[1])).max().unwrap_or(1).max(1);
    let mips = atlases().map(|a| a.mip_count()).min().unwrap_or(1).clamp(1, size.ilog2() + 1);
    let mut out = Species3 {
        vertices: Vec::new(),
        indices: Vec::new(),
        templates: vec![SeedDrawArgs::default(); SEED_GROUPS as usize],
        groups: vec![DrawSeedsGroup::default(); SEED_GROUPS as usize],
        layers: Vec::new(),
        size,
        mips,
    };
    for (species, impostor) in impostors.iter().enumerate().take(SEED_GROUPS as usize / lods) {
        let Some(impostor) = impostor else { continue };
        let top = impostor.mesh.vertices.iter().map(|v| v.position_model_m[1]).fold(f32::MIN, f32::max);
        let sphere = &impostor.bounding_sphere;
        let height = if top > 0.0 { top } else { (sphere.centre_model_m[1] * 2.0).max(1e-3) };
        for (lod, level) in impostor.lods[..lods].iter().enumerate() {
            let group = species * lods + lod;
            let indices = level.indices();
            out.templates[group] = SeedDrawArgs {
                index_count: indices.len() as u32,
                instance_count: 0,
                first_index: out.indices.len() as u32,
                base_vertex: out.vertices.len() as i32,
                first_instance: 0,
            };
            out.groups[group] = DrawSeedsGroup {
                layer: out.layers.len() as u32,
                alpha_cutoff: impostor.alpha_cutoff,
                inv_model_height_m: 1.0 / height,
                _pad: 0,
            };
            out.vertices.extend(level.vertices());
            out.indices.extend(indices);
            out.layers.push((0..mips).map(|m| resample(&level.atlas, m, mip_size([size; 2], m))).collect());
        }
    }
    Ok(out)
}

/// Mip `level` of `atlas` at `to` texels, nearest texel (a copy when the sizes agree).
fn resample(atlas: &crate::impostor::MipChain, level: u32, to: [u32; 2]) -> Vec<u8> {
    let from = atlas.level_size(level);
    let texels = &atlas.levels[level as usize];
    if from == to {
        return texels.clone();
    }
    let mut out = Vec::with_capacity((4 * to[0] * to[1]) as usize);
    for y in 0..to[1] {
        let sy = (y * from[1] / to[1]) as usize;
        for x in 0..to[0] {
            let sx = (x * from[0] / to[0]) as usize;
            let i = 4 * (sy * from[0] as usize + sx);
            out.extend_from_slice(&texels[i..i + 4]);
        }
    }
    out
}

fn pipeline(device: &wgpu::Device) -> (wgpu::RenderPipeline, wgpu::BindGroupLayout) {
    let vertex = wgpu::ShaderStages::VERTEX;
    let fragment = wgpu::ShaderStages::FRAGMENT;
    let storage = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: vertex,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let entries = [
        wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: vertex | fragment,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        },
        storage(1),
        storage(2),
        storage(3),
        wgpu::BindGroupLayoutEntry {
            binding: 4,
            visibility: fragment,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: true },
                view_dimension: wgpu::TextureViewDimension::D2Array,
                multisampled: false,
            },
            count: None,
        },
        wgpu::BindGroupLayoutEntry {
            binding: 5,
            visibility: fragment,
            ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
            count: None,
        },
    ];
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("draw_seeds"),
        entries: &entries,
    });
    let module = shaders::module(device, "draw_seeds");
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("draw_seeds"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("draw_seeds"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: size_of::<PlaneVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: Default::default(),
            targets: &[Some(COLOUR_FORMAT.into())],
        }),
        // A billboard is seen from both sides.
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    });
    (pipeline, layout)
}

#[cfg(test)]
mod tests;
