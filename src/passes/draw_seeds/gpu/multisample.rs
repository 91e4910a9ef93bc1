//! How it works: pass 4 drawn multisampled (`draw_seeds.samples` = `SEED_SAMPLES`), so that leaves
//! and billboard cut-outs are anti-aliased instead of alpha-tested at one sample per pixel. The
//! rest of the frame stays single-sampled: the seeds are drawn into their own multisampled colour
//! and depth targets, which start as the frame the earlier passes left (`fs_fill`: one triangle
//! over the view writes each pixel's colour, from a copy of the frame's, and the terrain's depth
//! to all of its samples), so trees are hidden by the terrain and stand over the ground exactly
//! as in the single-sampled draw. Each seed fragment then covers as many of its pixel's samples as
//! its sharpened alpha says (`fs_coverage`), depth-tested per sample, and the render pass resolves
//! the samples' mean into the frame's colour target. The frame's depth target keeps the terrain's
//! depth alone (nothing after pass 4 reads the trees' depth).

use wgpu::{ShaderStages as Stage, TextureSampleType, TextureViewDimension};

use crate::gpu::bindings::{Binding, BindingTable};
use crate::gpu::counter::Counting;
use crate::gpu::counts::Part;
use crate::gpu::layout::SEED_SAMPLES;
use crate::gpu::resources::pipeline_layout;
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT};

use super::SHADER;

/// `vs_fill`/`fs_fill`'s bindings: the frame's colour (a copy) and the terrain's depth.
pub const FILL_BINDINGS: BindingTable<2> = BindingTable {
    label: "draw_seeds fill",
    bindings: [
        Binding::texture(
            8,
            "frame_colour",
            Stage::FRAGMENT,
            TextureSampleType::Float { filterable: false },
            TextureViewDimension::D2,
        ),
        Binding::texture(
            9,
            "frame_depth",
            Stage::FRAGMENT,
            TextureSampleType::Depth,
            TextureViewDimension::D2,
        ),
    ],
};

/// The multisampled targets of pass 4 and the pipeline that fills them from the frame.
pub struct Multisample {
    /// The frame's colour target: copied from before, resolved into after.
    frame_colour: wgpu::Texture,
    frame_colour_view: wgpu::TextureView,
    /// The copy of the frame's colour the fill reads (the frame's own is the resolve target).
    ground: wgpu::Texture,
    colour: wgpu::TextureView,
    depth: wgpu::TextureView,
    fill: wgpu::RenderPipeline,
    fill_bind_group: wgpu::BindGroup,
}

impl Multisample {
    /// Targets of `frame_colour`'s size at `SEED_SAMPLES` samples, filled from `frame_colour` and
    /// the terrain's `frame_depth`, resolved into `frame_colour`.
    pub fn new(device: &wgpu::Device, frame_colour: &wgpu::Texture, frame_depth: &wgpu::Texture) -> Self {
        let target = |label, format, sample_count, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: frame_colour.size(),
                mip_level_count: 1,
                sample_count,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let attachment = wgpu::TextureUsages::RENDER_ATTACHMENT;
        let ground = target(
            "draw_seeds ground",
            COLOUR_FORMAT,
            1,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        let colour = target("draw_seeds colour samples", COLOUR_FORMAT, SEED_SAMPLES, attachment);
        let depth = target("draw_seeds depth samples", DEPTH_FORMAT, SEED_SAMPLES, attachment);
        let layout = FILL_BINDINGS.layout(device);
        let ground_view = ground.create_view(&Default::default());
        let depth_view = frame_depth.create_view(&Default::default());
        let fill_bind_group = FILL_BINDINGS.bind_group(
            device,
            &layout,
            [
                wgpu::BindingResource::TextureView(&ground_view),
                wgpu::BindingResource::TextureView(&depth_view),
            ],
        );
        let module = SHADER.module(device);
        let fill = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("draw_seeds fill"),
            layout: Some(&pipeline_layout(device, "draw_seeds fill", &[&layout])),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_fill"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_fill"),
                compilation_options: Default::default(),
                targets: &[Some(COLOUR_FORMAT.into())],
            }),
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Always),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: state(),
            multiview_mask: None,
            cache: None,
        });
        Self {
            frame_colour: frame_colour.clone(),
            frame_colour_view: frame_colour.create_view(&Default::default()),
            ground,
            colour: colour.create_view(&Default::default()),
            depth: depth.create_view(&Default::default()),
            fill,
            fill_bind_group,
        }
    }

    /// Records the copy of the frame's colour, then one render pass that fills the samples,
    /// lets `draw` record the seeds into them (its draws may run the `occlusion` queries) and
    /// resolves them into the frame's colour.
    pub fn encode(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        (occlusion, counting): (Option<&wgpu::QuerySet>, Counting<'_>),
        draw: impl FnOnce(&mut wgpu::RenderPass),
    ) {
        encoder.copy_texture_to_texture(
            self.frame_colour.as_image_copy(),
            self.ground.as_image_copy(),
            self.frame_colour.size(),
        );
        // Every sample is written by the fill: nothing needs loading, and nothing but the
        // resolve needs storing.
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("draw_seeds"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.colour,
                depth_slice: None,
                resolve_target: Some(&self.frame_colour_view),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Discard,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(0.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: occlusion,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.fill);
        pass.set_bind_group(0, &self.fill_bind_group, &[]);
        counting.begin(&mut pass, Part::Whole);
        counting.draw(&mut pass, 0..3, 0..1);
        counting.end(&mut pass);
        draw(&mut pass);
    }
}

/// The multisample state of pass 4's multisampled pipelines: `SEED_SAMPLES` samples, every one
/// enabled (coverage comes from `fs_coverage`'s sample mask, not from alpha).
pub fn state() -> wgpu::MultisampleState {
    wgpu::MultisampleState { count: SEED_SAMPLES, mask: !0, alpha_to_coverage_enabled: false }
}
