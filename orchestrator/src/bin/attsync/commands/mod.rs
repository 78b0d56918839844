//! The subcommands, one file each (`cli` struct + `exec`), and the flags
//! they share, declared once and `#[command(flatten)]`ed.

mod check;
mod conform;
mod export;
mod r#gen;
mod host;
mod margin;
mod mc;
mod run;
mod sweep;
mod verify;
mod view;

use attsync::Error;
use attsync::hosts::Hosts;
use attsync::interrupt::Interrupt;
pub use attsync::options::WaitArg;
use attsync::processes::ProcessOptions;
use attsync::processes::placement::Placement;
use attsync::run::Engine;
use attsync::scenario::{self, Loaded};
use clap::{Subcommand, ValueEnum};
use std::path::{Path, PathBuf};

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Validate a scenario and print its network.
    Check(check::Check),
    /// Run a scenario and write its results.
    Run(run::Run),
    /// Run a scenario for each value of one field (in parallel), and optionally
    /// bisect for the largest value that still converges.
    Sweep(sweep::Sweep),
    /// Check a plug-in agent program against PROTOCOL.md: attsync plays its
    /// orchestrator, leader and neighbours in lockstep and reports each rule.
    /// Exit code 0 only if every rule passes.
    Conform(conform::Conform),
    /// Convert a run's states.bin (the full state trajectory).
    Export(export::Export),
    /// Generate a scenario.
    Gen(r#gen::GenCmd),
    /// Monte Carlo over initial conditions: N trials from Haar-uniform
    /// attitudes and random rates, each classified; the failure rate with
    /// its exact 95 % bound. `--trial K` reruns one trial alone.
    Mc(mc::Mc),
    /// The delay margin of the closed loop linearised about synchronisation
    /// (schemes 2 and 3): the smallest common link delay at which a
    /// characteristic root crosses the imaginary axis, the crossing
    /// frequency, and the rightmost root at the scenario's own delay (the
    /// decay rate a run should show). docs/verdicts.md.
    Margin(margin::MarginCmd),
    /// Write a run directory's view.html again (the run in 3D, in any
    /// browser, offline) from its scenario.toml, summary.json and states.bin.
    View(view::View),
    /// Check a run against its manifest.json and re-run its scenario: prints
    /// "bit-identical" or the first difference (a changed file; the first
    /// differing sample: time, node, field, both values). Exit code 0 only if
    /// bit-identical, 1 if not, 2 if the run cannot be verified.
    Verify(verify::Verify),
    /// The daemon of one machine of a run across hosts: it accepts runs from
    /// `attsync run --hosts`, starts the nodes placed on it, carries the cut
    /// edges over Zenoh, and cleans up after each run. Runs until SIGTERM.
    Host(host::Host),
}

/// Runs `command`.
pub fn exec(command: Command) -> Result<(), Error> {
    match command {
        Command::Check(a) => check::exec(a),
        Command::Run(a) => run::exec(a, &interrupt()?),
        Command::Sweep(a) => sweep::exec(a, &interrupt()?),
        Command::Conform(a) => conform::exec(a),
        Command::Export(a) => export::exec(a),
        Command::Gen(a) => r#gen::exec(a),
        Command::Mc(a) => mc::exec(a, &interrupt()?),
        Command::Margin(a) => margin::exec(a),
        Command::View(a) => view::exec(a),
        Command::Verify(a) => verify::exec(a, &interrupt()?),
        Command::Host(a) => host::exec(a, &interrupt()?),
    }
}

/// The one handler of SIGINT, SIGTERM and SIGHUP (commands that run
/// scenarios install it; the others keep the default actions).
fn interrupt() -> Result<Interrupt, Error> {
    Interrupt::install().map_err(Error::Signals)
}

/// `--set`, shared by every command that loads a scenario.
#[derive(Debug, Clone, clap::Args)]
pub struct SetArgs {
    /// Override a field of the scenario (of every run of a sweep, of conform's
    /// neighbourhood): key.path=value (repeatable), e.g. simulation.duration=10.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

/// A scenario file and its `--set` overrides.
#[derive(Debug, Clone, clap::Args)]
pub struct ScenarioArgs {
    /// Scenario file (TOML).
    pub scenario: PathBuf,
    #[command(flatten)]
    pub overrides: SetArgs,
}

impl ScenarioArgs {
    /// The scenario with its overrides, validated (`check`: what to do with
    /// a step beyond RK4's stable one, `--no-stiffness-check`).
    pub fn load(&self, check: attsync::scenario::StiffnessCheck) -> Result<Loaded, Error> {
        Ok(scenario::load_with(
            &self.scenario,
            &self.overrides.set,
            check,
        )?)
    }
}

/// `--until` and `--max-duration`, shared by `run`, `sweep` and `mc`.
#[derive(Debug, Clone, clap::Args)]
pub struct UntilArgs {
    /// How long each run goes: `horizon` = the scenario's simulation.duration;
    /// `settled` = extend it (doubling) until the verdict is final —
    /// converged, persistent or diverging, not converging or undecided
    /// (docs/verdicts.md) — at most --max-duration.
    #[arg(long, value_enum, default_value_t = UntilArg::Horizon)]
    pub until: UntilArg,
    /// With --until settled (and sweep --find-margin): the longest horizon, s
    /// [default: 16 × simulation.duration].
    #[arg(long, value_name = "SECONDS")]
    pub max_duration: Option<f64>,
}

/// `--until`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum UntilArg {
    /// The scenario's simulation.duration.
    Horizon,
    /// Until the verdict is final (or --max-duration).
    Settled,
}

