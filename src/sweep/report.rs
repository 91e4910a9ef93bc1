//! How it works: a sweep's figures (`Trade`) and their three renderings: the JSON (this struct,
//! serialised) and the CSV (one row per point); the terminal table and Markdown tables for docs are `tables`'. PSNRs are capped at
//! `image_metrics::PSNR_CAP_DB` (identical images), so every figure is a finite number; figures a
//! point lacks (seeds on a dataset without land cover, GPU times where none arrived) are `null` in
//! the JSON and empty in the CSV.
//!
//! The JSON:
//! ```text
//! { "schema": "terramp-trade/3", "adapter": str, "timing": str, "dataset": str, "path": str,
//!   "resolution": [w, h], "warmup": int, "frames": int, "timing_rounds": int,
//!   "sample_t": [float],
//!   "popping_flight": { "frames": int, "step_m": float, "from_t": float } | null,
//!   "reference": str, "settings": str | null,
//!   "points": [ { "label": str, "preset": str, "knobs": { key: value },
//!                 "frame_ms": float, "gpu_ms", "cpu_ms", "fps", "seeds_selected": float | null,
//!                 "passes": [ { "label": str, "source": str, "median_ms": float } ],
//!                 "seeds": seeds | null, "any_part": any_part | null,
//!                 "ground_psnr_db", "frame_psnr_db", "frame_ssim", "frame_flip": float,
//!                 "photo_de2000": { "mean", "p95", "max": float } | null,
//!                 "popping": { "pairs": int, "largest", "truth_largest", "popping": float } | null,
//!                 "error": { "frame": region, "bands": [region] },
//!                 "samples": [ { "t", "ground_psnr_db", "frame_psnr_db", "frame_ssim",
//!                                "frame_flip": float, "seeds": seeds | null,
//!                                "any_part": any_part | null } ] } ] }
//! ```
//! where seeds is `{ "visible", "kept", "common": int, "recall_pct", "precision_pct",
//! "height_error_max_m", "height_error_mean_m": float }` (the exact summit oracle), any_part is
//! `{ "visible", "selected", "selected_visible": int, "recall_pct", "precision_pct",
//! "pixel_weighted_recall_pct": float, "missed_pct": { "reach", "density", "frustum",
//! "summit_hidden", "selection": float } }` (the truth's any-part oracle; why the missed samples
//! are missed, `truth::visibility::Missed`) and region is `{ "band":
//! { "name", "from_m", "to_m" }, "pixels", "mse", "psnr_db", "ssim", "flip",
//! "cover": { "truth_px", "drawn_px", "both_px": int, "truth_level_sum", "drawn_level_sum":
//! float } | null }` (`truth::compare`;
//! an infinite `to_m` and a figure of an empty band are `null`); popping is in levels of 255
//! (`reference::frame_change`). The CSV has the same figures under the same names (pass medians
//! as `<label>_ms`, seed figures without their `seeds.` prefix, the missed shares as
//! `missed_<why>_pct`, popping's as `popping`,
//! `block_change_largest` and `truth_block_change_largest`, knobs as `key=value;key=value`).

use std::collections::BTreeMap;

use serde::Serialize;

use crate::gpu::TimeSource;
use crate::photo::measure::DeltaE;
use crate::reference::accuracy::{HeightError, SeedAgreement};
use crate::reference::frame_change::Popping;
use crate::truth::compare::FrameError;
use crate::truth::visibility::{Missed, Visibility};

/// The version of the JSON layout.
pub const SCHEMA: &str = "terramp-trade/3";

