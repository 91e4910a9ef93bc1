//! How it works: drawing over a host's frame (`Renderer::render_into`). The host has drawn its
//! own geometry into its colour and depth targets (depth reversed-Z, 0 at infinity, cleared to 0
//! where it drew nothing) and submitted that work on the shared queue. terramp copies the host's
//! depth into its own depth target, and the terrain keeps it instead of clearing: the ground, the
//! trees, the Tile Load Map's occlusion and pass 3's culling all meet the host's geometry there,
//! so a tree behind the host's wall is culled, not drawn and then hidden. terramp's light starts
//! transparent; what its passes draw is opaque (the ground, the sky where nothing else is) or
//! blended over premultiplied (the texcells, the trees' resolved samples), so the light's alpha
//! is how much of each pixel terramp drew. The display shows that light over the host's colour
//! by it (the host's pixels in front stay as the host drew them), and the depth goes back to
//! the host's target, so what the host draws afterwards meets the terrain and the trees drawn
//! single-sampled (multisampled trees keep their depth in their own target).
//!
//! `render_into` submits the frame itself; `encode_frame` records the same frame into the host's
//! encoder, after the host's geometry, and leaves the submit to the host: the readbacks (which
//! map buffers, and a buffer mapped before the submit would fail it) start when the host says it
//! submitted, or at the next frame.

use super::{FrameReport, RenderError, Renderer};
use crate::camera::Camera;
use crate::passes::{DEPTH_FORMAT, HOST_HDR_FORMAT};

/// The host's colour and depth targets, of the renderer's size (`render.width` × `height`).
pub struct HostTargets<'a> {
    /// Colour, usable as a render attachment, one sample: display-ready in an sRGB format
    /// (exposed at `display.ev100`, through the tone curve; the hardware encodes on store), or
    /// linear HDR in `HOST_HDR_FORMAT` (exposed, through no curve: the host tone-maps).
    pub colour: &'a wgpu::Texture,
    /// Depth in `DEPTH_FORMAT` (32-bit float, reversed-Z: 1 at the near plane, 0 at infinity),
    /// copied from and back (`COPY_SRC | COPY_DST`), one sample.
    pub depth: &'a wgpu::Texture,
}

/// Why a host's targets cannot be drawn over.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum HostTargetError {
    /// A target's size is not the renderer's.
    #[error(
        "the host's {target} target is {size:?} pixels and the renderer's frame {frame:?}: resize one of them"
    )]
    Size {
        /// `colour` or `depth`.
        target: &'static str,
        /// The target's size.
        size: [u32; 2],
        /// The renderer's (`render.width`, `render.height`).
        frame: [u32; 2],
    },
    /// A target's format, usage or sample count is not one terramp can use.
    #[error("the host's {target} target: {why}")]
    Unusable {
        /// `colour` or `depth`.
        target: &'static str,
        /// What it must be.
        why: String,
    },
}

impl HostTargets<'_> {
    /// Whether these targets can take a frame of `frame` pixels.
    fn check(&self, frame: [u32; 2]) -> Result<(), HostTargetError> {
        for (target, texture) in [("colour", self.colour), ("depth", self.depth)] {
            let size = [texture.width(), texture.height()];
            if size != frame {
                return Err(HostTargetError::Size { target, size, frame });
            }
            if texture.sample_count() != 1 {
                let why =
                    format!("{} samples; terramp draws over single-sampled targets", texture.sample_count());
                return Err(HostTargetError::Unusable { target, why });
            }
        }
        let unusable = |target, why: String| Err(HostTargetError::Unusable { target, why });
        let (colour, depth) = (self.colour, self.depth);
        let format_ok = colour.format().is_srgb() || colour.format() == HOST_HDR_FORMAT;
        if !format_ok || !colour.usage().contains(wgpu::TextureUsages::RENDER_ATTACHMENT) {
            let why = format!(
                "{:?} with {:?}: needs an sRGB format (display-ready) or {HOST_HDR_FORMAT:?} (linear HDR) usable as a render attachment",
                colour.format(),
                colour.usage()
            );
            return unusable("colour", why);
        }
        let copies = wgpu::TextureUsages::COPY_SRC | wgpu::TextureUsages::COPY_DST;
        if depth.format() != DEPTH_FORMAT || !depth.usage().contains(copies) {
            let why = format!(
                "{:?} with {:?}: needs {DEPTH_FORMAT:?} with COPY_SRC | COPY_DST",
                depth.format(),
                depth.usage()
            );
            return unusable("depth", why);
        }
        Ok(())
    }

    /// A view of the host's colour target.
    pub(super) fn colour_view(&self) -> wgpu::TextureView {
        self.colour.create_view(&Default::default())
    }

    /// Records a copy of the host's depth into `own` (terramp's depth target, of its size).
    pub(super) fn copy_depth_in(&self, encoder: &mut wgpu::CommandEncoder, own: &wgpu::Texture) {
        encoder.copy_texture_to_texture(self.depth.as_image_copy(), own.as_image_copy(), own.size());
    }

    /// Records a copy of `own` (terramp's depth target) back into the host's depth.
    pub(super) fn copy_depth_back(&self, encoder: &mut wgpu::CommandEncoder, own: &wgpu::Texture) {
        encoder.copy_texture_to_texture(own.as_image_copy(), self.depth.as_image_copy(), own.size());
    }
}

