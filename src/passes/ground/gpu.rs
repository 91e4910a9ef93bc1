//! The ground pass's GPU half: the pipeline over the terrain's bind group, and the recorded draw.

use crate::config::Settings;
use crate::earth::gpu::EARTH;
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::resources::{depth_equal, frame_pass};
use crate::gpu::shaders::{AIR, ATMOSPHERE, CLOUDS, HASH, IMAGERY, TERRAIN_MESH, WgslSource};
use crate::passes::atmosphere::gpu::air::{
    AIR_GROUP, Air, AirVariants, air_constants, pipeline_layout_with_air,
};
use crate::passes::terrain::gpu::{MeshDraw, TerrainPass};
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT};

/// The ground pass's shader: the terrain mesh again, shaded (its bindings are the terrain's,
/// `terrain::gpu::BINDINGS`, and the air's, `atmosphere::gpu::air::AIR_BINDINGS`).
pub const SHADER: WgslSource = WgslSource {
    name: "ground",
    parts: &[
        TERRAIN_MESH,
        EARTH,
        IMAGERY,
        HASH,
        CLOUDS,
        ATMOSPHERE,
        AIR,
        include_str!("../../../shaders/ground.wgsl"),
    ],
};

/// Pass 2 on the GPU: its pipelines (depth-equal, no depth write; in the air's two variants) and
/// imagery sampler built once in `new`; `encode` records each frame's clear and the shaded redraw
/// of the terrain's nodes.
pub struct GroundPass {
    pipelines: AirVariants<wgpu::RenderPipeline>,
    sampler: wgpu::Sampler,
}

impl GroundPass {
    /// `software`: the adapter is a CPU rasteriser (decides automatic anisotropy); `air`: the
    /// atmosphere's bind group layout (`AIR_GROUP`).
    pub fn new(
        device: &wgpu::Device,
        settings: &Settings,
        software: bool,
        terrain: &TerrainPass,
        air: &wgpu::BindGroupLayout,
    ) -> Self {
        let module = SHADER.module(device);
        let layout = pipeline_layout_with_air(device, "ground", &[terrain.bind_group_layout()], air);
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("imagery"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            mipmap_filter: wgpu::MipmapFilterMode::Linear,
            anisotropy_clamp: settings.imagery.anisotropy_on(software),
            ..Default::default()
        });
        let device = device.clone();
        let pipelines = AirVariants::new(move |marched| {
            let constants = air_constants(marched);
            let compilation_options =
                wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("ground"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some("vs_main"),
                    compilation_options: compilation_options.clone(),
                    buffers: &[],
                },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some("fs_main"),
                    compilation_options,
                    targets: &[Some(COLOUR_FORMAT.into())],
                }),
                primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
                depth_stencil: Some(depth_equal(DEPTH_FORMAT)),
                multisample: Default::default(),
                multiview_mask: None,
                cache: None,
            })
        });
        Self { pipelines, sampler }
    }

    /// The imagery sampler the terrain bind group must hold.
    pub fn sampler(&self) -> &wgpu::Sampler {
        &self.sampler
    }

    /// Clears the (colour, depth) targets' colour (the sky pass fills what the ground leaves)
    /// and shades the ground the depth pass kept, lit and seen through `air`.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mesh: MeshDraw<'_>,
        (colour, depth): (&wgpu::TextureView, &wgpu::TextureView),
        air: &Air,
        counting: Counting<'_>,
    ) {
        // Transparent: what the frame's passes draw is opaque or blended over premultiplied, so
        // the light's alpha is their coverage, by which a host's frame shows it
        // (`Renderer::render_into`); the sky covers every pixel nothing else drew.
        let clear = Some(wgpu::Color::TRANSPARENT);
        let mut pass = frame_pass(encoder, "ground", colour, depth, clear, None);
        pass.set_pipeline(self.pipelines.get(air));
        pass.set_bind_group(AIR_GROUP, air.group(), &[]);
        counting.begin(&mut pass, Part::Whole);
        mesh.draw(&mut pass, counting);
        counting.end(&mut pass);
    }
}
