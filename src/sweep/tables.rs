//! How it works: a sweep's figures as tables: the terminal's (`table`) and Markdown for docs
//! (`markdown`): the trade (time; the seeds against the summit oracle and the truth's any-part
//! oracle; the frame against the truth; popping along a flight against the truth's), the truth's
//! tree pixels missed by why, the error per distance band, and each pass's median.

use std::fmt::Write;

use super::plot::front_slack;
use super::report::{Trade, pass_labels};

/// The figures as three Markdown tables (the trade, the error per band, each pass's median per
/// point), for docs.
pub fn markdown(trade: &Trade) -> String {
    let mut out = String::new();
    // Writing into a String cannot fail.
    let _ = write_markdown(&mut out, trade);
    out
}

fn write_markdown(out: &mut String, t: &Trade) -> std::fmt::Result {
    let opt = |v: Option<f64>, digits: usize| v.map_or("–".to_owned(), |v| format!("{v:.digits$}"));
    let pct = |v: Option<f64>| v.map_or("–".to_owned(), |v| format!("{v:.2} %"));
    // Each point's distance from the two fronts of the plot (FLIP; tree pixels missed).
    let flip: Vec<(f64, f64)> = t.points.iter().map(|p| (p.frame_flip, p.frame_ms)).collect();
    let missed: Vec<(f64, f64)> = t
        .points
        .iter()
        .map(|p| (p.any_part.map_or(f64::NAN, |a| 100.0 - a.pixel_weighted_recall_pct), p.frame_ms))
        .collect();
    writeln!(
        out,
        "| point | frame ms | GPU ms | visible (truth) | recall | precision | pixel-weighted recall | \
         recall / precision (summit oracle) | seed height error max / mean | ground PSNR | frame PSNR | SSIM | FLIP | \
         ΔE2000 vs photograph (mean / p95) | popping (truth's) | off the fronts (FLIP; pixels missed) |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")?;
    for (i, p) in t.points.iter().enumerate() {
        let slack = |points: &[(f64, f64)]| {
            let s = front_slack(points, points[i]);
            if s.is_finite() { format!("{s:.2}×") } else { "–".into() }
        };
        let fronts = format!("{}; {}", slack(&flip), slack(&missed));
        let (s, a) = (p.seeds.as_ref(), p.any_part.as_ref());
        let height = s.map_or("–".to_owned(), |s| {
            format!("{:.2} / {:.3} mm", 1000.0 * s.height_error_max_m, 1000.0 * s.height_error_mean_m)
        });
        let summit =
            s.map_or("–".to_owned(), |s| format!("{:.2} / {:.2} %", s.recall_pct, s.precision_pct));
        let popping = popping_text(p);
        writeln!(
            out,
            "| {} | {:.1} | {} | {} | {} | {} | {} | {summit} | {height} | {:.1} dB | {:.1} dB | {:.4} | {:.4} | {} | {popping} | {fronts} |",
            p.label,
            p.frame_ms,
            opt(p.gpu_ms, 1),
            a.map_or("–".to_owned(), |a| a.visible.to_string()),
            pct(a.map(|a| a.recall_pct)),
            pct(a.map(|a| a.precision_pct)),
            pct(a.map(|a| a.pixel_weighted_recall_pct)),
            p.ground_psnr_db,
            p.frame_psnr_db,
            p.frame_ssim,
            p.frame_flip,
            photo_text(p, " / ")
        )?;
    }
    if t.points.iter().any(|p| p.any_part.is_some()) {
        writeln!(
            out,
            "\nThe truth's tree pixels each point misses, by why (% of them all; the exact oracle's fate of each \
             missed seed under the point's settings):\n"
        )?;
        writeln!(
            out,
            "| point | missed | beyond reach | not grown (density) | outside frustum | summit hidden | pass 3's approximations |"
        )?;
        writeln!(out, "|---|---|---|---|---|---|---|")?;
        for p in &t.points {
            let Some(a) = p.any_part else { continue };
            let m = a.missed_pct;
            writeln!(
                out,
                "| {} | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.2} % | {:.2} % |",
                p.label,
                100.0 - a.pixel_weighted_recall_pct,
                m.reach,
                m.density,
                m.frustum,
                m.summit_hidden,
                m.selection
            )?;
        }
    }
    writeln!(
        out,
        "\nFrame error against the truth per distance band (PSNR / SSIM / FLIP; share of pixels; \
         forest cover: of the truth's forest pixels, the share the frame draws on, and of the \
         pixels it draws on, the share on the truth's forest; forest brightness: the mean level \
         of the frame's drawn pixels over that of the truth's forest pixels, 1 alike):\n"
    )?;
    writeln!(
        out,
        "| point | band | from–to m | pixels | PSNR | SSIM | FLIP | cover recall | cover precision | forest brightness |"
    )?;
    writeln!(out, "|---|---|---|---|---|---|---|---|---|---|")?;
    for p in &t.points {
        for r in &p.error.bands {
            let to = if r.band.to_m.is_finite() { format!("{:.0}", r.band.to_m) } else { "∞".into() };
            let share = 100.0 * r.pixels as f64 / p.error.frame.pixels.max(1) as f64;
            // A band with no pixel (or too thin for an SSIM window) has no figure.
            let figure = |v: f64, text: String| if v.is_finite() { text } else { "–".into() };
            let (recall, precision, brightness) = r.cover.map_or((f64::NAN, f64::NAN, f64::NAN), |c| {
                (c.recall_pct(), c.precision_pct(), c.brightness_ratio())
            });
            writeln!(
                out,
                "| {} | {} | {:.0}–{to} | {share:.1} % | {} | {} | {} | {} | {} | {} |",
                p.label,
                r.band.name,
                r.band.from_m,
                figure(r.psnr_db, format!("{:.1} dB", r.psnr_db)),
                figure(r.ssim, format!("{:.4}", r.ssim)),
                figure(r.flip, format!("{:.4}", r.flip)),
                figure(recall, format!("{recall:.1} %")),
                figure(precision, format!("{precision:.1} %")),
                figure(brightness, format!("{brightness:.3}"))
            )?;
        }
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

/// CIEDE2000 against the photograph, mean and p95, joined by `between`.
fn photo_text(p: &super::TradePoint, between: &str) -> String {
    p.photo_de2000.map_or("–".to_owned(), |d| format!("{:.2}{between}{:.2}", d.mean, d.p95))
}

/// Popping and, in brackets, the truth's largest block change along the same flight.
fn popping_text(p: &super::TradePoint) -> String {
    p.popping.map_or("–".to_owned(), |q| format!("{:+.1} ({:.1})", q.popping, q.truth_largest))
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
        "{:<w$} {:>9} {:>8} {:>9} {:>11} {:>8} {:>15} {:>11} {:>10} {:>7} {:>7} {:>13} {:>14}",
        "point",
        "frame ms",
        "GPU ms",
        "recall %",
        "precision %",
        "pw rec %",
        "height max/mean",
        "ground PSNR",
        "frame PSNR",
        "SSIM",
        "FLIP",
        "ΔE00 photo",
        "popping (truth)"
    )?;
    for p in &t.points {
        let (s, a) = (p.seeds.as_ref(), p.any_part.as_ref());
        let height = s.map_or("-".to_owned(), |s| {
            format!("{:.2}/{:.2} mm", 1000.0 * s.height_error_max_m, 1000.0 * s.height_error_mean_m)
        });
        writeln!(
            out,
            "{:<w$} {:>9.1} {:>8} {:>9} {:>11} {:>8} {:>15} {:>8.1} dB {:>7.1} dB {:>7.4} {:>7.4} {:>13} {:>14}",
            p.label,
            p.frame_ms,
            opt(p.gpu_ms, 1),
            opt(a.map(|a| a.recall_pct), 2),
            opt(a.map(|a| a.precision_pct), 2),
            opt(a.map(|a| a.pixel_weighted_recall_pct), 2),
            height,
            p.ground_psnr_db,
            p.frame_psnr_db,
            p.frame_ssim,
            p.frame_flip,
            photo_text(p, "/"),
            popping_text(p)
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
mod tests {
    use super::*;
    use crate::sweep::report::{SCHEMA, json, tests::trade};

    #[test]
    fn table_lists_every_point_and_pass() {
        let table = table(&trade());
        for text in [
            "fast",
            "accurate",
            "82.08",
            "97.50",
            "0.9300",
            "0.1250",
            "38.5 dB",
            "0.20/0.05 mm",
            "streaming",
            "+6.0 (9.2)",
            "23.50/44.25",
        ] {
            assert!(table.contains(text), "no {text:?} in\n{table}");
        }
        let md = markdown(&trade());
        // The trade, two bands, the passes.
        assert_eq!(md.lines().filter(|l| l.starts_with("| fast")).count(), 5, "{md}");
        assert!(
            md.contains("| 82.08 % |")
                && md.contains("97.00 / 99.00 %")
                && md.contains("| streaming |")
                && md.contains("| +6.0 (9.2) |")
                && md.contains("| 23.50 / 44.25 |")
                && md.contains("| fast | 2.50 % | 1.50 % | 0.50 % | 0.00 % | 0.25 % | 0.25 % |"),
            "{md}"
        );
        assert!(md.contains("| fast | meshes | 0–100 | 50.0 % |"), "{md}");
        let json: serde_json::Value = serde_json::from_str(&json(&trade())).unwrap();
        assert_eq!(json["schema"], SCHEMA);
        assert_eq!(json["points"][0]["passes"][0]["source"], "gpu_timestamps");
        assert_eq!(json["points"][1]["knobs"]["seeds.frustum_epsilon"], "0,1");
    }
}
