//! `attsync`: run networks of rigid bodies synchronising their attitudes.

use anyhow::Context;
use attsync::generate::{TreeParams, tree};
use attsync::processes::ProcessOptions;
use attsync::run::{Engine, RunError, RunOptions, run};
use attsync::scenario::{self, ScenarioError, schema::SchemeKind};
use clap::{Parser, Subcommand, ValueEnum};
use msgs::config::WaitStrategy;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Leader-follower attitude synchronisation on SO(3), one process per rigid body.
#[derive(Debug, Parser)]
#[command(name = "attsync", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Validate a scenario and print its network.
    Check {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Override a field: key.path=value (repeatable), e.g. simulation.duration=10.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Print instead the JSON configuration node ID (0 = leader) would
        /// receive (PROTOCOL.md; `run` and `iox_root` are placeholders).
        #[arg(long, value_name = "ID")]
        node_config: Option<u32>,
    },
    /// Run a scenario and write its results.
    Run {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Engine.
        #[arg(long, value_enum, default_value_t = Engine::Processes)]
        engine: Engine,
        /// How node processes wait for their inputs (processes engine).
        #[arg(long, value_enum, default_value_t = WaitArg::Adaptive)]
        wait: WaitArg,
        /// Longest wait of a node for one stage's inputs, s (processes engine).
        #[arg(long, default_value_t = 10.0)]
        stage_timeout: f64,
        /// Real-time mode: nodes run free against the wall clock at FACTOR
        /// simulated seconds per wall second [default FACTOR: 1], never wait for
        /// their inputs, and the links' measured age of information is reported.
        /// Not deterministic. Without it: deterministic lockstep.
        #[arg(long, value_name = "FACTOR", num_args = 0..=1, default_missing_value = "1")]
        realtime: Option<f64>,
        /// Results directory [default: results/<scenario name>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override a field: key.path=value (repeatable), e.g. simulation.duration=10.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Run a scenario for each value of one field (in parallel), and optionally
    /// bisect for the largest value that still converges.
    Sweep {
        /// Scenario file (TOML).
        scenario: PathBuf,
        /// Field to sweep, as for --set (e.g. network.delay, network.loss, scheme.control.k_r).
        #[arg(long)]
        param: String,
        /// Values, comma-separated (TOML literals).
        #[arg(long, value_delimiter = ',', required = true)]
        values: Vec<String>,
        /// Runs at once [default: number of cores].
        #[arg(long)]
        jobs: Option<usize>,
        /// Engine of every run.
        #[arg(long, value_enum, default_value_t = Engine::Processes)]
        engine: Engine,
        /// How node processes wait for their inputs (processes engine).
        #[arg(long, value_enum, default_value_t = WaitArg::Adaptive)]
        wait: WaitArg,
        /// Override a field of every run: key.path=value (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Sweep directory [default: results/<scenario name>-sweep-<param>].
        #[arg(long)]
        out: Option<PathBuf>,
        /// Converged: complete, and every agent's final attitude error below this.
        #[arg(long, default_value_t = 1e-3)]
        tolerance: f64,
        /// Bisect between the first value that does not converge and the one before it (the first must converge).
        #[arg(long)]
        find_margin: bool,
        /// Bisection iterations.
        #[arg(long, default_value_t = 8)]
        bisect: u32,
        /// Round bisection points to multiples of this [default: simulation.dt for delays, jitters and periods, else none].
        #[arg(long)]
        quantum: Option<f64>,
    },
    /// Check a plug-in agent program against PROTOCOL.md: attsync plays its
    /// orchestrator, leader and neighbours in lockstep and reports each rule.
    /// Exit code 0 only if every rule passes.
    Conform {
        /// Neighbourhood scenario [default: built-in: agent 2 between agents 1
        /// and 3, hearing the leader, observerless scheme, 0.2 s].
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// The candidate's agent id in the neighbourhood.
        #[arg(long, default_value_t = 2)]
        agent: u32,
        /// Override a field of the neighbourhood: key.path=value (repeatable).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Longest wait for one of the candidate's states, s.
        #[arg(long, default_value_t = 5.0)]
        stage_timeout: f64,
        /// Longest wait for the candidate to connect, s.
        #[arg(long, default_value_t = 20.0)]
        start_timeout: f64,
        /// Where the candidate's output goes [default: a file in the temp directory].
        #[arg(long)]
        log: Option<PathBuf>,
        /// Rule `law`: `builtin`, a departure from the built-in law fails;
        /// `own` (a deliberately different controller), it is reported as INFO.
        #[arg(long, value_enum, default_value_t = LawArg::Builtin)]
        law: LawArg,
        /// The candidate program and its arguments (after `--`).
        #[arg(last = true, required = true, value_name = "COMMAND")]
        command: Vec<String>,
    },
    /// Convert a run's states.bin (the full state trajectory).
    Export {
        /// The states.bin file of a run.
        states: PathBuf,
        /// Write CSV (long form: one row per node per sample; node 0 is the leader).
        #[arg(long, required = true)]
        csv: bool,
        /// Write here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Generate a scenario.
    Gen {
        #[command(subcommand)]
        what: Gen,
    },
}

#[derive(Debug, Subcommand)]
enum Gen {
    /// A random tree of agents (seeded, reproducible).
    Tree {
        /// Number of agents.
        #[arg(long)]
        agents: u32,
        /// Number of agents that hear the leader.
        #[arg(long, default_value_t = 1)]
        leader_links: u32,
        /// RNG seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Scheme.
        #[arg(long, value_enum, default_value_t = SchemeArg::ObserverTimeVarying)]
        scheme: SchemeArg,
        /// Horizon, s.
        #[arg(long, default_value_t = 40.0)]
        duration: f64,
        /// Write here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum WaitArg {
    /// Busy-poll.
    Spin,
    /// Poll with sched_yield.
    Yield,
    /// Sleep on iceoryx2 events (1 ms slices).
    Block,
    /// Yield a while, then block.
    Adaptive,
}

impl From<WaitArg> for WaitStrategy {
    fn from(w: WaitArg) -> Self {
        match w {
            WaitArg::Spin => WaitStrategy::Spin,
            WaitArg::Yield => WaitStrategy::Yield,
            WaitArg::Block => WaitStrategy::Block,
            WaitArg::Adaptive => WaitStrategy::Adaptive,
        }
    }
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum LawArg {
    /// The candidate must run the built-in law of its scheme.
    Builtin,
    /// It runs its own controller: a departure is information only.
    Own,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum SchemeArg {
    ObserverTimeVarying,
    ObserverConstant,
    Observerless,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match dispatch(cli) {
        Ok(code) => code,
        Err(e) => {
            if let Some(se) = e.downcast_ref::<ScenarioError>() {
                eprintln!("{se}");
                return ExitCode::from(2);
            }
            if let Some(RunError::Options(why)) = e.downcast_ref::<RunError>() {
                eprintln!("error: {why}");
                return ExitCode::from(2);
            }
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn dispatch(cli: Cli) -> anyhow::Result<ExitCode> {
    match cli.command {
        Command::Conform {
            scenario,
            agent,
            set,
            stage_timeout,
            start_timeout,
            log,
            law,
            command,
        } => {
            let log = log.unwrap_or_else(|| {
                std::env::temp_dir().join(format!("attsync-conform-{}.log", std::process::id()))
            });
            let opts = attsync::conform::ConformOptions {
                command,
                scenario,
                set,
                agent,
                stage_timeout,
                start_timeout,
                log,
                law: match law {
                    LawArg::Builtin => attsync::conform::LawMode::Builtin,
                    LawArg::Own => attsync::conform::LawMode::Own,
                },
            };
            let report = attsync::conform::conform(&opts)?;
            println!("{}", report.table());
            Ok(if report.passed() {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            })
        }
        Command::Check {
            scenario,
            set,
            node_config,
        } => {
            let loaded = scenario::load(&scenario, &set)?;
            let Some(id) = node_config else {
                print!("{}", attsync::scenario::report::describe(&loaded));
                return Ok(ExitCode::SUCCESS);
            };
            let net = &loaded.resolved.network;
            let index = match id {
                0 => 0,
                _ => match net.index_of(id) {
                    Some(i) => i + 1,
                    None => anyhow::bail!("{}: no node {id}", scenario.display()),
                },
            };
            let cfg = attsync::processes::node_configs(
                net,
                "RUN",
                std::path::Path::new("/tmp/attsync-iox2/RUN"),
                &ProcessOptions::default(),
            )
            .swap_remove(index);
            println!(
                "{}",
                serde_json::to_string_pretty(&cfg).expect("a config serialises")
            );
            Ok(ExitCode::SUCCESS)
        }
        Command::Run {
            scenario,
            engine,
            wait,
            stage_timeout,
            realtime,
            out,
            set,
            quiet,
        } => {
            let loaded = scenario::load(&scenario, &set)?;
            for w in &loaded.resolved.warnings {
                eprintln!("warning: {}: {w}", loaded.file.display());
            }
            let out = out.unwrap_or_else(|| PathBuf::from("results").join(loaded.name()));
            let interrupt = Arc::new(AtomicBool::new(false));
            let flag = interrupt.clone();
            ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
                .context("installing the Ctrl-C handler")?;
            let wait = wait.into();
            let opts = RunOptions {
                engine,
                out: out.clone(),
                processes: ProcessOptions {
                    wait,
                    stage_timeout,
                    realtime,
                    ..ProcessOptions::default()
                },
                progress: !quiet && std::io::stderr().is_terminal(),
            };
            let summary = run(&loaded, &opts, &interrupt)?;
            println!("{}", summary.table());
            println!("results: {}", out.display());
            Ok(match summary.incomplete_reason.as_deref() {
                None => ExitCode::SUCCESS,
                Some("interrupted") => ExitCode::from(130),
                Some(reason) => {
                    eprintln!("error: the run failed: {reason}");
                    ExitCode::from(1)
                }
            })
        }
        Command::Sweep {
            scenario,
            param,
            values,
            jobs,
            engine,
            wait,
            set,
            out,
            tolerance,
            find_margin,
            bisect,
            quantum,
        } => {
            let loaded = scenario::load(&scenario, &set)?;
            // Every value must make a valid scenario before anything runs
            // (exit code 2, like an invalid --set).
            for v in &values {
                let mut with = set.clone();
                with.push(format!("{param}={v}"));
                scenario::load(&scenario, &with)?;
            }
            let out = out.unwrap_or_else(|| {
                PathBuf::from("results").join(format!(
                    "{}-sweep-{}",
                    loaded.name(),
                    param.replace(['.', '[', ']'], "_")
                ))
            });
            let timing = ["delay", "jitter", "period"]
                .iter()
                .any(|k| param.ends_with(k));
            let quantum = quantum.unwrap_or(if timing {
                loaded.resolved.network.dt
            } else {
                0.0
            });
            let interrupt = Arc::new(AtomicBool::new(false));
            let flag = interrupt.clone();
            ctrlc::set_handler(move || flag.store(true, Ordering::Relaxed))
                .context("installing the Ctrl-C handler")?;
            let o = attsync::sweep::SweepOptions {
                scenario,
                param: param.clone(),
                values,
                jobs: jobs
                    .unwrap_or_else(|| std::thread::available_parallelism().map_or(2, |n| n.get())),
                set,
                run: RunOptions {
                    engine,
                    out: out.clone(),
                    processes: ProcessOptions {
                        wait: wait.into(),
                        ..ProcessOptions::default()
                    },
                    progress: false,
                },
                tolerance,
                find_margin: find_margin.then_some((bisect, quantum)),
            };
            let r = attsync::sweep::sweep(&o, &interrupt).map_err(anyhow::Error::msg)?;
            print!("{}", attsync::sweep::table(&param, &r));
            println!("results: {}", out.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Export {
            states,
            csv: _,
            out,
        } => {
            let mut text = Vec::new();
            attsync::results::states::export_csv(&states, &mut text).map_err(anyhow::Error::msg)?;
            match out {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("writing {}", path.display()))?,
                None => std::io::Write::write_all(&mut std::io::stdout(), &text)?,
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Gen {
            what:
                Gen::Tree {
                    agents,
                    leader_links,
                    seed,
                    scheme,
                    duration,
                    out,
                },
        } => {
            let scheme = match scheme {
                SchemeArg::ObserverTimeVarying => SchemeKind::ObserverTimeVarying,
                SchemeArg::ObserverConstant => SchemeKind::ObserverConstant,
                SchemeArg::Observerless => SchemeKind::Observerless,
            };
            let s = tree(&TreeParams {
                agents,
                leader_links,
                seed,
                scheme,
                duration,
            })
            .map_err(anyhow::Error::msg)?;
            let text = format!(
                "# Generated by: attsync gen tree --agents {agents} --leader-links {leader_links} --seed {seed}\n{}",
                toml::to_string(&s).context("serialising the scenario")?
            );
            match out {
                Some(path) => std::fs::write(&path, text)
                    .with_context(|| format!("writing {}", path.display()))?,
                None => print!("{text}"),
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}
