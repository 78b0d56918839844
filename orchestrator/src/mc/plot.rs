//! `mc.svg`: the empirical CDF of the settle times (to 1e-3 and 1e-6) and
//! the histogram of the final errors on a log scale.

use super::outcome::TrialResult;
use crate::results::plot::{PlotError, bars, canvas, chart, legend, line};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Which settle time of a trial a curve shows.
type Pick = fn(&TrialResult) -> Option<f64>;

/// Smallest error drawn (exact zeros and smaller are put in its bin).
const FLOOR: f64 = 1e-16;

/// Draws both panels into `file` (SVG).
pub fn draw(file: &Path, title: &str, results: &[TrialResult]) -> Result<(), PlotError> {
    let root = canvas(file, (1000, 900), title)?;
    let (top, bottom) = root.split_vertically(440);
    ecdf(&top, results)?;
    histogram(&bottom, results)?;
    root.present().map_err(PlotError::of)
}

/// The points of the ECDF of `times` (sorted) as a step line, over `n` trials.
fn steps(times: &[f64], n: usize, t_end: f64) -> Vec<(f64, f64)> {
    let mut pts = vec![(0.0, 0.0)];
    for (k, &t) in times.iter().enumerate() {
        pts.push((t, k as f64 / n as f64));
        pts.push((t, (k + 1) as f64 / n as f64));
    }
    let last = pts.last().map_or(0.0, |p| p.1);
    pts.push((t_end, last));
    pts
}

fn ecdf<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    results: &[TrialResult],
) -> Result<(), PlotError> {
    let n = results.len().max(1);
    let t_end = results.iter().map(|r| r.t_end).fold(1e-9, f64::max);
    let caption = "fraction of trials settled (ECDF of settle times; never settled: not reached)";
    let mut chart = chart(area, caption, 60)
        .build_cartesian_2d(0.0..t_end, 0.0..1.0)
        .map_err(PlotError::of)?;
    chart
        .configure_mesh()
        .x_desc("settle time (s)")
        .draw()
        .map_err(PlotError::of)?;
    let curves: [(&str, Pick, RGBColor); 2] = [
        ("att < 1e-3", |r| r.settle.att_1e3, BLUE),
        ("att < 1e-6", |r| r.settle.att_1e6, RED),
    ];
    for (label, pick, color) in curves {
        let mut times: Vec<f64> = results.iter().filter_map(pick).collect();
        times.sort_by(f64::total_cmp);
        line(
            &mut chart,
            steps(&times, n, t_end),
            color.stroke_width(2),
            label,
        )?;
    }
    legend(&mut chart, SeriesLabelPosition::LowerRight)
}

/// Counts of `log10(max(v, FLOOR))` in unit bins from `lo` (NaN: not counted).
fn bins(values: impl Iterator<Item = f64>, lo: i32, hi: i32) -> Vec<u32> {
    let mut c = vec![0; (hi - lo) as usize];
    for v in values.filter(|v| !v.is_nan()) {
        let b = (v.max(FLOOR).log10().floor() as i32).clamp(lo, hi - 1);
        c[(b - lo) as usize] += 1;
    }
    c
}

fn histogram<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    results: &[TrialResult],
) -> Result<(), PlotError> {
    let (lo, hi) = (-16, 2);
    let att = bins(results.iter().map(|r| r.final_max_att_err), lo, hi);
    let angvel = bins(results.iter().map(|r| r.final_max_angvel_err), lo, hi);
    let top = att.iter().chain(&angvel).copied().max().unwrap_or(1).max(1);
    let caption = "final max error over agents (histogram, log10 bins)";
    let mut chart = chart(area, caption, 60)
        .build_cartesian_2d(f64::from(lo)..f64::from(hi), 0.0..f64::from(top) * 1.1)
        .map_err(PlotError::of)?;
    chart
        .configure_mesh()
        .x_desc("log10 error (att: |R_i R_0^T|_I; angvel: rad/s)")
        .y_desc("trials")
        .draw()
        .map_err(PlotError::of)?;
    let series = [
        ("att_err", &att, BLUE, 0.05),
        ("angvel_err", &angvel, RED, 0.5),
    ];
    for (label, counts, color, off) in series {
        let rects = counts.iter().enumerate().map(move |(k, &c)| {
            let x = f64::from(lo) + k as f64 + off;
            Rectangle::new(
                [(x, 0.0), (x + 0.45, f64::from(c))],
                color.mix(0.7).filled(),
            )
        });
        bars(&mut chart, rects, label, color.filled(), 12)?;
    }
    legend(&mut chart, SeriesLabelPosition::UpperLeft)
}
