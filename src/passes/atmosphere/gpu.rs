//! The atmosphere pass's GPU half: the tables' textures and compute pipelines, the sky's render
//! pipelines, their binding tables; the fixed tables (transmittance, multiple scattering, sky
//! irradiance, the daylight balance) made once in `new`, the sky-view table, the
//! aerial-perspective volume and the sky recorded each frame.

pub mod air;
mod tables;

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension as Dim};

use crate::config::AtmosphereSettings;
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::gpu_types::AtmosphereUniforms;
use crate::gpu::layout::{ATMOSPHERE_WORKGROUP, MULTIPLE_TERMS, SKY_MARCHED_ABOVE_KM};
use crate::gpu::readback::{f16_texels, read_buffer, read_texture_slices};
use crate::gpu::resources::{buffer, compute_pipeline, depth_equal, frame_pass, pipeline_layout};
use crate::gpu::shaders::{ATMOSPHERE, WgslSource};
use crate::gpu::{Gpu, GpuError, Queue};
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT};

use super::frame::{SkyView, frame_uniforms, phase_moments};
use air::Air;
use tables::{Table, aerial_volume};

/// The tables' texel format: f32 radiances and transmittances, which storage textures can write
/// everywhere and which the shaders read by hand (`lut_read`), so no filtering of f32 is needed.
pub const LUT_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;

/// The sky-view table's: f16, which every adapter filters, so the sky pass reads it with one
/// bilinear sample a pixel (the twin rounds its texels the same way).
pub const SKY_VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;

/// The atmosphere's shader.
pub const SHADER: WgslSource =
    WgslSource { name: "atmosphere", parts: &[ATMOSPHERE, include_str!("../../../shaders/atmosphere.wgsl")] };

const LUT: TextureSampleType = TextureSampleType::Float { filterable: false };

/// `transmittance_lut`.
pub const TRANSMITTANCE_BINDINGS: BindingTable<2> = BindingTable {
    label: "atmosphere transmittance",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::COMPUTE, Access::Read),
        Binding::storage_texture(1, "transmittance_out", Stage::COMPUTE, LUT_FORMAT, Dim::D2),
    ],
};

/// `multiple_scattering_lut`.
pub const MULTIPLE_BINDINGS: BindingTable<3> = BindingTable {
    label: "atmosphere multiple scattering",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::COMPUTE, Access::Read),
        Binding::texture(2, "transmittance", Stage::COMPUTE, LUT, Dim::D2),
        Binding::storage_texture(3, "multiple_out", Stage::COMPUTE, LUT_FORMAT, Dim::D2),
    ],
};

/// `sky_view_lut`.
pub const SKY_VIEW_BINDINGS: BindingTable<4> = BindingTable {
    label: "atmosphere sky view",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::COMPUTE, Access::Read),
        Binding::texture(2, "transmittance", Stage::COMPUTE, LUT, Dim::D2),
        Binding::texture(4, "multiple", Stage::COMPUTE, LUT, Dim::D2),
        Binding::storage_texture(5, "sky_view_out", Stage::COMPUTE, SKY_VIEW_FORMAT, Dim::D2),
    ],
};

/// `aerial_perspective_lut`.
pub const AERIAL_BINDINGS: BindingTable<5> = BindingTable {
    label: "atmosphere aerial perspective",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::COMPUTE, Access::Read),
        Binding::texture(2, "transmittance", Stage::COMPUTE, LUT, Dim::D2),
        Binding::texture(4, "multiple", Stage::COMPUTE, LUT, Dim::D2),
        Binding::storage_texture(8, "aerial_inscatter_out", Stage::COMPUTE, SKY_VIEW_FORMAT, Dim::D3),
        Binding::storage_texture(9, "aerial_transmittance_out", Stage::COMPUTE, SKY_VIEW_FORMAT, Dim::D3),
    ],
};

/// `irradiance_lut`.
pub const IRRADIANCE_BINDINGS: BindingTable<4> = BindingTable {
    label: "atmosphere sky irradiance",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::COMPUTE, Access::Read),
        Binding::texture(2, "transmittance", Stage::COMPUTE, LUT, Dim::D2),
        Binding::texture(4, "multiple", Stage::COMPUTE, LUT, Dim::D2),
        Binding::storage_texture(10, "irradiance_out", Stage::COMPUTE, LUT_FORMAT, Dim::D2),
    ],
};

/// `daylight_balance`.
pub const DAYLIGHT_BINDINGS: BindingTable<4> = BindingTable {
    label: "atmosphere daylight balance",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::COMPUTE, Access::Read),
        Binding::texture(2, "transmittance", Stage::COMPUTE, LUT, Dim::D2),
        Binding::texture(11, "irradiance", Stage::COMPUTE, LUT, Dim::D2),
        Binding::storage::<[f32; 4]>(12, "daylight_out", Stage::COMPUTE, Access::ReadWrite),
    ],
};

