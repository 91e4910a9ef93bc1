//! How it works: `Summary::new` reduces a `Recording` to the figures of the table and of the JSON.
//! Per label, a frame's sample is the sum of that label's scopes in the frame (a CPU scope such as
//! the TLM analysis may run twice in a frame, or not at all); the label's statistics are over the
//! profiled frames where it ran (`samples` says how many). Rows come in frame order: a label first
//! seen in a later frame is placed after the label it followed there. GPU passes come first,
//! then CPU work. Totals sum each frame's GPU passes and its CPU work. Frames per second come
//! from the wall times: the median's reciprocal, and frames over total time. Seeds per frame are
//! medians over the profiled frames whose counters arrived.
//!
//! The JSON (`--json`) is this struct, serialised:
//! ```text
//! { "schema": "terramp-profile/1", "adapter": str, "timing": "gpu_timestamps" | "cpu_wait",
//!   "timing_note": str, "resolution": [w, h], "preset": str, "settings": str | null,
//!   "dataset": str, "path": str,
//!   "frames": { "warmup", "profiled", "first", "last", "with_gpu_timings": int },
//!   "fps": { "median", "mean": float },
//!   "passes": [ { "label": str, "source": "gpu_timestamps" | "cpu_wait" | "cpu",
//!                 "median_ms", "p95_ms", "mean_ms", "max_ms": float, "samples": int } ],
//!   "totals": { "gpu": stat | null, "cpu": stat | null, "frame_wall": stat | null },
//!   "seeds": { "frames": int, "checked_median": float | null, "selected_median": float | null,
//!              "overflow_frames": int,
//!              "per_frame": [ { "frame", "cells", "ranks", "checked", "selected", "overflow" } ] },
//!   "overdraw": [ ... ], "counts": { ... } }
//! ```
//! where a stat is `{ "median_ms", "p95_ms", "mean_ms", "max_ms", "samples" }`; `overdraw` (with
//! `gpu.count_fragments`) is `Overdraw`'s, `counts` is `profile::counts`' (its doc has the layout).

use std::collections::HashMap;

use serde::Serialize;

use super::counts::Counts;
use super::stats::{Stat, median};
use super::{Recording, SeedSample};
use crate::gpu::TimeSource;
use crate::gpu::fragments::PassFragments;

/// The version of the JSON layout.
pub const SCHEMA: &str = "terramp-profile/1";

/// What was profiled, and how.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Meta {
    /// The GPU adapter: name, backend, device type and driver (`Gpu::describe`).
    pub adapter: String,
    /// How GPU passes were timed.
    pub timing: TimeSource,
    /// Why, in words (for the table).
    pub timing_note: String,
    /// Viewport rendered, `[width, height]` in pixels.
    pub resolution: [u32; 2],
    /// The settings preset the run started from (in a sweep, the variant's label).
    pub preset: String,
    /// The settings file, if one overrode the preset.
    pub settings: Option<String>,
    /// The dataset's folder.
    pub dataset: String,
    /// The camera path file, or a description of the generated one.
    pub path: String,
    /// Warm-up frames rendered before the profiled ones and left out of every figure.
    pub warmup: u32,
}

/// How many frames the figures cover (`"frames"` in the JSON).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Frames {
    /// Warm-up frames rendered first and not profiled.
    pub warmup: u32,
    /// Profiled frames, those with a wall time.
    pub profiled: usize,
    /// The renderer's number of the first profiled frame (`None` when none was).
    pub first: Option<u64>,
    /// The renderer's number of the last profiled frame (`None` when none was).
    pub last: Option<u64>,
    /// Profiled frames whose GPU timings arrived.
    pub with_gpu_timings: usize,
}

/// Frames per second over the profiled frames' wall times (`"fps"` in the JSON).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fps {
    /// 1000 / the median frame wall time.
    pub median: f64,
    /// Frames / their total wall time.
    pub mean: f64,
}

/// One row of the table: one timed label's statistics over the profiled frames where it ran.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassStats {
    /// The profiler's label for the scope: a pass (`terrain`, `seed_select`, …) or CPU work.
    pub label: String,
    /// How it was timed: GPU timestamps, a CPU wait per pass, or plain CPU work.
    pub source: TimeSource,
    /// Its per-frame time (the sum of its scopes in the frame), ms.
    #[serde(flatten)]
    pub stat: Stat,
}

