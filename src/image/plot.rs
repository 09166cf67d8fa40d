//! Convergence plots (relMSE against render time, log-log) as SVG and PNG.
//!
//! Both files are drawn in memory and written atomically; text uses the embedded font so the
//! PNG looks the same on every machine.

use std::path::Path;
use std::sync::Once;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::font::FONT_TTF;
use super::io::{save_png_atomic, write_bytes_atomic};

/// Plot size in pixels (SVG user units and PNG pixels alike).
const SIZE: (u32, u32) = (800, 600);

/// Okabe–Ito palette: distinguishable under the common colour-vision deficiencies.
const PALETTE: [RGBColor; 8] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
    RGBColor(240, 228, 66),
];

/// plotters' ab_glyph text backend only knows fonts registered by name; do it once.
fn register_embedded_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Failure would mean the compiled-in font is broken; drawing then reports the error.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, FONT_TTF);
    });
}

/// Points that can appear on log-log axes (both coordinates finite and positive).
fn plottable(points: &[(f64, f64)]) -> impl Iterator<Item = (f64, f64)> + '_ {
    points
        .iter()
        .copied()
        .filter(|&(x, y)| x.is_finite() && y.is_finite() && x > 0.0 && y > 0.0)
}

/// Log-axis range covering `values` with a little headroom; a fallback when there are none.
fn log_range(values: impl Iterator<Item = f64>, fallback: (f64, f64)) -> std::ops::Range<f64> {
    let (lo, hi) = values.fold((f64::INFINITY, 0.0f64), |(lo, hi), v| (lo.min(v), hi.max(v)));
    if !lo.is_finite() {
        return fallback.0..fallback.1;
    }
    // A single decade or less looks degenerate on log axes; pad multiplicatively.
    let (lo, hi) = if hi / lo < 1.5 { (lo / 2.0, hi * 2.0) } else { (lo / 1.2, hi * 1.2) };
    lo..hi
}

/// Draw the chart onto any plotters backend.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    series: &[(String, Vec<(f64, f64)>)],
    title: &str,
) -> anyhow::Result<()>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let all = || series.iter().flat_map(|(_, p)| plottable(p));
    let xr = log_range(all().map(|p| p.0), (0.1, 10.0));
    let yr = log_range(all().map(|p| p.1), (1e-4, 1.0));
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(48)
        .y_label_area_size(72)
        .build_cartesian_2d(xr.log_scale(), yr.log_scale())?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .y_desc("relMSE")
        .x_label_formatter(&|v| format!("{v:.2}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()?;
    for (i, (name, points)) in series.iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        chart
            .draw_series(LineSeries::new(plottable(points), color.stroke_width(2)))?
            .label(name.as_str())
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], color.stroke_width(2)));
        chart.draw_series(plottable(points).map(|p| Circle::new(p, 3, color.filled())))?;
    }
    if !series.is_empty() {
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .label_font(("sans-serif", 14))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()?;
    }
    root.present()?;
    Ok(())
}

/// Log-log plot of relMSE against seconds, one line (with point markers) per named series and
/// a legend, written to `svg_path` and `png_path` (both atomically). Points with a non-positive
/// or non-finite coordinate cannot be shown on log axes and are skipped.
pub fn convergence_plot(
    series: &[(String, Vec<(f64, f64)>)],
    title: &str,
    svg_path: &Path,
    png_path: &Path,
) -> anyhow::Result<()> {
    register_embedded_font();
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, SIZE).into_drawing_area();
        draw(&root, series, title)?;
    }
    let mut rgb = vec![0u8; SIZE.0 as usize * SIZE.1 as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, SIZE).into_drawing_area();
        draw(&root, series, title)?;
    }
    let png = image::RgbImage::from_raw(SIZE.0, SIZE.1, rgb)
        .ok_or_else(|| anyhow::anyhow!("plot buffer has the wrong size"))?;
    write_bytes_atomic(svg_path, svg.as_bytes())?;
    save_png_atomic(&png, png_path)
}
