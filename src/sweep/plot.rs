//! How it works: `trade.png`, the trade as a picture: frame time (median wall time, ms) up, error
//! across, one labelled point per preset or knob value, presets ringed. Two panels share the time
//! axis: the frame's error against the ground truth (mean FLIP, which folds terrain, imagery and
//! seeds into what a viewer sees), and the seeds it misses (100 − pixel-weighted recall against
//! the truth's any-part oracle, %: the share of the truth's tree pixels whose tree is not drawn).
//! The second panel is left out when no point was judged against seeds. In each, the Pareto front
//! (`front`: the points no other beats on both time and error) is drawn as a staircase. Drawn by plotters into a pixel buffer and
//! saved as PNG with `image`; text uses the embedded DejaVu Sans Mono (assets/fonts), so the plot
//! needs no system font.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use super::SweepError;
use super::report::Trade;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");
const SIZE_PX: (u32, u32) = (1400, 640);

/// One panel's points: (label, error, frame ms, a preset).
type Series = Vec<(String, f64, f64, bool)>;

/// Which of `points` (error, time) are on the Pareto front: no other point is at least as good on
/// both and better on one. A NaN is on no front and beats nothing.
pub fn front(points: &[(f64, f64)]) -> Vec<bool> {
    let finite = |&(e, t): &(f64, f64)| e.is_finite() && t.is_finite();
    points
        .iter()
        .map(|p| {
            finite(p)
                && !points.iter().any(|q| finite(q) && q.0 <= p.0 && q.1 <= p.1 && (q.0 < p.0 || q.1 < p.1))
        })
        .collect()
}

/// How far `p` (error, time) is from the front of `points`: its time over the least time of any
/// point with no more error (1 on the front; 1.5: a point as accurate is 1.5× faster).
pub fn front_slack(points: &[(f64, f64)], p: (f64, f64)) -> f64 {
    let best = points.iter().filter(|q| q.0 <= p.0 && q.1.is_finite()).map(|q| q.1).fold(p.1, f64::min);
    p.1 / best
}

/// Draws the plot into `path`.
pub fn write(trade: &Trade, path: &Path) -> Result<(), SweepError> {
    let fail = |message: String| SweepError::Plot { path: path.display().to_string(), message };
    register_font("sans-serif", FontStyle::Normal, FONT).map_err(|_| fail("the embedded font".into()))?;
    let image_error: Series = trade
        .points
        .iter()
        .map(|p| (p.label.clone(), p.frame_flip, p.frame_ms, p.knobs.is_empty()))
        .collect();
    let seed_error: Series = trade
        .points
        .iter()
        .filter_map(|p| {
            let missed = 100.0 - p.any_part?.pixel_weighted_recall_pct;
            Some((p.label.clone(), missed, p.frame_ms, p.knobs.is_empty()))
        })
        .collect();
    let (w, h) = SIZE_PX;
    let mut pixels = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, SIZE_PX).into_drawing_area();
        root.fill(&WHITE).map_err(|e| fail(e.to_string()))?;
        // The dataset's folder name: the title should not depend on where it was measured.
        let dataset = Path::new(&trade.dataset)
            .file_name()
            .map_or(trade.dataset.clone(), |n| n.to_string_lossy().into_owned());
        let title = format!(
            "terramp speed trade: {dataset} at {}x{} ({} timed frames, {} sample poses)",
            trade.resolution[0],
            trade.resolution[1],
            trade.frames,
            trade.sample_t.len()
        );
        let root = root.titled(&title, ("sans-serif", 22)).map_err(|e| fail(e.to_string()))?;
        let flip = "frame error vs ground truth: mean FLIP";
        let panels: Vec<(&str, &Series)> = if seed_error.is_empty() {
            vec![(flip, &image_error)]
        } else {
            vec![
                (flip, &image_error),
                ("tree pixels missed vs ground truth: 100 - pixel-weighted recall (%)", &seed_error),
            ]
        };
        let areas = root.split_evenly((1, panels.len()));
        for (area, (x_desc, series)) in areas.iter().zip(panels) {
            panel(area, x_desc, series).map_err(fail)?;
        }
        root.present().map_err(|e| fail(e.to_string()))?;
    }
    let image = image::RgbImage::from_raw(w, h, pixels).ok_or_else(|| fail("buffer size".into()))?;
    image.save(path).map_err(|e| fail(e.to_string()))
}

