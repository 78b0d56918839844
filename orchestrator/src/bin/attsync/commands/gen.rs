//! `attsync gen`: generated scenarios.

use attsync::Error;
use attsync::generate::{TreeParams, WriteError, tree, write_file};
use attsync::options::OptionError;
use attsync::scenario::schema::SchemeKind;
use clap::{Subcommand, ValueEnum};
use std::path::PathBuf;

/// `attsync gen WHAT`.
#[derive(Debug, clap::Args)]
pub struct GenCmd {
    #[command(subcommand)]
    pub what: Gen,
}

/// What to generate.
#[derive(Debug, Subcommand)]
pub enum Gen {
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
        /// Horizon, s (default: 40 s, or longer as the slowest linear mode
        /// needs to converge; docs/stiffness.md).
        #[arg(long)]
        duration: Option<f64>,
        /// Write here instead of stdout.
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// `--scheme`.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum SchemeArg {
    ObserverTimeVarying,
    ObserverConstant,
    Observerless,
}

impl From<SchemeArg> for SchemeKind {
    fn from(s: SchemeArg) -> Self {
        match s {
            SchemeArg::ObserverTimeVarying => SchemeKind::ObserverTimeVarying,
            SchemeArg::ObserverConstant => SchemeKind::ObserverConstant,
            SchemeArg::Observerless => SchemeKind::Observerless,
        }
    }
}

/// Writes the scenario, headed by the command line that reproduces it
/// (streamed; into `--out` atomically).
pub fn exec(a: GenCmd) -> Result<(), Error> {
    let Gen::Tree {
        agents,
        leader_links,
        seed,
        scheme,
        duration,
        out,
    } = a.what;
    let p = TreeParams {
        agents,
        leader_links,
        seed,
        scheme: scheme.into(),
        duration,
    };
    p.check()?;
    // What `tree` refuses is the arguments (a duration `check` would
    // refuse, a tree too large for any horizon): invalid input, exit 2.
    let g = tree(&p).map_err(|e| Error::Options(OptionError::Conflict(e.to_string())))?;
    if let Some(w) = &g.warning {
        eprintln!("warning: {w}");
    }
    write_file(&p, &g, out.as_deref()).map_err(|e| match e {
        WriteError::Io { path, source } => Error::Write { path, source },
        e => Error::Generate(e.to_string()),
    })
}