impl Renderer {
    /// Renders one frame from `camera` over the host's frame in `host`: what the host drew there
    /// (and submitted before this call) occludes and is occluded by the terrain and the trees,
    /// and the host's depth holds theirs afterwards. terramp's own targets still hold the frame's
    /// light and depth (`read_light`, `read_depth`); its display target is not drawn. Targets it
    /// cannot use are refused with the reason, and nothing is drawn. terramp submits the frame
    /// itself; `encode_frame` records it into the host's encoder instead.
    pub fn render_into(
        &mut self,
        camera: &Camera,
        host: &HostTargets<'_>,
    ) -> Result<FrameReport, RenderError> {
        host.check([self.settings.render.width, self.settings.render.height])?;
        self.display.prepare_over(&self.gpu.device, host.colour.format());
        self.render_to(camera, Some(host))
    }

    /// Records one frame from `camera` over the host's targets into the host's `encoder`, after
    /// whatever the host recorded there before (its geometry), and submits nothing: the host
    /// submits the encoder, then may say so with `submitted`, and must before its next call to
    /// this renderer. The frame's CPU work (the LOD, the streaming, the uploads, which reach the
    /// GPU with the host's submit) runs here and waits for nothing; the readbacks of earlier
    /// frames that have arrived are taken first, so the report's `seeds` and `counts` are a frame
    /// or two older than in `render_into`'s. Without GPU timestamps the passes go untimed (timing
    /// them would mean submitting the host's encoder). `gpu.count_fragments`, which waits for each
    /// frame, is refused.
    pub fn encode_frame(
        &mut self,
        camera: &Camera,
        encoder: &mut wgpu::CommandEncoder,
        host: &HostTargets<'_>,
    ) -> Result<FrameReport, RenderError> {
        if self.fragments.is_some() {
            return Err(RenderError::FragmentsWait);
        }
        host.check([self.settings.render.width, self.settings.render.height])?;
        self.display.prepare_over(&self.gpu.device, host.colour.format());
        let (camera, mut report) = self.start_frame(camera)?;
        let frame = self.take_arrived(&mut report).and_then(|()| {
            let plan = self.prepare(&camera, &mut report)?;
            self.profiler.set_may_submit(false);
            let encoded = self.encode(encoder, &plan.nodes, &plan.tlm, Some(host));
            self.profiler.set_may_submit(true);
            encoded?;
            self.record_readbacks(encoder, plan);
            self.hosted_unsubmitted = true;
            Ok(())
        });
        self.conclude(frame, report)
    }

    /// Says that the encoder the last `encode_frame` recorded into is on the queue, so its
    /// readbacks start now instead of at the next frame. Calling it before the submit fails the
    /// submit (the readbacks' buffers would be mapped); calling it again does nothing.
    pub fn submitted(&mut self) {
        self.mark_hosted_submitted();
    }

    /// Starts the readbacks of a frame recorded into a host's encoder, if one waits.
    pub(super) fn mark_hosted_submitted(&mut self) {
        if std::mem::take(&mut self.hosted_unsubmitted) {
            self.mark_submitted();
        }
    }
}
