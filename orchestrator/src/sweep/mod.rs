//! `attsync sweep`: one scenario over a list of values of one field, or
//! over the grid of two fields' values ([`Axis`]: every value of the first
//! with every value of the second, drawn as a stability chart), runs in
//! parallel (each isolated), and the bisection that finds the stability
//! boundary of one field (`--find-margin`).
//!
//! Each run is judged by its verdict (`docs/verdicts.md`, `attsync_verdict`):
//! read from the largest attitude error over agents over the whole run, not
//! from its last sample; `converged` still means below `--tolerance`.
//! `--find-margin` bisects on whether the runs show the error decaying
//! (`converged` or `converging`), with
//! every run extended until its verdict is final (`--until settled`), and
//! puts the linearisation's exact margin (`attsync margin`,
//! `attitude::linear`) beside the bracket it finds ([`margin`]).
//!
//! Policy (all here, where tests reach it): every value must make a valid
//! scenario before anything runs ([`load_checked`], exit code 2 like an
//! invalid `--set`); bisection points are rounded to a quantum, by default
//! the step `simulation.dt` for a timing field ([`default_quantum`]);
//! `--jobs` × `--threads` stays within the cores unless both are given
//! ([`jobs_and_threads`]).

mod files;
mod grid_plot;
pub mod margin;
mod plot;

pub use files::{CSV_HEADER, csv_header, table};
pub use margin::{LinearMargin, MarginResult};

use crate::interrupt::Interrupt;
use crate::options::{self, OptionError};
use crate::pool::Flow;
use crate::results::layout::SweepLayout;
use crate::results::staging::Staging;
use crate::results::summary::Settle;
use crate::run::{Engine, RunError, RunOptions, run};
use crate::scenario::StiffnessCheck;
use crate::scenario::{self, Loaded, ScenarioError};
use attsync_verdict::{Kind, Verdict};
use std::path::{Path, PathBuf};
use thiserror::Error;

/// What to sweep and how.
#[derive(Debug, Clone)]
pub struct SweepOptions {
    /// Scenario file.
    pub scenario: PathBuf,
    /// Field path, as for `--set` (e.g. `network.delay`).
    pub param: String,
    /// Values (TOML literals).
    pub values: Vec<String>,
    /// A second field: every value of `param` runs with every value of
    /// this one (a grid, drawn as a stability chart).
    pub grid: Option<Axis>,
    /// Parallel runs (≥ 1; [`default_jobs`]).
    pub jobs: usize,
    /// Other overrides applied to every run.
    pub set: Vec<String>,
    /// Engine and output options of each run (`out` is the sweep directory).
    pub run: RunOptions,
    /// Bisect between the first value that does not converge and the one
    /// before it, for the margin.
    pub find_margin: Option<Bisection>,
    /// What validation does with a step beyond RK4's stable one (`--no-stiffness-check`).
    pub stiffness: StiffnessCheck,
}

/// A second swept field and its values (TOML literals).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    /// Field path, as for `--set`.
    pub param: String,
    /// Values (TOML literals).
    pub values: Vec<String>,
}

/// One run's point of the sweep: the value of the first field and, in a
/// grid, of the second.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// The value of [`SweepOptions::param`].
    pub value: String,
    /// The value of the grid's second field ([`SweepOptions::grid`]).
    pub value2: Option<String>,
}

impl Point {
    /// A point of the first field only.
    #[must_use]
    pub fn of(value: &str) -> Self {
        Self {
            value: value.to_string(),
            value2: None,
        }
    }

    /// The run's name in `runs/`: both values joined by `_`.
    #[must_use]
    pub fn label(&self) -> String {
        match &self.value2 {
            Some(v2) => format!("{}_{v2}", self.value),
            None => self.value.clone(),
        }
    }
}

impl SweepOptions {
    /// Every point to run: the values of `param`, each with every value of
    /// the grid's second field (the first field fastest).
    #[must_use]
    pub fn points(&self) -> Vec<Point> {
        let Some(g) = &self.grid else {
            return self.values.iter().map(|v| Point::of(v)).collect();
        };
        (g.values.iter())
            .flat_map(|v2| {
                self.values.iter().map(move |v| Point {
                    value: v.clone(),
                    value2: Some(v2.clone()),
                })
            })
            .collect()
    }

