//! The ground pass's GPU half: the pipeline over the terrain's bind group, and the recorded draw.

use crate::config::Settings;
use crate::earth::gpu::EARTH;
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::resources::{depth_equal, frame_pass, pipeline_layout};
use crate::gpu::shaders::{CLOUDS, HASH, IMAGERY, TERRAIN_MESH, WgslSource};
use crate::passes::terrain::gpu::{MeshDraw, TerrainPass};
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT};

/// The ground pass's shader: the terrain mesh again, shaded (its bindings are the terrain's,
/// `terrain::gpu::BINDINGS`).
pub const SHADER: WgslSource = WgslSource {
    name: "ground",
    parts: &[TERRAIN_MESH, EARTH, IMAGERY, HASH, CLOUDS, include_str!("../../../shaders/ground.wgsl")],
};

/// Pass 2 on the GPU: its pipeline (depth-equal, no depth write) and imagery sampler built once in
/// `new`; `encode` records each frame's clear to the sky and the shaded redraw of the terrain's nodes.
pub struct GroundPass {
    pipeline: wgpu::RenderPipeline,
    sampler: wgpu::Sampler,
}

impl GroundPass {
    /// `software`: the adapter is a CPU rasteriser (decides automatic anisotropy).
    pub fn new(device: &wgpu::Device, settings: &Settings, software: bool, terrain: &TerrainPass) -> Self {
        let module = SHADER.module(device);
        let layout = pipeline_layout(device, "ground", &[terrain.bind_group_layout()]);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("ground"),
            layout: Some(&layout),
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
            depth_stencil: Some(depth_equal(DEPTH_FORMAT)),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("imagery"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            anisotropy_clamp: settings.imagery.anisotropy_on(software),
            ..Default::default()
        });
        Self { pipeline, sampler }
    }

    /// The imagery sampler the terrain bind group must hold.
    pub fn sampler(&self) -> &wgpu::Sampler {
        &self.sampler
    }

    /// Clears `colour` to the sky and shades the ground the depth pass kept.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mesh: MeshDraw<'_>,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
        sky_linear: [f64; 3],
        counting: Counting<'_>,
    ) {
        let [r, g, b] = sky_linear;
        let mut pass =
            frame_pass(encoder, "ground", colour, depth, Some(wgpu::Color { r, g, b, a: 1.0 }), None);
        pass.set_pipeline(&self.pipeline);
        counting.begin(&mut pass, Part::Whole);
        mesh.draw(&mut pass, counting);
        counting.end(&mut pass);
    }
}
