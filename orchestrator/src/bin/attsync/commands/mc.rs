//! `attsync mc`: a Monte Carlo over initial conditions, one slice of its
//! trials (`--shard K/N`), one of its trials alone (`--trial K`), or its
//! slices merged (`attsync mc merge`).

use super::{ScenarioArgs, SetArgs, UntilArgs, WaitArg};
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
/// [--tolerance E] [--out DIR] [--set K=V]… [--trial K | --shard K/N]`, or
/// `attsync mc merge DIR… --out DIR`.
#[derive(Debug, clap::Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct Mc {
    /// `merge`: the shards' directories joined.
    #[command(subcommand)]
    pub action: Option<Action>,
    /// Scenario file (TOML).
    #[arg(required = true)]
    pub scenario: Option<PathBuf>,
    #[command(flatten)]
    pub overrides: SetArgs,
    /// Number of trials.
    #[arg(long, required_unless_present = "trial")]
    pub trials: Option<u64>,
    /// Master seed: trial K draws from ChaCha8 seeded with the (K+1)-th output of SplitMix64(S).
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Run only trial K (0-based), as a normal run into --out [default: results/<scenario name>-mc-trial-K], and print the `attsync run` line that reproduces it.
    #[arg(long, value_name = "K", conflicts_with = "shard")]
    pub trial: Option<u64>,
    /// Run only slice K of N of the trials (⌊(K−1)·T/N⌋ up to ⌊K·T/N⌋, each
    /// trial as in the whole run), for a job array; `attsync mc merge` joins
    /// the slices' directories into the files of one run.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<mc::Shard>,
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
    /// Results directory [default: results/<scenario name>-mc; a shard's,
    /// results/<scenario name>-shard-K-of-N-mc].
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

/// `attsync mc merge`.
#[derive(Debug, clap::Subcommand)]
pub enum Action {
    /// Join the directories of `attsync mc --shard K/N` (every K of one N)
    /// into the files one run of every trial writes, byte for byte.
    Merge(Merge),
}

/// `attsync mc merge DIR… --out DIR`.
#[derive(Debug, clap::Args)]
pub struct Merge {
    /// The shards' results directories (any order).
    #[arg(required = true)]
    pub dirs: Vec<PathBuf>,
    /// Results directory of the whole Monte Carlo.
    #[arg(long)]
    pub out: PathBuf,
}

/// Runs the Monte Carlo (one trial, one shard, or the merge) and prints its table.
pub fn exec(a: Mc, interrupt: &Interrupt) -> Result<(), Error> {
    if let Some(Action::Merge(m)) = a.action {
        return merge(&m);
    }
    let check = StiffnessCheck::from_flag(a.no_stiffness_check);
    let scenario = ScenarioArgs {
        scenario: a.scenario.clone().expect("clap requires SCENARIO"),
        overrides: a.overrides.clone(),
    };
    let loaded = scenario.load(check)?;
    for w in &loaded.resolved.warnings {
        eprintln!("warning: {}: {w}", loaded.file.display());
    }
    let nodes = loaded.resolved.network.agents.len() + 1;
    let jobs = a
        .jobs
        .unwrap_or_else(|| sweep::default_jobs(a.engine, nodes, sweep::cores()));
    let o = McOptions {
        scenario: scenario.scenario.clone(),
        set: scenario.overrides.set.clone(),
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
        out: (a.out.clone()).unwrap_or_else(|| match a.shard {
            None => mc::options::default_out(&loaded.name()),
            Some(s) => mc::options::default_out(&format!(
                "{}-shard-{}-of-{}",
                loaded.name(),
                s.index,
                s.count
            )),
        }),
        progress: !a.quiet && std::io::stderr().is_terminal(),
        stiffness: check,
        law: None,
        shard: a.shard,
    };
    match a.trial {
        Some(k) => alone(&o, k, a.out.is_none().then(|| loaded.name()), interrupt),
        None => many(&o, interrupt),
    }
}

fn merge(m: &Merge) -> Result<(), Error> {
    let r = mc::merge(&m.dirs, &m.out)?;
    print!("{}", report::table(&r.summary, &r.results));
    println!("{} shards merged", m.dirs.len());
    println!("results: {}", m.out.display());
    Ok(())
}

fn many(o: &McOptions, interrupt: &Interrupt) -> Result<(), Error> {
    let r = mc::monte_carlo(o, interrupt)?;
    if let Some(shard) = o.shard {
        let trials = o.range();
        println!(
            "shard {shard}: trials {}..{} of {}",
            trials.start, trials.end, o.trials
        );
    }
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
