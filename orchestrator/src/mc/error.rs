//! [`McError`]: why a Monte Carlo produced no results (or only some).

use crate::options::OptionError;
use crate::processes::ProcessError;
use crate::processes::capacity::CapacityError;
use crate::run::RunError;
use crate::scenario::ScenarioError;
use std::path::PathBuf;
use thiserror::Error;

/// Why `attsync mc` failed.
#[derive(Debug, Error)]
pub enum McError {
    /// The scenario, a `--set`, or its `[monte_carlo]` table is invalid.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// An option is out of range or does not fit the scenario.
    #[error(transparent)]
    Options(#[from] OptionError),
    /// This machine cannot run the scenario with the chosen engine (nothing started).
    #[error(transparent)]
    Capacity(Box<CapacityError>),
    /// The process engine could not start a trial (nothing is kept).
    #[error("trial {trial}: {source}")]
    Processes {
        /// The trial.
        trial: u64,
        /// Why.
        source: ProcessError,
    },
    /// `--trial K`: the trial's run produced no results.
    #[error(transparent)]
    Run(#[from] RunError),
    /// A file could not be written or read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// `--trial K`: the trial's `states.bin` cannot be read back (the
    /// message names the file).
    #[error(transparent)]
    States(#[from] crate::results::states::StatesError),
    /// Drawing `mc.svg` failed.
    #[error("{}: cannot draw plot: {message}", path.display())]
    Plot {
        /// The plot file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
    /// `attsync mc merge`: the directories are not one Monte Carlo's shards.
    #[error(transparent)]
    Merge(#[from] super::merge::MergeError),
    /// A signal stopped the Monte Carlo (the number); the trials done are kept.
    #[error("{}", crate::interrupt::reason(*.0))]
    Interrupted(i32),
}

impl From<CapacityError> for McError {
    fn from(e: CapacityError) -> Self {
        McError::Capacity(Box::new(e))
    }
}

impl McError {
    /// The process exit code (as [`crate::Error::exit_code`]): 2 for an
    /// invalid input or a refused capacity, 128 + N interrupted, else 1.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            McError::Scenario(_)
            | McError::Options(_)
            | McError::Capacity(_)
            | McError::Merge(_) => crate::exit::INVALID,
            McError::Interrupted(signal) => crate::interrupt::exit_code(*signal),
            McError::Run(e) => e.exit_code(),
            _ => crate::exit::FAILED,
        }
    }
}

/// Maps an I/O error at `path` to an [`McError::Io`].
pub(super) fn io_at(path: &std::path::Path) -> impl FnOnce(std::io::Error) -> McError + '_ {
    move |source| McError::Io {
        path: path.to_owned(),
        source,
    }
}
