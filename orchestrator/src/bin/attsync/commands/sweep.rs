//! `attsync sweep`: one field of a scenario over many values, or two over
//! their grid, in parallel, and optionally the bisection for the margin.

use super::{EngineArgs, HostsArgs, ScenarioArgs, UntilArgs};
use attsync::Error;
use attsync::interrupt::Interrupt;
use attsync::options::OptionError;
use attsync::run::{Engine, RunOptions};
use attsync::scenario::StiffnessCheck;
use attsync::sweep::{self, Axis, Bisection, SweepOptions};
use std::path::PathBuf;

/// `attsync sweep SCENARIO --param FIELD --values V1,V2,… [--param FIELD2
/// --values W1,W2,…] […]`.
#[derive(Debug, clap::Args)]
pub struct Sweep {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Field to sweep, as for --set (e.g. network.delay, network.loss,
    /// scheme.control.k_r); give it twice, each with its --values, to run
    /// the grid of both (sweep.svg: the stability chart).
    #[arg(long, required = true)]
    pub param: Vec<String>,
    /// Values of the --param before it, comma-separated (TOML literals).
    #[arg(long, required = true)]
    pub values: Vec<String>,
    /// Runs at once [default: in-process, the number of cores (or cores / --threads); processes, as many runs as fit the cores (nodes × runs ≤ cores), at least 1].
    #[arg(long)]
    pub jobs: Option<usize>,
    /// In-process engine: threads per run (≥ 1) [default: cores / jobs, at least 1].
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub engine: EngineArgs,
    #[command(flatten)]
    pub hosts: HostsArgs,
    /// Sweep directory [default: results/<scenario name>-sweep-<param>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Converged: the largest attitude error |R_i R_0^T|_I over agents below
    /// this and staying there (the verdict, docs/verdicts.md).
    #[arg(long, default_value_t = attsync::until::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    #[command(flatten)]
    pub until: UntilArgs,
    /// Bisect between the first value whose error does not decay (persistent
    /// or diverging) and the one before it (whose error must decay), every
    /// run extended until its verdict is final (--until settled unless
    /// given); for network.delay the linearisation's margin is put beside it.
    #[arg(long)]
    pub find_margin: bool,
    /// Bisection iterations.
    #[arg(long, default_value_t = 8)]
    pub bisect: u32,
    /// Round bisection points to multiples of this [default: simulation.dt for delays, jitters and periods, else none].
    #[arg(long)]
    pub quantum: Option<f64>,
    /// Do not refuse a simulation.dt beyond the largest stable RK4 step of
    /// the scenario's loops (docs/stiffness.md): warn, and run anyway.
    #[arg(long)]
    pub no_stiffness_check: bool,
}

/// Runs the sweep and prints its table.
pub fn exec(a: Sweep, interrupt: &Interrupt) -> Result<(), Error> {
    let hosts = a.hosts.load()?;
    let (jobs, threads) = sweep::jobs_and_threads(a.jobs, a.threads);
    let (param, values, grid) = axes(a.param, a.values)?;
    let mut o = SweepOptions {
        scenario: a.scenario.scenario.clone(),
        param,
        values,
        grid,
        jobs,
        set: a.scenario.overrides.set.clone(),
        run: RunOptions {
            engine: a.engine.engine,
            out: a.out.clone().unwrap_or_default(),
            processes: a.engine.process_options(None),
            progress: false,
            threads,
            view: false,
            hosts,
            judging: a.until.judging(a.tolerance, 1.0, a.find_margin),
            law: None,
        },
        find_margin: a.find_margin.then_some(Bisection {
            iterations: a.bisect,
            quantum: a.quantum,
        }),
        stiffness: StiffnessCheck::from_flag(a.no_stiffness_check),
    };
    o.validate()?;
    let base = o.load_checked()?;
    let net = &base.resolved.network;
    o.run.judging = a
        .until
        .judging(a.tolerance, net.steps as f64 * net.dt, a.find_margin);
    if let Some(h) = &o.run.hosts {
        // Every run places its own scenario again; the base, before any starts.
        attsync::hosts::Placement::of(h, &base.resolved.network)?;
    }
    let theory = base.resolved.theory_warning();
    for w in base.resolved.law_warning().into_iter().chain(theory) {
        eprintln!("warning: {}: {w}", base.file.display());
    }
    let nodes = base.resolved.network.agents.len() + 1;
    let cores = sweep::cores();
    match (o.run.engine, a.jobs) {
        (Engine::Processes, None) => o.jobs = sweep::default_jobs(o.run.engine, nodes, cores),
        (_, Some(jobs)) => {
            if let Some(w) = sweep::oversubscription(o.run.engine, jobs, nodes, cores) {
                eprintln!("warning: {w}");
            }
        }
        (Engine::InProcess, None) => {}
    }
    if a.out.is_none() {
        o.run.out = sweep::default_out(&base, &o.params().join("-"));
    }
    let r = sweep::sweep(&o, interrupt)?;
    print!("{}", sweep::table(&o.params().join(","), &r));
    println!("results: {}", o.run.out.display());
    Ok(())
}

/// The first field and its values, and the grid's second field if given:
/// one or two `--param`, each with its `--values`.
fn axes(
    mut params: Vec<String>,
    values: Vec<String>,
) -> Result<(String, Vec<String>, Option<Axis>), OptionError> {
    let split = |v: String| v.split(',').map(str::to_string).collect::<Vec<_>>();
    let mut values: Vec<Vec<String>> = values.into_iter().map(split).collect();
    if params.len() > 2 || params.len() != values.len() {
        return Err(OptionError::Conflict(format!(
            "--param is given {} times and --values {} times: give one or two --param, \
             each followed by its --values",
            params.len(),
            values.len()
        )));
    }
    let grid = (params.len() == 2).then(|| Axis {
        param: params.remove(1),
        values: values.remove(1),
    });
    Ok((params.remove(0), values.remove(0), grid))
}
