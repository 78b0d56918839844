//! Running the measurements of `attsync-bench run`: each one on an idle
//! machine (bounded wait), repetitions interleaved with the bare ring's, and
//! the medians of the repetitions ([`Agg`], [`BareAgg`]) kept in [`Results`].

use super::Options;
use super::plan::{Case, Plan, ring_spec};
use crate::bare::{self, BareRun, BareSpec};
use crate::error::Result;
use crate::measure::{self, AttsyncRun, Engine, wait_name};
use crate::stats::{CpuMeter, median, median_u64};
use msgs::config::WaitStrategy;
use std::collections::HashMap;
use std::time::{Duration, Instant};

const RUN_TIMEOUT: Duration = Duration::from_secs(600);
/// Other processes' CPU use (cores) below which the machine counts as idle.
pub(super) const IDLE_THRESHOLD: f64 = 0.1;

pub(super) fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

/// Medians of the repetitions of one measurement.
#[derive(Debug, Clone, Default)]
pub(super) struct Agg {
    pub ok: usize,
    pub errors: Vec<String>,
    pub wall: Option<f64>,
    pub run_seconds: Option<f64>,
    pub lockstep: Option<f64>,
    pub rss_max: Option<u64>,
    pub rss_median: Option<u64>,
    pub leader_rss: Option<u64>,
    /// Largest background load seen (cores).
    pub bg: Option<f64>,
}

impl Agg {
    /// The repetitions' medians, failures kept as errors.
    pub(super) fn collect(runs: Vec<Result<(AttsyncRun, Option<f64>)>>) -> Self {
        let mut ok = Vec::new();
        let mut errors = Vec::new();
        for r in runs {
            match r {
                Ok(x) => ok.push(x),
                Err(e) => errors.push(e.to_string()),
            }
        }
        Self::of(&ok, errors)
    }

    fn of(runs: &[(AttsyncRun, Option<f64>)], errors: Vec<String>) -> Self {
        let col = |f: &dyn Fn(&AttsyncRun) -> Option<f64>| {
            median(&runs.iter().filter_map(|(r, _)| f(r)).collect::<Vec<_>>())
        };
        let rss: Vec<u64> = runs
            .iter()
            .flat_map(|(r, _)| r.agent_rss_kb.iter().copied())
            .collect();
        Self {
            ok: runs.len(),
            errors,
            wall: col(&|r| Some(r.wall)),
            run_seconds: col(&|r| Some(r.run_seconds)),
            lockstep: col(&|r| r.lockstep),
            rss_max: rss.iter().copied().max(),
            rss_median: median_u64(&rss),
            leader_rss: runs.iter().filter_map(|(r, _)| r.leader_rss_kb).max(),
            bg: runs.iter().filter_map(|(_, b)| *b).reduce(f64::max),
        }
    }
}

/// Medians of the repetitions of a bare lockstep.
#[derive(Debug, Clone, Default)]
pub(super) struct BareAgg {
    pub ok: usize,
    pub errors: Vec<String>,
    pub span: Option<f64>,
    pub rss_max: Option<u64>,
    pub bg: Option<f64>,
}

impl BareAgg {
    pub(super) fn push(&mut self, r: Result<(BareRun, Option<f64>)>, spans: &mut Vec<f64>) {
        match r {
            Ok((b, bg)) => {
                self.ok += 1;
                spans.push(b.span);
                self.span = median(spans);
                self.rss_max = self.rss_max.max(Some(b.peak_rss_kb));
                self.bg = max_opt(self.bg, bg);
            }
            Err(e) => self.errors.push(e.to_string()),
        }
    }
}

/// Process-engine row.
#[derive(Debug, Clone)]
pub(super) struct ProcRow {
    pub case: usize,
    pub wait: WaitStrategy,
    pub steps: u64,
    pub note: String,
    pub attsync: Agg,
    pub ring: BareSpec,
}

/// Diagnostics row (adaptive).
#[derive(Debug, Clone)]
pub(super) struct DiagRow {
    pub case: usize,
    pub graph: BareSpec,
    pub pinned: BareSpec,
    pub quiet: Agg,
}

