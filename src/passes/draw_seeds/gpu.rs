//! Pass 4's GPU half: everything the species look like uploaded once (`new`: geometry, materials,
//! one texture array), the pipeline and binding table, the frame's constants and the recorded
//! indirect draws.

use std::ops::Range;

use bytemuck::Zeroable;
use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension};

use crate::classes::Species;
use crate::config::Settings;
use crate::earth::gpu::EARTH;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::fragments::CountedPass;
use crate::gpu::gpu_types::{
    DrawSeedsUniforms, SeedDrawArgs, SeedMaterial, SeedRecord, SeedShape, SeedVertex,
};
use crate::gpu::layout::{SEED_GROUPS, SEED_LODS};
use crate::gpu::resources::{buffer, buffer_init, frame_pass, write_rgba8_layer};
use crate::gpu::shaders::{AIR, ATMOSPHERE, CLOUDS, DITHER, HASH, SEED_RECORD, WIND, WgslSource};
use crate::impostor::{Impostor, mip_size};
use crate::passes::COLOUR_FORMAT;
use crate::passes::atmosphere::gpu::air::{AIR_GROUP, Air, AirVariants};
use crate::seeds::wind::bend_of;

use super::assets::{self, MeshDetail};
use super::frame::detail_templates;
use super::from_above::{FromAbove, Layers, from_above};
use super::{DrawSeedsError, LodChoices};
use multisample::Multisample;
use pipelines::{DepthTest, Draw, pipeline};

pub mod multisample;
mod pipelines;

/// Pass 4's shader.
pub const SHADER: WgslSource = WgslSource {
    name: "draw_seeds",
    parts: &[
        SEED_RECORD,
        DITHER,
        HASH,
        CLOUDS,
        WIND,
        EARTH,
        ATMOSPHERE,
        AIR,
        include_str!("../../../shaders/draw_seeds.wgsl"),
        include_str!("../../../shaders/draw_seeds/multisample.wgsl"),
    ],
};

/// Pass 4's bindings: the frame's constants, pass 3's records through compaction's order, and the
/// species' shapes (scale, bend), materials and textures.
pub const BINDINGS: BindingTable<8> = BindingTable {
    label: "draw_seeds",
    bindings: [
        // Storage, not uniform: see the binding's comment in the shader (lavapipe's variants).
        Binding::storage::<DrawSeedsUniforms>(0, "u", Stage::VERTEX_FRAGMENT, Access::Read),
        Binding::storage_array::<SeedRecord>(1, "records", Stage::VERTEX, Access::Read),
        Binding::storage_array::<u32>(2, "order", Stage::VERTEX, Access::Read),
        Binding::storage_array::<SeedShape>(3, "shapes", Stage::VERTEX, Access::Read),
        Binding::storage_array::<SeedMaterial>(4, "materials", Stage::VERTEX_FRAGMENT, Access::Read),
        Binding::texture(
            5,
            "textures",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: true },
            TextureViewDimension::D2Array,
        ),
        Binding::sampler(6, "clamp_sampler", Stage::FRAGMENT, wgpu::SamplerBindingType::Filtering),
        Binding::sampler(7, "repeat_sampler", Stage::FRAGMENT, wgpu::SamplerBindingType::Filtering),
    ],
};

/// The ground truth's seed-id target (`fs_truth`): per sample, the record index + 1 of the seed
/// drawn there, 0 where none is.
pub const SEED_ID_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;

/// What the draw reads from the earlier passes: pass 3's records and compaction's order.
pub struct DrawSeedsInputs<'a> {
    /// Pass 3's seed records (`SeedRecord`), in the blocks its workgroups wrote.
    pub records: &'a wgpu::Buffer,
    /// Compaction's permutation, draw slot → record index.
    pub order: &'a wgpu::Buffer,
}

