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
//! telemetry reduced to the first and last step.

use crate::measure::{self, AttsyncRun, BareRun, BareSpec, Bins, Engine, NodeTopo, wait_name};
use crate::stats::{CpuMeter, median, median_u64};
use attsync::processes::{ProcessOptions, node_configs};
use msgs::config::WaitStrategy;
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// Options of `attsync-bench run`.
#[derive(Debug, Clone)]
pub struct Options {
    /// Shorter durations, one repetition.
    pub quick: bool,
    /// Repetitions (default 3, or 1 with `quick`).
    pub reps: Option<usize>,
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

/// How long each run is.
#[derive(Debug, Clone, Copy)]
struct Plan {
    reps: usize,
    /// Simulated seconds: paper scenarios, tree-32, tree-100.
    paper: f64,
    tree32: f64,
    tree100: f64,
    /// Steps of a shortened spin run.
    spin_steps: u64,
    /// No spin runs above this many processes.
    spin_max_nodes: u32,
}

impl Plan {
    fn new(o: &Options) -> Self {
        let (paper, tree32, tree100, spin_steps) = if o.quick {
            (10.0, 0.5, 0.25, 20)
        } else {
            (40.0, 2.0, 1.0, 50)
        };
        Self {
            reps: o.reps.unwrap_or(if o.quick { 1 } else { 3 }),
            paper,
            tree32,
            tree100,
            spin_steps,
            spin_max_nodes: 16,
        }
    }
}

/// One scenario to measure.
#[derive(Debug, Clone)]
struct Case {
    label: String,
    scenario: PathBuf,
    /// `--set` overrides (the duration).
    sets: Vec<String>,
    nodes: u32,
    dt: f64,
    steps: u64,
    /// The node graph the process engine uses, and its fan-out limit.
    topo: Vec<NodeTopo>,
    max_fanout: usize,
}

impl Case {
    fn load(label: &str, scenario: PathBuf, duration: f64) -> Result<Self, String> {
        let sets = vec![format!("simulation.duration={duration:?}")];
        let loaded = attsync::scenario::load(&scenario, &sets).map_err(|e| e.to_string())?;
        let net = &loaded.resolved.network;
        let configs = node_configs(net, "x", Path::new("/tmp"), &ProcessOptions::default());
        Ok(Self {
            label: label.into(),
            scenario,
            sets,
            nodes: configs.len() as u32,
            dt: net.dt,
            steps: net.steps,
            max_fanout: configs.first().map_or(1, |c| c.limits.max_fanout),
            topo: configs
                .iter()
                .map(|c| NodeTopo {
                    id: c.id,
                    inputs: c.inputs.clone(),
                    outputs: c.outputs.clone(),
                })
                .collect(),
        })
    }

    fn sim_seconds(&self) -> f64 {
        self.steps as f64 * self.dt
    }

    /// The overrides for a run of `steps` steps.
    fn sets_for(&self, steps: u64) -> Vec<String> {
        if steps == self.steps {
            self.sets.clone()
        } else {
            vec![format!(
                "simulation.duration={:?}",
                round9(steps as f64 * self.dt)
            )]
        }
    }
}

fn max_opt(a: Option<f64>, b: Option<f64>) -> Option<f64> {
    match (a, b) {
        (Some(x), Some(y)) => Some(x.max(y)),
        (x, None) => x,
        (None, y) => y,
    }
}

fn round9(x: f64) -> f64 {
    (x * 1e9).round() / 1e9
}

/// Medians of the repetitions of one measurement.
#[derive(Debug, Clone, Default)]
struct Agg {
    ok: usize,
    errors: Vec<String>,
    wall: Option<f64>,
    run_seconds: Option<f64>,
    lockstep: Option<f64>,
    rss_max: Option<u64>,
    rss_median: Option<u64>,
    leader_rss: Option<u64>,
    /// Largest background load seen (cores).
    bg: Option<f64>,
}

impl Agg {
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
struct BareAgg {
    ok: usize,
    errors: Vec<String>,
    span: Option<f64>,
    rss_max: Option<u64>,
    bg: Option<f64>,
}

impl BareAgg {
    fn push(&mut self, r: Result<(BareRun, Option<f64>), String>, spans: &mut Vec<f64>) {
        match r {
            Ok((b, bg)) => {
                self.ok += 1;
                spans.push(b.span);
                self.span = median(spans);
                self.rss_max = self.rss_max.max(Some(b.peak_rss_kb));
                self.bg = max_opt(self.bg, bg);
            }
            Err(e) => self.errors.push(e),
        }
    }
}

/// Process-engine row.
#[derive(Debug, Clone)]
struct ProcRow {
    case: usize,
    wait: WaitStrategy,
    steps: u64,
    note: String,
    attsync: Agg,
    ring: BareKey,
}

/// Diagnostics row (adaptive).
#[derive(Debug, Clone)]
struct DiagRow {
    case: usize,
    graph: BareKey,
    quiet: Agg,
}

type BareKey = BareSpec;

/// Everything measured.
#[derive(Debug, Default)]
struct Results {
    cases: Vec<Case>,
    inproc: Vec<Agg>,
    procs: Vec<ProcRow>,
    bare: HashMap<BareKey, BareAgg>,
    bare_order: Vec<BareKey>,
    diag: Vec<DiagRow>,
    skipped: Vec<String>,
}

struct Runner<'a> {
    o: &'a Options,
    t0: Instant,
    /// Measurements started although the machine was not idle.
    not_idle: usize,
    measurements: usize,
    count: usize,
    bare_spans: HashMap<BareKey, Vec<f64>>,
}

const RUN_TIMEOUT: Duration = Duration::from_secs(600);
/// Other processes' CPU use (cores) below which the machine counts as idle.
const IDLE_THRESHOLD: f64 = 0.1;

impl Runner<'_> {
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

