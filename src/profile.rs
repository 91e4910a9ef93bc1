//! How it works: per-pass profiling of a flight (`terramp profile`), after Table 1 of Amara et al.
//! (2007). A `Session` drives the renderer along a camera path: warm-up frames first (caches fill,
//! shaders compile), then the profiled frames, with at most two frames in flight as a swapchain
//! would allow, so the frame rate is the GPU's and the CPU's, not the CPU running ahead. It records
//! into a `Recording`, keyed by frame number:
//! - each frame's start and wall time (start to the next frame's start, waits for the GPU included);
//! - every timed scope of each frame, from the profiler's history (GPU passes with their timestamp
//!   queries, or CPU-timed with a wait per pass on adapters without them; CPU work: terrain LOD
//!   selection, streaming and uploads, TLM analysis). Those arrive a frame or two late and are
//!   attributed to the frame they were recorded in;
//! - pass 3's seed counters, which also arrive late, attributed to their own frame (`SeedReport.frame`);
//! - each frame's counts (`gpu::counts`: draws, triangles, invocations, bytes per pass), late too,
//!   by their own frame.
//!
//! Labels are whatever the frame times: no pass list is fixed here. `Summary` turns a recording
//! into per-pass median and 95th percentile (see `stats` for the definitions), per-frame totals,
//! frames per second, seeds per frame and the counts' sums (`counts`); it serialises to the JSON of `--json`, `table` prints it
//! like the paper's table and `trace` writes the recording as a Chrome trace.

use std::collections::BTreeMap;

use serde::Serialize;
use thiserror::Error;

use crate::frame::{RenderError, SeedReport};
use crate::gpu::GpuError;
use crate::gpu::counts::FrameCounts;
use crate::gpu::fragments::PassFragments;
use crate::gpu::profiler::ScopeTiming;

pub mod counts;
pub mod session;
pub mod stats;
pub mod summary;
pub mod table;
pub mod trace;

pub use session::{Session, default_path, fly, load_path, orbit_path, timing_of};
pub use summary::{Meta, Summary};

/// Why a profiled flight, or writing what it measured, failed.
#[derive(Debug, Error)]
pub enum ProfileError {
    /// A frame failed to render.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// Waiting for the GPU between frames or at the end, or draining the profiler, failed.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// A height tile could not be read while laying out the default orbit path.
    #[error(transparent)]
    Pack(#[from] crate::dataset::PackError),
    /// The embedded default camera path does not parse.
    #[error(transparent)]
    Path(#[from] crate::path::PathError),
    /// A line of the per-frame JSON log (`fly`'s `log`) could not be written.
    #[error("writing the frame log: {0}")]
    Log(std::io::Error),
    /// An output file (the Chrome trace) could not be created or written.
    #[error("writing {path}: {source}")]
    Write {
        /// The file being written, as given.
        path: String,
        /// What the file system said.
        source: std::io::Error,
    },
}

/// When one profiled frame ran.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FrameSample {
    /// The renderer's frame number.
    pub frame: u64,
    /// Its start on the profiler's CPU clock (`Profiler::now_ms`), ms.
    pub start_ms: f64,
    /// From its start to the next frame's start, ms.
    pub wall_ms: f64,
}

/// Pass 3's counters of one frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct SeedSample {
    /// The renderer's frame number the counters are from (they arrive a frame or two later).
    pub frame: u64,
    /// Ring-0 cells pass 3 checked.
    pub cells: u32,
    /// Ranks checked in each cell: the first seeds of its pattern, those some class can grow.
    pub ranks: u32,
    /// Seeds checked, `cells × ranks`.
    pub checked: u32,
    /// Seeds that passed every cull, overflow included.
    pub selected: u32,
    /// Selected seeds left out because the record buffer (`seeds.capacity`) was full.
    pub overflow: u32,
}

impl From<&SeedReport> for SeedSample {
    fn from(r: &SeedReport) -> Self {
        Self {
            frame: r.frame,
            cells: r.cells,
            ranks: r.ranks,
            checked: r.counters.checked,
            selected: r.counters.selected,
            overflow: r.counters.overflow,
        }
    }
}

/// Everything a session measured.
#[derive(Debug, Clone, Default)]
pub struct Recording {
    /// The profiled frames, in order (warm-up frames are not in it).
    pub frames: Vec<FrameSample>,
    /// Timed scopes by frame number, in recording order (warm-up frames' too).
    pub scopes: BTreeMap<u64, Vec<ScopeTiming>>,
    /// Seed counters by the frame they count.
    pub seeds: BTreeMap<u64, SeedSample>,
    /// The foliage passes' fragments and pixels by frame (with `gpu.count_fragments`).
    pub fragments: BTreeMap<u64, Vec<PassFragments>>,
    /// Each frame's counts by the frame they count.
    pub counts: BTreeMap<u64, FrameCounts>,
}

