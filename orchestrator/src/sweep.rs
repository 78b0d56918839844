//! `attsync sweep`: one scenario over a list of values of one field, runs in
//! parallel (each isolated), and the bisection that finds the largest value
//! that still converges.
//!
//! Convergence criterion: the run completes and every agent's attitude error
//! `|Rᵢ R₀ᵀ|_I` at the end of the run is below `tolerance` (default 1e-3).

use crate::results::staging::Staging;
use crate::run::{RunOptions, run};
use crate::scenario;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

/// What to sweep and how.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Field path, as for `--set` (e.g. `network.delay`).
    pub param: String,
    /// Values (TOML literals).
    pub values: Vec<String>,
    /// Parallel runs.
    pub jobs: usize,
    /// Other overrides applied to every run.
    pub set: Vec<String>,
    /// Engine and output options of each run (`out` is the sweep directory).
    pub run: RunOptions,
    /// Convergence tolerance on the final attitude error.
    pub tolerance: f64,
    /// Bisect between the first and last value for the margin: iterations and quantum.
    pub find_margin: Option<(u32, f64)>,
}

/// One run of a sweep.
#[derive(Debug, Clone)]
pub struct SweepRow {
    /// The value, as given.
    pub value: String,
    /// Largest final attitude error over agents.
    pub final_max_att_err: f64,
    /// Time after which every agent's attitude error stays below 1e-3 (None: not by the end).
    pub time_to_1e3: Option<f64>,
    /// The convergence criterion.
    pub converged: bool,
    /// Whether the run reached its horizon.
    pub complete: bool,
    /// Results directory of the run, relative to the sweep directory.
    pub dir: String,
}

/// The sweep's result.
#[derive(Debug, Clone)]
pub struct SweepResult {
    /// Rows, in value order of execution (listed values first, then bisection).
    pub rows: Vec<SweepRow>,
    /// Largest value found to converge by bisection, and the smallest that did not.
    pub margin: Option<(f64, f64)>,
}

fn run_one(
    o: &SweepOptions,
    dir: &Path,
    k: usize,
    value: &str,
    interrupt: &AtomicBool,
) -> Result<SweepRow, String> {
    let mut set = o.set.clone();
    set.push(format!("{}={value}", o.param));
    let loaded = scenario::load(&o.scenario, &set).map_err(|e| e.to_string())?;
    let name = format!("{k:03}-{}", value.replace(['/', ' ', '"'], "_"));
    let opts = RunOptions {
        out: dir.join("runs").join(&name),
        progress: false,
        ..o.run.clone()
    };
    let s = run(&loaded, &opts, interrupt).map_err(|e| format!("{} = {value}: {e}", o.param))?;
    let time_to_1e3 = s
        .agents
        .iter()
        .map(|a| a.settle_time_1e3)
        .try_fold(0.0_f64, |m, t| t.map(|t| m.max(t)));
    Ok(SweepRow {
        value: value.to_string(),
        final_max_att_err: s.max_final_att_err,
        time_to_1e3,
        converged: s.complete && s.agents.iter().all(|a| a.final_att_err < o.tolerance),
        complete: s.complete,
        dir: format!("runs/{name}"),
    })
}

/// Runs `values` with up to `jobs` at once.
fn run_many(
    o: &SweepOptions,
    dir: &Path,
    first: usize,
    values: &[String],
    interrupt: &AtomicBool,
) -> Result<Vec<SweepRow>, String> {
    let next = Mutex::new(0usize);
    let out: Mutex<Vec<Option<Result<SweepRow, String>>>> = Mutex::new(vec![None; values.len()]);
    std::thread::scope(|s| {
        for _ in 0..o.jobs.max(1).min(values.len()) {
            s.spawn(|| {
                loop {
                    let k = {
                        let mut n = next.lock().expect("lock");
                        let k = *n;
                        *n += 1;
                        k
                    };
                    if k >= values.len() || interrupt.load(Ordering::Relaxed) {
                        return;
                    }
                    let r = run_one(o, dir, first + k, &values[k], interrupt);
                    out.lock().expect("lock")[k] = Some(r);
                }
            });
        }
    });
    out.into_inner()
        .expect("lock")
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err("interrupted".into())))
        .collect()
}

