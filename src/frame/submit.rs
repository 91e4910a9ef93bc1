//! How it works: a frame's GPU work ends in three steps around the queue's submit.
//! `record_readbacks` records, after the last pass, the copies of what comes back (the Tile Load
//! Map, pass 3's counters) and the resolves of the timing and counting queries. Once the command
//! buffer has been submitted (by terramp in `render`, or by the host that had the frame recorded
//! into its own encoder) `mark_submitted` starts the readbacks' maps and closes the profiler's
//! frame: a map asked for before the submit would fail it. `take_arrived` then takes, without
//! waiting, every readback that has arrived: the Tile Load Maps become load maps for the
//! streaming, pass 3's counters and the frame's counts go into the report.

use super::{FrameReport, LastFrame, RenderError, Renderer, TlmTag, prepare};
use crate::gpu::GpuError;
use crate::gpu::fragments::{PassFragments, with_counts};
use crate::passes::tile_load_map::analysis::analyse;

impl Renderer {
    /// Records the frame's readbacks and resolves into `encoder` (after the last timed pass: the
    /// CPU-timing fallback submits each pass's encoder on its own), keeps what tools read of the
    /// frame, and numbers the next one.
    pub(super) fn record_readbacks(&mut self, encoder: &mut wgpu::CommandEncoder, plan: prepare::FramePlan) {
        let prepare::FramePlan { layout, camera_grid_m, tlm, nodes, terrain, batches, clip_from_rel_m } =
            plan;
        let tag = TlmTag { frame: self.frame, layout, camera_grid_m };
        let before = self.tlm_readback.copied_bytes();
        self.tlm_readback.encode_copy(encoder, self.tlm.output(), tlm.output_bytes(), tag);
        self.counts.read_back("tile_load_map", self.tlm_readback.copied_bytes() - before);
        if let Some(stage) = self.seeds.as_mut() {
            stage.encode_readback(encoder, self.frame, &self.counts);
        }
        self.profiler.resolve(encoder);
        self.fragments.iter().for_each(|counter| counter.resolve(encoder));
        self.counts.resolve(encoder);
        self.last = Some(LastFrame { tlm, nodes, terrain, batches, clip_from_rel_m });
        self.frame += 1;
    }

    /// Starts the readbacks of the frame last recorded, and closes its timings: call once its
    /// command buffer is on the queue.
    pub(super) fn mark_submitted(&mut self) {
        self.counts.submitted();
        self.tlm_readback.submitted();
        if let Some(stage) = self.seeds.as_mut() {
            stage.submitted();
        }
        self.profiler.end_frame();
    }

    /// After terramp's own submit of frame `frame`: its readbacks started, its fragments read
    /// (with `gpu.count_fragments`, which waits for it), and whatever has arrived taken.
    pub(super) fn after_submit(&mut self, frame: u64, report: &mut FrameReport) -> Result<(), RenderError> {
        self.mark_submitted();
        if self.fragments.is_some() {
            report.fragments = self.read_fragments(frame, report)?;
        }
        self.take_arrived(report)
    }

    /// Takes every readback that has arrived, without waiting: the Tile Load Maps, pass 3's
    /// counters, the counts and the timings; and any GPU error raised since the last check.
    pub(super) fn take_arrived(&mut self, report: &mut FrameReport) -> Result<(), RenderError> {
        self.gpu.device.poll(wgpu::PollType::Poll).map_err(GpuError::from)?;
        self.analyse_arrived_tlms()?;
        report.tlm_readbacks_skipped = self.tlm_readback.skipped();
        if let Some(stage) = self.seeds.as_mut() {
            stage.collect(&self.gpu.device)?;
            report.seeds = stage.latest;
        }
        report.counts.extend(self.counts.collect(&self.gpu.device)?);
        while let Some(timings) = self.profiler.finished_frame(&self.gpu) {
            self.last_timings = timings;
        }
        Ok(self.gpu.check()?)
    }

    /// With `gpu.count_fragments`: waits for frame `frame`, reads the pixels its foliage passes
    /// covered, and takes its counts (and any older ones still in flight) for their invocations.
    fn read_fragments(
        &mut self,
        frame: u64,
        report: &mut FrameReport,
    ) -> Result<Vec<PassFragments>, RenderError> {
        let Some(counter) = &self.fragments else { return Ok(Vec::new()) };
        let before = self.gpu.queue.read_back_bytes();
        let passes = counter.read(&self.gpu)?;
        self.counts.read_back_late(frame, "fragments", self.gpu.queue.read_back_bytes() - before);
        report.counts.extend(self.counts.collect(&self.gpu.device)?);
        let counts = report.counts.iter().find(|c| c.frame == frame).ok_or_else(|| {
            GpuError::Validation("a frame's counts did not arrive after waiting for it".into())
        })?;
        Ok(with_counts(passes, counts))
    }

    /// Turns every TLM that has arrived into load maps, keeping the newest.
    fn analyse_arrived_tlms(&mut self) -> Result<(), RenderError> {
        while let Some(readback) = self.tlm_readback.try_take(&self.gpu.device)? {
            let TlmTag { frame, layout, camera_grid_m } = &readback.tag;
            let cells = readback.cast();
            let dataset = &self.dataset;
            let maps = self
                .profiler
                .cpu("tlm_analysis", || analyse(*frame, layout, &cells, *camera_grid_m, dataset));
            self.load_maps = Some(maps);
        }
        Ok(())
    }
}
