//! A sweep's files: `sweep.csv` (one row per run), `sweep.json` (the
//! criterion and the margin), `sweep.svg` ([`super::plot`]) and the table
//! printed at the end. Units are in every header.

use super::margin::{LinearMargin, MarginResult};
use super::{SweepError, SweepOptions, SweepResult, SweepRow, io_at};
use crate::results::layout::SweepLayout;
use crate::scenario::Loaded;
use std::fmt::Write as _;
use std::path::Path;

/// The exact header of `sweep.csv`.
pub const CSV_HEADER: &str = "value,verdict,decay_rate_per_s,linear_rate_per_s,final_max_att_err,\
settle_att_1e-3_s,settle_att_1e-6_s,settle_angvel_1e-3_s,settle_angvel_1e-6_s,converged,complete,duration_s,run";

fn opt(x: Option<f64>) -> String {
    x.map_or(String::new(), |v| v.to_string())
}

/// The header of `sweep.csv`: [`CSV_HEADER`] for one field; for a grid,
/// its first column is the two fields' paths (`network.delay,
/// scheme.control.k_r`).
#[must_use]
pub fn csv_header(o: &SweepOptions) -> String {
    match &o.grid {
        Some(g) => CSV_HEADER.replacen("value", &format!("{},{}", o.param, g.param), 1),
        None => CSV_HEADER.to_string(),
    }
}

/// One row of `sweep.csv`.
fn csv_row(r: &SweepRow) -> String {
    let s = &r.settle;
    let value = match &r.value2 {
        Some(v2) => format!("{},{v2}", r.value),
        None => r.value.clone(),
    };
    format!(
        "{},{},{},{},{},{},{},{},{},{},{},{},{}",
        value,
        r.verdict.kind.name(),
        opt(r.verdict.decay_rate),
        opt(r.linear_rate),
        r.final_max_att_err,
        opt(s.att_1e3),
        opt(s.att_1e6),
        opt(s.angvel_1e3),
        opt(s.angvel_1e6),
        r.converged,
        r.complete,
        r.duration,
        r.dir
    )
}

/// `sweep.csv`, `sweep.json`, `sweep.svg` and the staging marker.
pub(super) fn write(
    o: &SweepOptions,
    base: &Loaded,
    dir: &Path,
    rows: &[SweepRow],
    margin: Option<&MarginResult>,
) -> Result<(), SweepError> {
    let mut csv = format!("{}\n", csv_header(o));
    for r in rows {
        let _ = writeln!(csv, "{}", csv_row(r));
    }
    let layout = SweepLayout::new(dir);
    let file = layout.csv();
    std::fs::write(&file, csv).map_err(io_at(&file))?;
    let tolerance = o.run.judging.tolerance;
    let info = serde_json::json!({
        "param": o.param,
        "grid": o.grid.as_ref().map(|g| &g.param),
        "criterion": format!(
            "verdict from the largest attitude error over agents over the whole run \
             (docs/verdicts.md); converged: below {tolerance} and staying there; \
             the margin: whether the error decays (converged or converging)"
        ),
        "until": match o.run.judging.until {
            crate::until::Until::Horizon => serde_json::json!("horizon"),
            crate::until::Until::Settled { max_duration } =>
                serde_json::json!({"rule": "settled", "max_duration": max_duration}),
        },
        "margin": margin,
    });
    let info = serde_json::to_string_pretty(&info).expect("json") + "\n";
    let file = layout.json();
    std::fs::write(&file, &info).map_err(io_at(&file))?;
    match &o.grid {
        Some(g) => super::grid_plot::draw(&layout.svg(), (&o.param, &g.param), o, rows),
        None => super::plot::draw(&layout.svg(), &o.param, base, rows, margin),
    }
    .map_err(|e| SweepError::Plot(e.0))?;
    let file = layout.summary();
    std::fs::write(&file, &info).map_err(io_at(&file))
}

/// The table printed at the end (`param`: the swept fields, joined by
/// `,` for a grid).
#[must_use]
pub fn table(param: &str, r: &SweepResult) -> String {
    let mut s = format!(
        "{:>14} {:>11} {:>14} {:>14} {:>14} {:>16} {:>12}\n",
        param,
        "verdict",
        "decay_rate",
        "linear_rate",
        "final_max_att",
        "settle_att<1e-3",
        "duration"
    );
    let _ = writeln!(
        s,
        "{:>14} {:>11} {:>14} {:>14} {:>14} {:>16} {:>12}",
        "", "", "[1/s]", "[1/s]", "[1]", "[s]", "[s]"
    );
    let rate = |x: Option<f64>| x.map_or("-".into(), |v| format!("{v:.5}"));
    for row in &r.rows {
        let _ = writeln!(
            s,
            "{:>14} {:>11} {:>14} {:>14} {:>14.3e} {:>16} {:>12}",
            match &row.value2 {
                Some(v2) => format!("{},{v2}", row.value),
                None => row.value.clone(),
            },
            if row.failed() {
                "FAILED"
            } else {
                row.verdict.kind.name()
            },
            rate(row.verdict.decay_rate),
            rate(row.linear_rate),
            row.final_max_att_err,
            row.settle
                .att_1e3
                .map_or("never".into(), |t| format!("{t:.2}")),
            row.duration,
        );
    }
    if let Some(m) = &r.margin {
        let _ = writeln!(
            s,
            "margin: {param} = {} converges, {} does not",
            m.converges_up_to, m.fails_from
        );
        match &m.linear {
            Some(LinearMargin::Crossing { delay, omega }) => {
                let _ = writeln!(
                    s,
                    "linear margin: {delay:.6} s (a root crosses the imaginary axis at ω = {omega:.4} rad/s)"
                );
            }
            Some(LinearMargin::DelayIndependent) => {
                let _ = writeln!(s, "linear margin: none (stable for every delay)");
            }
            Some(LinearMargin::UnstableWithoutDelay) => {
                let _ = writeln!(s, "linear margin: 0 (unstable without delay)");
            }
            Some(LinearMargin::Unavailable { reason }) => {
                let _ = writeln!(s, "linear margin: unavailable ({reason})");
            }
            None => {}
        }
        if let Some(w) = &m.warning {
            let _ = writeln!(s, "warning: {w}");
        }
    }
    s
}