/// Pass 4b on the GPU: the species' geometry, materials and texture array uploaded and the pipeline
/// built once in `new`; each frame `prepare` writes the constants and `encode` records the draws.
pub struct DrawSeedsPass {
    draw: AirVariants<Draw>,
    /// The pass's own bind group layout (group 0) and the air's (`AIR_GROUP`).
    layouts: [wgpu::BindGroupLayout; 2],
    uniforms: wgpu::Buffer,
    materials: wgpu::Buffer,
    species: wgpu::Buffer,
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    texture_view: wgpu::TextureView,
    clamp_sampler: wgpu::Sampler,
    repeat_sampler: wgpu::Sampler,
    templates: Vec<SeedDrawArgs>,
    /// Each species' mesh template (`None`: baked without one).
    meshes: Vec<Option<SeedDrawArgs>>,
    /// What narrows the LOD 1 draws of meshes drawn with continuous LOD each frame.
    details: Vec<Option<MeshDetail>>,
    inv_model_height_m: Vec<f32>,
    /// Each species' tallest seed, metres (the class table's height range).
    tallest_m: Vec<f32>,
    species_drawn: usize,
    species_missing: usize,
    /// What each (species, draw LOD) group's geometry shows from above: the colour follow-up's
    /// yardstick, turned into `DrawSeedsUniforms::from_above` for each frame's sun.
    from_above: Vec<Option<FromAbove>>,
    /// With `draw_seeds.samples` > 1: the multisampled targets and their draw.
    multisample: Option<(Multisample, AirVariants<Draw>)>,
}