    fn attsync(
        &mut self,
        case: &Case,
        engine: Engine,
        sets: &[String],
        what: &str,
    ) -> Result<(AttsyncRun, Option<f64>), String> {
        self.count += 1;
        self.settle();
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

    fn bare(&mut self, res: &mut Results, spec: &BareSpec, what: &str) {
        if !res.bare.contains_key(spec) {
            res.bare_order.push(spec.clone());
        }
        self.settle();
        let meter = CpuMeter::start();
        let r = measure::bare(&self.o.bins, &self.o.work, spec, RUN_TIMEOUT);
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
        let spans = self.bare_spans.entry(spec.clone()).or_default();
        res.bare
            .entry(spec.clone())
            .or_default()
            .push(r.map(|b| (b, bg)), spans);
    }

    /// Runs a bare lockstep until it has `reps` attempts (cached across cases).
    fn bare_rep(&mut self, res: &mut Results, spec: &BareSpec, rep: usize, what: &str) {
        let done = res.bare.get(spec).map_or(0, |a| a.ok + a.errors.len());
        if done <= rep {
            self.bare(res, spec, what);
        }
    }
}

fn ring_spec(n: u32, steps: u64, wait: WaitStrategy) -> BareSpec {
    BareSpec {
        n,
        steps,
        wait,
        graph: None,
    }
}

/// Runs the whole benchmark and returns the Markdown report.
pub fn run(o: &Options) -> Result<String, String> {
    let plan = Plan::new(o);
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZero::get) as u32;
    let started_at = date();
    let load_before = crate::stats::loadavg();
    let t0 = Instant::now();
    std::fs::create_dir_all(&o.work).map_err(|e| format!("{}: {e}", o.work.display()))?;

    // Cases.
    let mut all = Vec::new();
    for (label, file) in [
        ("paper-timevarying", "timevarying.toml"),
        ("paper-constant-observer", "constant-observer.toml"),
        ("paper-constant-observerless", "constant-observerless.toml"),
    ] {
        all.push((label.to_string(), o.scenarios.join(file), plan.paper));
    }
    for (agents, duration) in [(31, plan.tree32), (99, plan.tree100)] {
        let file = o.work.join(format!("tree-{}.toml", agents + 1));
        let status = Command::new(&o.bins.attsync)
            .args(["gen", "tree", "--agents", &agents.to_string()])
            .args(["--leader-links", "2", "--seed", "1", "--out"])
            .arg(&file)
            .status()
            .map_err(|e| format!("attsync gen tree: {e}"))?;
        if !status.success() {
            return Err(format!("attsync gen tree --agents {agents} failed"));
        }
        all.push((format!("tree-{}", agents + 1), file, duration));
    }
    let mut res = Results::default();
    for (label, file, duration) in all {
        if o.only.is_empty() || o.only.iter().any(|s| label.contains(s.as_str())) {
            res.cases.push(Case::load(&label, file, duration)?);
        }
    }