impl UntilArgs {
    /// What a run is judged by, for a scenario of `duration` seconds
    /// (`settle`: until settled whatever `--until` says, as `sweep
    /// --find-margin` needs).
    pub fn judging(&self, tolerance: f64, duration: f64, settle: bool) -> attsync::run::Judging {
        use attsync::until::{DEFAULT_MAX_FACTOR, Until};
        let until = match self.until {
            UntilArg::Horizon if !settle => Until::Horizon,
            _ => Until::Settled {
                max_duration: self.max_duration.unwrap_or(DEFAULT_MAX_FACTOR * duration),
            },
        };
        attsync::run::Judging { tolerance, until }
    }
}

/// `--hosts`, shared by `run` and `sweep` (every run of a sweep the same).
#[derive(Debug, Clone, clap::Args)]
pub struct HostsArgs {
    /// Spread the nodes over machines as this placement file says
    /// (HOSTS.toml: [[host]] name, endpoint, agents, leader; docs/hosts.md);
    /// nodes on no host run on this machine. Processes engine.
    #[arg(long, value_name = "HOSTS.toml")]
    pub hosts: Option<PathBuf>,
    /// With --hosts: the lab's CA certificate (PEM), instead of the hosts
    /// file's `[tls] ca`.
    #[arg(long, value_name = "CA.pem", requires = "hosts")]
    pub ca: Option<PathBuf>,
    /// With --hosts: your certificate (PEM), instead of `[tls] cert`.
    #[arg(long, value_name = "CERT.pem", requires = "hosts")]
    pub cert: Option<PathBuf>,
    /// With --hosts: your private key (PEM), instead of `[tls] key`.
    #[arg(long, value_name = "KEY.pem", requires = "hosts")]
    pub key: Option<PathBuf>,
    /// With --hosts: plain TCP, nobody authenticated, nothing encrypted
    /// (warned about; the daemons must be --insecure too).
    #[arg(long, requires = "hosts")]
    pub insecure: bool,
}

impl HostsArgs {
    /// The hosts file, loaded and checked on its own, its security settled
    /// (the flags', else the file's) and its endpoints checked against it
    /// (a bad one: exit 2, before anything else). Warns if insecure.
    pub fn load(&self) -> Result<Option<Hosts>, Error> {
        let Some(path) = self.hosts.as_deref() else {
            return Ok(None);
        };
        let hosts = attsync::hosts::load(path)?;
        let flagged =
            self.ca.is_some() || self.cert.is_some() || self.key.is_some() || self.insecure;
        let given = flagged
            .then(|| {
                let (ca, cert, key) = (self.ca.clone(), self.cert.clone(), self.key.clone());
                attsync::trust::choose(ca, cert, key, self.insecure, attsync::trust::FLAGS)
            })
            .transpose()?;
        let hosts = hosts.secure(given)?;
        if hosts.security == Some(attsync::trust::Security::Insecure) {
            eprintln!("warning: {}", attsync::trust::INSECURE_WARNING);
        }
        Ok(Some(hosts))
    }
}

/// The engine of a run and the process engine's flags.
#[derive(Debug, Clone, clap::Args)]
pub struct EngineArgs {
    /// Engine.
    #[arg(long, value_enum, default_value_t = Engine::Processes)]
    pub engine: Engine,
    /// How node processes wait for their inputs (processes engine).
    #[arg(long, value_enum, default_value_t = WaitArg::Adaptive)]
    pub wait: WaitArg,
    /// Longest wait of a node for one stage's inputs, s (processes engine).
    #[arg(long, default_value_t = 10.0)]
    pub stage_timeout: f64,
    /// Where node processes run (processes engine): auto = spread over the cores, packed onto one while other programs keep the machine busy.
    #[arg(long, value_enum, default_value_t = Placement::Auto)]
    pub placement: Placement,
}

impl EngineArgs {
    /// The process engine's options (`realtime`: the factor, if any).
    pub fn process_options(&self, realtime: Option<f64>) -> ProcessOptions {
        ProcessOptions {
            wait: self.wait.into(),
            stage_timeout: self.stage_timeout,
            realtime,
            placement: self.placement,
            ..ProcessOptions::default()
        }
    }
}

/// Writes `bytes` to `out`, or to stdout.
fn write_output(out: Option<&Path>, bytes: &[u8]) -> Result<(), Error> {
    let written = match out {
        Some(path) => std::fs::write(path, bytes),
        None => std::io::Write::write_all(&mut std::io::stdout(), bytes),
    };
    written.map_err(|source| Error::Write {
        path: out.map_or_else(|| "<stdout>".into(), Path::to_owned),
        source,
    })
}
