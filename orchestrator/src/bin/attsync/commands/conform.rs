//! `attsync conform`: a plug-in agent program against PROTOCOL.md.

use super::SetArgs;
use attsync::Error;
use attsync::conform::{self, ConformOptions, LawMode};
use attsync::options::OptionError;
use std::path::PathBuf;

/// `attsync conform [--scenario F] [--agent ID] [--set K=V]… -- COMMAND…`.
#[derive(Debug, clap::Args)]
pub struct Conform {
    /// Neighbourhood scenario [default: built-in: agent 2 between agents 1
    /// and 3, hearing the leader, observerless scheme, 0.2 s].
    #[arg(long)]
    pub scenario: Option<PathBuf>,
    /// The candidate's agent id in the neighbourhood.
    #[arg(long, default_value_t = 2)]
    pub agent: u32,
    #[command(flatten)]
    pub overrides: SetArgs,
    /// Longest wait for one of the candidate's states, s.
    #[arg(long, default_value_t = 5.0)]
    pub stage_timeout: f64,
    /// Longest wait for the candidate to connect, s.
    #[arg(long, default_value_t = 20.0)]
    pub start_timeout: f64,
    /// Whose law the `law` rule holds the candidate to: `builtin` (a
    /// deviation from the built-in law of the scheme fails) or `own` (a
    /// deliberately different controller: the deviation is reported as INFO).
    #[arg(long, value_enum, default_value_t = LawArg::Builtin)]
    pub law: LawArg,
    /// Where the candidate's output goes [default: a file in the temp directory].
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Not accepted: conform runs one candidate on this machine only, against
    /// a neighbourhood in attsync's own process (exit 2).
    #[arg(long, value_name = "HOSTS.toml")]
    pub hosts: Option<PathBuf>,
    /// The candidate program and its arguments (after `--`).
    #[arg(last = true, required = true, value_name = "COMMAND")]
    pub command: Vec<String>,
}

/// `--law`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum LawArg {
    /// The built-in law of the configured scheme.
    Builtin,
    /// The candidate's own law (deviations are INFO).
    Own,
}

/// Checks the candidate and prints one verdict per rule; fails unless every
/// rule passes.
pub fn exec(a: Conform) -> Result<(), Error> {
    if a.hosts.is_some() {
        return Err(OptionError::Conflict(
            "--hosts: conform runs one candidate on this machine only (its neighbourhood runs in \
             attsync's own process); run it on the machine the candidate will run on"
                .into(),
        )
        .into());
    }
    let log = a.log.unwrap_or_else(|| {
        std::env::temp_dir().join(format!("attsync-conform-{}.log", std::process::id()))
    });
    let opts = ConformOptions {
        command: a.command,
        scenario: a.scenario,
        set: a.overrides.set,
        agent: a.agent,
        stage_timeout: a.stage_timeout,
        start_timeout: a.start_timeout,
        log,
        law: match a.law {
            LawArg::Builtin => LawMode::Builtin,
            LawArg::Own => LawMode::Own,
        },
    };
    opts.check()?;
    let loaded = conform::neighbourhood(&opts)?;
    let net = &loaded.resolved.network;
    attsync::options::node_index(net, opts.agent, "--agent", false, &loaded.file)?;
    let report = conform::conform(&opts).map_err(|e| Error::Conform(e.into()))?;
    println!("{}", report.table());
    if report.passed() {
        Ok(())
    } else {
        Err(Error::NotConforming)
    }
}
