//! The pipelines pass 4's draws go through (`Draw`: at once or after a depth prepass, at one
//! sample a pixel or `SEED_SAMPLES`), each over the pass's own bind group and the air's.

use super::{SHADER, multisample};
use crate::gpu::gpu_types::SeedVertex;
use crate::gpu::struct_layout::GpuLayout;
use crate::passes::atmosphere::gpu::air::{AirVariants, air_constants, pipeline_layout_with_air};
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT};

/// The pipelines a frame's draws go through: at once, or after a depth prepass.
pub(super) enum Draw {
    /// Each fragment alpha-tested, shaded and its depth written in one draw.
    Plain(wgpu::RenderPipeline),
    /// `depth` writes the depth of what the draws keep (colour writes off); `shade` repeats the
    /// draws with the depth test `Equal` and no depth write, lighting one fragment per sample.
    Prepassed { depth: wgpu::RenderPipeline, shade: wgpu::RenderPipeline },
}

impl Draw {
    /// The draw at 1 sample per pixel or `SEED_SAMPLES` (`multisample`), with or without a
    /// prepass, in both of the air's variants.
    pub(super) fn variants(
        device: &wgpu::Device,
        layouts: &[wgpu::BindGroupLayout; 2],
        (multisample, prepass): (bool, bool),
    ) -> AirVariants<Self> {
        let (device, layouts) = (device.clone(), layouts.clone());
        AirVariants::new(move |marched| Self::new(&device, &layouts, (multisample, prepass), marched))
    }

    /// The draw in the air's variant `marched`.
    fn new(
        device: &wgpu::Device,
        layouts: &[wgpu::BindGroupLayout; 2],
        (multisample, prepass): (bool, bool),
        marched: bool,
    ) -> Self {
        let colour = [Some(COLOUR_FORMAT.into())];
        let no_colour =
            [Some(wgpu::ColorTargetState { write_mask: wgpu::ColorWrites::empty(), ..COLOUR_FORMAT.into() })];
        let (state, [plain, depth, shade]) = match multisample {
            false => (Default::default(), ["fs_main", "fs_depth", "fs_main"]),
            true => (multisample::state(), ["fs_coverage", "fs_depth_coverage", "fs_shade_samples"]),
        };
        let written = DepthTest::Written;
        if !prepass {
            return Self::Plain(pipeline(device, layouts, (plain, &colour), state, (written, marched)));
        }
        Self::Prepassed {
            depth: pipeline(device, layouts, (depth, &no_colour), state, (written, marched)),
            shade: pipeline(device, layouts, (shade, &colour), state, (DepthTest::EqualToWritten, marched)),
        }
    }

    /// Whether this draw has a depth prepass.
    pub(super) fn prepassed(&self) -> bool {
        matches!(self, Self::Prepassed { .. })
    }
}

/// How a pipeline of the pass tests depth (reversed-Z).
#[derive(Clone, Copy)]
pub(super) enum DepthTest {
    /// Nearer than or as near as what is there, and written.
    Written,
    /// Exactly what the prepass wrote, not written again.
    EqualToWritten,
}

/// The pipeline of `fragment` into `targets`, its air marched per pixel where `marched`.
pub(super) fn pipeline(
    device: &wgpu::Device,
    [layout, air]: &[wgpu::BindGroupLayout; 2],
    (fragment, targets): (&str, &[Option<wgpu::ColorTargetState>]),
    multisample: wgpu::MultisampleState,
    (depth_test, marched): (DepthTest, bool),
) -> wgpu::RenderPipeline {
    let (depth_write_enabled, depth_compare) = match depth_test {
        DepthTest::Written => (true, wgpu::CompareFunction::GreaterEqual),
        DepthTest::EqualToWritten => (false, wgpu::CompareFunction::Equal),
    };
    let module = SHADER.module(device);
    let pipeline_layout = pipeline_layout_with_air(device, "draw_seeds", &[layout], air);
    let attributes = SeedVertex::layout().vertex_attributes();
    let constants = air_constants(marched);
    let compilation_options =
        wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("draw_seeds"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: compilation_options.clone(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: size_of::<SeedVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &attributes,
            })],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some(fragment),
            compilation_options,
            targets,
        }),
        // A billboard is seen from both sides, and so are leaves (the glTF's double-sided ones).
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(depth_write_enabled),
            depth_compare: Some(depth_compare),
            stencil: Default::default(),
            bias: Default::default(),
        }),
        multisample,
        multiview_mask: None,
        cache: None,
    })
}