    /// The swept fields: `param`, and the grid's second.
    #[must_use]
    pub fn params(&self) -> Vec<&str> {
        let mut all = vec![self.param.as_str()];
        all.extend(self.grid.as_ref().map(|g| g.param.as_str()));
        all
    }

    /// The overrides of the run at `p`: `set`, then `param=value` (and
    /// the second field's).
    #[must_use]
    pub fn overrides(&self, p: &Point) -> Vec<String> {
        let mut with = overrides(&self.set, &self.param, &p.value);
        if let (Some(g), Some(v2)) = (&self.grid, &p.value2) {
            with.push(format!("{}={v2}", g.param));
        }
        with
    }

    /// Loads the scenario with `set`, and checks that every point makes a
    /// valid scenario too (in a grid, every pair of values); returns the
    /// scenario without the swept fields.
    ///
    /// # Errors
    /// The first invalid scenario.
    pub fn load_checked(&self) -> Result<Loaded, ScenarioError> {
        let loaded = scenario::load_with(&self.scenario, &self.set, self.stiffness)?;
        for p in self.points() {
            scenario::load_with(&self.scenario, &self.overrides(&p), self.stiffness)?;
        }
        Ok(loaded)
    }
}

/// How the margin is bisected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bisection {
    /// Iterations (0..=[`options::MAX_BISECT`]).
    pub iterations: u32,
    /// Round bisection points to multiples of this (> 0); `None`:
    /// [`default_quantum`].
    pub quantum: Option<f64>,
}

impl SweepOptions {
    /// Checks `--jobs`, `--bisect`, `--quantum` and the options of every
    /// run ([`RunOptions::validate`]: `--tolerance`, `--max-duration` too).
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn validate(&self) -> Result<(), OptionError> {
        options::count("--jobs", self.jobs as u64, 1, u64::MAX)?;
        if let Some(g) = &self.grid {
            grid_conflict(&self.param, g, self.find_margin.is_some())?;
        }
        if let Some(b) = self.find_margin {
            options::count(
                "--bisect",
                u64::from(b.iterations),
                0,
                u64::from(options::MAX_BISECT),
            )?;
            if let Some(q) = b.quantum {
                options::positive("--quantum", q)?;
            }
        }
        self.run.validate()
    }
}

/// A grid that cannot run: a field twice, no values, or `--find-margin`
/// (a bisection of one field).
fn grid_conflict(param: &str, g: &Axis, find_margin: bool) -> Result<(), OptionError> {
    let conflict = |why: String| Err(OptionError::Conflict(why));
    if g.param == param {
        return conflict(format!("--param {param} is given twice"));
    }
    if g.values.is_empty() {
        return conflict(format!("--param {}: no --values", g.param));
    }
    if find_margin {
        return conflict(format!(
            "--find-margin bisects one field: give one --param (the grid of {param} and {} \
             draws the chart; its linear boundary is `attsync margin` per value)",
            g.param
        ));
    }
    Ok(())
}

/// Why a sweep produced no results.
#[derive(Debug, Error)]
pub enum SweepError {
    /// The scenario, or the scenario with one of the values, is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// An option is out of range.
    #[error(transparent)]
    Options(#[from] OptionError),
    /// One of the runs could not produce results.
    #[error("{param} = {value}: {source}")]
    Run {
        /// The swept field.
        param: String,
        /// The value of the run.
        value: String,
        /// Why.
        source: RunError,
    },
    /// `--find-margin` found no bracket to bisect, or a non-numeric one.
    #[error("--find-margin needs {0}")]
    Margin(String),
    /// A signal stopped the sweep (the number); nothing is kept.
    #[error("{}", crate::interrupt::reason(*.0))]
    Interrupted(i32),
    /// Writing the sweep's files failed.
    #[error("{path}: {source}")]
    Io {
        /// File or directory concerned.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Drawing `sweep.svg` failed.
    #[error("sweep.svg: {0}")]
    Plot(String),
}

impl SweepError {
    /// The process exit code ([`crate::error`]'s table): 2 for an invalid
    /// input, 128 + N interrupted, a run's own code, else 1.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            SweepError::Scenario(_) | SweepError::Options(_) => crate::exit::INVALID,
            SweepError::Interrupted(signal) => crate::interrupt::exit_code(*signal),
            SweepError::Run { source, .. } => source.exit_code(),
            _ => crate::exit::FAILED,
        }
    }
}

fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> SweepError + '_ {
    move |source| SweepError::Io {
        path: path.to_owned(),
        source,
    }
}

