//! `attsync mc`: a Monte Carlo over initial conditions, or one of its
//! trials alone (`--trial K`).

use super::{ScenarioArgs, UntilArgs, WaitArg};
use attsync::Error;
use attsync::interrupt::Interrupt;
use attsync::mc::{self, McOptions, report};
use attsync::processes::ProcessOptions;
use attsync::run::{self, Engine};
use attsync::scenario::StiffnessCheck;
use attsync::sweep;
use std::io::IsTerminal;
use std::path::PathBuf;

/// `attsync mc SCENARIO --trials N [--seed S] [--jobs J] [--engine E]
/// [--tolerance E] [--out DIR] [--set K=V]… [--trial K]`.
#[derive(Debug, clap::Args)]
pub struct Mc {
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Number of trials.
    #[arg(long, required_unless_present = "trial")]
    pub trials: Option<u64>,
    /// Master seed: trial K draws from ChaCha8 seeded with the (K+1)-th output of SplitMix64(S).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Run only trial K (0-based), as a normal run into --out [default: results/<scenario name>-mc-trial-K], and print the `attsync run` line that reproduces it.
    #[arg(long, value_name = "K")]
    pub trial: Option<u64>,
    /// Trials at once [default: in-process, the number of cores; processes, as many trials as fit the cores (nodes × trials ≤ cores), at least 1].
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Engine of each trial (in-process: each trial on one thread).
    #[arg(long, value_enum, default_value_t = Engine::InProcess)]
    pub engine: Engine,
    /// How node processes wait for their inputs (processes engine).
    #[arg(long, value_enum, default_value_t = WaitArg::Adaptive)]
    pub wait: WaitArg,
    /// Longest wait of a node for one stage's inputs, s (processes engine).
    #[arg(long, default_value_t = 10.0)]
    pub stage_timeout: f64,
    /// Converged: the largest attitude error |R_i R_0^T|_I over agents below
    /// this and staying there (the verdict, docs/verdicts.md); a trial fails
    /// when it is neither converged nor converging.
    #[arg(long, default_value_t = mc::options::DEFAULT_TOLERANCE)]
    pub tolerance: f64,
    #[command(flatten)]
    pub until: UntilArgs,
    /// Results directory [default: results/<scenario name>-mc].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// No progress bar.
    #[arg(long)]
    pub quiet: bool,
    /// Do not refuse a simulation.dt beyond the largest stable RK4 step of
    /// the scenario's loops (docs/stiffness.md): warn, and run anyway.
    #[arg(long)]
    pub no_stiffness_check: bool,
}

/// Runs the Monte Carlo (or one trial) and prints its table.
pub fn exec(a: Mc, interrupt: &Interrupt) -> Result<(), Error> {
    let check = StiffnessCheck::from_flag(a.no_stiffness_check);
    let loaded = a.scenario.load(check)?;
    for w in &loaded.resolved.warnings {
        eprintln!("warning: {}: {w}", loaded.file.display());
    }
    let nodes = loaded.resolved.network.agents.len() + 1;
    let jobs = a
        .jobs
        .unwrap_or_else(|| sweep::default_jobs(a.engine, nodes, sweep::cores()));
    let o = McOptions {
        scenario: a.scenario.scenario.clone(),
        set: a.scenario.overrides.set.clone(),
        trials: a.trials.unwrap_or(1),
        seed: a.seed,
        jobs,
        engine: a.engine,
        processes: ProcessOptions {
            wait: a.wait.into(),
            stage_timeout: a.stage_timeout,
            ..ProcessOptions::default()
        },
        judging: {
            let net = &loaded.resolved.network;
            a.until
                .judging(a.tolerance, net.steps as f64 * net.dt, false)
        },
        out: (a.out.clone()).unwrap_or_else(|| mc::options::default_out(&loaded.name())),
        progress: !a.quiet && std::io::stderr().is_terminal(),
        stiffness: check,
        law: None,
    };
    match a.trial {
        Some(k) => alone(&o, k, a.out.is_none().then(|| loaded.name()), interrupt),
        None => many(&o, interrupt),
    }
}

fn many(o: &McOptions, interrupt: &Interrupt) -> Result<(), Error> {
    let r = mc::monte_carlo(o, interrupt)?;
    print!("{}", report::table(&r.summary, &r.results));
    let n = r.results.len() as f64;
    println!(
        "{} trials in {:.1} s ({:.2} trials/s, {} at once)",
        r.results.len(),
        r.wall_seconds,
        n / r.wall_seconds.max(1e-9),
        o.jobs
    );
    println!(
        "reproduce trial K: attsync mc {} --seed {} --trial K",
        o.scenario.display(),
        o.seed
    );
    println!("results: {}", o.out.display());
    Ok(())
}

fn alone(o: &McOptions, k: u64, name: Option<String>, interrupt: &Interrupt) -> Result<(), Error> {
    let out = match name {
        Some(name) => {
            PathBuf::from(attsync::results::layout::RESULTS).join(format!("{name}-mc-trial-{k}"))
        }
        None => o.out.clone(),
    };
    let t = mc::trial_alone(o, k, &out, interrupt)?;
    println!("{}", t.summary.table());
    println!("{}", t.header);
    println!("{}", report::trial_row(&t.result));
    println!("reproduce: {}", t.command);
    println!("results: {}", out.display());
    Ok(run::verdict(&t.summary, interrupt)?)
}