/// `vs_sky`, `fs_sky`: the sky from the sky-view table.
pub const SKY_BINDINGS: BindingTable<5> = BindingTable {
    label: "sky",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::FRAGMENT, Access::Read),
        Binding::uniform::<[f32; 4]>(13, "daylight", Stage::FRAGMENT),
        Binding::texture(2, "transmittance", Stage::FRAGMENT, LUT, Dim::D2),
        Binding::texture(
            6,
            "sky_view",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: true },
            Dim::D2,
        ),
        Binding::sampler(7, "sky_sampler", Stage::FRAGMENT, wgpu::SamplerBindingType::Filtering),
    ],
};

/// `vs_sky`, `fs_sky_marched`: the sky marched per pixel.
pub const SKY_MARCHED_BINDINGS: BindingTable<4> = BindingTable {
    label: "sky marched",
    bindings: [
        Binding::storage::<AtmosphereUniforms>(0, "atmosphere", Stage::FRAGMENT, Access::Read),
        Binding::uniform::<[f32; 4]>(13, "daylight", Stage::FRAGMENT),
        Binding::texture(2, "transmittance", Stage::FRAGMENT, LUT, Dim::D2),
        Binding::texture(4, "multiple", Stage::FRAGMENT, LUT, Dim::D2),
    ],
};

/// The atmosphere on the GPU: its tables (the fixed ones made in `new`), the sky-view table's
/// and the aerial-perspective volume's pipelines, the sky's, the air the lit passes bind, and the
/// uniforms `prepare` writes each frame.
pub struct AtmospherePass {
    settings: AtmosphereSettings,
    /// The air's phase moments (`frame::phase_moments`), made once with the pass.
    phase_moments: [f32; 4],
    uniforms: wgpu::Buffer,
    transmittance: Table,
    multiple: Table,
    sky_view: Table,
    irradiance: Table,
    /// The display's balance for daylight (`daylight_balance`): 1 / the light per channel.
    daylight: wgpu::Buffer,
    sky_view_pipeline: wgpu::ComputePipeline,
    sky_view_group: wgpu::BindGroup,
    /// The sky's pipelines and bind groups: from the table, then marched per pixel.
    sky: [(wgpu::RenderPipeline, wgpu::BindGroup); 2],
    /// The aerial-perspective volume: in-scattered light, then transmittance (f16, 3D).
    aerial: [wgpu::Texture; 2],
    aerial_pipeline: wgpu::ComputePipeline,
    aerial_group: wgpu::BindGroup,
    /// What the ground, the seeds and the texcells bind of all this.
    air: Air,
}

impl AtmospherePass {
    /// The pass for the air of `settings`; makes its fixed tables and the daylight balance on
    /// `gpu` now (submitted, not waited for).
    pub fn new(gpu: &Gpu, settings: &AtmosphereSettings) -> Self {
        let device = &gpu.device;
        let module = SHADER.module(device);
        // Read as storage, never as a uniform: lavapipe specialises a shader on the values of
        // uniforms that steer its branches and keeps every variant, and the view's radius and the
        // sun's height steer the march's (`hits_ground`) and change every frame.
        let uniforms = buffer(
            device,
            "atmosphere uniforms",
            size_of::<AtmosphereUniforms>() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let daylight = buffer(
            device,
            "atmosphere daylight balance",
            size_of::<[f32; 4]>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        let table = |label: &str, size: [u32; 2], format| Table::new(device, label, size, 1, format);
        let transmittance = table("atmosphere transmittance", settings.transmittance_lut, LUT_FORMAT);
        let multiple = Table::new(
            device,
            "atmosphere multiple scattering",
            settings.multiple_scattering_lut,
            MULTIPLE_TERMS,
            LUT_FORMAT,
        );
        let sky_view = table("atmosphere sky view", settings.sky_view_lut, SKY_VIEW_FORMAT);
        let irradiance = table("atmosphere sky irradiance", settings.irradiance_lut, LUT_FORMAT);
        use wgpu::BindingResource::TextureView as View;
        let compute = |layout: &wgpu::BindGroupLayout, entry_point: &str| {
            compute_pipeline(
                device,
                entry_point,
                &pipeline_layout(device, entry_point, &[layout]),
                &module,
                entry_point,
            )
        };
        let u = uniforms.as_entire_binding();

        // The fixed tables, once: the view's part of the uniforms plays no part in them.
        let still = SkyView {
            view_world_from_clip: glam::DMat4::IDENTITY,
            up: glam::DVec3::Z,
            sun_dir: glam::DVec3::Z,
            altitude_m: 0.0,
        };
        let phase_moments = phase_moments(&settings.air);
        gpu.queue.write_buffer(
            &uniforms,
            0,
            bytemuck::bytes_of(&frame_uniforms(settings, &still, phase_moments)),
        );
        let fixed = [
            {
                let layout = TRANSMITTANCE_BINDINGS.layout(device);
                let group = TRANSMITTANCE_BINDINGS.bind_group(
                    device,
                    &layout,
                    [u.clone(), View(&transmittance.view)],
                );
                (compute(&layout, "transmittance_lut"), group, transmittance.workgroups())
            },
            {
                let layout = MULTIPLE_BINDINGS.layout(device);
                let views = [View(&transmittance.view), View(&multiple.view)];
                let [a, b] = views;
                let group = MULTIPLE_BINDINGS.bind_group(device, &layout, [u.clone(), a, b]);
                (compute(&layout, "multiple_scattering_lut"), group, multiple.workgroups())
            },
            {
                let layout = IRRADIANCE_BINDINGS.layout(device);
                let group = IRRADIANCE_BINDINGS.bind_group(
                    device,
                    &layout,
                    [u.clone(), View(&transmittance.view), View(&multiple.view), View(&irradiance.view)],
                );
                (compute(&layout, "irradiance_lut"), group, irradiance.workgroups())
            },
            {
                let layout = DAYLIGHT_BINDINGS.layout(device);
                let group = DAYLIGHT_BINDINGS.bind_group(
                    device,
                    &layout,
                    [
                        u.clone(),
                        View(&transmittance.view),
                        View(&irradiance.view),
                        daylight.as_entire_binding(),
                    ],
                );
                (compute(&layout, "daylight_balance"), group, [1, 1, 1])
            },
        ];
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("atmosphere tables"),
                timestamp_writes: None,
            });
            // In order: each reads the tables before it.
            for (pipeline, group, workgroups) in &fixed {
                pass.set_pipeline(pipeline);
                pass.set_bind_group(0, group, &[]);
                Counting::OFF.dispatch(&mut pass, *workgroups);
            }
        }
        gpu.queue.submit([encoder.finish()]);