/// A sweep's figures: every point's speed and accuracy over the same path and sample poses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trade {
    /// Always `SCHEMA`, so readers can tell the layout.
    pub schema: &'static str,
    /// The GPU adapter the points ran on (`Gpu::describe`).
    pub adapter: String,
    /// How GPU passes were timed, in words.
    pub timing: String,
    /// The dataset's folder.
    pub dataset: String,
    /// The camera path file, or a description of the generated one.
    pub path: String,
    /// Viewport of every point and the reference, `[width, height]` in pixels.
    pub resolution: [u32; 2],
    /// Untimed frames each point renders at the path's start, in every timing round.
    pub warmup: u32,
    /// Timed frames each point renders, spread evenly along the path.
    pub frames: u32,
    /// Rounds the timed frames were split into, every round timing each point in turn.
    pub timing_rounds: u32,
    /// Path parameters of the sample poses.
    pub sample_t: Vec<f64>,
    /// The flight popping is measured along (`None`: not measured).
    pub popping_flight: Option<PoppingFlight>,
    /// What the images are compared with.
    pub reference: String,
    /// The settings file laid over every preset, if any.
    pub settings: Option<String>,
    /// One per preset × knob values, in the order of `knobs::points`.
    pub points: Vec<TradePoint>,
}

/// The short flight of consecutive frames popping is measured along.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PoppingFlight {
    /// Frames flown.
    pub frames: u32,
    /// Metres between consecutive frames.
    pub step_m: f64,
    /// The path parameter it starts at (the middle sample pose).
    pub from_t: f64,
}

/// One point of the sweep: its timings over the flight and its accuracy at the sample poses.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TradePoint {
    /// The preset, then ` key=value` for each knob (`Point::label`).
    pub label: String,
    /// The preset the point starts from.
    pub preset: String,
    /// The knob values laid over the preset, by settings key.
    pub knobs: BTreeMap<String, String>,
    /// Median wall time of a timed frame (start to the next frame's start), ms.
    pub frame_ms: f64,
    /// Median sum of a timed frame's GPU passes, ms (`None` when no GPU timings arrived).
    pub gpu_ms: Option<f64>,
    /// Median sum of a timed frame's CPU work (LOD selection, streaming, TLM analysis), ms.
    pub cpu_ms: Option<f64>,
    /// 1000 / `frame_ms`.
    pub fps: Option<f64>,
    /// Median seeds pass 3 kept per timed frame.
    pub seeds_selected: Option<f64>,
    /// Median time of each pass over the timed frames, GPU passes first.
    pub passes: Vec<PassTime>,
    /// Against the exact summit oracle (pass 3's rule, exactly), over all sample poses; `None`
    /// without land cover.
    pub seeds: Option<SeedFigures>,
    /// Against the any-part oracle of the point's world's truth, over all sample poses; `None`
    /// without land cover or impostors.
    pub any_part: Option<AnyPartFigures>,
    /// The ground (the frame without seeds) against the truth's ground, over all sample poses:
    /// PSNR of the pooled squared error, dB (capped at `image_metrics::PSNR_CAP_DB`).
    pub ground_psnr_db: f64,
    /// The frame against the truth, over all sample poses: PSNR of the pooled squared error, dB.
    pub frame_psnr_db: f64,
    /// The frame against the truth: SSIM over all sample poses' windows (1 = identical).
    pub frame_ssim: f64,
    /// The frame against the truth: mean FLIP over all sample poses' pixels (0 = identical).
    pub frame_flip: f64,
    /// The frame against its photograph frame (`photo`): CIEDE2000 of the 5 × 5 blocks at least
    /// half wooded, pooled over the sample poses; `None` when no block counted.
    pub photo_de2000: Option<DeltaE>,
    /// Along the popping flight, the largest 4 × 4 block change between frames against the
    /// truth's; `None` when not measured.
    pub popping: Option<Popping>,
    /// The frame's errors, whole and per distance band, pooled over the sample poses.
    pub error: FrameError,
    /// The same figures at each sample pose, in path order.
    pub samples: Vec<SampleFigures>,
}

/// One pass's median time at one point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassTime {
    /// The profiler's label for the pass or CPU step (`seed_select`, `streaming`, …).
    pub label: String,
    /// How it was timed: GPU timestamps, a CPU wait per pass, or plain CPU work.
    pub source: TimeSource,
    /// Median over the timed frames where it ran, ms.
    pub median_ms: f64,
}

