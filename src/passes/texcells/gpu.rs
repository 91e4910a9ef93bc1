//! The texcell pass's GPU half: the forest samples' texture array, their 3D texture (the
//! silhouettes') and the class → sample table (fixed: uploaded once in `new`), the uniforms (the settings' and samples': rewritten by
//! `write_uniforms` when the settings change them), the pipeline over the terrain's bind group and
//! its own, the quadrant grid's index buffer; `prepare` uploads the frame's slice instances and
//! `encode` draws them over the frame, blended, depth-tested against the ground, writing no depth.

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension};

use crate::dataset::surface::diagonal_rises;
use crate::earth::gpu::EARTH;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::fragments::CountedPass;
use crate::gpu::gpu_types::{TexcellRecord, TexcellUniforms};
use crate::gpu::resources::{buffer, buffer_init, frame_pass, write_rgba8_layer};
use crate::gpu::shaders::{
    AIR, ATMOSPHERE, CLOUDS, DITHER, HASH, IMAGERY, LANDCOVER, TERRAIN_MESH, WgslSource,
};
use crate::passes::atmosphere::gpu::air::{
    AIR_GROUP, Air, AirVariants, air_constants, pipeline_layout_with_air,
};
use crate::passes::terrain::gpu::{MeshDraw, TerrainPass};
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT};
use crate::streaming::TileCache;
use crate::texcell::ForestSample;

use super::TexcellsError;
use super::frame::MAX_RECORDS;

pub mod probe;

/// The texcell pass's shader: the terrain mesh and the ground's colour, then its own.
pub const SHADER: WgslSource = WgslSource {
    name: "texcells",
    parts: &[
        TERRAIN_MESH,
        EARTH,
        IMAGERY,
        HASH,
        CLOUDS,
        DITHER,
        LANDCOVER,
        ATMOSPHERE,
        AIR,
        include_str!("../../../shaders/texcells.wgsl"),
    ],
};

/// Group 1 of the pass (group 0 is the terrain's, `terrain::gpu::BINDINGS`).
pub const BINDINGS: BindingTable<8> = BindingTable {
    label: "texcells",
    bindings: [
        Binding::uniform::<TexcellUniforms>(0, "tu", Stage::VERTEX_FRAGMENT),
        Binding::storage_array::<TexcellRecord>(1, "texcell_records", Stage::VERTEX, Access::Read),
        Binding::texture(
            2,
            "forest_slices",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: true },
            TextureViewDimension::D2Array,
        ),
        Binding::sampler(3, "forest_sampler", Stage::FRAGMENT, wgpu::SamplerBindingType::Filtering),
        Binding::storage_array::<u32>(4, "sample_of_class", Stage::FRAGMENT, Access::Read),
        Binding::storage_array::<u32>(5, "lcc_page_table", Stage::FRAGMENT, Access::Read),
        Binding::texture(
            6,
            "lcc_tiles",
            Stage::FRAGMENT,
            TextureSampleType::Uint,
            TextureViewDimension::D2Array,
        ),
        Binding::texture(
            7,
            "forest_volume",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: true },
            TextureViewDimension::D3,
        ),
    ],
};

/// The texcell pass: built once per renderer over the forest samples of its dense classes.
pub struct TexcellsPass {
    pipelines: AirVariants<wgpu::RenderPipeline>,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    records: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
    slices: wgpu::TextureView,
    volume: wgpu::TextureView,
    sampler: wgpu::Sampler,
    sample_of_class: wgpu::Buffer,
}

/// Slice instances this frame draws, as uploaded.
#[derive(Debug, Clone, Copy, Default)]
pub struct PreparedTexcells {
    instances: u32,
}