impl Recording {
    /// The profiled frames' numbers, for filtering what arrived late.
    pub fn is_profiled(&self, frame: u64) -> bool {
        self.frames.binary_search_by_key(&frame, |f| f.frame).is_ok()
    }

    /// The scopes of the profiled frames.
    pub fn profiled_scopes(&self) -> impl Iterator<Item = (&FrameSample, &[ScopeTiming])> {
        self.frames.iter().filter_map(|f| Some((f, self.scopes.get(&f.frame)?.as_slice())))
    }

    /// The seed counters of the profiled frames.
    pub fn profiled_seeds(&self) -> impl Iterator<Item = &SeedSample> {
        self.seeds.values().filter(|s| self.is_profiled(s.frame))
    }

    /// Adds `other`'s frames after this recording's, renumbered past its last frame, so that
    /// flights of separate renderers (each numbering its frames from 0) pool into one recording.
    /// The start times stay on each renderer's own clock: only wall times are pooled.
    pub fn append(&mut self, other: Recording) {
        let last = [
            self.frames.last().map(|f| f.frame),
            self.scopes.keys().next_back().copied(),
            self.seeds.keys().next_back().copied(),
            self.fragments.keys().next_back().copied(),
            self.counts.keys().next_back().copied(),
        ];
        let offset = last.into_iter().flatten().max().map_or(0, |f| f + 1);
        self.frames.extend(other.frames.into_iter().map(|f| FrameSample { frame: f.frame + offset, ..f }));
        self.scopes.extend(other.scopes.into_iter().map(|(frame, scopes)| (frame + offset, scopes)));
        self.seeds.extend(
            other
                .seeds
                .into_iter()
                .map(|(frame, s)| (frame + offset, SeedSample { frame: frame + offset, ..s })),
        );
        self.fragments.extend(other.fragments.into_iter().map(|(frame, f)| (frame + offset, f)));
        self.counts.extend(
            other
                .counts
                .into_iter()
                .map(|(frame, c)| (frame + offset, FrameCounts { frame: frame + offset, ..c })),
        );
    }

    /// The counts of the profiled frames, in frame order.
    pub fn profiled_counts(&self) -> impl Iterator<Item = &FrameCounts> {
        self.counts.iter().filter(|(frame, _)| self.is_profiled(**frame)).map(|(_, c)| c)
    }

    /// The fragment counts of the profiled frames.
    pub fn profiled_fragments(&self) -> impl Iterator<Item = &[PassFragments]> {
        self.fragments.iter().filter(|(frame, _)| self.is_profiled(**frame)).map(|(_, f)| f.as_slice())
    }
}

/// How the paper's Table 1 names a pass, for the labels it has a row for.
pub fn paper_name(label: &str) -> Option<&'static str> {
    Some(match label {
        "terrain" => "terrain mesh",
        "tile_load_map" => "pass 1",
        "ground" => "pass 2",
        "seed_select" => "pass 3",
        "compact" | "draw_seeds" => "pass 4",
        "streaming" => "streaming + uploads",
        _ => return None,
    })
}

#[cfg(test)]
pub(crate) mod test_data {
    use super::*;
    use crate::gpu::{PassTiming, TimeSource};

    pub fn scope(label: &str, source: TimeSource, start_ms: f64, ms: f64) -> ScopeTiming {
        ScopeTiming { timing: PassTiming { label: label.into(), ms, source }, start_ms }
    }

    /// Four profiled frames (10..14) of 20 ms each, with GPU passes on a clock 1000 ms ahead.
    pub fn recording() -> Recording {
        let mut r = Recording::default();
        for i in 0..4u64 {
            let frame = 10 + i;
            let start_ms = 100.0 + 20.0 * i as f64;
            r.frames.push(FrameSample { frame, start_ms, wall_ms: 20.0 });
            let k = i as f64;
            let gpu = 1100.0 + 20.0 * k;
            let mut scopes = vec![
                scope("streaming", TimeSource::Cpu, start_ms + 1.0, 2.0 + k),
                scope("terrain", TimeSource::GpuTimestamps, gpu + 3.0, 4.0 + k),
                scope("tile_load_map", TimeSource::GpuTimestamps, gpu + 8.0, 1.0),
            ];
            if i > 0 {
                scopes.push(scope("seed_select", TimeSource::GpuTimestamps, gpu + 10.0, 3.0));
            }
            r.scopes.insert(frame, scopes);
            r.seeds.insert(
                frame,
                SeedSample { frame, cells: 2, ranks: 5, checked: 10, selected: i as u32, overflow: 0 },
            );
        }
        // A warm-up frame's late arrivals are kept but not profiled.
        r.scopes.insert(9, vec![scope("terrain", TimeSource::GpuTimestamps, 1000.0, 50.0)]);
        r.seeds.insert(9, SeedSample { frame: 9, cells: 1, ranks: 1, checked: 1, selected: 1, overflow: 0 });
        r
    }
}