/// How the seeds pass 3 kept agree with the exact oracle's visible seeds, and how high they stand.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SeedFigures {
    /// Seeds the oracle sees.
    pub visible: u64,
    /// Seeds pass 3 kept.
    pub kept: u64,
    /// Seeds both kept and visible.
    pub common: u64,
    /// Visible seeds kept, % (100 when nothing is visible).
    pub recall_pct: f64,
    /// Kept seeds that are visible, % (100 when nothing is kept).
    pub precision_pct: f64,
    /// Largest distance of a kept seed's ground height from the f64 drawn ground, metres.
    pub height_error_max_m: f64,
    /// Mean distance of the kept seeds' ground heights from the f64 drawn ground, metres.
    pub height_error_mean_m: f64,
}

impl SeedFigures {
    /// The figures of `agreement` and `height`, as percentages and metres.
    pub fn of(agreement: &SeedAgreement, height: &HeightError) -> Self {
        Self {
            visible: agreement.visible,
            kept: agreement.kept,
            common: agreement.common,
            recall_pct: 100.0 * agreement.recall(),
            precision_pct: 100.0 * agreement.precision(),
            height_error_max_m: height.max_m,
            height_error_mean_m: height.mean_m(),
        }
    }
}

/// How the seeds pass 3 kept compare with the truth's visible ones (any sample shows them).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AnyPartFigures {
    /// Seeds with at least one sample in the truth.
    pub visible: u64,
    /// Seeds pass 3 kept.
    pub selected: u64,
    /// Kept seeds that are visible.
    pub selected_visible: u64,
    /// Visible seeds kept, %.
    pub recall_pct: f64,
    /// Kept seeds that are visible, %.
    pub precision_pct: f64,
    /// The truth's seed samples whose seed pass 3 kept, %.
    pub pixel_weighted_recall_pct: f64,
    /// The truth's seed samples missed, % of them all, by why (`truth::visibility::Missed`): the
    /// five add up to 100 − `pixel_weighted_recall_pct`.
    pub missed_pct: MissedPct,
}

/// `Missed` as percentages of the truth's seed samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MissedPct {
    /// Beyond the point's reach for the seed's size.
    pub reach: f64,
    /// Not grown at the point's density (or class, or rules).
    pub density: f64,
    /// Bounding sphere outside the view by pass 3's test.
    pub frustum: f64,
    /// Summit hidden by the terrain, another part showing.
    pub summit_hidden: f64,
    /// Kept by the exact rule, lost to pass 3's approximations.
    pub selection: f64,
}

impl AnyPartFigures {
    /// The figures of `v` and `missed`, as percentages.
    pub fn of(v: &Visibility, missed: &Missed) -> Self {
        let pct = |n: u64| if v.seed_samples == 0 { 0.0 } else { 100.0 * n as f64 / v.seed_samples as f64 };
        Self {
            visible: v.visible,
            selected: v.selected,
            selected_visible: v.selected_visible,
            recall_pct: 100.0 * v.recall(),
            precision_pct: 100.0 * v.precision(),
            pixel_weighted_recall_pct: 100.0 * v.pixel_weighted_recall(),
            missed_pct: MissedPct {
                reach: pct(missed.reach),
                density: pct(missed.density),
                frustum: pct(missed.frustum),
                summit_hidden: pct(missed.summit_hidden),
                selection: pct(missed.selection),
            },
        }
    }
}

/// A point's accuracy at one sample pose.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SampleFigures {
    /// The pose's path parameter, 0 to 1.
    pub t: f64,
    /// The ground (the frame without seeds) against the reference's, PSNR in dB.
    pub ground_psnr_db: f64,
    /// The frame against the reference's frame, PSNR in dB.
    pub frame_psnr_db: f64,
    /// The frame against the reference's frame, SSIM (1 = identical).
    pub frame_ssim: f64,
    /// The frame against the truth, mean FLIP (0 = identical).
    pub frame_flip: f64,
    /// The seeds against the summit oracle at this pose; `None` without land cover.
    pub seeds: Option<SeedFigures>,
    /// The seeds against the any-part oracle at this pose; `None` without land cover or impostors.
    pub any_part: Option<AnyPartFigures>,
}