/// The overrides of the run of `value`: `set`, then `param=value`.
fn overrides(set: &[String], param: &str, value: &str) -> Vec<String> {
    let mut with = set.to_vec();
    with.push(format!("{param}={value}"));
    with
}

/// Loads the scenario with `set`, and checks that every value of `param`
/// makes a valid scenario too; returns the scenario without `param`.
///
/// # Errors
/// The first invalid scenario.
pub fn load_checked(
    scenario: &Path,
    set: &[String],
    param: &str,
    values: &[String],
    check: StiffnessCheck,
) -> Result<Loaded, ScenarioError> {
    let loaded = scenario::load_with(scenario, set, check)?;
    for v in values {
        scenario::load_with(scenario, &overrides(set, param, v), check)?;
    }
    Ok(loaded)
}

/// The default sweep directory: `results/<scenario name>-sweep-<param>`
/// (`.`, `[` and `]` of the field path as `_`).
#[must_use]
pub fn default_out(loaded: &Loaded, param: &str) -> PathBuf {
    crate::results::layout::default_sweep_dir(&loaded.name(), param)
}

/// The default quantum of bisection points: the step `dt` for a timing
/// field (one whose name ends in `delay`, `jitter` or `period`, which are
/// only meaningful in whole steps), else none.
#[must_use]
pub fn default_quantum(param: &str, dt: f64) -> Option<f64> {
    let timing = ["delay", "jitter", "period"]
        .iter()
        .any(|k| param.ends_with(k));
    timing.then_some(dt)
}

/// The number of cores (2 if unknown).
#[must_use]
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(2, std::num::NonZero::get)
}

/// The default number of runs at once, so that a sweep does not by itself
/// oversubscribe the machine: with the in-process engine one run per core;
/// with the process engine (a run is `nodes` processes in lockstep) as many
/// runs as fit `cores` processes, at least one.
#[must_use]
pub fn default_jobs(engine: Engine, nodes: usize, cores: usize) -> usize {
    match engine {
        Engine::InProcess => cores.max(1),
        Engine::Processes => (cores / nodes.max(1)).max(1),
    }
}

/// A warning when `jobs` runs of `nodes` processes each put more lockstep
/// processes on the machine than one run alone (a run slows down by more
/// than its share: a late node stalls its whole network).
#[must_use]
pub fn oversubscription(engine: Engine, jobs: usize, nodes: usize, cores: usize) -> Option<String> {
    let fits = default_jobs(engine, nodes, cores);
    (engine == Engine::Processes && jobs > fits).then(|| {
        format!(
            "--jobs {jobs}: {jobs} runs of {nodes} processes each is {} lockstep processes on {cores} cores; \
             each run then waits for its slowest node's turn on a core (the default, --jobs {fits}, avoids this)",
            jobs * nodes
        )
    })
}

/// `--jobs` and `--threads` of a sweep, from what was given: both given,
/// both kept; only `--threads T`: `jobs = max(1, cores / T)`; otherwise
/// `jobs` (default the cores) runs of `max(1, cores / jobs)` threads each.
/// So by default `jobs × threads` does not exceed the cores (a sweep of
/// many values gains more from whole runs in parallel than from threads
/// inside each).
#[must_use]
pub fn jobs_and_threads(jobs: Option<usize>, threads: Option<usize>) -> (usize, usize) {
    let cores = cores();
    match (jobs, threads) {
        (Some(j), Some(t)) => (j, t),
        (None, Some(t)) => ((cores / t.max(1)).max(1), t),
        (j, None) => {
            let j = j.unwrap_or(cores);
            (j, (cores / j.max(1)).max(1))
        }
    }
}

/// One run of a sweep.
#[derive(Debug, Clone)]
pub struct SweepRow {
    /// The value, as given.
    pub value: String,
    /// In a grid, the value of the second field.
    pub value2: Option<String>,
    /// Largest final attitude error over agents.
    pub final_max_att_err: f64,
    /// When every agent had settled ([`Settle::latest`] of the agents').
    pub settle: Settle,
    /// The run's verdict.
    pub verdict: Verdict,
    /// The horizon the run ended with, s (longer than the scenario's when
    /// `--until settled` extended it).
    pub duration: f64,
    /// The verdict is `converged` (below `--tolerance` and staying there).
    pub converged: bool,
    /// Whether the run reached its horizon.
    pub complete: bool,
    /// The real part of the rightmost root of the run's linearisation
    /// (`attitude::linear`), 1/s: the decay rate it predicts; `None` where
    /// the scenario cannot be linearised.
    pub linear_rate: Option<f64>,
    /// Results directory of the run, relative to the sweep directory.
    pub dir: String,
}

