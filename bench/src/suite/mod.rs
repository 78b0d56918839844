//! `attsync-bench run [--quick] [--out FILE]`: the whole benchmark — the
//! cases, what is measured for each, and the Markdown report.
//!
//! Cases: the three paper scenarios (`scenarios/paper/*.toml`, 7 agents + the
//! leader = 8 nodes) and two generated trees (`attsync gen tree --agents 31|99
//! --leader-links 2 --seed 1`: 32 and 100 nodes with the leader). For each
//! case: the in-process engine; the process engine with every wait strategy;
//! a bare iceoryx2 lockstep ring of the same number of processes, the same
//! wait strategy and the same number of steps; and, with the default
//! strategy (adaptive), two diagnostics that split attsync's per-exchange
//! cost: a bare lockstep over the scenario's own graph, and attsync with
//! telemetry reduced to the first and last step. Then the contention case
//! ([`contend`]): paper-timevarying with as many CPU-bound competitors as
//! cores, per strategy, against the idle run and the bare ring under load.
//!
//! # Layout
//! - [`plan`]: durations, the cases, the spin rule.
//! - [`run`](mod@run): running the measurements and aggregating repetitions.
//! - [`contend`]: the contention case and its competitors.
//! - [`report`]: the Markdown report.
//! - this file: [`Options`] and the driver [`run()`].

mod contend;
mod plan;
mod report;
mod run;

pub use contend::burn;

use crate::error::{BenchError, Result};
use crate::measure::Bins;
use msgs::config::WaitStrategy;
use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

/// The case measured under contention too (8 nodes, scheme 1).
const CONTENDED_CASE: &str = "paper-timevarying";

/// Options of `attsync-bench run`.
#[derive(Debug, Clone)]
pub struct Options {
    /// Shorter durations, one repetition.
    pub quick: bool,
    /// Repetitions (default 3, or 1 with `quick`).
    pub reps: Option<usize>,
    /// Simulated seconds of every case, instead of the plan's.
    pub duration: Option<f64>,
    /// Only the cases whose label contains one of these.
    pub only: Vec<String>,
    /// Only these wait strategies (all if empty).
    pub waits: Vec<WaitStrategy>,
    /// Where the paper scenarios are.
    pub scenarios: PathBuf,
    /// Scratch directory (results of every run, bare-ring namespaces).
    pub work: PathBuf,
    /// Before each measurement, wait up to this long for the machine to be
    /// idle (zero: don't wait).
    pub idle_wait: Duration,
    /// The programs.
    pub bins: Bins,
}

/// Runs the whole benchmark and returns the Markdown report.
pub fn run(o: &Options) -> Result<String> {
    let plan = plan::Plan::new(o);
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get) as u32;
    let started_at = date();
    let load_before = crate::stats::loadavg();
    let t0 = Instant::now();
    std::fs::create_dir_all(&o.work).map_err(BenchError::io(&o.work))?;
    let mut res = run::Results {
        cases: plan::cases(o, &plan)?,
        ..run::Results::default()
    };
    let waits: Vec<WaitStrategy> = [
        WaitStrategy::Adaptive,
        WaitStrategy::Yield,
        WaitStrategy::Block,
        WaitStrategy::Spin,
    ]
    .into_iter()
    .filter(|w| o.waits.is_empty() || o.waits.contains(w))
    .collect();
    let mut r = run::Runner::new(o, t0);
    for ci in 0..res.cases.len() {
        r.case(&mut res, ci, &plan, &waits);
    }
    if let Some(ci) = res.cases.iter().position(|c| c.label == CONTENDED_CASE) {
        r.contended(o, &mut res, ci, &plan, &waits);
    }
    let cx = report::Context {
        cores,
        started_at,
        load_before,
        total: t0.elapsed().as_secs_f64(),
        idle: format!(
            "{} of {} measurements started on an idle machine (other processes < {} cores for 0.5 s; waited up to {} s for it)",
            r.measurements - r.not_idle,
            r.measurements,
            run::IDLE_THRESHOLD,
            o.idle_wait.as_secs()
        ),
    };
    Ok(report::report(o, &plan, &res, &cx))
}

fn date() -> String {
    Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M UTC"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}
