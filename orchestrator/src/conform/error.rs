//! Why `attsync conform` could not check a candidate at all (a failing rule
//! is not an error: it is in the [`Report`](super::Report)).

use crate::processes::ProcessError;
use crate::scenario::ScenarioError;
use msgs::config::ConfigError;
use std::path::PathBuf;
use thiserror::Error;

/// The harness itself could not run.
#[derive(Debug, Error)]
pub enum ConformError {
    /// The neighbourhood scenario does not load.
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The candidate's agent id is not in the neighbourhood.
    #[error("agent {agent} is not in the neighbourhood {}", file.display())]
    NotInNeighbourhood {
        /// The id asked for.
        agent: u32,
        /// The neighbourhood's scenario file.
        file: PathBuf,
    },
    /// The run's namespace or the harness's iceoryx2 ports could not be set up.
    #[error(transparent)]
    Ports(#[from] ProcessError),
    /// An iceoryx2 call of the harness failed.
    #[error(transparent)]
    Iceoryx(#[from] msgs::iox::IoxError),
    /// A service the harness plays could not be opened.
    #[error("iceoryx2: {0}")]
    Open(#[from] msgs::open::OpenError),
    /// The candidate's configuration could not be written.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A file or directory of the harness could not be created.
    #[error("{path}: {source}")]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The candidate's program could not be started.
    #[error("cannot start `{command}`: {reason}")]
    Start {
        /// The command, as given.
        command: String,
        /// Why (the OS error).
        reason: String,
    },
}
