//! `attsync conform -- <command…>`: runs a candidate agent program against a
//! scripted neighbourhood (attsync plays the orchestrator, the leader and
//! the candidate's neighbours, in lockstep) and checks it against each rule
//! of PROTOCOL.md, with the reason for every failure.
//!
//! The neighbourhood is a scenario (by default [`NEIGHBOURHOOD`]: agent 2
//! between agents 1 and 3, hearing the leader); every node but the
//! candidate runs in-process on attsync's own model, fed with what the
//! candidate publishes, so the candidate is exercised in a real closed loop.
//! Rule `law` ([`replay`]) then replays the inputs it was given through
//! attsync's own agent and compares the states it published.

mod candidate;
mod error;
mod harness;
mod law;
mod lockstep;
mod neighbourhood;
mod probe;
mod rules;
mod telemetry_check;
mod wires;

pub use error::ConformError;
pub use law::{At, Deviation, ExchangeRecord, LawError, LawRecord, Quantity, TOLERANCE, replay};
pub use rules::{Report, Rule, RuleId, Verdict};

use crate::scenario::{self, Loaded};
use std::path::PathBuf;

/// The built-in neighbourhood.
pub const NEIGHBOURHOOD: &str = include_str!("neighbourhood.toml");

/// What to check and how.
#[derive(Debug, Clone)]
pub struct ConformOptions {
    /// The candidate: program and arguments (`--config FILE` is appended).
    pub command: Vec<String>,
    /// Neighbourhood scenario (`None`: [`NEIGHBOURHOOD`]).
    pub scenario: Option<PathBuf>,
    /// `--set` overrides of the neighbourhood.
    pub set: Vec<String>,
    /// The candidate's agent id in the neighbourhood.
    pub agent: u32,
    /// Longest wait for one of the candidate's messages, s.
    pub stage_timeout: f64,
    /// Longest wait for the candidate to connect, s.
    pub start_timeout: f64,
    /// Where the candidate's output goes.
    pub log: PathBuf,
    /// What a departure from the built-in law is (rule `law`).
    pub law: LawMode,
}

impl ConformOptions {
    /// `conform`'s `--stage-timeout` and `--start-timeout` (durations).
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn check(&self) -> Result<(), crate::options::OptionError> {
        crate::options::seconds("--stage-timeout", self.stage_timeout)?;
        crate::options::seconds("--start-timeout", self.start_timeout)
    }
}

/// How rule `law` judges a candidate whose published states depart from
/// the built-in law of its scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LawMode {
    /// It must run the built-in law: a departure fails.
    #[default]
    Builtin,
    /// It runs its own controller on purpose (e.g. `examples/saturated_agent`):
    /// the departure is reported for information only.
    Own,
}

/// The neighbourhood of `opts`.
pub fn neighbourhood(opts: &ConformOptions) -> Result<Loaded, scenario::ScenarioError> {
    match &opts.scenario {
        Some(file) => scenario::load(file, &opts.set),
        None => scenario::load_str(
            std::path::Path::new("<built-in conform neighbourhood>"),
            NEIGHBOURHOOD,
            &opts.set,
        ),
    }
}

/// Runs every check; errors only if the harness itself cannot run.
pub fn conform(opts: &ConformOptions) -> Result<Report, ConformError> {
    let loaded = neighbourhood(opts)?;
    let net = &loaded.resolved.network;
    let Some(index) = net.index_of(opts.agent) else {
        return Err(ConformError::NotInNeighbourhood {
            agent: opts.agent,
            file: loaded.file.clone(),
        });
    };
    let mut report = Report::new(opts.log.clone());
    probe::version_probe(net, index, opts, &mut report)?;
    harness::session(net, index, opts, &mut report)?;
    Ok(report)
}
