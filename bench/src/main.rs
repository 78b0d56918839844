//! `attsync-bench`: the benchmark of attsync's engines against a bare
//! iceoryx2 lockstep ring (results in BENCHMARKS.md).
//!
//! ```sh
//! cargo build --release --workspace
//! ./target/release/attsync-bench run --out bench-results.md       # full, ~10–15 min on 2 cores
//! ./target/release/attsync-bench run --quick --out quick.md       # ~2 min, one repetition
//! ./target/release/attsync-bench run --only tree-32 --reps 1      # one case
//! ./target/release/attsync-bench scale --agents 10,100,1000 --threads 1,2   # in-process scale
//! ./target/release/attsync-bench conclusions                       # attsync margin timings, --until settled overhead
//! ```
//! It needs `attsync`, `attsync-agent` and `attsync-leader` beside it (or
//! `--bin-dir`), and the paper scenarios (`--scenarios`, default
//! `scenarios/paper` of this workspace). Run it on an otherwise idle
//! machine: before each measurement it waits (up to `--idle-wait` seconds,
//! default 20) for other processes to leave the CPUs idle, and the report's
//! "bg load" column shows how much other work ran during the measurements.
//!
//! `attsync-bench ring-node …` is internal: one process of the bare ring,
//! started by `run` (see [`ring`]).
//!
//! The benchmark is not part of `cargo test`: its unit tests check parsing
//! and statistics, and `tests/quick.rs` runs one short case end to end and
//! checks that every figure of the report was measured; nothing is timed.
//!
//! # Layout
//! - [`suite`]: `run` — the plan, the measurements, the report.
//! - [`measure`]: one `attsync run`, its figures read from `summary.json`.
//! - [`bare`]: one bare lockstep of `ring-node` processes; [`ring`]: one
//!   `ring-node` process.
//! - [`scale`]: `scale` — the in-process engine against N and threads.
//! - [`hosts`]: `hosts` — one scenario on one machine and split over 2
//!   and 3 hosts on loopback (daemons in mount namespaces of their own);
//!   [`crossing`]: then a cut edge hop by hop, with lookahead, in real time.
//! - [`zping`]: `zenoh-ping` — Zenoh's own round trip on loopback, next to
//!   plain TCP (the floor under the bridge across hosts).
//! - [`procs`]: child processes with bounded waits; [`stats`]: medians, CPU
//!   load, the machine; [`error`]: [`error::BenchError`].

mod bare;
mod conclusions;
mod crossing;
mod error;
mod hosts;
mod measure;
mod procs;
mod restart;
mod ring;
mod scale;
mod stats;
mod suite;
mod zping;

use anyhow::{Context as _, bail};
use attsync::options::WaitArg;
use clap::{Parser, Subcommand};
use msgs::config::{Contention, WaitStrategy};
use std::path::PathBuf;
use std::process::ExitCode;