/// Per-frame totals (`"totals"` in the JSON); `None` where no profiled frame had a sample.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Totals {
    /// Sum of each frame's GPU passes (timestamped or CPU-waited), ms.
    pub gpu: Option<Stat>,
    /// Sum of each frame's CPU work (LOD selection, streaming, TLM analysis), ms.
    pub cpu: Option<Stat>,
    /// Frame wall time, start to the next frame's start, waits for the GPU included, ms.
    pub frame_wall: Option<Stat>,
}

/// Pass 3's counters over the profiled frames (`"seeds"` in the JSON).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Seeds {
    /// Profiled frames whose counters arrived.
    pub frames: usize,
    /// Median seeds checked per frame (`None` when no counters arrived).
    pub checked_median: Option<f64>,
    /// Median seeds selected per frame, overflow included (`None` when no counters arrived).
    pub selected_median: Option<f64>,
    /// Frames whose output buffer overflowed.
    pub overflow_frames: usize,
    /// Each profiled frame's counters, in frame order.
    pub per_frame: Vec<SeedSample>,
}

/// One foliage pass's overdraw over the profiled frames (`"overdraw"` in the JSON, with
/// `gpu.count_fragments`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Overdraw {
    /// The pass's label and its counts summed over those frames (flat in the JSON).
    #[serde(flatten)]
    pub total: PassFragments,
    /// Profiled frames counted.
    pub frames: usize,
    /// `total.shaded / total.covered_px` (`None` when it covered nothing).
    pub fragments_per_covered_px: Option<f64>,
    /// `total.prepass_shaded / total.covered_px`.
    pub prepass_per_covered_px: Option<f64>,
    /// `total.written / total.covered_px`.
    pub written_per_covered_px: Option<f64>,
    /// `total.triangles / total.covered_px`.
    pub triangles_per_covered_px: Option<f64>,
    /// Median fragments shaded per frame.
    pub shaded_median: Option<f64>,
}

impl Overdraw {
    /// Per pass, in the order the frames list them.
    fn of(frames: Vec<&[PassFragments]>) -> Vec<Self> {
        // Per pass: its summed counts and each frame's fragments shaded.
        let mut rows: Vec<(PassFragments, Vec<f64>)> = Vec::new();
        for pass in frames.into_iter().flatten() {
            let at = rows.iter().position(|(total, _)| total.label == pass.label).unwrap_or_else(|| {
                rows.push((PassFragments { label: pass.label, ..Default::default() }, Vec::new()));
                rows.len() - 1
            });
            let (total, shaded) = &mut rows[at];
            total.add(pass);
            shaded.push(pass.shaded as f64);
        }
        rows.into_iter()
            .map(|(total, shaded)| {
                let per_px = |n: u64| (total.covered_px > 0).then(|| n as f64 / total.covered_px as f64);
                Self {
                    frames: shaded.len(),
                    fragments_per_covered_px: per_px(total.shaded),
                    prepass_per_covered_px: per_px(total.prepass_shaded),
                    written_per_covered_px: per_px(total.written),
                    triangles_per_covered_px: per_px(total.triangles),
                    shaded_median: median(&shaded),
                    total,
                }
            })
            .collect()
    }
}

/// A profiled flight reduced to the figures of the table and the JSON of `--json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Always `SCHEMA`, so readers can tell the layout.
    pub schema: &'static str,
    /// What was profiled, and how (its fields sit at the top level of the JSON).
    #[serde(flatten)]
    pub meta: Meta,
    /// How many frames the figures cover.
    pub frames: Frames,
    /// Frames per second; `None` when no profiled frame has a positive wall time.
    pub fps: Option<Fps>,
    /// One row per timed label: GPU passes first, then CPU work, each in frame order.
    pub passes: Vec<PassStats>,
    /// Per-frame GPU, CPU and wall-time totals.
    pub totals: Totals,
    /// Pass 3's seeds per frame.
    pub seeds: Seeds,
    /// The foliage passes' fragments per covered pixel (empty unless `gpu.count_fragments`).
    pub overdraw: Vec<Overdraw>,
    /// What each pass asked of the GPU, summed over the profiled frames.
    pub counts: Counts,
}