/// Everything measured.
#[derive(Debug, Default)]
pub(super) struct Results {
    pub cases: Vec<Case>,
    pub inproc: Vec<Agg>,
    pub procs: Vec<ProcRow>,
    pub bare: HashMap<BareSpec, BareAgg>,
    pub bare_order: Vec<BareSpec>,
    pub diag: Vec<DiagRow>,
    pub contended: Vec<super::contend::ContendRow>,
    pub skipped: Vec<String>,
}

/// Runs measurements and logs each to stderr.
pub(super) struct Runner<'a> {
    o: &'a Options,
    t0: Instant,
    /// Measurements started although the machine was not idle.
    pub not_idle: usize,
    pub measurements: usize,
    count: usize,
    bare_spans: HashMap<BareSpec, Vec<f64>>,
}

impl<'a> Runner<'a> {
    pub fn new(o: &'a Options, t0: Instant) -> Self {
        Self {
            o,
            t0,
            not_idle: 0,
            measurements: 0,
            count: 0,
            bare_spans: HashMap::new(),
        }
    }

    /// Waits (bounded) for an idle machine before a measurement.
    fn settle(&mut self) {
        self.measurements += 1;
        if !self.o.idle_wait.is_zero() && !crate::stats::wait_idle(IDLE_THRESHOLD, self.o.idle_wait)
        {
            self.not_idle += 1;
            self.log("machine still busy with other work; measuring anyway");
        }
    }

    fn log(&self, msg: &str) {
        eprintln!("[{:6.1} s] {msg}", self.t0.elapsed().as_secs_f64());
    }

    /// One `attsync run` of `case` on an idle machine (bounded wait) and the
    /// background load during it.
    pub(super) fn attsync(
        &mut self,
        case: &Case,
        engine: Engine,
        sets: &[String],
        what: &str,
    ) -> Result<(AttsyncRun, Option<f64>)> {
        self.settle();
        self.attsync_now(case, engine, sets, what)
    }

    /// [`Runner::attsync`] without waiting for an idle machine.
    pub(super) fn attsync_now(
        &mut self,
        case: &Case,
        engine: Engine,
        sets: &[String],
        what: &str,
    ) -> Result<(AttsyncRun, Option<f64>)> {
        self.count += 1;
        let out = self.o.work.join("runs").join(format!("{:04}", self.count));
        let meter = CpuMeter::start();
        let r = measure::attsync(
            &self.o.bins,
            &case.scenario,
            engine,
            sets,
            &out,
            RUN_TIMEOUT,
        );
        let bg = meter.foreign_cores();
        let _ = std::fs::remove_dir_all(&out);
        let _ = std::fs::remove_file(out.with_extension("console.txt"));
        match &r {
            Ok(a) => self.log(&format!(
                "{} {what}: {} steps, wall {:.3} s, run {:.3} s{}",
                case.label,
                a.steps,
                a.wall,
                a.run_seconds,
                a.lockstep
                    .map(|l| format!(", lockstep {l:.3} s"))
                    .unwrap_or_default()
            )),
            Err(e) => self.log(&format!("{} {what}: FAILED: {e}", case.label)),
        }
        r.map(|a| (a, bg))
    }

    /// `reps` runs of `case`; after the k-th, `between(self, k)` (to
    /// interleave another measurement, so slow drifts of the machine hit
    /// both alike).
    fn attsync_reps(
        &mut self,
        case: &Case,
        engine: Engine,
        sets: &[String],
        what: &str,
        reps: usize,
        mut between: impl FnMut(&mut Self, usize),
    ) -> Agg {
        let mut runs = Vec::new();
        let mut errors = Vec::new();
        for k in 0..reps {
            match self.attsync(case, engine, sets, &format!("{what} rep {}", k + 1)) {
                Ok(x) => runs.push(x),
                Err(e) => errors.push(e.to_string()),
            }
            between(self, k);
        }
        Agg::of(&runs, errors)
    }