impl SweepRow {
    /// Whether the run showed its error decaying: `converged` or
    /// `converging`. `persistent`, `diverging`, a failed run — and a run
    /// still `undecided` at `--max-duration`, whose decay its window could
    /// not establish — do not: the bracket is conservative (near the
    /// margin a growing mode and a dying transient can leave a flat
    /// envelope whose fitted rate has either sign).
    #[must_use]
    pub fn decays(&self) -> bool {
        self.complete && matches!(self.verdict.kind, Kind::Converged | Kind::Converging)
    }

    /// Whether the run failed: it ended early and not because it diverged.
    #[must_use]
    pub fn failed(&self) -> bool {
        !self.complete && self.verdict.kind != Kind::Diverging
    }
}

/// The sweep's result.
#[derive(Debug, Clone)]
pub struct SweepResult {
    /// Rows, in value order of execution (listed values first, then bisection).
    pub rows: Vec<SweepRow>,
    /// `--find-margin`: the bracket found by bisection and the linear margin.
    pub margin: Option<MarginResult>,
}

fn run_one(
    o: &SweepOptions,
    dir: &Path,
    k: usize,
    point: &Point,
    interrupt: &Interrupt,
) -> Result<SweepRow, SweepError> {
    let loaded = scenario::load_with(&o.scenario, &o.overrides(point), o.stiffness)?;
    let value = &point.label();
    let name = crate::results::layout::sweep_run_name(k, value);
    let opts = RunOptions {
        out: SweepLayout::new(dir).run(k, value).root().to_owned(),
        progress: false,
        ..o.run.clone()
    };
    let s = run(&loaded, &opts, interrupt).map_err(|source| SweepError::Run {
        param: o.params().join(", "),
        value: match &point.value2 {
            Some(v2) => format!("{}, {v2}", point.value),
            None => point.value.clone(),
        },
        source,
    })?;
    let linear_rate = attitude::linear::Linearisation::of(&loaded.resolved.network)
        .ok()
        .map(|l| l.rightmost().re);
    let settle = Settle::latest(s.agents.iter().map(|a| &a.settle));
    let verdict = s
        .verdict
        .clone()
        .unwrap_or_else(|| o.run.judging.verdict(&[]));
    Ok(SweepRow {
        value: point.value.clone(),
        value2: point.value2.clone(),
        final_max_att_err: s.max_final_att_err,
        settle,
        converged: verdict.kind == Kind::Converged,
        verdict,
        duration: s.duration,
        complete: s.complete,
        linear_rate,
        dir: format!("runs/{name}"),
    })
}

/// The error of an interrupted sweep.
fn interrupted(interrupt: &Interrupt) -> SweepError {
    SweepError::Interrupted(interrupt.signal().unwrap_or(signal_hook::consts::SIGINT))
}

/// Runs `points` with up to `jobs` at once. An interrupt stops the sweep.
fn run_many(
    o: &SweepOptions,
    dir: &Path,
    first: usize,
    points: &[Point],
    interrupt: &Interrupt,
) -> Result<Vec<SweepRow>, SweepError> {
    let out = crate::pool::run(
        points.len(),
        o.jobs,
        || interrupt.is_set(),
        |k| Flow::Next(run_one(o, dir, first + k, &points[k], interrupt)),
    );
    if interrupt.is_set() {
        return Err(interrupted(interrupt));
    }
    out.into_iter()
        .map(|r| r.unwrap_or_else(|| Err(interrupted(interrupt))))
        .collect()
}

