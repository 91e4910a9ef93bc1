//! How it works: counting a render pass's fragments against the pixels it changes, the measure of
//! its overdraw (`gpu.count_fragments`, for `profile`). Alpha-tested foliage shades many fragments
//! per pixel it finally shows: the cut-out planes' transparent texels, and the planes behind
//! others. The fragments shaded come from a pipeline-statistics query around the pass's draws
//! (`FRAGMENT_SHADER_INVOCATIONS`: what the driver ran, discarded fragments included, so the
//! shaders are not changed by the measure); the pixels covered are those whose colour the pass
//! changed, found by copying the colour target before and after the pass and comparing the copies
//! once the frame is done. The readback blocks, so a counting renderer's frames are serialised;
//! the timings of such a flight are not the ones to quote.
//!
//! What an invocation is belongs to the adapter. Mesa's llvmpipe (lavapipe) runs the shader on
//! whole 4 × 4 blocks and counts 16 for each block it runs, whatever part of it the triangle
//! covers: the lanes it pays for, an upper bound of the fragments (`tests/overdraw.rs`: a
//! full-screen triangle, which its clipper cuts at the screen's edge into a fan of three, counts
//! each pixel once and the blocks along the shared edges twice). It counts them before its early
//! depth test, so a fragment hidden by a nearer one counts as much as a shaded one. Hardware GPUs
//! shade 2 × 2 quads and count the covered fragments that pass their early tests, helper lanes not
//! included.
//!
//! The fragments shaded are the frame's counts' (`gpu::counts`: the pass's shading draws' query,
//! and its prepass's apart), which also give the vertex shader's invocations and the triangles the
//! clipper passes on: fragments per triangle tell a pass of small triangles (llvmpipe: about a
//! block, 16 lanes, each) from one of large, overlapping ones. A counting renderer waits for each
//! frame, so its counts have arrived when the pixels are read.
//!
//! Two more figures do not depend on the adapter. An occlusion query over the same draws counts
//! the samples that passed the depth test and were not discarded: those written, overwritten ones
//! included, a lower bound of the fragments shaded in any order. A pass with a depth prepass
//! (`draw_seeds.depth_prepass`) counts the prepass's invocations apart, and its
//! shading draws' written samples are then exactly the fragments that reach the lighting on a GPU
//! that tests depth before shading.

use super::counts::FrameCounts;
use super::readback::{read_buffer, read_texture};
use super::resources::frame_pass;
use super::{Gpu, GpuError};

/// What one counted pass did in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct PassFragments {
    /// The pass's label, as the profiler times it.
    pub label: &'static str,
    /// Fragment shader invocations of the shading draws, discarded ones included.
    pub shaded: u64,
    /// Fragment shader invocations of the depth prepass (0 without one): alpha tests, no lighting.
    pub prepass_shaded: u64,
    /// Vertex shader invocations of the shading draws (the prepass runs as many again).
    pub vertices: u64,
    /// Triangles the shading draws sent to the rasteriser (after clipping; those whose vertices
    /// a draw collapsed out of the view are not among them).
    pub triangles: u64,
    /// Samples of the shading draws that passed the depth test and were not discarded.
    pub written: u64,
    /// Pixels whose colour the pass changed.
    pub covered_px: u64,
}

/// The occlusion queries and colour copies of the passes `labels` names, for one frame at a time.
pub struct FragmentCounter {
    labels: Vec<&'static str>,
    /// Per pass, the shading draws' samples written.
    occlusion: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    /// Per pass, the colour target before and after it.
    copies: Vec<[wgpu::Texture; 2]>,
    texel_bytes: u32,
}

/// One counted pass of the frame being recorded: `begin`/`end` around its draws.
#[derive(Clone, Copy)]
pub struct CountedPass<'a> {
    counter: &'a FragmentCounter,
    index: u32,
}

impl<'a> CountedPass<'a> {
    /// The occlusion queries: the render pass the counted draws are in must be begun with them.
    pub fn occlusion_set(self) -> &'a wgpu::QuerySet {
        &self.counter.occlusion
    }

    /// Starts counting the samples the pass's shading draws write (their invocations are the
    /// frame's counts' `Part::Shading`).
    pub fn begin(self, pass: &mut wgpu::RenderPass) {
        pass.begin_occlusion_query(self.index);
    }

    /// Stops counting the shading draws (call after the last).
    pub fn end(self, pass: &mut wgpu::RenderPass) {
        pass.end_occlusion_query();
    }

    /// Counts a pass that draws nothing this frame: an empty render pass (labelled `label`, over
    /// `colour` and `depth`) still ends its query, at zero.
    pub fn nothing(
        self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        let mut pass = frame_pass(encoder, label, colour, depth, None, Some(self.occlusion_set()));
        self.begin(&mut pass);
        self.end(&mut pass);
    }
}