    let mut r = Runner {
        o,
        t0,
        not_idle: 0,
        measurements: 0,
        count: 0,
        bare_spans: HashMap::new(),
    };
    let waits = [
        WaitStrategy::Adaptive,
        WaitStrategy::Yield,
        WaitStrategy::Block,
        WaitStrategy::Spin,
    ];
    let waits: Vec<WaitStrategy> = waits
        .into_iter()
        .filter(|w| o.waits.is_empty() || o.waits.contains(w))
        .collect();
    for ci in 0..res.cases.len() {
        let case = res.cases[ci].clone();
        // In-process engine.
        let mut runs = Vec::new();
        let mut errors = Vec::new();
        for k in 0..plan.reps {
            match r.attsync(
                &case,
                Engine::InProcess,
                &case.sets,
                &format!("in-process rep {}", k + 1),
            ) {
                Ok(x) => runs.push(x),
                Err(e) => errors.push(e),
            }
        }
        res.inproc.push(Agg::of(&runs, errors));

        // Process engine and the bare ring, per wait strategy.
        for &wait in &waits {
            let (steps, note) = if wait != WaitStrategy::Spin || case.nodes <= cores {
                (case.steps, String::new())
            } else if case.nodes <= plan.spin_max_nodes {
                (
                    plan.spin_steps.min(case.steps),
                    format!(
                        "shortened to {} steps: {} spinning processes on {cores} cores",
                        plan.spin_steps, case.nodes
                    ),
                )
            } else {
                res.skipped.push(format!(
                    "{} (N = {}): spin skipped — {} busy-polling processes on {cores} cores \
                     progress only when the scheduler preempts one (see the N = 8 spin rows)",
                    case.label, case.nodes, case.nodes
                ));
                continue;
            };
            let sets = case.sets_for(steps);
            let ring = ring_spec(case.nodes, steps, wait);
            let mut runs = Vec::new();
            let mut errors = Vec::new();
            for k in 0..plan.reps {
                // Interleaved, so slow drifts of the machine hit both alike.
                match r.attsync(
                    &case,
                    Engine::Processes(wait),
                    &sets,
                    &format!("processes {} rep {}", wait_name(wait), k + 1),
                ) {
                    Ok(x) => runs.push(x),
                    Err(e) => errors.push(e),
                }
                r.bare_rep(&mut res, &ring, k, "ring");
            }
            res.procs.push(ProcRow {
                case: ci,
                wait,
                steps,
                note,
                attsync: Agg::of(&runs, errors),
                ring,
            });
        }

        // Diagnostics (adaptive): the scenario's graph without the model, and
        // attsync with telemetry only at the first and last step.
        if !waits.contains(&WaitStrategy::Adaptive) {
            continue;
        }
        let graph = BareSpec {
            n: case.nodes,
            steps: case.steps,
            wait: WaitStrategy::Adaptive,
            graph: Some((case.topo.clone(), case.max_fanout)),
        };
        let mut quiet_sets = case.sets.clone();
        quiet_sets.push(format!(
            "output.sample_period={:?}",
            round9(case.sim_seconds())
        ));
        let mut runs = Vec::new();
        let mut errors = Vec::new();
        for k in 0..plan.reps {
            match r.attsync(
                &case,
                Engine::Processes(WaitStrategy::Adaptive),
                &quiet_sets,
                &format!("processes adaptive, telemetry off, rep {}", k + 1),
            ) {
                Ok(x) => runs.push(x),
                Err(e) => errors.push(e),
            }
            r.bare_rep(&mut res, &graph, k, "same-graph bare lockstep");
        }
        res.diag.push(DiagRow {
            case: ci,
            graph,
            quiet: Agg::of(&runs, errors),
        });
    }
    let total = t0.elapsed().as_secs_f64();
    let idle = format!(
        "{} of {} measurements started on an idle machine (other processes < {IDLE_THRESHOLD} cores for 0.5 s; waited up to {} s for it)",
        r.measurements - r.not_idle,
        r.measurements,
        o.idle_wait.as_secs()
    );
    Ok(report(
        o,
        &plan,
        cores,
        &res,
        &started_at,
        &load_before,
        total,
        &idle,
    ))
}

fn date() -> String {
    Command::new("date")
        .args(["-u", "+%Y-%m-%d %H:%M UTC"])
        .output()
        .ok()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}

fn f(x: Option<f64>, digits: usize) -> String {
    x.map_or_else(|| "—".into(), |v| format!("{v:.digits$}"))
}

fn rate(steps: u64, secs: Option<f64>) -> Option<f64> {
    secs.filter(|s| *s > 0.0).map(|s| steps as f64 / s)
}

fn us_per_exchange(steps: u64, secs: Option<f64>) -> Option<f64> {
    secs.map(|s| s / (steps as f64 * 4.0) * 1e6)
}

fn kb(x: Option<u64>) -> String {
    x.map_or_else(|| "—".into(), |v| v.to_string())
}