impl Summary {
    /// Reduces `recording` to per-label statistics, totals, frames per second and seeds per frame.
    pub fn new(recording: &Recording, meta: Meta) -> Self {
        let mut order: Vec<(String, TimeSource)> = Vec::new();
        let mut samples: HashMap<String, Vec<f64>> = HashMap::new();
        let (mut gpu_totals, mut cpu_totals) = (Vec::new(), Vec::new());
        for (_, scopes) in recording.profiled_scopes() {
            let mut previous: Option<usize> = None;
            let mut sums: Vec<(&str, f64)> = Vec::new();
            for scope in scopes {
                let t = &scope.timing;
                let at = match order.iter().position(|(label, _)| *label == t.label) {
                    Some(at) => at,
                    None => {
                        let at = previous.map_or(0, |p| p + 1);
                        order.insert(at, (t.label.clone(), t.source));
                        at
                    }
                };
                previous = Some(at);
                match sums.iter_mut().find(|(label, _)| *label == t.label) {
                    Some((_, sum)) => *sum += t.ms,
                    None => sums.push((&t.label, t.ms)),
                }
            }
            for &(label, ms) in &sums {
                samples.entry(label.to_owned()).or_default().push(ms);
            }
            let total = |gpu: bool| {
                let ms = scopes.iter().filter(|s| (s.timing.source != TimeSource::Cpu) == gpu);
                let ms: Vec<f64> = ms.map(|s| s.timing.ms).collect();
                (!ms.is_empty()).then(|| ms.iter().sum::<f64>())
            };
            gpu_totals.extend(total(true));
            cpu_totals.extend(total(false));
        }
        // GPU passes first, then CPU work; frame order within each (the sort is stable).
        order.sort_by_key(|(_, source)| *source == TimeSource::Cpu);
        let passes: Vec<PassStats> = order
            .into_iter()
            .filter_map(|(label, source)| {
                let stat = Stat::of(samples.get(&label)?)?;
                Some(PassStats { label, source, stat })
            })
            .collect();
        let labels: Vec<&str> = passes.iter().map(|p| p.label.as_str()).collect();
        let counts = Counts::of(recording, &labels);
        let wall: Vec<f64> = recording.frames.iter().map(|f| f.wall_ms).collect();
        let frame_wall = Stat::of(&wall);
        let total_s = wall.iter().sum::<f64>() / 1000.0;
        let fps = frame_wall
            .filter(|s| s.median_ms > 0.0 && total_s > 0.0)
            .map(|s| Fps { median: 1000.0 / s.median_ms, mean: wall.len() as f64 / total_s });
        let per_frame: Vec<SeedSample> = recording.profiled_seeds().copied().collect();
        let seeds = Seeds {
            frames: per_frame.len(),
            checked_median: median(&per_frame.iter().map(|s| f64::from(s.checked)).collect::<Vec<_>>()),
            selected_median: median(&per_frame.iter().map(|s| f64::from(s.selected)).collect::<Vec<_>>()),
            overflow_frames: per_frame.iter().filter(|s| s.overflow > 0).count(),
            per_frame,
        };
        let frames = Frames {
            warmup: meta.warmup,
            profiled: recording.frames.len(),
            first: recording.frames.first().map(|f| f.frame),
            last: recording.frames.last().map(|f| f.frame),
            with_gpu_timings: gpu_totals.len(),
        };
        Self {
            schema: SCHEMA,
            meta,
            frames,
            fps,
            passes,
            totals: Totals { gpu: Stat::of(&gpu_totals), cpu: Stat::of(&cpu_totals), frame_wall },
            seeds,
            overdraw: Overdraw::of(recording.profiled_fragments().collect()),
            counts,
        }
    }

