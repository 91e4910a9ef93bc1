//! How it works: a sweep's figures (`Trade`) and their three renderings: the JSON (this struct,
//! serialised), the CSV (one row per point), the terminal table and Markdown tables for docs. PSNRs are capped at
//! `image_metrics::PSNR_CAP_DB` (identical images), so every figure is a finite number; figures a
//! point lacks (seeds on a dataset without land cover, GPU times where none arrived) are `null` in
//! the JSON and empty in the CSV.
//!
//! The JSON:
//! ```text
//! { "schema": "terramp-trade/1", "adapter": str, "timing": str, "dataset": str, "path": str,
//!   "resolution": [w, h], "warmup": int, "frames": int, "sample_t": [float], "reference": str,
//!   "settings": str | null,
//!   "points": [ { "label": str, "preset": str, "knobs": { key: value },
//!                 "frame_ms": float, "gpu_ms", "cpu_ms", "fps", "seeds_selected": float | null,
//!                 "passes": [ { "label": str, "source": str, "median_ms": float } ],
//!                 "seeds": seeds | null,
//!                 "ground_psnr_db", "frame_psnr_db", "frame_ssim": float,
//!                 "samples": [ { "t", "ground_psnr_db", "frame_psnr_db", "frame_ssim": float,
//!                                "seeds": seeds | null } ] } ] }
//! ```
//! where seeds is `{ "visible", "kept", "common": int, "recall_pct", "precision_pct",
//! "height_error_max_m", "height_error_mean_m": float }`. The CSV has the same figures under the
//! same names (pass medians as `<label>_ms`, seed figures without their `seeds.` prefix, knobs as
//! `key=value;key=value`).

use std::collections::BTreeMap;
use std::fmt::Write;

use serde::Serialize;

use crate::gpu::TimeSource;
use crate::reference::accuracy::{HeightError, SeedAgreement};

/// The version of the JSON layout.
pub const SCHEMA: &str = "terramp-trade/1";

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
    /// Untimed frames each point renders at the path's start.
    pub warmup: u32,
    /// Timed frames each point renders, spread evenly along the path.
    pub frames: u32,
    /// Path parameters of the sample poses.
    pub sample_t: Vec<f64>,
    /// What the images are compared with.
    pub reference: String,
    /// The settings file laid over every preset, if any.
    pub settings: Option<String>,
    /// One per preset × knob values, in the order of `knobs::points`.
    pub points: Vec<TradePoint>,
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
    /// Over all sample poses; `None` without land cover.
    pub seeds: Option<SeedFigures>,
    /// The ground (the frame without seeds) against the reference's, over all sample poses: PSNR
    /// of the pooled squared error, dB (capped at `image_metrics::PSNR_CAP_DB`).
    pub ground_psnr_db: f64,
    /// The frame against the reference's frame, over all sample poses: PSNR of the pooled
    /// squared error, dB (capped at `image_metrics::PSNR_CAP_DB`).
    pub frame_psnr_db: f64,
    /// The frame against the reference's frame: mean SSIM over the sample poses (1 = identical).
    pub frame_ssim: f64,
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
    /// The seeds against the oracle at this pose; `None` without land cover.
    pub seeds: Option<SeedFigures>,
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
pub const CSV_COLUMNS: [&str; 18] = [
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
    "ground_psnr_db",
    "frame_psnr_db",
    "frame_ssim",
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
        let s = p.seeds.as_ref();
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
                Some(p.ground_psnr_db),
                Some(p.frame_psnr_db),
                Some(p.frame_ssim),
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

/// The figures as two Markdown tables (the trade, then each pass's median per point), for docs.
pub fn markdown(trade: &Trade) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail.
    let _ = write_markdown(&mut out, trade);
    out
}

fn write_markdown(out: &mut String, t: &Trade) -> std::fmt::Result {
    let opt = |v: Option<f64>, digits: usize| v.map_or("–".to_owned(), |v| format!("{v:.digits$}"));
    writeln!(
        out,
        "| point | frame ms | GPU ms | visible (oracle) | recall | precision | seed height error max / mean | ground PSNR | frame PSNR | frame SSIM |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|")?;
    for p in &t.points {
        let s = p.seeds.as_ref();
        let pct = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.2} %"));
        let height = s.map_or("–".to_owned(), |s| {
            format!("{:.2} / {:.3} mm", 1000.0 * s.height_error_max_m, 1000.0 * s.height_error_mean_m)
        });
        writeln!(
            out,
            "| {} | {:.1} | {} | {} | {} | {} | {height} | {:.1} dB | {:.1} dB | {:.4} |",
            p.label,
            p.frame_ms,
            opt(p.gpu_ms, 1),
            s.map_or("–".to_owned(), |s| s.visible.to_string()),
            pct(s.map(|s| s.recall_pct)),
            pct(s.map(|s| s.precision_pct)),
            p.ground_psnr_db,
            p.frame_psnr_db,
            p.frame_ssim
        )?;
    }
    let labels = pass_labels(t);
    writeln!(out, "\nMedian time per pass, ms:\n")?;
    writeln!(out, "| point | {} |", labels.join(" | "))?;
    writeln!(out, "|---|{}", "---|".repeat(labels.len()))?;
    for p in &t.points {
        let cells: Vec<String> = labels
            .iter()
            .map(|l| opt(p.passes.iter().find(|q| &q.label == l).map(|q| q.median_ms), 2))
            .collect();
        writeln!(out, "| {} | {} |", p.label, cells.join(" | "))?;
    }
    Ok(())
}