fn panel(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    x_desc: &str,
    series: &Series,
) -> Result<(), String> {
    let max_x = series.iter().map(|s| s.1).filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    let max_y = series.iter().map(|s| s.2).filter(|v| v.is_finite()).fold(0.0f64, f64::max);
    // Room for the labels to the right of the points; never an empty range.
    let x_end = if max_x > 0.0 { max_x * 1.35 } else { 1e-3 };
    let y_end = if max_y > 0.0 { max_y * 1.15 } else { 1.0 };
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..x_end, 0.0..y_end)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("frame time, ms (median wall)")
        .axis_desc_style(("sans-serif", 16))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    let colours = [
        RGBColor(31, 119, 180),
        RGBColor(214, 39, 40),
        RGBColor(44, 160, 44),
        RGBColor(148, 103, 189),
        RGBColor(255, 127, 14),
        RGBColor(140, 86, 75),
    ];
    // The front as a staircase: from each front point across to the next more accurate one's
    // error, then down... to its time.
    let points: Vec<(f64, f64)> = series.iter().map(|s| (s.1, s.2)).collect();
    let on_front = front(&points);
    let mut steps: Vec<(f64, f64)> =
        points.iter().zip(&on_front).filter(|(_, f)| **f).map(|(p, _)| *p).collect();
    steps.sort_by(|a, b| a.0.total_cmp(&b.0));
    let stairs: Vec<(f64, f64)> = steps
        .windows(2)
        .flat_map(|w| [w[0], (w[1].0, w[0].1), w[1]])
        .chain(steps.first().copied().filter(|_| steps.len() == 1))
        .collect();
    let grey = RGBColor(120, 120, 120);
    chart.draw_series(LineSeries::new(stairs, grey.stroke_width(2))).map_err(|e| e.to_string())?;
    for (i, (label, x, y, preset)) in series.iter().enumerate() {
        if !(x.is_finite() && y.is_finite()) {
            continue;
        }
        let colour = colours[i % colours.len()];
        // The label beside its point, not over it; a preset ringed.
        let ring = if *preset { 10 } else { 0 };
        let marker = EmptyElement::at((*x, *y))
            + Circle::new((0, 0), 5, colour.filled())
            + Circle::new((0, 0), ring, colour.stroke_width(2))
            + Text::new(label.clone(), (10, -18), ("sans-serif", 14).into_font().color(&colour));
        chart.draw_series(std::iter::once(marker)).map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_keeps_the_points_nothing_beats_and_slack_measures_the_rest() {
        // (error, time): b beats d on both; c is the most accurate; a the fastest.
        let points = [(0.30, 10.0), (0.10, 20.0), (0.05, 40.0), (0.12, 30.0), (f64::NAN, 1.0)];
        assert_eq!(front(&points), [true, true, true, false, false]);
        assert_eq!(front_slack(&points, points[3]), 1.5);
        assert_eq!(front_slack(&points, points[1]), 1.0);
    }

    #[test]
    fn the_plot_is_a_png_of_the_stated_size() {
        let dir = std::env::temp_dir().join(format!("terramp-plot-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("trade.png");
        write(&super::super::report::tests::trade(), &file).unwrap();
        let image = image::open(&file).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), SIZE_PX);
        // Something is drawn besides the white page (axes, labels, points).
        assert!(image.pixels().filter(|p| p.0 != [255, 255, 255]).count() > 10_000);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
