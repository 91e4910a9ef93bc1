//! How it works: the frames' counts (`gpu::counts`) reduced for the table and the JSON. Per label
//! (in the timing table's order, then those it has no row for), the counts of the profiled frames whose counts
//! arrived are summed, exactly; the frame's row sums every label. A figure absent in any of those
//! frames (no pipeline statistics; a query or an indirect draw's arguments the frame had no room
//! for) is absent in the sum, never a partial one. The table shows each sum over the frames, per
//! frame (a mean, so it may be fractional), three significant figures from ten thousand up; the
//! JSON keeps the exact sums (`"counts"`):
//! ```text
//! { "frames": int, "statistics": bool, "absent": [str],
//!   "passes": [ pass ], "frame": pass }
//! ```
//! where a pass is `{ "label", "draw_calls", "indirect_draws", "dispatches", "indirect_dispatches":
//! int, "triangles_submitted": int | null, "statistics": { "vertex_invocations",
//! "clipped_triangles", "fragment_invocations", "compute_invocations": int } | null,
//! "bytes_uploaded", "bytes_read_back": int }`.

use std::fmt::Write;

use serde::Serialize;

use super::Recording;
use crate::gpu::counts::{FrameCounts, PassCounts, Statistics};

/// The figures an adapter without pipeline statistics cannot count, as the JSON names them.
pub const STATISTICS_FIGURES: [&str; 4] =
    ["vertex_invocations", "clipped_triangles", "fragment_invocations", "compute_invocations"];

/// The profiled frames' counts (`"counts"` in the JSON).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Counts {
    /// Profiled frames whose counts arrived: the sums are over these.
    pub frames: usize,
    /// Every one of those frames ran the pipeline-statistics queries.
    pub statistics: bool,
    /// The figures this adapter could not count (`STATISTICS_FIGURES` without pipeline statistics).
    pub absent: Vec<&'static str>,
    /// Per label, its counts summed over the frames.
    pub passes: Vec<PassCounts>,
    /// Every label's counts summed: the frames' own.
    pub frame: PassCounts,
}

impl Counts {
    /// The sums of `recording`'s profiled frames' counts, labels in `order` first (the timing
    /// rows'), then the others as the frames first name them.
    pub fn of(recording: &Recording, order: &[&str]) -> Self {
        let frames: Vec<&FrameCounts> = recording.profiled_counts().collect();
        let statistics = !frames.is_empty() && frames.iter().all(|f| f.statistics);
        let mut passes: Vec<PassCounts> = Vec::new();
        for frame in &frames {
            for pass in &frame.passes {
                match passes.iter_mut().find(|p| p.label == pass.label) {
                    Some(sum) => sum.add(pass),
                    None => passes.push(pass.clone()),
                }
            }
        }
        let rank = |label: &str| order.iter().position(|&o| o == label).unwrap_or(order.len());
        passes.sort_by_key(|p| rank(p.label));
        let start = PassCounts {
            label: "frame",
            triangles_submitted: Some(0),
            statistics: statistics.then(Statistics::default),
            ..Default::default()
        };
        let frame = frames.iter().fold(start, |mut sum, f| {
            sum.add(&f.total());
            sum
        });
        let absent = if statistics || frames.is_empty() { Vec::new() } else { STATISTICS_FIGURES.to_vec() };
        Self { frames: frames.len(), statistics, absent, passes, frame }
    }
}

/// The counts' block of the table: one row per label and the frame's, each count per frame.
pub fn write_table(out: &mut String, counts: &Counts) -> std::fmt::Result {
    if counts.frames == 0 {
        return writeln!(out, "Counts: none arrived");
    }
    let stats = if counts.statistics { "with" } else { "without" };
    writeln!(out, "\nCounts per frame (mean of {} frames, {stats} pipeline statistics)", counts.frames)?;
    let columns = [
        "draws",
        "indirect",
        "dispatches",
        "triangles",
        "vertices",
        "clipped",
        "fragments",
        "compute",
        "uploaded B",
        "read B",
    ];
    let width = counts.passes.iter().map(|p| p.label.len()).max().unwrap_or(0).max(16);
    write!(out, "{:<width$}", "")?;
    for column in columns {
        write!(out, " {column:>10}")?;
    }
    writeln!(out)?;
    let per_frame = |n: u64| n as f64 / counts.frames as f64;
    for pass in counts.passes.iter().chain([&counts.frame]) {
        let s = pass.statistics;
        let cells = [
            Some(pass.draw_calls),
            Some(pass.indirect_draws),
            Some(pass.dispatches + pass.indirect_dispatches),
            pass.triangles_submitted,
            s.map(|s| s.vertex_invocations),
            s.map(|s| s.clipped_triangles),
            s.map(|s| s.fragment_invocations),
            s.map(|s| s.compute_invocations),
            Some(pass.bytes_uploaded),
            Some(pass.bytes_read_back),
        ];
        write!(out, "{:<width$}", pass.label)?;
        for cell in cells {
            write!(out, " {:>10}", cell.map_or("-".to_owned(), |n| compact(per_frame(n))))?;
        }
        writeln!(out)?;
    }
    if !counts.absent.is_empty() {
        writeln!(out, "absent (this adapter has no pipeline statistics): {}", counts.absent.join(", "))?;
    }
    Ok(())
}

