//! How it works: `trade.png`, the trade as a picture: frame time (median wall time, ms) up, error
//! across, one labelled point per preset or knob value. Two panels share the time axis: the
//! frame's image error against the all-resident accurate reference (1 − SSIM, which folds mesh,
//! imagery and seeds into one number), and the seed set's error against the exact oracle
//! (100 − F1 %, F1 the harmonic mean of recall and precision, so both lost and extra seeds count).
//! The second panel is left out when no point has seeds. Drawn by plotters into a pixel buffer and
//! saved as PNG with `image`; text uses the embedded DejaVu Sans Mono (assets/fonts), so the plot
//! needs no system font.

use std::path::Path;

use plotters::prelude::*;
use plotters::style::{FontStyle, register_font};

use super::SweepError;
use super::report::Trade;

const FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSansMono.ttf");
const SIZE_PX: (u32, u32) = (1400, 640);

/// The seed-set error of a point, %: 100 − F1 of recall and precision.
pub fn seed_error_pct(recall_pct: f64, precision_pct: f64) -> f64 {
    let (r, p) = (recall_pct / 100.0, precision_pct / 100.0);
    if r + p <= 0.0 { 100.0 } else { 100.0 * (1.0 - 2.0 * r * p / (r + p)) }
}

/// One panel's points: (label, error, frame ms).
type Series = Vec<(String, f64, f64)>;

/// Draws the plot into `path`.
pub fn write(trade: &Trade, path: &Path) -> Result<(), SweepError> {
    let fail = |message: String| SweepError::Plot { path: path.display().to_string(), message };
    register_font("sans-serif", FontStyle::Normal, FONT).map_err(|_| fail("the embedded font".into()))?;
    let image_error: Series =
        trade.points.iter().map(|p| (p.label.clone(), (1.0 - p.frame_ssim).max(0.0), p.frame_ms)).collect();
    let seed_error: Series = trade
        .points
        .iter()
        .filter_map(|p| {
            Some((p.label.clone(), seed_error_pct(p.seeds?.recall_pct, p.seeds?.precision_pct), p.frame_ms))
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
        let panels: Vec<(&str, &Series)> = if seed_error.is_empty() {
            vec![("frame error vs accurate, all resident: 1 - SSIM", &image_error)]
        } else {
            vec![
                ("frame error vs accurate, all resident: 1 - SSIM", &image_error),
                ("seed-set error vs exact oracle: 100 - F1 (%)", &seed_error),
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
    let max_x = series.iter().map(|s| s.1).fold(0.0f64, f64::max);
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
    for (i, (label, x, y)) in series.iter().enumerate() {
        let colour = colours[i % colours.len()];
        // The label beside its point, not over it.
        let marker = EmptyElement::at((*x, *y))
            + Circle::new((0, 0), 6, colour.filled())
            + Text::new(label.clone(), (10, -18), ("sans-serif", 14).into_font().color(&colour));
        chart.draw_series(std::iter::once(marker)).map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_error_is_100_minus_f1() {
        assert_eq!(seed_error_pct(100.0, 100.0), 0.0);
        assert!((seed_error_pct(90.0, 60.0) - 28.0).abs() < 1e-9); // F1 = 2·0.54/1.5 = 0.72
        assert_eq!(seed_error_pct(0.0, 0.0), 100.0);
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