/// Runs the sweep and writes `sweep.csv`, `sweep.svg` and every run's
/// results under `runs/` into `o.run.out` (atomically). Nothing runs unless
/// every option is valid and every value makes a valid scenario.
///
/// # Errors
/// See [`SweepError`]; an interrupted sweep leaves nothing behind.
pub fn sweep(o: &SweepOptions, interrupt: &Interrupt) -> Result<SweepResult, SweepError> {
    o.validate()?;
    let base = o.load_checked()?;
    let o = &margin::settled_for_margin(o, &base);
    interrupt.arm();
    let staging = Staging::new(&o.run.out).map_err(io_at(&o.run.out))?;
    let dir = staging.path().to_owned();
    let mut rows = run_many(o, &dir, 0, &o.points(), interrupt)?;
    let margin = match o.find_margin {
        Some(b) => {
            let quantum = b
                .quantum
                .or_else(|| default_quantum(&o.param, base.resolved.network.dt));
            let (lo, hi) = bisect(o, &dir, &mut rows, b.iterations, quantum, interrupt)?;
            Some(margin::result(&o.param, &base, lo, hi, quantum))
        }
        None => None,
    };
    files::write(o, &base, &dir, &rows, margin.as_ref())?;
    staging.commit().map_err(io_at(&o.run.out))?;
    Ok(SweepResult { rows, margin })
}

/// The bracket: the first value whose error does not decay and the one before it.
fn bracket(o: &SweepOptions, rows: &[SweepRow]) -> Result<(f64, f64), SweepError> {
    let parse = |v: &str| {
        v.parse::<f64>()
            .map_err(|_| SweepError::Margin(format!("numeric values, got {v:?}")))
    };
    let Some(k) = rows.iter().position(|r| !r.decays()) else {
        return Err(SweepError::Margin(format!(
            "a value whose error does not decay: the error decays for every value of {}",
            o.param
        )));
    };
    if k == 0 {
        return Err(SweepError::Margin(format!(
            "a first value whose error decays: at {} = {} it is {}",
            o.param,
            rows[0].value,
            rows[0].verdict.kind.name()
        )));
    }
    Ok((parse(&rows[k - 1].value)?, parse(&rows[k].value)?))
}

/// `mid` rounded to a multiple of `quantum`, written without round-off
/// noise (`0.1 + 0.2` is `0.3`).
#[must_use]
pub fn quantise(mid: f64, quantum: f64) -> f64 {
    let decimals = (-quantum.log10()).ceil().max(0.0) as usize + 1;
    format!("{:.decimals$}", (mid / quantum).round() * quantum)
        .parse()
        .expect("a formatted number parses")
}

