//! How it works: pass 4b, drawing the seeds (DESIGN § "The frame", step 4). Everything a species
//! looks like is uploaded once, at `new` (`assets`): its real mesh and its billboard clouds of 17,
//! 8 and 2 planes in one vertex and one index buffer, every texture (cloud atlases, mesh textures)
//! as a layer of one RGBA8 sRGB texture array, and a material table the vertices index. The draw
//! group of (species, LOD) gets its index range as a compaction template (`templates`, for
//! `CompactPass::set_templates`), and its cross-fade draw the next LOD's range.
//!
//! Each frame `encode` records two `draw_indexed_indirect`s per group from compaction's argument
//! buffer (an empty group costs nothing): its own, and the same instances with the next LOD's
//! geometry. `shaders/draw_seeds.wgsl` reads an instance's record through compaction's `order`,
//! scales the model to the seed's height, turns it by the seed's jitter, places it camera-relative
//! and projects it with the terrain's matrix; it draws into the colour target with the terrain
//! depth (reversed-Z, `GreaterEqual`, depth written). A seed in the outer `seeds.fade_fraction`
//! of its LOD's reach cross-fades: its own geometry keeps the pixels whose (per-seed shifted)
//! Bayer threshold is below the fade, the next LOD's geometry the others, so each pixel shows
//! exactly one of the two and nothing pops; outside the band the cross-fade draw collapses its
//! vertices. The last LOD fades out to nothing at the visibility radius.

mod assets;

use std::path::{Path, PathBuf};

use bytemuck::Zeroable;
use thiserror::Error;
use wgpu::util::DeviceExt;

use crate::classes::Species;
use crate::config::Settings;
use crate::gpu::gpu_types::{DrawSeedsUniforms, SeedDrawArgs, SeedMaterial, SeedVertex};
use crate::impostor::{Impostor, ImpostorError, MANIFEST_FILE, mip_size};
use crate::seeds::SEED_LODS;
use crate::shaders;
use crate::terrain::{COLOUR_FORMAT, DEPTH_FORMAT};

pub use assets::MAX_LAYER_TEXELS;

/// How much of the ground colour under a seed it takes on.
pub const GROUND_BLEND: f32 = 0.2;