impl TexcellsPass {
    /// Uploads `samples` (all of one shape: `texcell::load` checks each, the stage checks they
    /// agree) into one texture array, sample `s`'s slice pyramid level `k`, slice `j` at layer
    /// `s · 2^N + j · 2^k`, mips `k` and coarser (so a patch drawing level `k` reads its own
    /// aggregated slices there); `sample_of_class[palette index]` is a sample index + 1, or 0.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (terrain, air): (&TerrainPass, &wgpu::BindGroupLayout),
        node_cells: u32,
        samples: &[ForestSample],
        sample_of_class: &[u32],
        uniforms: &TexcellUniforms,
    ) -> Result<Self, TexcellsError> {
        let first = samples.first().ok_or(TexcellsError::NoSamples)?;
        let (texels, finest) = (first.texels(), first.slice_count());
        let layers = samples.len() as u32 * finest;
        let max = device.limits().max_texture_array_layers;
        if layers > max {
            return Err(TexcellsError::TooManyLayers { layers, max });
        }
        let mips = texels.ilog2() + 1;
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("forest slices"),
            size: wgpu::Extent3d { width: texels, height: texels, depth_or_array_layers: layers },
            mip_level_count: mips,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Rgba8UnormSrgb,
            usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
            view_formats: &[],
        });
        for (s, sample) in samples.iter().enumerate() {
            // Finest level first: each coarser level then overwrites the mips it owns.
            for (k, level) in sample.slices.iter().enumerate() {
                for (j, chain) in level.iter().enumerate() {
                    let layer = s as u32 * finest + ((j as u32) << k);
                    for (m, bytes) in chain.levels.iter().enumerate() {
                        let mip = k as u32 + m as u32;
                        let side = (texels >> mip).max(1);
                        if mip >= mips || bytes.len() != (4 * side * side) as usize {
                            continue;
                        }
                        write_rgba8_layer(queue, &texture, layer, mip, [side, side], bytes);
                    }
                }
            }
        }
        let slices = texture.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..Default::default()
        });
        let volume = volume_texture(device, queue, samples, texels, finest).create_view(&Default::default());
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("forest slices"),
            // The sample wraps like a torus: its tiles' neighbours are compatible tiles.
            address_mode_u: wgpu::AddressMode::Repeat,
            address_mode_v: wgpu::AddressMode::Repeat,
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            ..Default::default()
        });
        use wgpu::BufferUsages as U;
        let table = if sample_of_class.is_empty() { &[0][..] } else { sample_of_class };
        let sample_of_class = buffer_init(device, "texcell classes", bytemuck::cast_slice(table), U::STORAGE);
        let uniforms =
            buffer_init(device, "texcell uniforms", bytemuck::bytes_of(uniforms), U::UNIFORM | U::COPY_DST);
        let records_bytes = u64::from(MAX_RECORDS) * size_of::<TexcellRecord>() as u64;
        let records = buffer(device, "texcell records", records_bytes, U::STORAGE | U::COPY_DST);
        let index_data = quadrant_indices(node_cells / 2);
        let indices = buffer_init(device, "texcell grid", bytemuck::cast_slice(&index_data), U::INDEX);
        let layout = BINDINGS.layout(device);
        let pipelines = pipelines(device, (terrain, air), &layout);
        Ok(Self {
            pipelines,
            layout,
            uniforms,
            records,
            indices,
            index_count: index_data.len() as u32,
            slices,
            volume,
            sampler,
            sample_of_class,
        })
    }

    /// The pass's own bind group (group 1) over the land-cover cache, fixed for a renderer's life.
    pub fn bind_group(&self, device: &wgpu::Device, landcover: &TileCache) -> wgpu::BindGroup {
        use wgpu::BindingResource as R;
        BINDINGS.bind_group(
            device,
            &self.layout,
            [
                self.uniforms.as_entire_binding(),
                self.records.as_entire_binding(),
                R::TextureView(&self.slices),
                R::Sampler(&self.sampler),
                self.sample_of_class.as_entire_binding(),
                landcover.page_table.as_entire_binding(),
                R::TextureView(&landcover.view),
                R::TextureView(&self.volume),
            ],
        )
    }

    /// Replaces the uniforms (the band, opacity and colour settings) from the next frame on.
    pub fn write_uniforms(&self, queue: &crate::gpu::Queue, uniforms: &TexcellUniforms) {
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(uniforms));
    }

    /// Uploads the frame's slice instances (at most `MAX_RECORDS`).
    pub fn prepare(&self, queue: &crate::gpu::Queue, records: &[TexcellRecord]) -> PreparedTexcells {
        let kept = &records[..records.len().min(MAX_RECORDS as usize)];
        if !kept.is_empty() {
            queue.write_buffer(&self.records, 0, bytemuck::cast_slice(kept));
        }
        PreparedTexcells { instances: kept.len() as u32 }
    }

    /// Draws the frame's slices over `colour`, depth-tested against the ground in `depth`, lit
    /// and seen through `air` (the atmosphere's group); `counting` counts them, and `count` their
    /// samples written and pixels covered.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (mesh, bind_group, air): (MeshDraw<'_>, &wgpu::BindGroup, &Air),
        (colour, depth): (&wgpu::TextureView, &wgpu::TextureView),
        prepared: PreparedTexcells,
        (count, counting): (Option<CountedPass<'_>>, Counting<'_>),
    ) {
        let mut pass =
            frame_pass(encoder, "texcells", colour, depth, None, count.map(CountedPass::occlusion_set));
        counting.begin(&mut pass, Part::Shading);
        count.inspect(|c| c.begin(&mut pass));
        if prepared.instances > 0 {
            pass.set_pipeline(self.pipelines.get(air));
            pass.set_bind_group(0, mesh.bind_group, &[]);
            pass.set_bind_group(1, bind_group, &[]);
            pass.set_bind_group(AIR_GROUP, air.group(), &[]);
            pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
            counting.draw_indexed(&mut pass, 0..self.index_count, 0, 0..prepared.instances);
        }
        count.inspect(|c| c.end(&mut pass));
        counting.end(&mut pass);
    }
}

