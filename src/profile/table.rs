//! How it works: the terminal table of `terramp profile`, shaped like Table 1 of Amara et al.
//! (2007): one row per pass in frame order (named as the paper does where it has a row for it),
//! then the CPU work, the totals and the frame's wall time, each with its median and 95th
//! percentile in milliseconds and the frames it was measured in; then seeds checked and selected
//! per frame, and frames per second; then what each pass asked of the GPU per frame (`counts`).

use std::fmt::Write;

use super::paper_name;
use super::stats::Stat;
use super::summary::Summary;
use crate::gpu::TimeSource;

/// The table, ready to print.
pub fn render(summary: &Summary) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail.
    let _ = write_table(&mut out, summary);
    out
}

fn write_table(out: &mut String, s: &Summary) -> std::fmt::Result {
    let m = &s.meta;
    let settings = m.settings.as_deref().map(|f| format!(" + {f}")).unwrap_or_default();
    writeln!(
        out,
        "terramp profile: {} · path {} · {}×{} · preset {}{settings}",
        m.dataset, m.path, m.resolution[0], m.resolution[1], m.preset
    )?;
    writeln!(out, "adapter: {}", m.adapter)?;
    writeln!(out, "GPU passes timed with {}", m.timing_note)?;
    let f = &s.frames;
    match (f.first, f.last) {
        (Some(first), Some(last)) => writeln!(
            out,
            "{} frames ({first}..={last}) after {} warm-up frames; GPU timings arrived for {}",
            f.profiled, f.warmup, f.with_gpu_timings
        )?,
        _ => writeln!(out, "no frames profiled")?,
    }
    let width = s.passes.iter().map(|p| p.label.len()).max().unwrap_or(0).max(16);
    let head = format!("{:<5} {:<width$} {:<19}", "", "", "");
    writeln!(out, "\n{head} {:>10} {:>10} {:>7}", "median ms", "p95 ms", "frames")?;
    let mut group = None;
    for pass in &s.passes {
        let kind = if pass.source == TimeSource::Cpu { "CPU" } else { "GPU" };
        let shown = if group == Some(kind) { "" } else { kind };
        group = Some(kind);
        let row = format!("{shown:<5} {:<width$} {:<19}", pass.label, paper_name(&pass.label).unwrap_or(""));
        stat_row(out, &row, Some(&pass.stat))?;
    }
    let label = |text: &str| format!("{text:<w$}", w = 5 + 1 + width + 1 + 19);
    stat_row(out, &label("Total GPU passes"), s.totals.gpu.as_ref())?;
    stat_row(out, &label("Total CPU work"), s.totals.cpu.as_ref())?;
    stat_row(out, &label("Frame (wall time)"), s.totals.frame_wall.as_ref())?;
    writeln!(out)?;
    let seeds = &s.seeds;
    let count = |v: Option<f64>| match v {
        None => "-".to_owned(),
        Some(v) if v.fract() == 0.0 => format!("{v:.0}"),
        Some(v) => format!("{v:.1}"),
    };
    writeln!(
        out,
        "{} {:>10} / frame (median of {} frames)",
        label("Seeds checked"),
        count(seeds.checked_median),
        seeds.frames
    )?;
    writeln!(out, "{} {:>10} / frame", label("Seeds selected"), count(seeds.selected_median))?;
    if seeds.overflow_frames > 0 {
        writeln!(out, "{} {:>10} frames", label("Seed buffer overflowed"), seeds.overflow_frames)?;
    }
    for pass in &s.overdraw {
        let per_px = |f: Option<f64>| f.map_or("-".to_owned(), |f| format!("{f:.2}"));
        writeln!(
            out,
            "{} {:>10} fragments / covered pixel ({} shaded, {} pixels, {} frames; prepass {}, written {}, triangles {})",
            label(&format!("Overdraw {}", pass.total.label)),
            per_px(pass.fragments_per_covered_px),
            pass.total.shaded,
            pass.total.covered_px,
            pass.frames,
            per_px(pass.prepass_per_covered_px),
            per_px(pass.written_per_covered_px),
            per_px(pass.triangles_per_covered_px),
        )?;
    }
    match &s.fps {
        Some(fps) => {
            writeln!(out, "{} {:>10.1} Hz median ({:.1} Hz mean)", label("FPS"), fps.median, fps.mean)?
        }
        None => writeln!(out, "{} {:>10}", label("FPS"), "-")?,
    }
    super::counts::write_table(out, &s.counts)
}

fn stat_row(out: &mut String, row: &str, stat: Option<&Stat>) -> std::fmt::Result {
    match stat {
        Some(st) => writeln!(out, "{row} {:>10.3} {:>10.3} {:>7}", st.median_ms, st.p95_ms, st.samples),
        None => writeln!(out, "{row} {:>10} {:>10} {:>7}", "-", "-", 0),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::Recording;
    use crate::profile::summary::test_meta;
    use crate::profile::test_data::recording;

    #[test]
    fn rows_in_order_with_medians_seeds_and_fps() {
        let table = render(&Summary::new(&recording(), test_meta()));
        let at = |text: &str| table.find(text).unwrap_or_else(|| panic!("no {text:?} in\n{table}"));
        assert!(at("terrain") < at("tile_load_map"));
        assert!(at("tile_load_map") < at("seed_select"));
        assert!(at("seed_select") < at("streaming"));
        assert!(at("streaming") < at("Total GPU passes"));
        let terrain = table.lines().find(|l| l.contains("terrain mesh")).unwrap();
        assert!(terrain.contains("5.500") && terrain.contains("7.000"), "{terrain}");
        assert!(table.lines().find(|l| l.contains("pass 3")).unwrap().contains("seed_select"));
        assert!(table.lines().find(|l| l.starts_with("Seeds selected")).unwrap().contains("1.5"));
        assert!(table.lines().find(|l| l.starts_with("FPS")).unwrap().contains("50.0 Hz"));
    }

    #[test]
    fn an_empty_summary_still_prints() {
        let table = render(&Summary::new(&Recording::default(), test_meta()));
        assert!(table.contains("no frames profiled") && table.contains("FPS"));
    }
}