/// `value` in at most ten characters: exact below ten thousand (one decimal when fractional),
/// else three significant figures with k, M or G.
pub fn compact(value: f64) -> String {
    if value.abs() < 10_000.0 {
        return if value.fract() == 0.0 { format!("{value:.0}") } else { format!("{value:.1}") };
    }
    let (scaled, unit) = [(1e9, "G"), (1e6, "M"), (1e3, "k")]
        .into_iter()
        .find(|(scale, _)| value.abs() >= *scale)
        .map_or((value, ""), |(scale, unit)| (value / scale, unit));
    let decimals = if scaled.abs() >= 100.0 {
        0
    } else if scaled.abs() >= 10.0 {
        1
    } else {
        2
    };
    format!("{scaled:.decimals$} {unit}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::test_data::recording;

    fn frame(frame: u64, triangles: Option<u64>, statistics: Option<Statistics>) -> FrameCounts {
        let pass = |label| PassCounts {
            label,
            draw_calls: 2,
            triangles_submitted: triangles,
            statistics,
            bytes_uploaded: 100,
            ..Default::default()
        };
        let passes = vec![pass("terrain"), PassCounts { indirect_draws: 3, ..pass("draw_seeds") }];
        FrameCounts { frame, statistics: statistics.is_some(), passes }
    }

    #[test]
    fn sums_over_the_profiled_frames_exactly() {
        let stats = Statistics { vertex_invocations: 7, fragment_invocations: 5, ..Default::default() };
        let mut r = recording();
        r.counts.insert(9, frame(9, Some(1000), Some(stats)));
        r.counts.insert(10, frame(10, Some(30), Some(stats)));
        r.counts.insert(11, frame(11, Some(12), Some(stats)));
        let counts = Counts::of(&r, &["draw_seeds"]);
        assert_eq!((counts.frames, counts.statistics, counts.absent.len()), (2, true, 0), "9 is a warm-up");
        let seeds = &counts.passes[0];
        assert_eq!(
            (seeds.label, seeds.indirect_draws, seeds.triangles_submitted),
            ("draw_seeds", 6, Some(42))
        );
        assert_eq!(counts.frame.triangles_submitted, Some(84));
        assert_eq!(counts.frame.statistics.unwrap().vertex_invocations, 28);
        assert_eq!((counts.frame.draw_calls, counts.frame.bytes_uploaded), (8, 400));
        let mut table = String::new();
        write_table(&mut table, &counts).unwrap();
        let row = table.lines().find(|l| l.starts_with("frame")).unwrap();
        assert_eq!(
            row.split_whitespace().collect::<Vec<_>>(),
            ["frame", "4", "3", "0", "42", "14", "0", "10", "0", "200", "0"]
        );
    }

    #[test]
    fn without_statistics_the_figures_are_named_absent() {
        let mut r = recording();
        r.counts.insert(10, frame(10, Some(3), None));
        let counts = Counts::of(&r, &[]);
        assert_eq!(counts.absent, STATISTICS_FIGURES);
        assert_eq!(counts.frame.statistics, None);
        let mut table = String::new();
        write_table(&mut table, &counts).unwrap();
        assert!(
            table.contains("absent (this adapter has no pipeline statistics): vertex_invocations"),
            "{table}"
        );
        let json = serde_json::to_value(&counts).unwrap();
        assert_eq!(json["frame"]["statistics"], serde_json::Value::Null);
        assert_eq!(json["frame"]["triangles_submitted"], 6);
    }

    #[test]
    fn compact_numbers() {
        assert_eq!(compact(42.0), "42");
        assert_eq!(compact(2.5), "2.5");
        assert_eq!(compact(9999.0), "9999");
        assert_eq!(compact(12_345.0), "12.3 k");
        assert_eq!(compact(8_500_000.0), "8.50 M");
        assert_eq!(compact(123_456_789.0), "123 M");
    }
}
