//! The display pass's GPU half: one full-screen triangle that reads the frame's colour target and
//! writes the display target, its pipeline built in `new` for the settings' tone curve (the
//! curve is a shader constant, so no pipeline holds the other curve's code), the exposure
//! written by `prepare` each frame (a viewer turns it).

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension as Dim};

use crate::config::{DisplaySettings, ToneCurve};
use crate::gpu::bindings::{Access, Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::gpu_types::DisplayUniforms;
use crate::gpu::resources::{buffer, pipeline_layout};
use crate::gpu::shaders::WgslSource;
use crate::gpu::{Gpu, Queue};
use crate::passes::DISPLAY_FORMAT;

use super::uniforms;

/// The display's shader.
pub const SHADER: WgslSource =
    WgslSource { name: "display", parts: &[include_str!("../../../shaders/display.wgsl")] };

/// `vs_display`, `fs_display`.
pub const BINDINGS: BindingTable<3> = BindingTable {
    label: "display",
    bindings: [
        Binding::storage::<DisplayUniforms>(0, "display", Stage::FRAGMENT, Access::Read),
        Binding::uniform::<[f32; 4]>(1, "daylight", Stage::FRAGMENT),
        Binding::texture(
            2,
            "scene",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: false },
            Dim::D2,
        ),
    ],
};

/// The display on the GPU: its pipeline, its bind group over the frame's colour target and the
/// atmosphere's daylight balance, and its uniforms.
pub struct DisplayPass {
    pipeline: wgpu::RenderPipeline,
    /// The pipeline that shows the light over a host's colour target, for its format
    /// (`prepare_over`).
    over: Option<(wgpu::TextureFormat, wgpu::RenderPipeline)>,
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    uniforms: wgpu::Buffer,
    daylight: wgpu::Buffer,
    settings: DisplaySettings,
}

impl DisplayPass {
    /// The display of `scene` (the frame's colour target) balanced by `daylight` (the atmosphere
    /// pass's), through `settings`' tone curve.
    pub fn new(
        gpu: &Gpu,
        settings: &DisplaySettings,
        scene: &wgpu::TextureView,
        daylight: &wgpu::Buffer,
    ) -> Self {
        let device = &gpu.device;
        // Storage, as the atmosphere's uniforms: lavapipe keeps a shader variant per value of a
        // uniform it sees steer code, and the exposure changes while a viewer turns it.
        let uniforms = buffer(
            device,
            "display uniforms",
            size_of::<DisplayUniforms>() as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        gpu.queue.write_buffer(&uniforms, 0, bytemuck::bytes_of(&super::uniforms(settings)));
        let layout = BINDINGS.layout(device);
        let group = bind(device, &layout, &uniforms, daylight, scene);
        let pipeline = display_pipeline(device, &layout, settings.tone_curve, Shown::Display);
        Self {
            pipeline,
            over: None,
            layout,
            group,
            uniforms,
            daylight: daylight.clone(),
            settings: settings.clone(),
        }
    }

    /// Displays `scene` from now on (the frame's light made again at another size).
    pub fn rebind(&mut self, device: &wgpu::Device, scene: &wgpu::TextureView) {
        self.group = bind(device, &self.layout, &self.uniforms, &self.daylight, scene);
    }

    /// Writes the frame's exposure as `live` has it now (the tone curve stays the pass's own).
    pub fn prepare(&mut self, queue: &Queue, live: &DisplaySettings) {
        if live.ev100 != self.settings.ev100 {
            self.settings.ev100 = live.ev100;
            queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&uniforms(&self.settings)));
        }
    }

    /// Records the display of the frame's colour target into `display` (every pixel).
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        display: &wgpu::TextureView,
        counting: Counting<'_>,
    ) {
        self.record(encoder, (&self.pipeline, &self.group), display, counting);
    }

    /// Makes the pipeline that shows the light over a host's colour target of `format` (an sRGB
    /// format, the hardware encoding on store; or a float format, which takes the light exposed
    /// and through no curve: `HOST_HDR_FORMAT`), unless it has it.
    pub fn prepare_over(&mut self, device: &wgpu::Device, format: wgpu::TextureFormat) {
        if self.over.as_ref().is_none_or(|(made, _)| *made != format) {
            let shown = Shown::Over(format);
            self.over =
                Some((format, display_pipeline(device, &self.layout, self.settings.tone_curve, shown)));
        }
    }

    /// Records the display of the frame's colour target over `host` by its coverage (the light's
    /// alpha), through the pipeline `prepare_over` made; records nothing without one.
    pub fn encode_over(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        host: &wgpu::TextureView,
        counting: Counting<'_>,
    ) {
        if let Some((_, pipeline)) = &self.over {
            self.record(encoder, (pipeline, &self.group), host, counting);
        }
    }

    /// Records the display of another light texture (`COLOUR_FORMAT`, the frame's size or any)
    /// into `display`: for tools that draw over a copy of the frame (the ground truth).
    pub fn encode_light(
        &self,
        device: &wgpu::Device,
        encoder: &mut wgpu::CommandEncoder,
        light: &wgpu::TextureView,
        display: &wgpu::TextureView,
    ) {
        let group = bind(device, &self.layout, &self.uniforms, &self.daylight, light);
        self.record(encoder, (&self.pipeline, &group), display, Counting::OFF);
    }

    fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (pipeline, group): (&wgpu::RenderPipeline, &wgpu::BindGroup),
        display: &wgpu::TextureView,
        counting: Counting<'_>,
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("display"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: display,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        counting.begin(&mut pass, Part::Whole);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, group, &[]);
        counting.draw(&mut pass, 0..3, 0..1);
        counting.end(&mut pass);
    }
}

