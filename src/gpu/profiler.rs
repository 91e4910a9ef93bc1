//! How it works: every pass of a frame is recorded through `Profiler::pass`, which brackets it with
//! GPU timestamp queries (wgpu-profiler) when the adapter can write them inside encoders. Results
//! arrive a frame or two later, when the query buffers map, so timing never stalls the frame.
//!
//! Without timestamps the profiler falls back to CPU timing: it submits what was recorded before
//! the pass, waits, then records, submits and waits for the pass alone. That serialises the frame
//! (so it is slower), but each figure is still the pass's own wall time; into an encoder it may
//! not submit (a host's), passes go untimed. CPU work (TLM analysis, uploads) is timed with `cpu`
//! scopes either way. Timings are in milliseconds.
//!
//! Each frame is numbered by the `end_frame` calls before it. `keep_history` makes the profiler
//! also keep every finished frame with its number and each scope's start (on the GPU's timestamp
//! clock, or on the profiler's own CPU clock, `now_ms`), for `terramp profile` and its traces.

use std::time::Instant;

use wgpu_profiler::{GpuProfiler, GpuProfilerSettings, GpuTimerQueryResult};

use super::{Gpu, GpuError};

/// Frames whose GPU timings may be in flight at once. When one more ends, the newest pending one
/// is dropped (as wgpu-profiler does, so the two queues stay paired): a profiler that is never
/// read cannot grow.
const MAX_PENDING_FRAMES: usize = 4;

/// Where a timing came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeSource {
    /// GPU timestamp queries written around the pass inside its encoder.
    GpuTimestamps,
    /// CPU wall time of the pass submitted on its own and waited for (no timestamps).
    CpuWait,
    /// CPU wall time of CPU work timed with `Profiler::cpu`.
    Cpu,
}

/// How long one pass or CPU scope of a frame took.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PassTiming {
    /// The label given to `Profiler::pass` or `Profiler::cpu`.
    pub label: String,
    /// Its duration, milliseconds.
    pub ms: f64,
    /// How the duration was measured.
    pub source: TimeSource,
}

/// A timing and when it started: for `GpuTimestamps`, on the GPU's timestamp clock (its origin is
/// the driver's); else on the profiler's CPU clock (`Profiler::now_ms`).
#[derive(Debug, Clone, PartialEq)]
pub struct ScopeTiming {
    /// The scope's label, duration and source.
    pub timing: PassTiming,
    /// When it started, milliseconds, on the clock its source implies (see above).
    pub start_ms: f64,
}

/// Every scope of one frame, in the order they were recorded (CPU scopes first).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FrameTimings {
    /// `end_frame` calls before this frame's.
    pub frame: u64,
    /// Its timed scopes, each with its start.
    pub scopes: Vec<ScopeTiming>,
}

impl FrameTimings {
    fn timings(&self) -> Vec<PassTiming> {
        self.scopes.iter().map(|s| s.timing.clone()).collect()
    }
}

/// Times a frame's passes (GPU timestamps, or CPU waits without them) and its CPU work, and hands
/// each frame's timings back once they are all in.
pub struct Profiler {
    timestamps: Option<GpuProfiler>,
    /// The origin of the CPU clock.
    epoch: Instant,
    /// CPU-measured timings of the frame being recorded.
    cpu: FrameTimings,
    /// CPU timings of frames whose GPU timings are still in flight, oldest first.
    pending: std::collections::VecDeque<FrameTimings>,
    /// Finished frames, kept while `keep_history` is on.
    history: Option<Vec<FrameTimings>>,
    /// Whether `pass` may submit the encoder it is given: not one a host will submit itself.
    may_submit: bool,
}

impl Profiler {
    /// GPU timestamps when `use_timestamps` and the adapter has them, else CPU timing.
    pub fn new(gpu: &Gpu, use_timestamps: bool) -> Self {
        let timestamps = if use_timestamps && gpu.has_timestamps {
            GpuProfiler::new(
                &gpu.device,
                GpuProfilerSettings {
                    max_num_pending_frames: MAX_PENDING_FRAMES,
                    // Debug groups only serve capture tools, and Mesa lavapipe 22.3 crashes in
                    // vkCmdBeginDebugUtilsLabelEXT once compute passes share the encoder.
                    enable_debug_groups: false,
                    ..Default::default()
                },
            )
            .ok()
        } else {
            None
        };
        Self {
            timestamps,
            epoch: Instant::now(),
            cpu: FrameTimings::default(),
            pending: Default::default(),
            history: None,
            may_submit: true,
        }
    }

    /// Passes are timed with GPU timestamp queries; false: with CPU waits, which serialise the frame.
    pub fn uses_gpu_timestamps(&self) -> bool {
        self.timestamps.is_some()
    }

    /// Now on the profiler's CPU clock, ms.
    pub fn now_ms(&self) -> f64 {
        ms_since(self.epoch)
    }

    /// The number of the frame being recorded (`end_frame` calls so far).
    pub fn frame(&self) -> u64 {
        self.cpu.frame
    }

    /// Starts (or stops and forgets) keeping every finished frame for `take_history`.
    pub fn keep_history(&mut self, keep: bool) {
        self.history = keep.then(Vec::new);
    }