/// Runs the sweep and writes `sweep.csv`, `sweep.svg` and every run's
/// results under `runs/` into `o.run.out` (atomically).
pub fn sweep(o: &SweepOptions, interrupt: &AtomicBool) -> Result<SweepResult, String> {
    // Validate every value before running anything.
    for v in &o.values {
        let mut set = o.set.clone();
        set.push(format!("{}={v}", o.param));
        scenario::load(&o.scenario, &set).map_err(|e| e.to_string())?;
    }
    let staging = Staging::new(&o.run.out).map_err(|e| format!("{}: {e}", o.run.out.display()))?;
    let dir = staging.path().to_owned();
    let mut rows = run_many(o, &dir, 0, &o.values, interrupt)?;
    let mut margin = None;
    if let Some((iterations, quantum)) = o.find_margin {
        let parse = |v: &str| {
            v.parse::<f64>()
                .map_err(|_| format!("--find-margin needs numeric values, got {v:?}"))
        };
        // Bracket: the first value that does not converge and the one before it.
        let Some(k) = rows.iter().position(|r| !r.converged) else {
            return Err(format!(
                "--find-margin needs a value that does not converge: every value of {} converges",
                o.param
            ));
        };
        if k == 0 {
            return Err(format!(
                "--find-margin needs the first value to converge: {} = {} does not",
                o.param, rows[0].value
            ));
        }
        let (mut lo, mut hi) = (parse(&rows[k - 1].value)?, parse(&rows[k].value)?);
        for _ in 0..iterations {
            let mut mid = 0.5 * (lo + hi);
            if quantum > 0.0 {
                // A multiple of the quantum, written without round-off noise.
                let decimals = (-quantum.log10()).ceil().max(0.0) as usize + 1;
                mid = format!("{:.decimals$}", (mid / quantum).round() * quantum)
                    .parse()
                    .expect("a formatted number parses");
                if mid <= lo.min(hi) + quantum * 0.5 || mid >= lo.max(hi) - quantum * 0.5 {
                    break;
                }
            }
            let value = format!("{mid}");
            let row =
                run_many(o, &dir, rows.len(), std::slice::from_ref(&value), interrupt)?.remove(0);
            if row.converged {
                lo = mid;
            } else {
                hi = mid;
            }
            rows.push(row);
        }
        margin = Some((lo, hi));
    }
    let mut csv = String::from("value,final_max_att_err,time_to_1e-3,converged,complete,run\n");
    for r in &rows {
        let _ = writeln!(
            csv,
            "{},{},{},{},{},{}",
            r.value,
            r.final_max_att_err,
            r.time_to_1e3.map_or(String::new(), |t| t.to_string()),
            r.converged,
            r.complete,
            r.dir
        );
    }
    std::fs::write(dir.join("sweep.csv"), csv).map_err(|e| e.to_string())?;
    let info = serde_json::json!({
        "param": o.param,
        "criterion": format!("complete and every agent's final att_err < {}", o.tolerance),
        "margin": margin.map(|(lo, hi)| serde_json::json!({"largest_converging": lo, "smallest_failing": hi})),
    });
    std::fs::write(
        dir.join("sweep.json"),
        serde_json::to_string_pretty(&info).expect("json") + "\n",
    )
    .map_err(|e| e.to_string())?;
    plot(&dir.join("sweep.svg"), &o.param, &rows).map_err(|e| format!("sweep.svg: {e}"))?;
    std::fs::write(
        dir.join(crate::results::staging::MARKER),
        serde_json::to_string_pretty(&info).expect("json") + "\n",
    )
    .map_err(|e| e.to_string())?;
    staging.commit().map_err(|e| e.to_string())?;
    Ok(SweepResult { rows, margin })
}

/// The table printed at the end.
#[must_use]
pub fn table(param: &str, r: &SweepResult) -> String {
    let mut s = format!(
        "{:>14} {:>16} {:>12} {:>9}\n",
        param, "final_max_att", "t_to_1e-3", "converged"
    );
    for row in &r.rows {
        let _ = writeln!(
            s,
            "{:>14} {:>16.3e} {:>12} {:>9}",
            row.value,
            row.final_max_att_err,
            row.time_to_1e3
                .map_or("never".into(), |t| format!("{t:.2}")),
            if row.converged {
                "yes"
            } else if row.complete {
                "no"
            } else {
                "FAILED"
            }
        );
    }
    if let Some((lo, hi)) = r.margin {
        let _ = writeln!(s, "margin: {param} = {lo} converges, {hi} does not");
    }
    s
}

fn plot(file: &Path, param: &str, rows: &[SweepRow]) -> Result<(), String> {
    let pts: Vec<(f64, f64, bool)> = rows
        .iter()
        .filter_map(|r| {
            r.value
                .parse::<f64>()
                .ok()
                .map(|v| (v, r.final_max_att_err.max(1e-16), r.converged))
        })
        .collect();
    if pts.is_empty() {
        return Ok(());
    }
    let (x0, x1) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.0), b.max(p.0))
        });
    let (x0, x1) = if x1 > x0 {
        (x0, x1)
    } else {
        (x0 - 1.0, x1 + 1.0)
    };
    let root = SVGBackend::new(file, (900, 500)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .margin(15)
        .caption(
            format!("final max attitude error vs {param}"),
            ("sans-serif", 18),
        )
        .x_label_area_size(40)
        .y_label_area_size(70)
        .build_cartesian_2d(x0..x1, (1e-16f64..1.0).log_scale())
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc(param)
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()
        .map_err(|e| e.to_string())?;
    let mut sorted = pts.clone();
    sorted.sort_by(|a, b| a.0.total_cmp(&b.0));
    chart
        .draw_series(LineSeries::new(
            sorted.iter().map(|p| (p.0, p.1)),
            BLUE.stroke_width(2),
        ))
        .map_err(|e| e.to_string())?;
    chart
        .draw_series(pts.iter().map(|p| {
            Circle::new(
                (p.0, p.1),
                5,
                if p.2 { GREEN.filled() } else { RED.filled() },
            )
        }))
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
