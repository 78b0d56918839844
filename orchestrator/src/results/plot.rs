//! `errors.svg`: attitude and angular-velocity errors per agent against
//! time, log scale, like the paper's figures (Section `simulation`).

use super::Series;
use plotters::prelude::*;
use std::path::Path;

/// Smallest value drawn on the log axes (exact zeros are clamped to it).
const FLOOR: f64 = 1e-16;

/// Draws the two panels into `file` (SVG).
pub fn draw(file: &Path, title: &str, series: &[Series]) -> Result<(), String> {
    let root = SVGBackend::new(file, (1000, 900)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let root = root
        .titled(title, ("sans-serif", 22))
        .map_err(|e| e.to_string())?;
    let (top, bottom) = root.split_vertically(440);
    panel(&top, "attitude error |R_i R_0^T|_I", series, |s| &s.att)?;
    panel(
        &bottom,
        "angular velocity error ||w_i - w_0|| (rad/s)",
        series,
        |s| &s.angvel,
    )?;
    root.present().map_err(|e| e.to_string())
}

fn panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    label: &str,
    series: &[Series],
    pick: impl Fn(&Series) -> &Vec<f64>,
) -> Result<(), String> {
    let t_end = series
        .iter()
        .filter_map(|s| s.t.last().copied())
        .fold(0.0_f64, f64::max)
        .max(1e-9);
    let values = series.iter().flat_map(|s| pick(s).iter().copied());
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v.max(FLOOR)), hi.max(v.max(FLOOR)))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo / 2.0, hi * 2.0)
    } else {
        (FLOOR, 1.0)
    };
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(70)
        .caption(label, ("sans-serif", 16))
        .build_cartesian_2d(0.0..t_end, (lo..hi).log_scale())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("t (s)")
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|e| e.to_string())?;
    for (k, s) in series.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let ys = pick(s);
        chart
            .draw_series(LineSeries::new(
                s.t.iter().zip(ys).map(|(&t, &y)| (t, y.max(FLOOR))),
                color.stroke_width(2),
            ))
            .map_err(|e| e.to_string())?
            .label(format!("agent {}", s.id))
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], color.stroke_width(2))
            });
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .position(SeriesLabelPosition::UpperRight)
        .draw()
        .map_err(|e| e.to_string())
}
