//! The benchmark's errors: one enum for every fallible step of
//! `attsync-bench run` and `attsync-bench ring-node`.

use std::path::PathBuf;

/// Why a measurement (or the whole benchmark) failed.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A file or directory could not be read, written or created.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// What the OS said.
        source: std::io::Error,
    },
    /// A program could not be started or waited for.
    #[error("cannot start {program}: {source}")]
    Spawn {
        /// The program.
        program: String,
        /// What the OS said.
        source: std::io::Error,
    },
    /// A program ended unsuccessfully.
    #[error("{program} {outcome}")]
    Failed {
        /// The program (`attsync`, `ring-node 3`, …).
        program: String,
        /// How it ended and the last lines it printed.
        outcome: String,
    },
    /// Something did not happen within its time limit.
    #[error("timed out after {seconds:.1} s {what}")]
    Timeout {
        /// The limit, s.
        seconds: f64,
        /// What was waited for.
        what: String,
    },
    /// A results file lacks what the benchmark reads from it.
    #[error("{}: {what}", path.display())]
    Results {
        /// The file (`summary.json`, a ring-node's report).
        path: PathBuf,
        /// What is wrong with it.
        what: String,
    },
    /// A run did not reach its horizon or did not do every step.
    #[error("incomplete run: {0}")]
    Incomplete(String),
    /// A scenario could not be loaded.
    #[error(transparent)]
    Scenario(#[from] attsync::scenario::ScenarioError),
    /// iceoryx2 refused to create the node or its namespace.
    #[error(transparent)]
    Iox(#[from] msgs::iox::IoxError),
    /// iceoryx2 refused to open a port or to send or receive.
    #[error("{what}: {detail}")]
    Iceoryx {
        /// The port or operation.
        what: String,
        /// iceoryx2's error.
        detail: String,
    },
    /// A bare-lockstep node received a message out of lockstep.
    #[error("{0}")]
    Protocol(String),
    /// An invalid command-line value.
    #[error("{0}")]
    Usage(String),
}

impl BenchError {
    /// An [`BenchError::Io`] error at `path`.
    pub fn io(path: impl Into<PathBuf>) -> impl FnOnce(std::io::Error) -> Self {
        let path = path.into();
        move |source| Self::Io { path, source }
    }

    /// An [`BenchError::Iceoryx`] error of `what`, from iceoryx2's (Debug) error.
    pub fn iox<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> Self {
        move |e| {
            let e = msgs::iox::iox(what)(e);
            Self::Iceoryx {
                what: e.what.to_string(),
                detail: e.detail,
            }
        }
    }

    /// An [`BenchError::Iceoryx`] error of `what`, from an error message.
    pub fn iox_msg<E: std::fmt::Display>(what: &str) -> impl FnOnce(E) -> Self + '_ {
        move |e| Self::Iceoryx {
            what: what.to_string(),
            detail: e.to_string(),
        }
    }
}

/// The benchmark's result type.
pub type Result<T, E = BenchError> = std::result::Result<T, E>;