/// The pretty-printed JSON.
pub fn json(trade: &Trade) -> String {
    // Strings, numbers, options and maps of strings: serialising cannot fail.
    serde_json::to_string_pretty(trade).unwrap_or_default()
}

/// Every pass label of any point, in first-seen order.
pub fn pass_labels(trade: &Trade) -> Vec<String> {
    let mut labels: Vec<String> = Vec::new();
    for pass in trade.points.iter().flat_map(|p| &p.passes) {
        if !labels.contains(&pass.label) {
            labels.push(pass.label.clone());
        }
    }
    labels
}

/// The fixed CSV columns before the passes' `<label>_ms`.
pub const CSV_COLUMNS: [&str; 33] = [
    "label",
    "preset",
    "knobs",
    "frame_ms",
    "gpu_ms",
    "cpu_ms",
    "fps",
    "seeds_selected",
    "visible",
    "kept",
    "common",
    "recall_pct",
    "precision_pct",
    "height_error_max_m",
    "height_error_mean_m",
    "any_part_visible",
    "any_part_recall_pct",
    "any_part_precision_pct",
    "pixel_weighted_recall_pct",
    "missed_reach_pct",
    "missed_density_pct",
    "missed_frustum_pct",
    "missed_summit_hidden_pct",
    "missed_selection_pct",
    "ground_psnr_db",
    "frame_psnr_db",
    "frame_ssim",
    "frame_flip",
    "photo_de2000_mean",
    "photo_de2000_p95",
    "popping",
    "block_change_largest",
    "truth_block_change_largest",
];

fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

fn number(v: Option<f64>) -> String {
    v.map(|v| format!("{v}")).unwrap_or_default()
}