    /// The frames finished since the last call, oldest first (none unless `keep_history`).
    pub fn take_history(&mut self) -> Vec<FrameTimings> {
        self.history.as_mut().map(std::mem::take).unwrap_or_default()
    }

    /// Records the pass `label` into `encoder`, timed.
    pub fn pass<R>(
        &mut self,
        gpu: &Gpu,
        encoder: &mut wgpu::CommandEncoder,
        label: &str,
        record: impl FnOnce(&mut wgpu::CommandEncoder) -> R,
    ) -> Result<R, GpuError> {
        if let Some(profiler) = &self.timestamps {
            let mut scope = profiler.scope(label, encoder);
            return Ok(record(&mut scope));
        }
        if !self.may_submit {
            return Ok(record(encoder));
        }
        let new_encoder = || gpu.device.create_command_encoder(&Default::default());
        gpu.queue.submit([std::mem::replace(encoder, new_encoder()).finish()]);
        gpu.wait()?;
        let start = Instant::now();
        let result = record(encoder);
        gpu.queue.submit([std::mem::replace(encoder, new_encoder()).finish()]);
        gpu.wait()?;
        self.push_cpu(label, start, TimeSource::CpuWait);
        Ok(result)
    }

    /// Whether `pass` may submit the encoders it is given (true unless set). Without timestamps a
    /// pass is timed by submitting and waiting; into an encoder the host submits, passes are
    /// recorded untimed instead.
    pub fn set_may_submit(&mut self, may_submit: bool) {
        self.may_submit = may_submit;
    }

    /// Times CPU work of the frame being recorded.
    pub fn cpu<R>(&mut self, label: &str, work: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let result = work();
        self.push_cpu(label, start, TimeSource::Cpu);
        result
    }

    fn push_cpu(&mut self, label: &str, start: Instant, source: TimeSource) {
        let start_ms = start.saturating_duration_since(self.epoch).as_secs_f64() * 1000.0;
        let timing = PassTiming { label: label.into(), ms: ms_since(start), source };
        self.cpu.scopes.push(ScopeTiming { timing, start_ms });
    }

    /// Call on the frame's last encoder, just before it is submitted.
    pub fn resolve(&mut self, encoder: &mut wgpu::CommandEncoder) {
        if let Some(profiler) = &mut self.timestamps {
            profiler.resolve_queries(encoder);
        }
    }

    /// Call after the frame's last submit.
    pub fn end_frame(&mut self) {
        if self.pending.len() == MAX_PENDING_FRAMES {
            match self.timestamps {
                Some(_) => self.pending.pop_back(),
                None => self.pending.pop_front(),
            };
        }
        if let Some(profiler) = &mut self.timestamps {
            // Only fails on unclosed scopes, which `pass` cannot leave behind.
            let _ = profiler.end_frame();
        }
        let next = FrameTimings { frame: self.cpu.frame + 1, scopes: Vec::new() };
        self.pending.push_back(std::mem::replace(&mut self.cpu, next));
    }

    /// The timings of the oldest frame whose results are all in; `None` while they are in flight.
    pub fn finished_frame(&mut self, gpu: &Gpu) -> Option<Vec<PassTiming>> {
        let frame = match &mut self.timestamps {
            None => self.pending.pop_front()?,
            Some(profiler) => {
                let results = profiler.process_finished_frame(gpu.queue.get_timestamp_period())?;
                let mut frame = self.pending.pop_front().unwrap_or_default();
                frame.scopes.extend(flatten(&results));
                frame
            }
        };
        Some(self.finished(frame))
    }

    fn finished(&mut self, frame: FrameTimings) -> Vec<PassTiming> {
        let timings = frame.timings();
        if let Some(history) = &mut self.history {
            history.push(frame);
        }
        timings
    }

    /// Waits for every frame in flight and returns their timings, oldest first.
    pub fn drain(&mut self, gpu: &Gpu) -> Result<Vec<Vec<PassTiming>>, GpuError> {
        let mut frames = Vec::new();
        // Each frame's query buffers map on a poll after its work is done; a few polls suffice.
        let mut polls_left = 8 * self.pending.len() + 8;
        while !self.pending.is_empty() && polls_left > 0 {
            gpu.wait()?;
            polls_left -= 1;
            if let Some(frame) = self.finished_frame(gpu) {
                frames.push(frame);
            }
        }
        // Frames whose timestamps never arrived keep their CPU timings.
        while let Some(frame) = self.pending.pop_front() {
            frames.push(self.finished(frame));
        }
        Ok(frames)
    }
}

fn flatten(results: &[GpuTimerQueryResult]) -> Vec<ScopeTiming> {
    results
        .iter()
        .filter_map(|r| {
            let time = r.time.as_ref()?;
            let timing = PassTiming {
                label: r.label.clone(),
                ms: (time.end - time.start) * 1000.0,
                source: TimeSource::GpuTimestamps,
            };
            Some(ScopeTiming { timing, start_ms: time.start * 1000.0 })
        })
        .collect()
}

fn ms_since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1000.0
}