/// The terminal table: the trade, then each pass's median per point.
pub fn table(trade: &Trade) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail.
    let _ = write_table(&mut out, trade);
    out
}

fn write_table(out: &mut String, t: &Trade) -> std::fmt::Result {
    writeln!(
        out,
        "terramp sweep: {} · path {} · {}×{} · {} timed frames after {} warm-up · {} sample poses",
        t.dataset,
        t.path,
        t.resolution[0],
        t.resolution[1],
        t.frames,
        t.warmup,
        t.sample_t.len()
    )?;
    writeln!(out, "adapter: {} · GPU passes timed with {}", t.adapter, t.timing)?;
    writeln!(out, "reference: {}\n", t.reference)?;
    let w = t.points.iter().map(|p| p.label.len()).max().unwrap_or(0).max(8);
    let opt = |v: Option<f64>, digits: usize| v.map_or("-".to_owned(), |v| format!("{v:.digits$}"));
    writeln!(
        out,
        "{:<w$} {:>9} {:>8} {:>9} {:>10} {:>14} {:>11} {:>10} {:>7}",
        "point",
        "frame ms",
        "GPU ms",
        "recall %",
        "precision %",
        "height max/mean",
        "ground PSNR",
        "frame PSNR",
        "SSIM"
    )?;
    for p in &t.points {
        let s = p.seeds.as_ref();
        let height = s.map_or("-".to_owned(), |s| {
            format!("{:.2}/{:.2} mm", 1000.0 * s.height_error_max_m, 1000.0 * s.height_error_mean_m)
        });
        writeln!(
            out,
            "{:<w$} {:>9.1} {:>8} {:>9} {:>11} {:>15} {:>8.1} dB {:>7.1} dB {:>7.4}",
            p.label,
            p.frame_ms,
            opt(p.gpu_ms, 1),
            opt(s.map(|s| s.recall_pct), 2),
            opt(s.map(|s| s.precision_pct), 2),
            height,
            p.ground_psnr_db,
            p.frame_psnr_db,
            p.frame_ssim
        )?;
    }
    let labels = pass_labels(t);
    writeln!(out, "\nmedian ms per pass")?;
    let cw = labels.iter().map(String::len).max().unwrap_or(0).max(7);
    write!(out, "{:<w$}", "point")?;
    for l in &labels {
        write!(out, " {l:>cw$}")?;
    }
    writeln!(out)?;
    for p in &t.points {
        write!(out, "{:<w$}", p.label)?;
        for l in &labels {
            let ms = p.passes.iter().find(|q| &q.label == l).map(|q| q.median_ms);
            write!(out, " {:>cw$}", opt(ms, 2))?;
        }
        writeln!(out)?;
    }
    Ok(())
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
            ground_psnr_db: 38.5,
            frame_psnr_db: 30.25,
            frame_ssim: ssim,
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
            sample_t: vec![0.25, 0.75],
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
                && lines[0].ends_with("frame_ssim,terrain_ms,ground_ms,streaming_ms"),
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

    #[test]
    fn table_lists_every_point_and_pass() {
        let table = table(&trade());
        for text in ["fast", "accurate", "97.00", "0.9300", "38.5 dB", "0.20/0.05 mm", "streaming"] {
            assert!(table.contains(text), "no {text:?} in\n{table}");
        }
        let md = markdown(&trade());
        assert_eq!(md.lines().filter(|l| l.starts_with("| fast")).count(), 2, "{md}");
        assert!(md.contains("| 97.00 % |") && md.contains("| streaming |"), "{md}");
        let json: serde_json::Value = serde_json::from_str(&json(&trade())).unwrap();
        assert_eq!(json["schema"], SCHEMA);
        assert_eq!(json["points"][0]["passes"][0]["source"], "gpu_timestamps");
        assert_eq!(json["points"][1]["knobs"]["seeds.frustum_epsilon"], "0,1");
    }
}