    /// The pretty-printed JSON of `--json`.
    pub fn to_json(&self) -> String {
        // A struct of strings, numbers and options: serialising it cannot fail.
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

#[cfg(test)]
pub(crate) fn test_meta() -> Meta {
    Meta {
        adapter: "test adapter".into(),
        timing: TimeSource::GpuTimestamps,
        timing_note: "GPU timestamp queries".into(),
        resolution: [160, 90],
        preset: "balanced".into(),
        settings: None,
        dataset: "data/test".into(),
        path: "config/paths/default.toml".into(),
        warmup: 10,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::test_data::recording;

    #[test]
    fn passes_in_frame_order_gpu_first_with_known_statistics() {
        let summary = Summary::new(&recording(), test_meta());
        let labels: Vec<&str> = summary.passes.iter().map(|p| p.label.as_str()).collect();
        assert_eq!(labels, ["terrain", "tile_load_map", "seed_select", "streaming"]);
        let terrain = &summary.passes[0];
        // 4, 5, 6, 7 ms: the warm-up frame's 50 ms is left out.
        assert_eq!((terrain.stat.median_ms, terrain.stat.p95_ms, terrain.stat.samples), (5.5, 7.0, 4));
        assert_eq!(summary.passes[2].stat.samples, 3);
        assert_eq!(summary.passes[3].source, TimeSource::Cpu);
        let gpu = summary.totals.gpu.unwrap();
        assert_eq!((gpu.median_ms, gpu.samples), (9.5, 4)); // 5, 9, 10, 11
        let fps = summary.fps.unwrap();
        assert_eq!((fps.median, fps.mean), (50.0, 50.0));
        assert_eq!(summary.frames.first, Some(10));
        assert_eq!(summary.frames.with_gpu_timings, 4);
    }

    #[test]
    fn seeds_are_medians_over_profiled_frames() {
        let summary = Summary::new(&recording(), test_meta());
        assert_eq!(summary.seeds.frames, 4);
        assert_eq!(summary.seeds.checked_median, Some(10.0));
        assert_eq!(summary.seeds.selected_median, Some(1.5));
        assert!(summary.seeds.per_frame.iter().all(|s| s.frame >= 10));
    }

    #[test]
    fn json_has_the_documented_fields() {
        let json: serde_json::Value =
            serde_json::from_str(&Summary::new(&recording(), test_meta()).to_json()).expect("valid JSON");
        for key in ["schema", "adapter", "timing", "resolution", "preset", "dataset", "path", "frames", "fps"]
        {
            assert!(json.get(key).is_some(), "no {key} in {json}");
        }
        let pass = &json["passes"][0];
        assert_eq!(pass["label"], "terrain");
        assert_eq!(pass["source"], "gpu_timestamps");
        assert!(pass["median_ms"].as_f64().is_some() && pass["p95_ms"].as_f64().is_some());
        assert_eq!(json["seeds"]["per_frame"].as_array().map(Vec::len), Some(4));
        assert_eq!(json["timing"], "gpu_timestamps");
    }

    #[test]
    fn appended_flights_pool_their_frames_without_colliding() {
        let mut pooled = recording();
        let mut slower = recording();
        for f in &mut slower.frames {
            f.wall_ms = 40.0;
        }
        pooled.append(slower);
        let summary = Summary::new(&pooled, test_meta());
        // Both flights' frames 10..14 kept apart: 8 profiled frames, 4 at 20 ms and 4 at 40 ms.
        assert_eq!(summary.frames.profiled, 8);
        assert_eq!(summary.totals.frame_wall.unwrap().median_ms, 30.0);
        assert_eq!(summary.passes[0].stat.samples, 8);
        assert_eq!(summary.seeds.frames, 8);
        // The second flight's warm-up arrivals stay out of the profiled figures.
        assert_eq!(summary.passes[0].stat.p95_ms, 7.0);
    }

    #[test]
    fn an_empty_recording_summarises_to_nothing() {
        let summary = Summary::new(&Recording::default(), test_meta());
        assert!(summary.passes.is_empty() && summary.fps.is_none() && summary.seeds.checked_median.is_none());
    }

    #[test]
    fn overdraw_is_the_profiled_frames_fragments_over_their_covered_pixels() {
        let mut recording = recording();
        let pass = |shaded, covered_px| {
            let (prepass_shaded, written, vertices, triangles) =
                (shaded / 2, covered_px + 10, 7, covered_px / 4);
            vec![PassFragments {
                label: "draw_seeds",
                shaded,
                prepass_shaded,
                vertices,
                triangles,
                written,
                covered_px,
            }]
        };
        recording.fragments.insert(9, pass(1000, 1));
        recording.fragments.insert(10, pass(300, 100));
        recording.fragments.insert(11, pass(500, 100));
        let summary = Summary::new(&recording, test_meta());
        let [row] = summary.overdraw.as_slice() else { panic!("{:?}", summary.overdraw) };
        assert_eq!(
            (row.frames, row.total.shaded, row.total.covered_px),
            (2, 800, 200),
            "frame 9 is a warm-up frame"
        );
        assert_eq!((row.fragments_per_covered_px, row.shaded_median), (Some(4.0), Some(400.0)));
        assert_eq!((row.prepass_per_covered_px, row.written_per_covered_px), (Some(2.0), Some(1.1)));
        assert_eq!(
            (row.total.vertices, row.total.triangles, row.triangles_per_covered_px),
            (14, 50, Some(0.25))
        );
        let table = super::super::table::render(&summary);
        let lines = [
            "Overdraw draw_seeds",
            "4.00 fragments / covered pixel",
            "prepass 2.00",
            "written 1.10",
            "triangles 0.25",
        ];
        for line in lines {
            assert!(table.contains(line), "{line:?} in {table}");
        }
    }
}
