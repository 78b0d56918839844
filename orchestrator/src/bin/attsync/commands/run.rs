//! `attsync run`: a scenario through an engine into a results directory.

use super::{EngineArgs, HostsArgs, ScenarioArgs, UntilArgs};
use attsync::Error;
use attsync::interrupt::Interrupt;
use attsync::run::{self, RunOptions};
use attsync::scenario::StiffnessCheck;
use std::io::IsTerminal;
use std::path::PathBuf;

/// `attsync run SCENARIO [--engine E] [--wait W] [--stage-timeout S]
/// [--realtime [FACTOR]] [--threads N] [--hosts HOSTS.toml] [--out DIR]
/// [--set K=V]… [--quiet] [--no-stiffness-check] [--no-view] [--tolerance E]
/// [--until horizon|settled] [--max-duration S]`.
#[derive(Debug, clap::Args)]
pub struct Run {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    #[command(flatten)]
    pub engine: EngineArgs,
    #[command(flatten)]
    pub hosts: HostsArgs,
    /// Real-time mode: nodes run free against the wall clock at FACTOR
    /// simulated seconds per wall second [default FACTOR: 1], never wait for
    /// their inputs, and the links' measured age of information is reported.
    /// Not deterministic. Without it: deterministic lockstep.
    #[arg(long, value_name = "FACTOR", num_args = 0..=1, default_missing_value = "1")]
    pub realtime: Option<f64>,
    /// In-process engine: threads that step the agents (≥ 1; each gets at
    /// least 64 agents, so a small network runs on fewer) [default: number
    /// of cores]. The results are bit-identical for any N.
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
    /// Results directory [default: results/<scenario name>].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Do not refuse a simulation.dt beyond the largest stable RK4 step of
    /// the scenario's loops (docs/stiffness.md): warn, and run anyway.
    #[arg(long)]
    pub no_stiffness_check: bool,
    /// Do not write view.html (the run in 3D in a browser; `attsync view
    /// DIR` writes it later from the results).
    #[arg(long)]
    pub no_view: bool,
    /// Converged: the largest attitude error |R_i R_0^T|_I over agents below
    /// this and staying there (the verdict, docs/verdicts.md).
    #[arg(long, default_value_t = attsync::until::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    #[command(flatten)]
    pub until: UntilArgs,
}

/// Runs the scenario, prints its summary; an incomplete run is an error
/// (its results are kept).
pub fn exec(a: Run, interrupt: &Interrupt) -> Result<(), Error> {
    let hosts = a.hosts.load()?;
    let mut opts = RunOptions {
        engine: a.engine.engine,
        out: a.out.clone().unwrap_or_default(),
        processes: a.engine.process_options(a.realtime),
        progress: !a.quiet && std::io::stderr().is_terminal(),
        threads: a.threads.unwrap_or_else(run::default_threads),
        view: !a.no_view,
        hosts,
        judging: a.until.judging(a.tolerance, 1.0, false),
        law: None,
    };
    opts.validate()?;
    let loaded = a
        .scenario
        .load(StiffnessCheck::from_flag(a.no_stiffness_check))?;
    let net = &loaded.resolved.network;
    opts.judging = a
        .until
        .judging(a.tolerance, net.steps as f64 * net.dt, false);
    for w in &loaded.resolved.warnings {
        eprintln!("warning: {}: {w}", loaded.file.display());
    }
    if a.out.is_none() {
        opts.out = run::default_out(&loaded);
    }
    let summary = run::run(&loaded, &opts, interrupt)?;
    println!("{}", summary.table());
    println!("results: {}", opts.out.display());
    Ok(run::verdict(&summary, interrupt)?)
}
