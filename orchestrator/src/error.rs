//! [`enum@Error`]: every way a command of `attsync` can fail, and the exit code
//! of each ([`Error::exit_code`]):
//!
//! The codes are [`crate::exit`]'s table.
//!
//! Each error type decides its own code with an `exit_code()`
//! ([`RunError::exit_code`], [`RunEnd::exit_code`], [`SweepError::exit_code`],
//! [`crate::mc::McError::exit_code`], [`crate::failure::Failure::exit_code`]…);
//! [`Error::exit_code`] only asks the one it wraps.
//!
//! `attsync verify` ([`crate::verify`]): 0 bit-identical, 1 different (or the
//! re-run failed), 2 a missing or bad manifest or a run that cannot be verified.

use crate::options::OptionError;
use crate::run::{RunEnd, RunError};
use crate::scenario::ScenarioError;
use crate::sweep::SweepError;
use std::path::PathBuf;
use thiserror::Error;

/// Why a command failed.
#[derive(Debug, Error)]
pub enum Error {
    /// The scenario, or a `--set`, is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The hosts file (`--hosts`) is invalid or does not fit the scenario.
    #[error(transparent)]
    Hosts(#[from] crate::hosts::HostsError),
    /// An option is out of range or does not fit the scenario.
    #[error(transparent)]
    Options(#[from] OptionError),
    /// A run could not produce results.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A run wrote its results but did not complete.
    #[error(transparent)]
    RunEnd(#[from] RunEnd),
    /// A sweep produced no results.
    #[error(transparent)]
    Sweep(#[from] SweepError),
    /// The conformance harness could not run.
    #[error("{0}")]
    Conform(Box<dyn std::error::Error + Send + Sync>),
    /// The candidate program failed at least one rule of PROTOCOL.md.
    #[error("the candidate does not conform to PROTOCOL.md (see the table)")]
    NotConforming,
    /// A states.bin file could not be exported.
    #[error("{0}")]
    Export(String),
    /// A scenario could not be generated.
    #[error("{0}")]
    Generate(String),
    /// Writing an output file failed.
    #[error("writing {path}: {source}")]
    Write {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// A Monte Carlo produced no results (or was interrupted).
    #[error(transparent)]
    Mc(#[from] crate::mc::McError),
    /// `attsync verify` could not verify a run ([`crate::verify::VerifyError::exit_code`]).
    #[error(transparent)]
    Verify(#[from] crate::verify::VerifyError),
    /// `attsync verify`: the files or the re-run differ from the record (the report says where).
    #[error("the run does not reproduce bit for bit (the report above says where)")]
    NotIdentical,
    /// The signal handler could not be installed.
    #[error("installing the signal handler: {0}")]
    Signals(std::io::Error),
    /// Security flags that cannot be used (`--ca`, `--cert`, `--key`,
    /// `--insecure`, `--allow-plugin`, `--gen-certs`).
    #[error(transparent)]
    Trust(#[from] crate::trust::TrustError),
    /// `attsync host` could not start or serve.
    #[error("attsync host: {0}")]
    Host(#[from] crate::remote::daemon::HostError),
    /// A run directory's `view.html` could not be made (`attsync view`).
    #[error(transparent)]
    View(#[from] crate::view::ViewError),
    /// `attsync margin`: the scenario cannot be linearised.
    #[error(transparent)]
    Margin(#[from] crate::margin::MarginError),
}

impl Error {
    /// The process exit code for this error (see the module's table).
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Scenario(_) | Error::Hosts(_) | Error::Options(_) | Error::Margin(_) => {
                crate::exit::INVALID
            }
            Error::Run(e) => e.exit_code(),
            Error::RunEnd(e) => e.exit_code(),
            Error::Verify(e) => e.exit_code(),
            Error::Sweep(e) => e.exit_code(),
            Error::Mc(e) => e.exit_code(),
            Error::Host(e) => crate::exit::invalid_if(e.is_invalid()),
            Error::Trust(e) => crate::exit::invalid_if(e.is_invalid()),
            _ => crate::exit::FAILED,
        }
    }

    /// Whether the message is printed as it is (a scenario's or a hosts
    /// file's lines already read `FILE: FIELD: REASON`), not after `error: `.
    #[must_use]
    pub fn is_scenario(&self) -> bool {
        matches!(
            self,
            Error::Scenario(_)
                | Error::Margin(_)
                | Error::Hosts(_)
                | Error::Run(RunError::Hosts(_))
                | Error::Sweep(SweepError::Scenario(_))
                | Error::Mc(crate::mc::McError::Scenario(_))
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exit_codes() {
        let opt = || OptionError::Conflict("x".into());
        assert_eq!(Error::from(opt()).exit_code(), 2);
        assert_eq!(Error::from(RunError::Options(opt())).exit_code(), 2);
        assert_eq!(Error::from(SweepError::Options(opt())).exit_code(), 2);
        assert_eq!(Error::from(RunEnd::Interrupted(15)).exit_code(), 143);
        assert_eq!(Error::from(RunEnd::Interrupted(1)).exit_code(), 129);
        assert_eq!(Error::from(SweepError::Interrupted(2)).exit_code(), 130);
        let died = crate::failure::Failure::Recorded("node died".into());
        assert_eq!(Error::from(RunEnd::Failed(died)).exit_code(), 1);
        let capacity = crate::processes::capacity::CapacityError {
            engine: "processes",
            nodes: 5001,
            limit: "the open-file limit".into(),
            need: "50 064 open files".into(),
            have: "is 64".into(),
            advice: "raise it".into(),
        };
        assert_eq!(Error::from(RunError::from(capacity)).exit_code(), 2);
        assert_eq!(Error::NotConforming.exit_code(), 1);
        let diverged = crate::failure::Failure::Diverged(Some("diverged at t = 0.01 s: …".into()));
        let diverged = RunEnd::Diverged(diverged);
        assert_eq!(Error::from(diverged).exit_code(), 3);
        assert_eq!(Error::Export("bad file".into()).exit_code(), 1);
        let run = SweepError::Run {
            param: "network.delay".into(),
            value: "1".into(),
            source: RunError::Plot {
                path: "x.svg".into(),
                message: "m".into(),
            },
        };
        assert_eq!(Error::from(run).exit_code(), 1);
    }
}
