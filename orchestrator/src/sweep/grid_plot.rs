//! `sweep.svg` of a grid (two `--param`): the stability chart every delay
//! paper draws. One cell per run at (value of the first field, value of
//! the second), filled with the colour of its verdict (a failed run
//! black); in it, the linearisation's prediction (`attitude::linear`, the
//! real part of the rightmost root): a white dot where it predicts the
//! error decays, a cross where it does not. Where dot and fill disagree,
//! simulation and theory part ways (or the horizon was too short:
//! `--until settled`). Values sit at equal spacing, in the order given.

use super::plot::colour;
use super::{SweepOptions, SweepRow};
use crate::results::plot::PlotError;
use attsync_verdict::Kind;
use plotters::coord::ranged1d::SegmentValue;
use plotters::prelude::*;
use std::path::Path;

/// The legend: each verdict's fill, in order from best to worst.
const KINDS: [Kind; 5] = [
    Kind::Converged,
    Kind::Converging,
    Kind::Undecided,
    Kind::Persistent,
    Kind::Diverging,
];

/// A cell's fill: its verdict's colour, black for a run that failed.
fn fill(r: &SweepRow) -> RGBColor {
    if r.failed() {
        BLACK
    } else {
        colour(r.verdict.kind)
    }
}

/// A run's cell: the indices of its values among the given ones.
fn cell(o: &SweepOptions, r: &SweepRow) -> Option<(usize, usize)> {
    let g = o.grid.as_ref()?;
    let i = o.values.iter().position(|v| *v == r.value)?;
    let j = g.values.iter().position(|v| Some(v) == r.value2.as_ref())?;
    Some((i, j))
}

/// The name of value `v` of `values` at a segment's centre, else nothing.
fn label(values: &[String], v: &SegmentValue<usize>) -> String {
    match v {
        SegmentValue::CenterOf(i) => values.get(*i).cloned().unwrap_or_default(),
        _ => String::new(),
    }
}

/// Draws the chart of `rows` over the grid `(first, second)` into `file`.
pub(super) fn draw(
    file: &Path,
    (first, second): (&str, &str),
    o: &SweepOptions,
    rows: &[SweepRow],
) -> Result<(), PlotError> {
    let Some(g) = &o.grid else { return Ok(()) };
    let (n1, n2) = (o.values.len(), g.values.len());
    let root = SVGBackend::new(file, (980, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(PlotError::of)?;
    let (left, right) = root.split_horizontally(760);
    let mut chart = ChartBuilder::on(&left)
        .margin(15)
        .caption(
            format!("verdict per run: {first} × {second}"),
            ("sans-serif", 18),
        )
        .x_label_area_size(45)
        .y_label_area_size(80)
        .build_cartesian_2d((0..n1).into_segmented(), (0..n2).into_segmented())
        .map_err(PlotError::of)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(first)
        .y_desc(second)
        .x_labels(n1 + 1)
        .y_labels(n2 + 1)
        .x_label_formatter(&|v| label(&o.values, v))
        .y_label_formatter(&|v| label(&g.values, v))
        .draw()
        .map_err(PlotError::of)?;
    let e = |e: DrawingAreaErrorKind<_>| PlotError::of(e);
    let cells: Vec<((usize, usize), &SweepRow)> =
        rows.iter().filter_map(|r| Some((cell(o, r)?, r))).collect();
    let at = |i: usize, j: usize| (SegmentValue::Exact(i), SegmentValue::Exact(j));
    chart
        .draw_series(
            cells
                .iter()
                .map(|&((i, j), r)| Rectangle::new([at(i, j), at(i + 1, j + 1)], fill(r).filled())),
        )
        .map_err(e)?;
    let centre = |i: usize, j: usize| (SegmentValue::CenterOf(i), SegmentValue::CenterOf(j));
    let decays = |r: &&SweepRow| r.linear_rate.is_some_and(|x| x < 0.0);
    for style in [WHITE.filled(), BLACK.stroke_width(1)] {
        chart
            .draw_series(
                (cells.iter().filter(|(_, r)| decays(r)))
                    .map(|&((i, j), _)| Circle::new(centre(i, j), 5, style)),
            )
            .map_err(e)?;
    }
    chart
        .draw_series(
            (cells.iter())
                .filter(|(_, r)| r.linear_rate.is_some() && !decays(r))
                .map(|&((i, j), _)| Cross::new(centre(i, j), 6, BLACK.stroke_width(2))),
        )
        .map_err(e)?;
    legend(&right).map_err(e)?;
    root.present().map_err(PlotError::of)
}

/// The legend, in the right-hand panel: the fills, then the markers.
fn legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = ("sans-serif", 14).into_font();
    let mut y = 60;
    let row = |y: i32, text: String| area.draw(&Text::new(text, (40, y - 7), font.clone()));
    for k in KINDS {
        area.draw(&Rectangle::new(
            [(12, y - 8), (30, y + 8)],
            colour(k).filled(),
        ))?;
        row(y, format!("verdict: {}", k.name()))?;
        y += 26;
    }
    area.draw(&Rectangle::new([(12, y - 8), (30, y + 8)], BLACK.filled()))?;
    row(y, "the run failed".into())?;
    y += 40;
    area.draw(&Circle::new((21, y), 5, BLACK.stroke_width(1)))?;
    row(y, "linearisation: decays".into())?;
    y += 26;
    area.draw(&Cross::new((21, y), 6, BLACK.stroke_width(2)))?;
    row(y, "linearisation: does not".into())
}