        let layout = SKY_VIEW_BINDINGS.layout(device);
        let sky_view_group = SKY_VIEW_BINDINGS.bind_group(
            device,
            &layout,
            [u.clone(), View(&transmittance.view), View(&multiple.view), View(&sky_view.view)],
        );
        let sky_view_pipeline = compute(&layout, "sky_view_lut");
        let linear = wgpu::SamplerDescriptor {
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        };
        let sky_sampler =
            device.create_sampler(&wgpu::SamplerDescriptor { label: Some("sky view"), ..linear.clone() });
        let d = daylight.as_entire_binding();
        let layout = SKY_BINDINGS.layout(device);
        let table_group = SKY_BINDINGS.bind_group(
            device,
            &layout,
            [
                u.clone(),
                d.clone(),
                View(&transmittance.view),
                View(&sky_view.view),
                wgpu::BindingResource::Sampler(&sky_sampler),
            ],
        );
        let table_sky = (sky_pipeline(device, &module, &layout, "fs_sky"), table_group);
        let layout = SKY_MARCHED_BINDINGS.layout(device);
        let marched_group = SKY_MARCHED_BINDINGS.bind_group(
            device,
            &layout,
            [u.clone(), d, View(&transmittance.view), View(&multiple.view)],
        );
        let marched_sky = (sky_pipeline(device, &module, &layout, "fs_sky_marched"), marched_group);
        let aerial = ["aerial perspective in-scattering", "aerial perspective transmittance"]
            .map(|label| aerial_volume(device, label, settings.aerial_perspective_lut));
        let layout = AERIAL_BINDINGS.layout(device);
        let views = aerial.each_ref().map(|t| t.create_view(&Default::default()));
        let aerial_group = AERIAL_BINDINGS.bind_group(
            device,
            &layout,
            [u, View(&transmittance.view), View(&multiple.view), View(&views[0]), View(&views[1])],
        );
        let aerial_pipeline = compute(&layout, "aerial_perspective_lut");
        let aerial_sampler =
            device.create_sampler(&wgpu::SamplerDescriptor { label: Some("aerial perspective"), ..linear });
        let air = Air::new(
            device,
            &uniforms,
            &daylight,
            [&transmittance.view, &irradiance.view, &multiple.view],
            &views,
            &aerial_sampler,
        );
        Self {
            settings: settings.clone(),
            phase_moments,
            uniforms,
            transmittance,
            multiple,
            sky_view,
            irradiance,
            daylight,
            sky_view_pipeline,
            sky_view_group,
            sky: [table_sky, marched_sky],
            aerial,
            aerial_pipeline,
            aerial_group,
            air,
        }
    }

    /// What the lit passes bind at `AIR_GROUP`: its layout for their pipelines, its group to set.
    pub fn air(&self) -> &Air {
        &self.air
    }

    /// Writes the frame's uniforms for `view`, aerial perspective as `live` has it now (a viewer
    /// turns it; the air and the tables' sizes stay the pass's own, fixed when it was built).
    pub fn prepare(&self, queue: &Queue, view: &SkyView, live: &AtmosphereSettings) {
        let settings =
            AtmosphereSettings { aerial_perspective: live.aerial_perspective, ..self.settings.clone() };
        let uniforms = frame_uniforms(&settings, view, self.phase_moments);
        self.air.marched.set(uniforms.up[3] - uniforms.radii[0] > SKY_MARCHED_ABOVE_KM);
        queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms));
    }

    /// Records the sky-view table for the frame's view.
    pub fn encode_sky_view(&self, encoder: &mut wgpu::CommandEncoder, counting: Counting<'_>) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("atmosphere sky view"),
            timestamp_writes: None,
        });
        counting.begin(&mut pass, Part::Whole);
        pass.set_pipeline(&self.sky_view_pipeline);
        pass.set_bind_group(0, &self.sky_view_group, &[]);
        self.sky_view.dispatch(&mut pass, counting);
        counting.end(&mut pass);
    }

    /// Records the sky over the frame's (colour, depth) targets where the depth still holds the
    /// far plane.
    pub fn encode_sky(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (colour, depth): (&wgpu::TextureView, &wgpu::TextureView),
        counting: Counting<'_>,
    ) {
        let mut pass = frame_pass(encoder, "sky", colour, depth, None, None);
        counting.begin(&mut pass, Part::Whole);
        let (pipeline, group) = &self.sky[usize::from(self.air.marched())];
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        counting.draw(&mut pass, 0..3, 0..1);
        counting.end(&mut pass);
    }

    /// Records the aerial-perspective volume for the frame's view, which the ground, the seeds
    /// and the texcells are seen through.
    pub fn encode_aerial(&self, encoder: &mut wgpu::CommandEncoder, counting: Counting<'_>) {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("aerial perspective"),
            timestamp_writes: None,
        });
        counting.begin(&mut pass, Part::Whole);
        pass.set_pipeline(&self.aerial_pipeline);
        pass.set_bind_group(0, &self.aerial_group, &[]);
        let [w, h, _] = self.settings.aerial_perspective_lut;
        counting.dispatch(&mut pass, [w.div_ceil(ATMOSPHERE_WORKGROUP), h.div_ceil(ATMOSPHERE_WORKGROUP), 1]);
        counting.end(&mut pass);
    }

    /// The aerial-perspective volume as the GPU made it (in-scattering, transmittance; slice by
    /// slice, row by row), waiting for it: for tests and tools.
    pub fn read_back_aerial(&self, gpu: &Gpu) -> Result<[Vec<[f32; 4]>; 2], GpuError> {
        let read = |texture: &wgpu::Texture| -> Result<Vec<[f32; 4]>, GpuError> {
            Ok(f16_texels(&read_texture_slices(gpu, texture, 8)?))
        };
        Ok([read(&self.aerial[0])?, read(&self.aerial[1])?])
    }

    /// The four tables as the GPU made them (transmittance, multiple scattering, sky view, sky
    /// irradiance), waiting for it: for tests and tools, never the frame.
    pub fn read_back(&self, gpu: &Gpu) -> Result<[Vec<[f32; 4]>; 4], GpuError> {
        Ok([
            self.transmittance.read_back(gpu)?,
            self.multiple.read_back(gpu)?,
            self.sky_view.read_back(gpu)?,
            self.irradiance.read_back(gpu)?,
        ])
    }

    /// The daylight balance every lit pass and the display read: 1 / daylight's light per channel.
    pub fn daylight(&self) -> &wgpu::Buffer {
        &self.daylight
    }

    /// The display's daylight balance as the GPU made it (rgb), waiting for it: for tests.
    pub fn read_back_daylight(&self, gpu: &Gpu) -> Result<[f32; 4], GpuError> {
        let bytes = read_buffer(gpu, &self.daylight, size_of::<[f32; 4]>() as u64)?;
        Ok(bytemuck::pod_read_unaligned(&bytes))
    }
}

fn sky_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    layout: &wgpu::BindGroupLayout,
    fragment: &str,
) -> wgpu::RenderPipeline {
    let layout = pipeline_layout(device, fragment, &[layout]);
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("sky"),
        layout: Some(&layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some("vs_sky"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment),
            compilation_options: Default::default(),
            targets: &[Some(COLOUR_FORMAT.into())],
        }),
        primitive: Default::default(),
        // Only where nothing was drawn: the depth target still holds the far plane (reversed-Z 0).
        depth_stencil: Some(depth_equal(DEPTH_FORMAT)),
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}