fn failures(label: &str, errors: &[String], ok: usize, out: &mut Vec<String>) {
    if !errors.is_empty() {
        out.push(format!(
            "{label}: {} of {} repetitions failed: {}",
            errors.len(),
            errors.len() + ok,
            errors[0]
        ));
    }
}

#[allow(clippy::too_many_arguments)]
fn report(
    o: &Options,
    plan: &Plan,
    cores: u32,
    res: &Results,
    started_at: &str,
    load_before: &str,
    total: f64,
    idle: &str,
) -> String {
    let mut s = String::new();
    let mut notes = Vec::new();
    let w = &mut s;
    let _ = writeln!(
        w,
        "## attsync benchmark{}\n",
        if o.quick { " (quick)" } else { "" }
    );
    let _ = writeln!(
        w,
        "- machine: {}; started {started_at}; took {total:.0} s; load average before: {load_before}, after: {}",
        crate::stats::machine(),
        crate::stats::loadavg()
    );
    let _ = writeln!(
        w,
        "- **nodes** = agents + the leader; in the process engine each node is one OS process \
         (the orchestrator is one more, mostly asleep); the bare ring of N nodes is N processes."
    );
    let _ = writeln!(
        w,
        "- durations: paper scenarios {} s simulated, tree-32 {} s, tree-100 {} s (dt = 1 ms, so 1000 steps per simulated second; \
         4 exchanges per step); every figure is the median of {} repetition(s), each column's median taken separately; \
         peak RSS: max and median over every agent process of every repetition (leader excluded, listed below).",
        plan.paper, plan.tree32, plan.tree100, plan.reps
    );
    let _ = writeln!(
        w,
        "- `spin` with more processes than cores ({cores}): shortened to {} steps up to {} processes, skipped above.",
        plan.spin_steps, plan.spin_max_nodes
    );
    let _ = writeln!(
        w,
        "- times: **wall** = around the whole `attsync run` command, measured by the benchmark (process start, validation, \
         spawning and connecting the nodes, the run, writing results); **run** = `summary.json` `wall_seconds` \
         (for the process engine: from before spawning the nodes to the last telemetry, so it includes start-up); \
         **lockstep** = first node's `started` to last node's `done` in the node logs (the steady state, no start-up); \
         the bare ring's time is measured the same way (first loop start to last loop end). \
         **bg load** = CPU used by other processes on the machine during the runs (cores, max over repetitions)."
    );
    let _ = writeln!(w, "- {idle}.");
    let _ = writeln!(w);

    // In-process.
    let _ = writeln!(w, "### In-process engine\n");
    let _ = writeln!(
        w,
        "| case | nodes | simulated s | steps | wall s | run s | steps/s (run) | real-time factor (run) | real-time factor (wall) |"
    );
    let _ = writeln!(w, "|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (c, a) in res.cases.iter().zip(&res.inproc) {
        let sim = c.sim_seconds();
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            c.label,
            c.nodes,
            sim,
            c.steps,
            f(a.wall, 3),
            f(a.run_seconds, 3),
            f(rate(c.steps, a.run_seconds), 0),
            f(a.run_seconds.map(|r| sim / r), 1),
            f(a.wall.map(|r| sim / r), 1)
        );
        failures(
            &format!("{} in-process", c.label),
            &a.errors,
            a.ok,
            &mut notes,
        );
    }
    let _ = writeln!(w);

    // Processes vs ring.
    let _ = writeln!(
        w,
        "### Process engine vs bare iceoryx2 ring (same N, wait strategy and steps)\n"
    );
    let _ = writeln!(
        w,
        "| case | nodes | wait | steps | wall s | real-time factor (wall) | run s | lockstep s | wall − lockstep s | steps/s (lockstep) | ring steps/s | attsync ÷ ring (lockstep) | attsync ÷ ring (wall) | agent peak RSS max / median kB | bg load |"
    );
    let _ = writeln!(
        w,
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for p in &res.procs {
        let c = &res.cases[p.case];
        let a = &p.attsync;
        let ring = res.bare.get(&p.ring).cloned().unwrap_or_default();
        let ring_rate = rate(p.steps, ring.span);
        let lock_rate = rate(p.steps, a.lockstep);
        let wall_rate = rate(p.steps, a.wall);
        let ratio = |x: Option<f64>| x.zip(ring_rate).map(|(a, b)| a / b);
        let bg = max_opt(a.bg, ring.bg);
        let _ = writeln!(
            w,
            "| {} | {} | {}{} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} / {} | {} |",
            c.label,
            c.nodes,
            wait_name(p.wait),
            if p.note.is_empty() { "" } else { " ¹" },
            p.steps,
            f(a.wall, 2),
            f(a.wall.map(|x| p.steps as f64 * c.dt / x), 2),
            f(a.run_seconds, 2),
            f(a.lockstep, 2),
            f(a.wall.zip(a.lockstep).map(|(w, l)| w - l), 2),
            f(lock_rate, 0),
            f(ring_rate, 0),
            f(ratio(lock_rate), 2),
            f(ratio(wall_rate), 2),
            kb(a.rss_max),
            kb(a.rss_median),
            f(bg, 2)
        );
        failures(
            &format!("{} processes {}", c.label, wait_name(p.wait)),
            &a.errors,
            a.ok,
            &mut notes,
        );
        if !p.note.is_empty() {
            notes.push(format!("¹ {} {}: {}", c.label, wait_name(p.wait), p.note));
        }
    }
    let _ = writeln!(w);
    let leader: Vec<String> = res
        .procs
        .iter()
        .filter(|p| p.wait == WaitStrategy::Adaptive)
        .map(|p| {
            format!(
                "{} {} kB",
                res.cases[p.case].label,
                kb(p.attsync.leader_rss)
            )
        })
        .collect();
    let _ = writeln!(
        w,
        "Leader process peak RSS (adaptive): {}.\n",
        leader.join(", ")
    );

    // Bare ring.
    let _ = writeln!(
        w,
        "### Bare iceoryx2 lockstep ring (`attsync-bench ring-node`)\n"
    );
    let _ = writeln!(
        w,
        "| N | wait | steps | loop s | steps/s | µs per exchange | ring-node peak RSS max kB | bg load |"
    );
    let _ = writeln!(w, "|---:|---|---:|---:|---:|---:|---:|---:|");
    for k in res.bare_order.iter().filter(|k| k.graph.is_none()) {
        let b = &res.bare[k];
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            k.n,
            wait_name(k.wait),
            k.steps,
            f(b.span, 3),
            f(rate(k.steps, b.span), 0),
            f(us_per_exchange(k.steps, b.span), 1),
            kb(b.rss_max),
            f(b.bg, 2)
        );
        failures(
            &format!("ring N={} {}", k.n, wait_name(k.wait)),
            &b.errors,
            b.ok,
            &mut notes,
        );
    }
    let _ = writeln!(w);

    // Diagnostics.
    let _ = writeln!(
        w,
        "### Where an exchange's time goes (adaptive, µs per exchange = lockstep s ÷ (4 × steps))\n"
    );
    let _ = writeln!(
        w,
        "| case | nodes | steps | bare ring | bare, scenario's graph | attsync, telemetry off | attsync | in-process engine, all nodes in one thread |"
    );
    let _ = writeln!(w, "|---|---:|---:|---:|---:|---:|---:|---:|");
    for d in &res.diag {
        let c = &res.cases[d.case];
        let ring = res
            .bare
            .get(&ring_spec(c.nodes, c.steps, WaitStrategy::Adaptive))
            .and_then(|b| b.span);
        let graph = res.bare.get(&d.graph).cloned().unwrap_or_default();
        let att = res
            .procs
            .iter()
            .find(|p| p.case == d.case && p.wait == WaitStrategy::Adaptive)
            .and_then(|p| p.attsync.lockstep);
        let inproc = res.inproc[d.case].run_seconds;
        let _ = writeln!(
            w,
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            c.label,
            c.nodes,
            c.steps,
            f(us_per_exchange(c.steps, ring), 1),
            f(us_per_exchange(c.steps, graph.span), 1),
            f(us_per_exchange(c.steps, d.quiet.lockstep), 1),
            f(us_per_exchange(c.steps, att), 1),
            f(us_per_exchange(c.steps, inproc), 2)
        );
        failures(
            &format!("{} same-graph bare", c.label),
            &graph.errors,
            graph.ok,
            &mut notes,
        );
        failures(
            &format!("{} telemetry off", c.label),
            &d.quiet.errors,
            d.quiet.ok,
            &mut notes,
        );
    }
    let _ = writeln!(
        w,
        "\n\"bare, scenario's graph\": `ring-node` processes wired like the scenario (each node's inputs and receivers as \
         the process engine wires them, the leader with no inputs), no model. \"telemetry off\": \
         `--set output.sample_period=<duration>` (telemetry only at the first and last step)."
    );
    for sk in &res.skipped {
        notes.push(sk.clone());
    }
    if !notes.is_empty() {
        let _ = writeln!(w, "\nNotes:");
        for n in notes {
            let _ = writeln!(w, "- {n}");
        }
    }
    s
}