/// Benchmark of attsync: in-process engine, process engine per wait strategy, bare iceoryx2 ring.
#[derive(Debug, Parser)]
#[command(name = "attsync-bench", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Debug, Subcommand)]
enum Cmd {
    /// Run the whole benchmark and print a Markdown report.
    Run {
        /// Shorter runs (paper scenarios 10 s, trees 0.5 / 0.25 s) and one repetition.
        #[arg(long)]
        quick: bool,
        /// Also write the report to this file.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Repetitions per measurement (default 3, 1 with --quick).
        #[arg(long)]
        reps: Option<usize>,
        /// Simulated seconds of every case (default: the plan's, see --quick).
        #[arg(long)]
        duration: Option<f64>,
        /// Only cases whose label contains this (repeatable): paper-timevarying, tree-32, …
        #[arg(long)]
        only: Vec<String>,
        /// Only this wait strategy (repeatable; default: all four).
        #[arg(long, value_enum)]
        wait: Vec<WaitArg>,
        /// Directory of the paper scenarios.
        #[arg(long)]
        scenarios: Option<PathBuf>,
        /// Directory of attsync, attsync-agent, attsync-leader (default: beside this program).
        #[arg(long)]
        bin_dir: Option<PathBuf>,
        /// Scratch directory (default: `<tmp>/attsync-bench-<pid>`, removed at the end).
        #[arg(long)]
        work: Option<PathBuf>,
        /// Before each measurement, wait up to this many seconds for other
        /// processes to leave the CPUs idle (0: don't wait).
        #[arg(long, default_value_t = 20)]
        idle_wait: u64,
    },
    /// (internal) A CPU-bound competitor of the contention case: spins until killed.
    Burn,
    /// Issue 32: `attsync margin`'s wall time (paper scenarios, generated
    /// trees) and what `--until settled` costs against one run of the same
    /// final horizon (a Markdown report).
    Conclusions {
        /// Directory of the paper scenarios (default: scenarios/paper).
        #[arg(long)]
        scenarios: Option<PathBuf>,
        /// Repetitions per measurement (medians).
        #[arg(long, default_value_t = 3)]
        reps: usize,
    },
    /// Issue 35: what a crash and restart of an agent costs in the process
    /// engine (the paper's observerless run with and without, a Markdown table).
    Restart {
        /// Directory of the paper scenarios (default: scenarios/paper).
        #[arg(long)]
        scenarios: Option<PathBuf>,
        /// Repetitions per measurement (medians).
        #[arg(long, default_value_t = 5)]
        reps: usize,
        /// Simulated seconds of every run.
        #[arg(long, default_value_t = 20.0)]
        duration: f64,
        /// Crashes and restarts per run.
        #[arg(long, default_value_t = 4)]
        restarts: usize,
    },
    /// In-process scale: agent-steps/s of the in-process engine against N
    /// agents and threads, per scheme (networks built in memory; a Markdown table).
    Scale {
        /// Numbers of agents, comma-separated.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "10,100,1000,10000,100000"
        )]
        agents: Vec<u32>,
        /// Thread counts, comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "1,2")]
        threads: Vec<usize>,
        /// Schemes (repeatable; default: all three).
        #[arg(long, value_enum)]
        scheme: Vec<scale::tree::SchemeArg>,
        /// Use exactly the threads asked for, however few agents each gets.
        #[arg(long)]
        exact: bool,
        /// Agent-steps per measurement.
        #[arg(long, default_value_t = scale::BUDGET)]
        budget: u64,
    },
    /// Zenoh's own round trip on loopback for a state-sized payload, with
    /// attsync's session configuration: plain TCP (the floor), Zenoh's
    /// default transport and its low-latency one, interleaved (a Markdown
    /// table).
    ZenohPing {
        /// Payload bytes (a state on the bridge: 152).
        #[arg(long, default_value_t = 152)]
        payload: usize,
        /// Round trips per measurement.
        #[arg(long, default_value_t = 20_000)]
        rounds: usize,
        /// Round trips not counted, before each measurement.
        #[arg(long, default_value_t = 2_000)]
        warmup: usize,
        /// Measurements per transport.
        #[arg(long, default_value_t = 3)]
        reps: usize,
    },
    /// A scenario on one machine and split over 2 and 3 `attsync host`
    /// daemons on loopback, each in a mount namespace of its own (root),
    /// repetitions interleaved (a Markdown table).
    Hosts {
        /// The scenario (default: the paper's time-varying run).
        #[arg(long)]
        scenario: Option<PathBuf>,
        /// Simulated seconds.
        #[arg(long, default_value_t = 40.0)]
        duration: f64,
        /// Repetitions of every placement.
        #[arg(long, default_value_t = 3)]
        reps: usize,
        /// Machine counts, comma-separated (1: the orchestrator's alone).
        #[arg(long, value_delimiter = ',', default_value = "1,2,3")]
        machines: Vec<usize>,
        /// Delays on every link for the lookahead table, in steps,
        /// comma-separated.
        #[arg(long, value_delimiter = ',', default_value = "0,1,2,4,20")]
        delays: Vec<u64>,
    },
    /// (internal) The echoing end of `zenoh-ping`.
    ZenohPong {
        /// The ping's endpoint.
        #[arg(long)]
        connect: String,
        /// What carries the pings.
        #[arg(long, value_enum)]
        transport: zping::Transport,
    },
    /// (internal) One process of the bare iceoryx2 lockstep ring.
    RingNode(RingNodeArgs),
}

/// `ring-node`'s flags.
#[derive(Debug, clap::Args)]
struct RingNodeArgs {
    /// Run id (iceoryx2 namespace).
    #[arg(long)]
    run: String,
    /// Run directory (iceoryx2 root ROOT/iox, barrier files).
    #[arg(long)]
    root: PathBuf,
    /// This node's id.
    #[arg(long)]
    index: u32,
    /// Number of nodes.
    #[arg(long)]
    n: u32,
    /// Steps (4 exchanges each).
    #[arg(long)]
    steps: u64,
    /// Wait strategy.
    #[arg(long, value_enum)]
    wait: WaitArg,
    /// Input ids, comma-separated (default: the ring neighbours; may be empty).
    #[arg(long)]
    inputs: Option<String>,
    /// Receiver ids, comma-separated (default: the ring neighbours).
    #[arg(long)]
    outputs: Option<String>,
    /// Fan-out limit of the services (default 2, the ring's).
    #[arg(long, default_value_t = 2)]
    max_fanout: usize,
    /// Longest wait for one exchange's inputs, s.
    #[arg(long, default_value_t = 10.0)]
    stage_timeout: f64,
    /// Longest wait at each barrier, s.
    #[arg(long, default_value_t = 120.0)]
    barrier_timeout: f64,
    /// Longest single sleep on the wake event, ms (a lost wake-up costs this).
    #[arg(long, default_value_t = 1)]
    block_slice_ms: u64,
    /// Adaptive: block for a while after a stolen yield, as a node that
    /// nothing places does (default: not, as attsync's nodes under its
    /// default placement).
    #[arg(long)]
    stolen_holds: bool,
}