    fn bare(&mut self, res: &mut Results, spec: &BareSpec, what: &str) {
        if !res.bare.contains_key(spec) {
            res.bare_order.push(spec.clone());
        }
        let r = self.bare_once(spec, what);
        let spans = self.bare_spans.entry(spec.clone()).or_default();
        res.bare.entry(spec.clone()).or_default().push(r, spans);
    }

    /// One bare lockstep on an idle machine (bounded wait).
    pub(super) fn bare_once(
        &mut self,
        spec: &BareSpec,
        what: &str,
    ) -> Result<(BareRun, Option<f64>)> {
        self.settle();
        self.bare_now(spec, what)
    }

    /// [`Runner::bare_once`] without waiting for an idle machine.
    pub(super) fn bare_now(
        &mut self,
        spec: &BareSpec,
        what: &str,
    ) -> Result<(BareRun, Option<f64>)> {
        let meter = CpuMeter::start();
        let r = bare::bare(&self.o.bins, &self.o.work, spec, RUN_TIMEOUT);
        let bg = meter.foreign_cores();
        match &r {
            Ok(b) => self.log(&format!(
                "{what} N={} {} {} steps: span {:.3} s",
                spec.n,
                wait_name(spec.wait),
                spec.steps,
                b.span
            )),
            Err(e) => self.log(&format!("{what} N={}: FAILED: {e}", spec.n)),
        }
        r.map(|b| (b, bg))
    }

    /// Runs a bare lockstep until it has `rep + 1` attempts (cached across cases).
    fn bare_rep(&mut self, res: &mut Results, spec: &BareSpec, rep: usize, what: &str) {
        let done = res.bare.get(spec).map_or(0, |a| a.ok + a.errors.len());
        if done <= rep {
            self.bare(res, spec, what);
        }
    }

    /// Every measurement of case `ci`: the in-process engine, the process
    /// engine per wait strategy against the bare ring, and (with adaptive)
    /// the diagnostics.
    pub fn case(&mut self, res: &mut Results, ci: usize, plan: &Plan, waits: &[WaitStrategy]) {
        let case = res.cases[ci].clone();
        let inproc = self.attsync_reps(
            &case,
            Engine::InProcess,
            &case.sets,
            "in-process",
            plan.reps,
            |_, _| {},
        );
        res.inproc.push(inproc);
        let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get) as u32;
        for &wait in waits {
            let (steps, note) = match plan.steps_for(&case, wait, cores) {
                Ok(x) => x,
                Err(skipped) => {
                    res.skipped.push(skipped.to_string());
                    continue;
                }
            };
            let ring = ring_spec(case.nodes, steps, wait);
            let what = format!("processes {}", wait_name(wait));
            let sets = case.sets_for(steps);
            let engine = Engine::Processes(wait);
            let attsync = self.attsync_reps(&case, engine, &sets, &what, plan.reps, |r, k| {
                r.bare_rep(res, &ring, k, "ring");
            });
            res.procs.push(ProcRow {
                case: ci,
                wait,
                steps,
                note,
                attsync,
                ring,
            });
        }
        if waits.contains(&WaitStrategy::Adaptive) {
            self.diagnostics(res, ci, plan);
        }
    }

    /// Diagnostics (adaptive): the scenario's graph without the model (left
    /// to the scheduler, and pinned like attsync's placement), and attsync
    /// with telemetry only at the first and last step.
    fn diagnostics(&mut self, res: &mut Results, ci: usize, plan: &Plan) {
        let case = res.cases[ci].clone();
        let graph = case.graph_spec();
        let pinned = case.pinned_graph_spec();
        let quiet = self.attsync_reps(
            &case,
            Engine::Processes(WaitStrategy::Adaptive),
            &case.quiet_sets(),
            "processes adaptive, telemetry off,",
            plan.reps,
            |r, k| {
                r.bare_rep(res, &graph, k, "same-graph bare lockstep");
                r.bare_rep(res, &pinned, k, "same-graph bare lockstep, pinned,");
            },
        );
        res.diag.push(DiagRow {
            case: ci,
            graph,
            pinned,
            quiet,
        });
    }
}
