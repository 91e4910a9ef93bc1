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
//! full-screen triangle, clipped into two, counts each pixel once and the blocks along their shared
//! edge twice). Hardware GPUs shade 2 × 2 quads and count the covered fragments, helper lanes not
//! included.

use super::readback::{read_buffer, read_texture};
use super::resources::frame_pass;
use super::{Gpu, GpuError};

/// What one counted pass did in one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub struct PassFragments {
    /// The pass's label, as the profiler times it.
    pub label: &'static str,
    /// Fragment shader invocations, discarded ones included.
    pub shaded: u64,
    /// Pixels whose colour the pass changed.
    pub covered_px: u64,
}

/// The queries and colour copies of the passes `labels` names, for one frame at a time.
pub struct FragmentCounter {
    labels: Vec<&'static str>,
    queries: wgpu::QuerySet,
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

impl CountedPass<'_> {
    /// Starts counting the pass's fragments (call first in the render pass).
    pub fn begin(self, pass: &mut wgpu::RenderPass) {
        pass.begin_pipeline_statistics_query(&self.counter.queries, self.index);
    }

    /// Stops counting (call after the pass's last draw).
    pub fn end(self, pass: &mut wgpu::RenderPass) {
        pass.end_pipeline_statistics_query();
    }

    /// Counts a pass that draws nothing this frame: an empty render pass (labelled `label`, over
    /// `colour` and `depth`) still ends the query, at zero.
    pub fn nothing(
        self,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        colour: &wgpu::TextureView,
        depth: &wgpu::TextureView,
    ) {
        let mut pass = frame_pass(encoder, label, colour, depth, None);
        self.begin(&mut pass);
        self.end(&mut pass);
    }
}

impl FragmentCounter {
    /// Counts the passes `labels` over `colour` (a `COPY_SRC` 2D colour target); `None` when the
    /// adapter has no pipeline-statistics queries.
    pub fn new(gpu: &Gpu, labels: &[&'static str], colour: &wgpu::Texture) -> Option<Self> {
        if !gpu.device.features().contains(wgpu::Features::PIPELINE_STATISTICS_QUERY) {
            return None;
        }
        let texel_bytes = colour.format().block_copy_size(None)?;
        let count = labels.len() as u32;
        let queries = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("fragments shaded"),
            ty: wgpu::QueryType::PipelineStatistics(
                wgpu::PipelineStatisticsTypes::FRAGMENT_SHADER_INVOCATIONS,
            ),
            count,
        });
        let resolved = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fragments shaded"),
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
        Some(Self { labels: labels.to_vec(), queries, resolved, copies, texel_bytes })
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
        encoder.resolve_query_set(&self.queries, 0..self.labels.len() as u32, &self.resolved, 0);
    }

    /// Waits for the frame and returns each counted pass's fragments and pixels (every pass the
    /// counter names must have been recorded through `around` this frame).
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<PassFragments>, GpuError> {
        let shaded: Vec<u64> =
            bytemuck::pod_collect_to_vec(&read_buffer(gpu, &self.resolved, self.labels.len() as u64 * 8)?);
        let texel = self.texel_bytes as usize;
        self.labels
            .iter()
            .zip(&self.copies)
            .zip(shaded)
            .map(|((&label, [before, after]), shaded)| {
                let aspect = wgpu::TextureAspect::All;
                let (before, after) = (
                    read_texture(gpu, before, aspect, self.texel_bytes)?,
                    read_texture(gpu, after, aspect, self.texel_bytes)?,
                );
                let covered_px =
                    before.chunks_exact(texel).zip(after.chunks_exact(texel)).filter(|(b, a)| b != a).count()
                        as u64;
                Ok(PassFragments { label, shaded, covered_px })
            })
            .collect()
    }
}
