//! `sweep.svg`: the stability chart. The decay rate each run measured
//! (1/s, negative = decaying) against the swept value, one dot per run
//! coloured by its verdict, the zero line, and the linearisation's
//! prediction (the real part of its rightmost root): for a swept delay a
//! curve over the whole range, else through the runs' values.

use super::SweepRow;
use super::margin::{DELAY_FIELD, LinearMargin, MarginResult};
use crate::results::plot::PlotError;
use crate::scenario::Loaded;
use attsync_verdict::Kind;
use plotters::prelude::*;
use std::path::Path;

/// Points of the linear curve of a swept delay.
const CURVE_POINTS: usize = 120;

/// The colour of a verdict's dot (and of a grid's cell).
pub(super) fn colour(kind: Kind) -> RGBColor {
    match kind {
        Kind::Converged => GREEN,
        Kind::Converging => RGBColor(0, 130, 200),
        Kind::Persistent => RGBColor(230, 140, 0),
        Kind::Diverging => RED,
        Kind::Undecided => RGBColor(128, 128, 128),
    }
}

/// The linear prediction over `[x0, x1]`: a curve for a swept delay, else
/// the runs' own predictions in value order.
fn linear_curve(
    param: &str,
    base: &Loaded,
    rows: &[SweepRow],
    x0: f64,
    x1: f64,
) -> Vec<(f64, f64)> {
    if param == DELAY_FIELD
        && let Ok(l) = attitude::linear::Linearisation::of(&base.resolved.network)
    {
        return (0..=CURVE_POINTS)
            .map(|k| x0 + (x1 - x0) * k as f64 / CURVE_POINTS as f64)
            .filter(|&d| d >= 0.0)
            .map(|d| (d, l.rightmost_at(d).re))
            .collect();
    }
    let mut pts: Vec<(f64, f64)> = rows
        .iter()
        .filter_map(|r| Some((r.value.parse::<f64>().ok()?, r.linear_rate?)))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    pts
}

/// Draws the chart into `file` (nothing for non-numeric values).
pub(super) fn draw(
    file: &Path,
    param: &str,
    base: &Loaded,
    rows: &[SweepRow],
    margin: Option<&MarginResult>,
) -> Result<(), PlotError> {
    let dots: Vec<(f64, f64, Kind)> = rows
        .iter()
        .filter_map(|r| {
            let v = r.value.parse::<f64>().ok()?;
            Some((v, r.verdict.decay_rate?, r.verdict.kind))
        })
        .collect();
    let xs: Vec<f64> = rows.iter().filter_map(|r| r.value.parse().ok()).collect();
    if xs.is_empty() {
        return Ok(());
    }
    let (x0, x1) = xs
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let (x0, x1) = if x1 > x0 {
        (x0, x1)
    } else {
        (x0 - 1.0, x1 + 1.0)
    };
    let curve = linear_curve(param, base, rows, x0, x1);
    let ys = dots.iter().map(|d| d.1).chain(curve.iter().map(|p| p.1));
    let (y0, y1) = ys.fold((0.0_f64, 0.0_f64), |(a, b), y| (a.min(y), b.max(y)));
    let pad = 0.08 * (y1 - y0).max(1e-3);
    let root = SVGBackend::new(file, (900, 520)).into_drawing_area();
    root.fill(&WHITE).map_err(PlotError::of)?;
    let mut chart = ChartBuilder::on(&root)
        .margin(15)
        .caption(
            format!("decay rate of the largest attitude error vs {param}"),
            ("sans-serif", 18),
        )
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
        .map_err(PlotError::of)?;
    chart
        .configure_mesh()
        .x_desc(param)
        .y_desc("decay rate [1/s] (< 0: decays)")
        .y_label_formatter(&|v| format!("{:.3}", if v.abs() < 1e-12 { 0.0 } else { *v }))
        .draw()
        .map_err(PlotError::of)?;
    let e = |e: DrawingAreaErrorKind<_>| PlotError::of(e);
    chart
        .draw_series(LineSeries::new(
            [(x0, 0.0), (x1, 0.0)],
            BLACK.stroke_width(1),
        ))
        .map_err(e)?;
    if !curve.is_empty() {
        chart
            .draw_series(LineSeries::new(curve, BLUE.stroke_width(2)))
            .map_err(e)?
            .label("linearisation: Re(rightmost root)")
            .legend(|(x, y)| PathElement::new([(x, y), (x + 20, y)], BLUE.stroke_width(2)));
    }
    if let Some(LinearMargin::Crossing { delay, .. }) = margin.and_then(|m| m.linear.as_ref())
        && (x0..=x1).contains(delay)
    {
        chart
            .draw_series(DashedLineSeries::new(
                [(*delay, y0 - pad), (*delay, y1 + pad)],
                6,
                4,
                BLUE.stroke_width(1),
            ))
            .map_err(e)?;
    }
    chart
        .draw_series(
            dots.iter()
                .map(|&(x, y, k)| Circle::new((x, y), 5, colour(k).filled())),
        )
        .map_err(e)?
        .label("simulation: fitted decay rate (colour: verdict)")
        .legend(|(x, y)| Circle::new((x + 10, y), 5, GREEN.filled()));
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(e)?;
    root.present().map_err(PlotError::of)
}