/// The samples' 3D textures stacked along z (sample `s` at depths `s · D` to `(s + 1) · D` for `D`
/// finest slices), with the mips that keep them apart: down to one texel of depth each (level
/// log2 D), whose side, L / D texels, is the coarsest the silhouettes read.
fn volume_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    samples: &[ForestSample],
    texels: u32,
    finest: u32,
) -> wgpu::Texture {
    let mips = finest.ilog2().min(texels.ilog2()) + 1;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("forest volume"),
        size: wgpu::Extent3d {
            width: texels,
            height: texels,
            depth_or_array_layers: finest * samples.len() as u32,
        },
        mip_level_count: mips,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D3,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (s, sample) in samples.iter().enumerate() {
        for (mip, level) in sample.volume.iter().enumerate().take(mips as usize) {
            let slice_bytes = (4 * level.side * level.side) as usize;
            for (z, bytes) in level.bytes.chunks_exact(slice_bytes).enumerate() {
                let depth = s as u32 * level.depth + z as u32;
                write_rgba8_layer(queue, &texture, depth, mip as u32, [level.side, level.side], bytes);
            }
        }
    }
    texture
}

/// The blended slice pipeline: premultiplied "over", both faces (a camera inside the canopy sees
/// slices from below), depth-tested against the ground (reversed-Z), no depth written.
fn pipelines(
    device: &wgpu::Device,
    (terrain, air): (&TerrainPass, &wgpu::BindGroupLayout),
    own: &wgpu::BindGroupLayout,
) -> AirVariants<wgpu::RenderPipeline> {
    let module = SHADER.module(device);
    let layout = pipeline_layout_with_air(device, "texcells", &[terrain.bind_group_layout(), own], air);
    let device = device.clone();
    AirVariants::new(move |marched| pipeline(&device, (&module, &layout), marched))
}

fn pipeline(
    device: &wgpu::Device,
    (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
    marched: bool,
) -> wgpu::RenderPipeline {
    let over = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
        operation: wgpu::BlendOperation::Add,
    };
    let constants = air_constants(marched);
    let compilation_options =
        wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("texcells"),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_texcell"),
            compilation_options: compilation_options.clone(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some("fs_texcell"),
            compilation_options,
            targets: &[Some(wgpu::ColorTargetState {
                format: COLOUR_FORMAT,
                blend: Some(wgpu::BlendState { color: over, alpha: over }),
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        primitive: Default::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(false),
            depth_compare: Some(wgpu::CompareFunction::GreaterEqual),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}

/// Triangles of a quadrant's `cells`² grid ((cells + 1)² vertices, no skirts), each cell cut along
/// the diagonal the terrain's grid cuts it (`dataset::surface::diagonal_rises`: a quadrant starts
/// at an even cell, so its cells have their node cells' parity), counter-clockwise from above.
pub fn quadrant_indices(cells: u32) -> Vec<u32> {
    let row = cells + 1;
    let mut indices = Vec::with_capacity((6 * cells * cells) as usize);
    for j in 0..cells {
        for i in 0..cells {
            let (sw, se, nw, ne) = (j * row + i, j * row + i + 1, (j + 1) * row + i, (j + 1) * row + i + 1);
            if diagonal_rises([i, j]) {
                indices.extend_from_slice(&[sw, se, ne, sw, ne, nw]);
            } else {
                indices.extend_from_slice(&[sw, se, nw, se, ne, nw]);
            }
        }
    }
    indices
}
