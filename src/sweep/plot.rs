//! How it works: `trade.png`, the trade as a picture: frame time (median wall time, ms) up, error
//! across, one point per preset or knob value. Presets are ringed and named; a knob's points share
//! a colour (the legend names the knob) and are labelled with their value alone, so thirty points
//! stay legible. Two panels share the time axis: the frame's error against the ground truth (mean FLIP, which folds terrain, imagery and
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
const SIZE_PX: (u32, u32) = (1600, 760);

/// One point of a panel.
struct Dot {
    /// The legend's group: "presets", or the knobs the point varies.
    group: String,
    /// Its label beside the point: the preset's name, or the knob values alone.
    short: String,
    error: f64,
    frame_ms: f64,
}

/// One panel's points.
type Series = Vec<Dot>;

/// The point's dot: its legend group and short label.
fn dot(p: &super::TradePoint, error: f64) -> Dot {
    let (group, short) = match p.knobs.is_empty() {
        true => ("presets".to_owned(), p.preset.clone()),
        false => (
            p.knobs.keys().cloned().collect::<Vec<_>>().join(" + "),
            p.knobs.values().cloned().collect::<Vec<_>>().join(", "),
        ),
    };
    Dot { group, short, error, frame_ms: p.frame_ms }
}

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
    let image_error: Series = trade.points.iter().map(|p| dot(p, p.frame_flip)).collect();
    let seed_error: Series = trade
        .points
        .iter()
        .filter_map(|p| Some(dot(p, 100.0 - p.any_part?.pixel_weighted_recall_pct)))
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
    let finite: Vec<&Dot> = series.iter().filter(|d| d.error.is_finite() && d.frame_ms.is_finite()).collect();
    let max_x = finite.iter().map(|d| d.error).fold(0.0f64, f64::max);
    let (min_y, max_y) =
        finite.iter().map(|d| d.frame_ms).fold((f64::INFINITY, 0.0f64), |(lo, hi), t| (lo.min(t), hi.max(t)));
    // Room for the labels to the right of the points; the times' own range, never an empty one.
    let x_end = if max_x > 0.0 { max_x * 1.2 } else { 1e-3 };
    let pad = ((max_y - min_y) * 0.08).max(max_y * 0.02).max(1e-3);
    let (y_start, y_end) = if max_y > 0.0 { ((min_y - pad).max(0.0), max_y + pad) } else { (0.0, 1.0) };
    let mut chart = ChartBuilder::on(area)
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(64)
        .build_cartesian_2d(0.0..x_end, y_start..y_end)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc("frame time, ms (median wall)")
        .axis_desc_style(("sans-serif", 16))
        .label_style(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    // The front as a staircase: from each front point across to the next more accurate one's
    // error, then down... to its time.
    let points: Vec<(f64, f64)> = series.iter().map(|d| (d.error, d.frame_ms)).collect();
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
    let mut groups: Vec<&str> = Vec::new();
    for d in &finite {
        if !groups.contains(&d.group.as_str()) {
            groups.push(&d.group);
        }
    }
    for (g, group) in groups.iter().enumerate() {
        let colour = COLOURS[g % COLOURS.len()];
        let presets = *group == "presets";
        let dots = finite.iter().filter(|d| d.group == *group).map(|d| {
            // The label beside its point, not over it; a preset ringed and named larger.
            let (ring, size) = if presets { (10, 16) } else { (0, 12) };
            EmptyElement::at((d.error, d.frame_ms))
                + Circle::new((0, 0), 5, colour.filled())
                + Circle::new((0, 0), ring, colour.stroke_width(2))
                + Text::new(d.short.clone(), (9, -14), ("sans-serif", size).into_font().color(&colour))
        });
        chart
            .draw_series(dots)
            .map_err(|e| e.to_string())?
            .label(*group)
            .legend(move |(x, y)| Circle::new((x + 8, y), 5, colour.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(grey)
        .label_font(("sans-serif", 13))
        .draw()
        .map_err(|e| e.to_string())?;
    Ok(())
}

/// The groups' colours, in the order the groups first appear (presets first).
const COLOURS: [RGBColor; 12] = [
    RGBColor(20, 20, 20),
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(127, 127, 127),
    RGBColor(0, 0, 128),
];

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