impl DrawSeedsPass {
    /// Uploads the impostors of `species` (by species index; `None`: not drawn), LOD 1 as
    /// `choices` says (continuous LOD, slicings), and builds the pipelines, with a depth prepass
    /// when `depth_prepass` (`draw_seeds.depth_prepass`), over the atmosphere's `air` layout.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        impostors: &[Option<Impostor>],
        species: &[Species],
        choices: LodChoices,
        depth_prepass: bool,
        air: &wgpu::BindGroupLayout,
    ) -> Result<Self, DrawSeedsError> {
        if !device.features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE) {
            return Err(DrawSeedsError::NoFirstInstance);
        }
        let built = assets::gather(impostors, choices)?;
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
                write_rgba8_layer(queue, &texture, layer as u32, mip as u32, [w, h], texels);
            }
        }
        let texture_view = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let buffer_of = |label, contents: &[u8], usage| buffer_init(device, label, contents, usage);
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
        let layout = BINDINGS.layout(device);
        let layouts = [layout, air.clone()];
        let draw = Draw::variants(device, &layouts, (false, depth_prepass));
        let species_drawn = impostors.iter().filter(|i| i.is_some()).count();
        let layers = Layers { levels: &built.layers, size: built.size };
        let from_above = (0..SEED_GROUPS as usize)
            .map(|group| {
                let species_index = group / SEED_LODS as usize;
                let crown_shading = species.get(species_index).map_or(0.0, |s| s.crown_shading);
                let inv_height_m = built.inv_model_height_m.get(species_index).copied().unwrap_or(0.0);
                let geometry = (built.vertices.as_slice(), built.indices.as_slice());
                let template = built.templates.get(group)?;
                from_above(template, geometry, &built.materials, &layers, (crown_shading, inv_height_m))
            })
            .collect();
        let shapes: Vec<SeedShape> = (built.inv_model_height_m.iter().enumerate())
            .map(|(i, &inv_model_height_m)| SeedShape {
                inv_model_height_m,
                wind_bend: species.get(i).map_or(0.0, |s| bend_of(s.kind)),
                ground_blend: species.get(i).map_or(0.0, |s| s.ground_blend),
                crown_shading: species.get(i).map_or(0.0, |s| s.crown_shading),
            })
            .collect();
        Ok(Self {
            draw,
            layouts,
            uniforms: buffer(
                device,
                "draw_seeds uniforms",
                size_of::<DrawSeedsUniforms>() as u64,
                wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            ),
            materials: buffer_of("seed materials", &materials, storage),
            species: buffer_of("seed species shapes", bytemuck::cast_slice(&shapes), storage),
            vertices: buffer_of("seed vertices", &vertices, wgpu::BufferUsages::VERTEX),
            indices: buffer_of("seed indices", &indices, wgpu::BufferUsages::INDEX),
            texture_view,
            clamp_sampler: sampler("seed atlases", wgpu::AddressMode::ClampToEdge),
            repeat_sampler: sampler("seed mesh textures", wgpu::AddressMode::Repeat),
            templates: built.templates,
            meshes: built.meshes,
            details: built.details,
            inv_model_height_m: built.inv_model_height_m,
            tallest_m: species.iter().map(|s| s.height_m[1]).collect(),
            species_drawn,
            species_missing: impostors.len() - species_drawn,
            from_above,
            multisample: None,
        })
    }

    /// The same pass drawing multisampled (`draw_seeds.samples` = `SEED_SAMPLES`) over the frame's
    /// `colour` and the terrain's `depth`, resolving into `colour` (`multisample`).
    pub fn multisampled(
        mut self,
        device: &wgpu::Device,
        colour: &wgpu::Texture,
        depth: &wgpu::Texture,
    ) -> Self {
        let draw = Draw::variants(device, &self.layouts, (true, self.draw.of(false).prepassed()));
        self.multisample = Some((Multisample::new(device, colour, depth), draw));
        self
    }

    /// Draws multisampled into targets of `colour`'s and `depth`'s size from now on, if it does
    /// (the frame's targets made again at another size); the pipelines stay.
    pub fn resize_multisampled(
        &mut self,
        device: &wgpu::Device,
        colour: &wgpu::Texture,
        depth: &wgpu::Texture,
    ) {
        if let Some((targets, _)) = self.multisample.as_mut() {
            *targets = Multisample::new(device, colour, depth);
        }
    }

    /// The draws' index ranges, for `CompactPass::set_templates` (`SEED_DRAWS` of them).
    pub fn templates(&self) -> &[SeedDrawArgs] {
        &self.templates
    }

    /// This frame's index ranges (`frame::detail_templates`: LOD 1's meshes narrowed to what their
    /// nearest seeds keep through a lens of `focal_px`), `None` when no mesh is drawn with
    /// continuous LOD (`templates` hold).
    pub fn frame_templates(&self, settings: &Settings, focal_px: f32) -> Option<Vec<SeedDrawArgs>> {
        self.details.iter().any(Option::is_some).then(|| {
            let (details, tallest_m) = (&self.details, &self.tallest_m);
            detail_templates(
                &self.templates,
                details,
                tallest_m,
                &self.inv_model_height_m,
                settings,
                focal_px,
            )
        })
    }

    /// Species with an impostor, and species left undrawn for want of one.
    pub fn species_counts(&self) -> (usize, usize) {
        (self.species_drawn, self.species_missing)
    }

    /// The bind group over pass 3's records and compaction's order (fixed for a renderer's life).
    pub fn bind_group(&self, device: &wgpu::Device, inputs: &DrawSeedsInputs) -> wgpu::BindGroup {
        use wgpu::BindingResource as R;
        BINDINGS.bind_group(
            device,
            &self.layouts[0],
            [
                self.uniforms.as_entire_binding(),
                inputs.records.as_entire_binding(),
                inputs.order.as_entire_binding(),
                self.species.as_entire_binding(),
                self.materials.as_entire_binding(),
                R::TextureView(&self.texture_view),
                R::Sampler(&self.clamp_sampler),
                R::Sampler(&self.repeat_sampler),
            ],
        )
    }

    /// The ground truth's pipeline over this pass's geometry and bindings: `fs_truth` writes each
    /// fragment's colour and its seed's id (`SEED_ID_FORMAT`).
    pub fn truth_pipeline(&self, device: &wgpu::Device) -> AirVariants<wgpu::RenderPipeline> {
        let (device, layouts) = (device.clone(), self.layouts.clone());
        AirVariants::new(move |marched| {
            let targets = [Some(COLOUR_FORMAT.into()), Some(SEED_ID_FORMAT.into())];
            let options = (DepthTest::Written, marched);
            pipeline(&device, &layouts, ("fs_truth", &targets), Default::default(), options)
        })
    }

    /// Species `species`'s full mesh (its LOD 0 geometry), or `None` when its model has none
    /// (LOD 0 is then its first billboard cloud) or no impostor.
    pub fn mesh_of(&self, species: u32) -> Option<SeedDrawArgs> {
        self.meshes.get(species as usize).copied().flatten().filter(|t| t.index_count > 0)
    }

    /// Records the ground truth's draws into `pass` (its pipeline from `truth_pipeline`, the bind
    /// group over records whose `order` is the identity, and the air's): per entry, `mesh` once
    /// for each record in the range.
    pub fn encode_meshes(
        &self,
        pass: &mut wgpu::RenderPass,
        pipeline: &wgpu::RenderPipeline,
        (bind_group, air): (&wgpu::BindGroup, &wgpu::BindGroup),
        draws: &[(SeedDrawArgs, Range<u32>)],
    ) {
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_bind_group(AIR_GROUP, air, &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        for (mesh, instances) in draws {
            let indices = mesh.first_index..mesh.first_index + mesh.index_count;
            pass.draw_indexed(indices, mesh.base_vertex, instances.clone());
        }
    }

    /// Writes the frame's constants, with each group's colour follow-up under their sun.
    pub fn prepare(&self, queue: &crate::gpu::Queue, uniforms: &DrawSeedsUniforms) {
        let mut uniforms = *uniforms;
        let sun = glam::Vec4::from(uniforms.sun_dir).truncate();
        for (yardstick, seen) in uniforms.from_above.iter_mut().zip(&self.from_above) {
            *yardstick = seen.as_ref().map_or([0.0; 4], |seen| seen.yardstick(sun));
        }
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
    }

    /// Records each group's draw and cross-fade draw from `draw_args` (compaction's) into the
    /// targets (multisampled when `multisampled` made it so, resolved into `colour`), lit and
    /// seen through the air's group; `counting` counts them, and `count` their samples written
    /// and pixels covered.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        bind_group: (&wgpu::BindGroup, &Air),
        draw_args: &wgpu::Buffer,
        (colour, depth): (&wgpu::TextureView, &wgpu::TextureView),
        (count, counting): (Option<CountedPass<'_>>, Counting<'_>),
    ) {
        if self.species_drawn == 0 {
            if let Some(count) = count {
                count.nothing(encoder, "draw_seeds", colour, depth);
            }
            return;
        }
        let occlusion = count.map(CountedPass::occlusion_set);
        if let Some((targets, draw)) = &self.multisample {
            targets.encode(encoder, (occlusion, counting), |pass| {
                self.record(pass, draw.get(bind_group.1), bind_group, draw_args, (count, counting))
            });
            return;
        }
        let mut pass = frame_pass(encoder, "draw_seeds", colour, depth, None, occlusion);
        self.record(&mut pass, self.draw.get(bind_group.1), bind_group, draw_args, (count, counting));
    }

    /// Every group's indirect draws through `draw`'s pipelines.
    fn record(
        &self,
        pass: &mut wgpu::RenderPass,
        draw: &Draw,
        (bind_group, air): (&wgpu::BindGroup, &Air),
        draw_args: &wgpu::Buffer,
        (count, counting): (Option<CountedPass<'_>>, Counting<'_>),
    ) {
        pass.set_bind_group(0, bind_group, &[]);
        pass.set_bind_group(AIR_GROUP, air.group(), &[]);
        pass.set_vertex_buffer(0, self.vertices.slice(..));
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        let draws = |pass: &mut wgpu::RenderPass, pipeline| {
            pass.set_pipeline(pipeline);
            let stride = size_of::<SeedDrawArgs>() as u64;
            for draw in near_to_far_draws().filter(|&d| self.templates[d].index_count > 0) {
                counting.draw_indexed_indirect(pass, draw_args, draw as u64 * stride);
            }
        };
        let shade = match draw {
            Draw::Plain(shade) => shade,
            Draw::Prepassed { depth, shade } => {
                counting.begin(pass, Part::Prepass);
                draws(pass, depth);
                counting.end(pass);
                shade
            }
        };
        counting.begin(pass, Part::Shading);
        count.inspect(|c| c.begin(pass));
        draws(pass, shade);
        count.inspect(|c| c.end(pass));
        counting.end(pass);
    }
}

/// The draws (`SEED_DRAWS`) nearest first: LOD by LOD, each LOD's own draws of every species, then
/// their cross-fades into the next (seeds at that LOD's reach); each draw is near to far within
/// (pass 3 checks its cells nearest first). Nearer crowns' depth then hides what is behind them
/// before it is shaded.
pub(super) fn near_to_far_draws() -> impl Iterator<Item = usize> {
    let (groups, lods) = (SEED_GROUPS as usize, SEED_LODS as usize);
    let species = groups / lods;
    (0..lods).flat_map(move |lod| {
        let own = (0..species).map(move |s| s * lods + lod);
        own.clone().chain(own.map(move |g| groups + g))
    })
}