/// Where a display pipeline writes: the display target, or over a host's colour of a format.
#[derive(Clone, Copy)]
enum Shown {
    Display,
    Over(wgpu::TextureFormat),
}

/// The display's pipeline for `curve` (a shader constant), writing as `shown` says.
fn display_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    curve: ToneCurve,
    shown: Shown,
) -> wgpu::RenderPipeline {
    let module = SHADER.module(device);
    let index = |curve: ToneCurve| f64::from(curve.index());
    let constants =
        [("TONE_CURVE", index(curve)), ("AGX", index(ToneCurve::Agx)), ("LINEAR", index(ToneCurve::Linear))];
    let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    let (entry_point, target) = match shown {
        Shown::Display => ("fs_display", DISPLAY_FORMAT.into()),
        Shown::Over(format) => {
            // Colour by the coverage over the host's; coverage as premultiplied alpha does.
            let colour = wgpu::BlendComponent {
                src_factor: wgpu::BlendFactor::SrcAlpha,
                dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
                operation: wgpu::BlendOperation::Add,
            };
            let alpha = wgpu::BlendComponent { src_factor: wgpu::BlendFactor::One, ..colour };
            let blend = Some(wgpu::BlendState { color: colour, alpha });
            let entry_point = if format.is_srgb() { "fs_display_over" } else { "fs_display_over_linear" };
            (entry_point, wgpu::ColorTargetState { format, blend, write_mask: wgpu::ColorWrites::ALL })
        }
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(entry_point),
        layout: Some(&pipeline_layout(device, "display", &[layout])),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_display"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(entry_point),
            compilation_options: options,
            targets: &[Some(target)],
        }),
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    })
}

fn bind(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    uniforms: &wgpu::Buffer,
    daylight: &wgpu::Buffer,
    light: &wgpu::TextureView,
) -> wgpu::BindGroup {
    let light = wgpu::BindingResource::TextureView(light);
    BINDINGS.bind_group(device, layout, [uniforms.as_entire_binding(), daylight.as_entire_binding(), light])
}