#[derive(Debug, Error)]
pub enum DrawSeedsError {
    #[error("seeds.impostors = {0:?} is not a folder (bake one with `terramp-data bake`)")]
    NoFolder(PathBuf),
    #[error(transparent)]
    Impostor(#[from] ImpostorError),
    #[error("impostor {model:?} has {lods} billboard-cloud LODs; the seed draw needs {}", SEED_LODS - 1)]
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
    materials: wgpu::Buffer,
    species: wgpu::Buffer,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    texture_view: wgpu::TextureView,
    clamp_sampler: wgpu::Sampler,
    repeat_sampler: wgpu::Sampler,
    templates: Vec<SeedDrawArgs>,
    species_drawn: usize,
    species_missing: usize,
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
        let built = assets::gather(impostors)?;
        let max = device.limits().max_texture_array_layers;
        let layers = built.layers.len().max(1) as u32;
        if layers > max {
            return Err(DrawSeedsError::TooManyLayers { layers, max });
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("seed textures"),
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
                        texture: &texture,
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
        let texture_view = texture.create_view(&wgpu::TextureViewDescriptor {
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
        let or_one = |v: &[u8], one: &[u8]| if v.is_empty() { one.to_vec() } else { v.to_vec() };
        let vertices =
            or_one(bytemuck::cast_slice(&built.vertices), bytemuck::bytes_of(&SeedVertex::zeroed()));
        let indices = or_one(bytemuck::cast_slice(&built.indices), &[0; 4]);
        let materials =
            or_one(bytemuck::cast_slice(&built.materials), bytemuck::bytes_of(&SeedMaterial::zeroed()));
        let storage = wgpu::BufferUsages::STORAGE;
        let sampler = |label, address_mode| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: address_mode,
                address_mode_v: address_mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                ..Default::default()
            })
        };
        let (pipeline, layout) = pipeline(device);
        let species_drawn = impostors.iter().filter(|i| i.is_some()).count();
        Ok(Self {
            pipeline,
            layout,
            uniforms: device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("draw_seeds uniforms"),
                size: size_of::<DrawSeedsUniforms>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }),
            materials: buffer("seed materials", &materials, storage),
            species: buffer("seed species scale", bytemuck::cast_slice(&built.inv_model_height_m), storage),
            vertices: buffer("seed vertices", &vertices, wgpu::BufferUsages::VERTEX),
            indices: buffer("seed indices", &indices, wgpu::BufferUsages::INDEX),
            texture_view,
            clamp_sampler: sampler("seed atlases", wgpu::AddressMode::ClampToEdge),
            repeat_sampler: sampler("seed mesh textures", wgpu::AddressMode::Repeat),
            templates: built.templates,
            species_drawn,
            species_missing: impostors.len() - species_drawn,
        })
    }

    /// The draws' index ranges, for `CompactPass::set_templates` (`SEED_DRAWS` of them).
    pub fn templates(&self) -> &[SeedDrawArgs] {
        &self.templates
    }

    /// Species with an impostor, and species left undrawn for want of one.
    pub fn species_counts(&self) -> (usize, usize) {
        (self.species_drawn, self.species_missing)
    }

    pub fn bind_group(&self, device: &wgpu::Device, inputs: &DrawSeedsInputs) -> wgpu::BindGroup {
        use wgpu::BindingResource as R;
        let resources = [
            self.uniforms.as_entire_binding(),
            inputs.records.as_entire_binding(),
            inputs.order.as_entire_binding(),
            self.species.as_entire_binding(),
            self.materials.as_entire_binding(),
            R::TextureView(&self.texture_view),
            R::Sampler(&self.clamp_sampler),
            R::Sampler(&self.repeat_sampler),
        ];
        let entries: Vec<_> = resources
            .into_iter()
            .enumerate()
            .map(|(binding, resource)| wgpu::BindGroupEntry { binding: binding as u32, resource })
            .collect();
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

    /// Records each group's draw and cross-fade draw from `draw_args` (compaction's) into the
    /// targets.
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
        for (draw, template) in self.templates.iter().enumerate() {
            if template.index_count > 0 {
                pass.draw_indexed_indirect(draw_args, draw as u64 * stride);
            }
        }
    }
}

/// The frame's constants from the settings and the terrain's matrix, sun and haze.
pub fn draw_uniforms(
    settings: &Settings,
    terrain: &crate::gpu::gpu_types::TerrainUniforms,
) -> DrawSeedsUniforms {
    DrawSeedsUniforms {
        clip_from_view_world: terrain.clip_from_view_world,
        sun_dir: terrain.sun_dir,
        haze: terrain.haze,
        lod_reach_m: crate::seeds::lod_reach_m(settings).map(|r| r as f32),
        inv_reference_height_m: (1.0 / settings.seeds.reference_height_m) as f32,
        sink_fraction: settings.seeds.sink_fraction as f32,
        fade_fraction: settings.seeds.fade_fraction as f32,
        ground_blend: GROUND_BLEND,
    }
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
    let entry = |binding, visibility, ty| wgpu::BindGroupLayoutEntry { binding, visibility, ty, count: None };
    let uniform = wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Uniform,
        has_dynamic_offset: false,
        min_binding_size: None,
    };
    let texture = wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension: wgpu::TextureViewDimension::D2Array,
        multisampled: false,
    };
    let sampler = wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering);
    let entries = [
        entry(0, vertex | fragment, uniform),
        storage(1),
        storage(2),
        storage(3),
        wgpu::BindGroupLayoutEntry { visibility: vertex | fragment, ..storage(4) },
        entry(5, fragment, texture),
        entry(6, fragment, sampler),
        entry(7, fragment, sampler),
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
    let attributes = wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2, 3 => Uint32];
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("draw_seeds"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: Default::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: size_of::<SeedVertex>() as u64,
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
        // A billboard is seen from both sides, and so are leaves (the glTF's double-sided ones).
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