impl PassFragments {
    /// Adds `other`'s counts to these (the label stays).
    pub fn add(&mut self, other: &Self) {
        self.shaded += other.shaded;
        self.prepass_shaded += other.prepass_shaded;
        self.vertices += other.vertices;
        self.triangles += other.triangles;
        self.written += other.written;
        self.covered_px += other.covered_px;
    }
}

impl FragmentCounter {
    /// The passes it counts.
    pub fn labels(&self) -> &[&'static str] {
        &self.labels
    }

    /// Counts the passes `labels` over `colour` (a `COPY_SRC` 2D colour target); `None` when the
    /// adapter has no pipeline-statistics queries (the frame's counts then have no invocations).
    pub fn new(gpu: &Gpu, labels: &[&'static str], colour: &wgpu::Texture) -> Option<Self> {
        if !gpu.device.features().contains(wgpu::Features::PIPELINE_STATISTICS_QUERY) {
            return None;
        }
        let texel_bytes = colour.format().block_copy_size(None)?;
        let count = labels.len() as u32;
        let query_set = |label, ty, count| {
            gpu.device.create_query_set(&wgpu::QuerySetDescriptor { label: Some(label), ty, count })
        };
        let occlusion = query_set("samples written", wgpu::QueryType::Occlusion, count);
        let resolved = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("samples written"),
            size: u64::from(count) * 8,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let copy = || {
            gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("colour before/after a counted pass"),
                size: colour.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: colour.format(),
                usage: wgpu::TextureUsages::COPY_DST | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        let copies = labels.iter().map(|_| [copy(), copy()]).collect();
        Some(Self { labels: labels.to_vec(), occlusion, resolved, copies, texel_bytes })
    }

    /// Records pass `label` (one of this counter's) between copies of `colour`; `record` gets the
    /// handle to count its draws with. A pass it does not count is recorded as it is.
    pub fn around<R>(
        counter: Option<&Self>,
        label: &str,
        encoder: &mut wgpu::CommandEncoder,
        colour: &wgpu::Texture,
        record: &dyn Fn(&mut wgpu::CommandEncoder, Option<CountedPass<'_>>) -> R,
    ) -> R {
        let Some((counter, index)) =
            counter.and_then(|c| Some((c, c.labels.iter().position(|&l| l == label)? as u32)))
        else {
            return record(encoder, None);
        };
        let [before, after] = &counter.copies[index as usize];
        encoder.copy_texture_to_texture(colour.as_image_copy(), before.as_image_copy(), colour.size());
        let result = record(encoder, Some(CountedPass { counter, index }));
        encoder.copy_texture_to_texture(colour.as_image_copy(), after.as_image_copy(), colour.size());
        result
    }

    /// Copies the queries into a readable buffer: call on the frame's last encoder.
    pub fn resolve(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.resolve_query_set(&self.occlusion, 0..self.labels.len() as u32, &self.resolved, 0);
    }

    /// Waits for the frame and returns each counted pass's samples written and pixels covered,
    /// its invocations not yet in (`with_counts` adds them once the frame's counts arrive).
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<PassFragments>, GpuError> {
        let count = self.labels.len();
        let written: Vec<u64> =
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, &self.resolved, count as u64 * 8)?);
        let texel = self.texel_bytes as usize;
        self.labels
            .iter()
            .zip(&self.copies)
            .zip(written)
            .map(|((&label, [before, after]), written)| {
                let aspect = wgpu::TextureAspect::All;
                let (before, after) = (
                    read_texture(gpu, before, aspect, self.texel_bytes)?,
                    read_texture(gpu, after, aspect, self.texel_bytes)?,
                );
                let covered_px =
                    before.chunks_exact(texel).zip(after.chunks_exact(texel)).filter(|(b, a)| b != a).count()
                        as u64;
                Ok(PassFragments { label, written, covered_px, ..Default::default() })
            })
            .collect()
    }
}

/// `passes` (from `FragmentCounter::read`) with the fragments shaded, vertices and triangles of
/// their shading draws and the fragments of their prepass, from the frame's `counts` (a pass that
/// drew nothing has none: zero).
pub fn with_counts(mut passes: Vec<PassFragments>, counts: &FrameCounts) -> Vec<PassFragments> {
    for pass in &mut passes {
        let counted = counts.pass(pass.label);
        let shading = counted.and_then(|c| c.shading).unwrap_or_default();
        pass.shaded = shading.fragment_invocations;
        pass.vertices = shading.vertex_invocations;
        pass.triangles = shading.clipped_triangles;
        pass.prepass_shaded = counted.and_then(|c| c.prepass).unwrap_or_default().fragment_invocations;
    }
    passes
}