/// One header line, then one line per point.
pub fn csv(trade: &Trade) -> String {
    let labels = pass_labels(trade);
    let mut header: Vec<String> = CSV_COLUMNS.iter().map(|c| (*c).to_owned()).collect();
    header.extend(labels.iter().map(|l| format!("{l}_ms")));
    let mut out = header.join(",") + "\n";
    for p in &trade.points {
        let (s, a) = (p.seeds.as_ref(), p.any_part.as_ref());
        let knobs = p.knobs.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(";");
        let mut row = vec![csv_field(&p.label), csv_field(&p.preset), csv_field(&knobs)];
        row.extend([Some(p.frame_ms), p.gpu_ms, p.cpu_ms, p.fps, p.seeds_selected].map(number));
        row.extend(
            [s.map(|s| s.visible), s.map(|s| s.kept), s.map(|s| s.common)]
                .map(|v| v.map(|v| v.to_string()).unwrap_or_default()),
        );
        row.extend(
            [
                s.map(|s| s.recall_pct),
                s.map(|s| s.precision_pct),
                s.map(|s| s.height_error_max_m),
                s.map(|s| s.height_error_mean_m),
                a.map(|a| a.visible as f64),
                a.map(|a| a.recall_pct),
                a.map(|a| a.precision_pct),
                a.map(|a| a.pixel_weighted_recall_pct),
                a.map(|a| a.missed_pct.reach),
                a.map(|a| a.missed_pct.density),
                a.map(|a| a.missed_pct.frustum),
                a.map(|a| a.missed_pct.summit_hidden),
                a.map(|a| a.missed_pct.selection),
                Some(p.ground_psnr_db),
                Some(p.frame_psnr_db),
                Some(p.frame_ssim),
                Some(p.frame_flip),
                p.photo_de2000.map(|d| d.mean),
                p.photo_de2000.map(|d| d.p95),
                p.popping.map(|q| q.popping),
                p.popping.map(|q| q.largest),
                p.popping.map(|q| q.truth_largest),
            ]
            .map(number),
        );
        row.extend(
            labels.iter().map(|l| number(p.passes.iter().find(|q| &q.label == l).map(|q| q.median_ms))),
        );
        out += &(row.join(",") + "\n");
    }
    out
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    pub fn trade() -> Trade {
        let point = |label: &str, frame_ms: f64, recall_pct: f64, ssim: f64| TradePoint {
            label: label.into(),
            preset: label.split(' ').next().unwrap_or_default().into(),
            knobs: BTreeMap::new(),
            frame_ms,
            gpu_ms: Some(frame_ms * 0.8),
            cpu_ms: None,
            fps: Some(1000.0 / frame_ms),
            seeds_selected: Some(1200.0),
            passes: vec![
                PassTime {
                    label: "terrain".into(),
                    source: TimeSource::GpuTimestamps,
                    median_ms: frame_ms * 0.3,
                },
                PassTime {
                    label: "ground".into(),
                    source: TimeSource::GpuTimestamps,
                    median_ms: frame_ms * 0.5,
                },
            ],
            seeds: Some(SeedFigures {
                visible: 1000,
                kept: 990,
                common: 980,
                recall_pct,
                precision_pct: 99.0,
                height_error_max_m: 2e-4,
                height_error_mean_m: 5e-5,
            }),
            any_part: Some(AnyPartFigures {
                visible: 1200,
                selected: 990,
                selected_visible: 985,
                recall_pct: 82.08,
                precision_pct: 99.49,
                pixel_weighted_recall_pct: 97.5,
                missed_pct: MissedPct {
                    reach: 1.5,
                    density: 0.5,
                    frustum: 0.0,
                    summit_hidden: 0.25,
                    selection: 0.25,
                },
            }),
            ground_psnr_db: 38.5,
            frame_psnr_db: 30.25,
            frame_ssim: ssim,
            frame_flip: 0.125,
            photo_de2000: Some(DeltaE { mean: 23.5, p95: 44.25, max: 50.0 }),
            popping: Some(Popping { pairs: 7, largest: 14.5, truth_largest: 9.25, popping: 6.0 }),
            error: crate::truth::compare::tests::error(30.25, ssim, 0.125),
            samples: Vec::new(),
        };
        let mut knobbed = point("balanced seeds.frustum_epsilon=0,1", 80.0, 99.5, 0.93);
        knobbed.knobs.insert("seeds.frustum_epsilon".into(), "0,1".into());
        knobbed.passes.push(PassTime { label: "streaming".into(), source: TimeSource::Cpu, median_ms: 0.5 });
        Trade {
            schema: SCHEMA,
            adapter: "test".into(),
            timing: "GPU timestamps".into(),
            dataset: "data/x".into(),
            path: "orbit".into(),
            resolution: [64, 36],
            warmup: 2,
            frames: 4,
            timing_rounds: 2,
            sample_t: vec![0.25, 0.75],
            popping_flight: Some(PoppingFlight { frames: 8, step_m: 2.0, from_t: 0.75 }),
            reference: "accurate".into(),
            settings: None,
            points: vec![point("fast", 40.0, 97.0, 0.9), knobbed, point("accurate", 120.0, 100.0, 1.0)],
        }
    }

    #[test]
    fn csv_has_a_row_per_point_with_quoted_fields_and_every_pass() {
        let csv = csv(&trade());
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 4);
        assert!(
            lines[0].starts_with("label,preset,knobs,frame_ms")
                && lines[0].ends_with(
                    "frame_flip,photo_de2000_mean,photo_de2000_p95,popping,block_change_largest,truth_block_change_largest,\
                     terrain_ms,ground_ms,streaming_ms"
                ),
            "{}",
            lines[0]
        );
        assert!(
            lines[2].starts_with(
                "\"balanced seeds.frustum_epsilon=0,1\",balanced,\"seeds.frustum_epsilon=0,1\",80,"
            ),
            "{}",
            lines[2]
        );
        assert!(lines[1].ends_with(",12,20,"), "fast has no streaming pass: {}", lines[1]);
    }
}