fn id_list(s: Option<String>) -> anyhow::Result<Option<Vec<u32>>> {
    s.map(|s| {
        s.split(',')
            .filter(|x| !x.trim().is_empty())
            .map(|x| x.trim().parse().with_context(|| format!("node id {x:?}")))
            .collect()
    })
    .transpose()
}

fn main() -> ExitCode {
    match dispatch(Cli::parse().command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("attsync-bench: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn dispatch(cmd: Cmd) -> anyhow::Result<()> {
    match cmd {
        Cmd::Burn => suite::burn(),
        Cmd::Conclusions { scenarios, reps } => {
            let dir = scenarios.unwrap_or_else(|| PathBuf::from("scenarios/paper"));
            print!("{}", conclusions::report(&dir, reps)?);
            Ok(())
        }
        Cmd::Restart {
            scenarios,
            reps,
            duration,
            restarts,
        } => {
            let dir = scenarios.unwrap_or_else(|| PathBuf::from("scenarios/paper"));
            print!("{}", restart::report(&dir, reps, duration, restarts)?);
            Ok(())
        }
        Cmd::Hosts {
            scenario,
            duration,
            reps,
            machines,
            delays,
        } => hosts_table(scenario, duration, reps, (machines, delays)),
        Cmd::ZenohPong { connect, transport } => zping::pong(&connect, transport),
        Cmd::ZenohPing {
            payload,
            rounds,
            warmup,
            reps,
        } => zenoh_ping_table(payload, rounds, warmup, reps),
        Cmd::Scale {
            agents,
            threads,
            scheme,
            exact,
            budget,
        } => {
            scale_table(&agents, &threads, &scheme, (exact, budget));
            Ok(())
        }
        Cmd::RingNode(a) => ring_node(a),
        Cmd::Run {
            quick,
            out,
            reps,
            duration,
            only,
            wait,
            scenarios,
            bin_dir,
            work,
            idle_wait,
        } => {
            let opts = RunArgs {
                quick,
                reps,
                duration,
                only,
                wait,
                scenarios,
                bin_dir,
                work,
                idle_wait,
            };
            run(opts, out)
        }
    }
}

/// `attsync-bench ring-node`: runs one node of the bare ring, prints its line.
fn ring_node(a: RingNodeArgs) -> anyhow::Result<()> {
    let node = ring::RingNode {
        run: a.run,
        root: a.root,
        index: a.index,
        n: a.n,
        steps: a.steps,
        wait: a.wait.into(),
        inputs: id_list(a.inputs)?,
        outputs: id_list(a.outputs)?,
        max_fanout: a.max_fanout,
        stage_timeout: a.stage_timeout,
        barrier_timeout: a.barrier_timeout,
        block_slice: std::time::Duration::from_millis(a.block_slice_ms),
        contention: if a.stolen_holds {
            Contention::Waiter
        } else {
            Contention::Placement
        },
    };
    println!("{}", node.run()?.line());
    Ok(())
}

/// `rel` in the current directory if it is there, else in the repository
/// this program was built from.
fn in_repository(rel: &str) -> PathBuf {
    let local = PathBuf::from(rel);
    if local.exists() {
        local
    } else {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(rel)
    }
}

/// `attsync-bench hosts`: measures, then prints the table.
fn hosts_table(
    scenario: Option<PathBuf>,
    duration: f64,
    reps: usize,
    (machines, delays): (Vec<usize>, Vec<u64>),
) -> anyhow::Result<()> {
    let bench = std::env::current_exe().context("own path")?;
    let dir = bench.parent().map(PathBuf::from).unwrap_or_default();
    let scenario = scenario.unwrap_or_else(|| in_repository("scenarios/paper/timevarying.toml"));
    let work = std::env::temp_dir().join(format!("attsync-bench-hosts-{}", std::process::id()));
    let crossing = crossing::Options {
        scenario: scenario.clone(),
        duration,
        reps,
        delays,
        work: work.clone(),
    };
    let o = hosts::Options {
        scenario,
        duration,
        reps,
        machines,
        work: work.clone(),
    };
    let bins = measure::Bins {
        attsync: dir.join("attsync"),
        bench,
    };
    println!(
        "machine: {}; load average before: {}",
        stats::machine(),
        stats::loadavg()
    );
    let placed = hosts::measure(&o, &bins);
    let crossed = placed.is_ok().then(|| crossing::measure(&crossing, &bins));
    let _ = std::fs::remove_dir_all(&work);
    print!("{}", hosts::table(&placed?));
    if let Some(c) = crossed {
        print!("{}", crossing::tables(&c?));
    }
    println!("load average after: {}", stats::loadavg());
    Ok(())
}

/// `attsync-bench zenoh-ping`: `reps` measurements per transport,
/// interleaved, each row printed as it comes.
fn zenoh_ping_table(
    payload: usize,
    rounds: usize,
    warmup: usize,
    reps: usize,
) -> anyhow::Result<()> {
    println!(
        "machine: {}; load average before: {}",
        stats::machine(),
        stats::loadavg()
    );
    println!("{}", zping::HEADER);
    for _ in 0..reps {
        for transport in [
            zping::Transport::Tcp,
            zping::Transport::Default,
            zping::Transport::Lowlatency,
        ] {
            let port = std::net::TcpListener::bind("127.0.0.1:0")?
                .local_addr()?
                .port();
            let p = zping::Ping {
                payload,
                rounds,
                warmup,
                transport,
                port,
            };
            let rtt = zping::ping(p)?;
            println!("{}", zping::row(&p, &rtt));
        }
    }
    Ok(())
}

/// `attsync-bench scale`: measures every (scheme, N, threads), printing
/// each figure as it comes (stderr) and the table at the end.
fn scale_table(
    agents: &[u32],
    threads: &[usize],
    schemes: &[scale::tree::SchemeArg],
    (exact, budget): (bool, u64),
) {
    let schemes = if schemes.is_empty() {
        &scale::tree::SchemeArg::ALL[..]
    } else {
        schemes
    };
    let load = stats::loadavg();
    let started = std::time::Instant::now();
    let cpu = stats::cpu_seconds();
    let mut figures = Vec::new();
    for &s in schemes {
        for &n in agents.iter().filter(|&&n| n > 0) {
            for &t in threads.iter().filter(|&&t| t > 0) {
                let f = scale::measure(s, n, t, exact, budget);
                eprintln!(
                    "{} N={n} threads={t} ({}): {:.3e} agent-steps/s",
                    s.name(),
                    f.threads,
                    f.agent_steps_per_s()
                );
                figures.push(f);
            }
        }
    }
    print!("{}", scale::table(&figures, threads));
    let cpu = cpu.zip(stats::cpu_seconds()).map(|(a, b)| b - a);
    println!(
        "\nWhole table: {:.0} s wall, {} CPU; load average (1, 5, 15 min) {} at the start, {} at the end.\n",
        started.elapsed().as_secs_f64(),
        cpu.map_or("–".into(), |c| format!("{c:.0} s")),
        load,
        stats::loadavg()
    );
    print!("{}", scale::conditions(&figures));
}

/// The arguments of `run` that become [`suite::Options`].
struct RunArgs {
    quick: bool,
    reps: Option<usize>,
    duration: Option<f64>,
    only: Vec<String>,
    wait: Vec<WaitArg>,
    scenarios: Option<PathBuf>,
    bin_dir: Option<PathBuf>,
    work: Option<PathBuf>,
    idle_wait: u64,
}

/// `attsync-bench run`: checks the programs, runs the suite, prints (and writes) the report.
fn run(a: RunArgs, out: Option<PathBuf>) -> anyhow::Result<()> {
    let bench = std::env::current_exe().context("own path")?;
    let dir = a
        .bin_dir
        .or_else(|| bench.parent().map(PathBuf::from))
        .unwrap_or_default();
    for b in ["attsync", "attsync-agent", "attsync-leader"] {
        if !dir.join(b).is_file() {
            bail!(
                "{} is missing: build with `cargo build --release --workspace` or pass --bin-dir",
                dir.join(b).display()
            );
        }
    }
    let scenarios = a
        .scenarios
        .unwrap_or_else(|| in_repository("scenarios/paper"));
    let (work, temporary) = match a.work {
        Some(w) => (w, false),
        None => (
            std::env::temp_dir().join(format!("attsync-bench-{}", std::process::id())),
            true,
        ),
    };
    let opts = suite::Options {
        quick: a.quick,
        reps: a.reps,
        duration: a.duration,
        only: a.only,
        waits: a.wait.into_iter().map(WaitStrategy::from).collect(),
        scenarios,
        work: work.clone(),
        idle_wait: std::time::Duration::from_secs(a.idle_wait),
        bins: measure::Bins {
            attsync: dir.join("attsync"),
            bench,
        },
    };
    let result = suite::run(&opts);
    if temporary {
        let _ = std::fs::remove_dir_all(&work);
    }
    let report = result?;
    println!("{report}");
    if let Some(path) = out {
        std::fs::write(&path, &report).with_context(|| path.display().to_string())?;
    }
    Ok(())
}