/// Bisects the bracket for `iterations` (fewer once the points, rounded to
/// `quantum`, meet): the largest value whose error decays and the smallest
/// whose error does not.
fn bisect(
    o: &SweepOptions,
    dir: &Path,
    rows: &mut Vec<SweepRow>,
    iterations: u32,
    quantum: Option<f64>,
    interrupt: &Interrupt,
) -> Result<(f64, f64), SweepError> {
    let (mut lo, mut hi) = bracket(o, rows)?;
    for _ in 0..iterations {
        let mut mid = 0.5 * (lo + hi);
        if let Some(q) = quantum.filter(|&q| q > 0.0) {
            mid = quantise(mid, q);
            if mid <= lo.min(hi) + q * 0.5 || mid >= lo.max(hi) - q * 0.5 {
                break;
            }
        }
        let point = Point::of(&format!("{mid}"));
        let row = run_many(o, dir, rows.len(), std::slice::from_ref(&point), interrupt)?.remove(0);
        if row.decays() {
            lo = mid;
        } else {
            hi = mid;
        }
        rows.push(row);
    }
    Ok((lo, hi))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::processes::ProcessOptions;

    #[test]
    fn a_sweep_does_not_oversubscribe_the_machine_by_default() {
        // The paper run: 8 processes; 2 cores: one run at a time.
        assert_eq!(default_jobs(Engine::Processes, 8, 2), 1);
        assert_eq!(default_jobs(Engine::Processes, 8, 16), 2);
        assert_eq!(default_jobs(Engine::Processes, 3, 16), 5);
        assert_eq!(default_jobs(Engine::InProcess, 8, 2), 2);
        assert_eq!(oversubscription(Engine::Processes, 1, 8, 2), None);
        let w = oversubscription(Engine::Processes, 2, 8, 2).unwrap();
        assert!(w.contains("16 lockstep processes on 2 cores"), "{w}");
        assert!(w.contains("--jobs 1"), "{w}");
        assert_eq!(oversubscription(Engine::InProcess, 4, 8, 2), None);
    }

    fn paper() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper/constant-observerless.toml")
    }

    fn options() -> SweepOptions {
        SweepOptions {
            scenario: paper(),
            param: "network.delay".into(),
            values: vec!["0".into(), "0.1".into()],
            grid: None,
            jobs: 2,
            set: Vec::new(),
            run: RunOptions {
                engine: Engine::InProcess,
                out: PathBuf::from("unused"),
                processes: ProcessOptions::default(),
                progress: false,
                threads: 1,
                view: false,
                hosts: None,
                judging: crate::run::Judging::default(),
                law: None,
            },
            find_margin: Some(Bisection {
                iterations: 8,
                quantum: None,
            }),
            stiffness: StiffnessCheck::Refuse,
        }
    }

    #[test]
    fn jobs_times_threads_stay_within_the_cores_by_default() {
        let cores = cores();
        assert_eq!(jobs_and_threads(None, None), (cores, 1));
        assert_eq!(jobs_and_threads(Some(3), Some(5)), (3, 5));
        let (j, t) = jobs_and_threads(None, Some(cores));
        assert_eq!((j, t), (1, cores));
        let (j, t) = jobs_and_threads(Some(1), None);
        assert_eq!((j, t), (1, cores));
        for given in 1..=2 * cores {
            let (j, t) = jobs_and_threads(Some(given), None);
            assert!(j * t <= cores.max(given), "{j} × {t}");
        }
    }

    #[test]
    fn timing_fields_default_to_the_step_as_quantum() {
        assert_eq!(default_quantum("network.delay", 1e-3), Some(1e-3));
        assert_eq!(default_quantum("network.jitter", 1e-3), Some(1e-3));
        assert_eq!(default_quantum("edge[0].period", 2e-3), Some(2e-3));
        assert_eq!(default_quantum("network.loss", 1e-3), None);
        assert_eq!(default_quantum("scheme.control.k_r", 1e-3), None);
    }

    #[test]
    fn bisection_points_are_clean_multiples_of_the_quantum() {
        assert_eq!(quantise(0.123_456, 1e-3), 0.123);
        assert_eq!(quantise(0.1 + 0.2, 0.1), 0.3);
        assert_eq!(quantise(7.4, 2.0), 8.0);
    }

    #[test]
    fn every_value_is_checked_before_anything_runs() {
        let set = ["simulation.duration=0.1".to_string()];
        let ok = ["0".to_string(), "0.01".to_string()];
        let base = load_checked(&paper(), &set, "network.delay", &ok, StiffnessCheck::Refuse)
            .expect("valid");
        assert_eq!(
            default_out(&base, "agent[2].omega"),
            PathBuf::from(format!("results/{}-sweep-agent_2__omega", base.name()))
        );
        let bad = ["0".to_string(), "-1".to_string()];
        let e = load_checked(
            &paper(),
            &set,
            "network.delay",
            &bad,
            StiffnessCheck::Refuse,
        )
        .unwrap_err();
        assert!(e.to_string().contains("network.delay"), "{e}");
    }

    /// Puts one option out of range.
    type Breaker = fn(&mut SweepOptions);

    #[test]
    fn options_out_of_range_are_refused() {
        assert_eq!(options().validate(), Ok(()));
        let cases: [(&str, Breaker); 7] = [
            ("--jobs", |o| o.jobs = 0),
            ("--tolerance", |o| o.run.judging.tolerance = f64::NAN),
            ("--tolerance", |o| o.run.judging.tolerance = 0.0),
            ("--bisect", |o| {
                o.find_margin.as_mut().unwrap().iterations = 65
            }),
            ("--quantum", |o| {
                o.find_margin.as_mut().unwrap().quantum = Some(0.0)
            }),
            ("--quantum", |o| {
                o.find_margin.as_mut().unwrap().quantum = Some(f64::INFINITY)
            }),
            ("--stage-timeout", |o| o.run.processes.stage_timeout = -1.0),
        ];
        for (option, break_it) in cases {
            let mut o = options();
            break_it(&mut o);
            let e = o.validate().unwrap_err();
            assert!(e.to_string().starts_with(option), "{option}: {e}");
        }
    }

    #[test]
    fn an_interrupted_sweep_leaves_nothing() {
        let tmp = tempfile::tempdir().expect("tempdir");
        let mut o = options();
        o.run.out = tmp.path().join("sweep");
        let interrupt = Interrupt::new();
        interrupt.trigger(signal_hook::consts::SIGTERM);
        let e = sweep(&o, &interrupt).unwrap_err();
        assert!(matches!(e, SweepError::Interrupted(15)), "{e}");
        assert_eq!(e.to_string(), "interrupted by SIGTERM");
        assert_eq!(std::fs::read_dir(tmp.path()).expect("dir").count(), 0);
    }
}
