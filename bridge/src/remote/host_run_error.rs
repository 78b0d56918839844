//! Why a host refuses a run request ([`RequestError`]) or cannot start the
//! nodes of one it admitted ([`StartError`]); the orchestrator gets the text.

use crate::trust::allow::AdmitError;
use launch::supervise::MissingBinaries;
use msgs::iox::IoxError;
use msgs::open::OpenError;
use std::path::PathBuf;
use thiserror::Error;

/// Why a host refuses a run request (nothing has started).
#[derive(Debug, Error)]
pub enum RequestError {
    /// The request could not be fetched from the orchestrator (Zenoh's text).
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// Its pieces did not come, or do not make a payload.
    #[error("its request: {0}")]
    Pieces(#[from] super::pieces::CollectError),
    /// It is not a run request's JSON.
    #[error("a bad request: {0}")]
    Json(#[from] serde_json::Error),
    /// It is for another run or another host than offered.
    #[error("the request of run {offered_run} for {offered_host} came for run {run} on {host}")]
    Mismatch {
        /// The run offered.
        offered_run: String,
        /// The host offered.
        offered_host: String,
        /// The run of the request.
        run: String,
        /// The host of the request.
        host: String,
    },
    /// One of its nodes cannot be started here.
    #[error("a bad request: node {node}: {why}")]
    BadNode {
        /// The node's name.
        node: String,
        /// What is wrong with it.
        why: String,
    },
    /// The allowlist refuses a node's plug-in command.
    #[error("host {host} refuses {node}'s plug-in command {command:?}: {reason}")]
    Refused {
        /// This host.
        host: String,
        /// The node.
        node: String,
        /// Its command.
        command: Vec<String>,
        /// Why.
        reason: AdmitError,
    },
}

/// Why a host cannot start the nodes of a run it admitted.
#[derive(Debug, Error)]
pub enum StartError {
    /// The node binaries are missing.
    #[error(transparent)]
    Binaries(#[from] MissingBinaries),
    /// The run's namespace could not be created.
    #[error("namespace: {0}")]
    Namespace(std::io::Error),
    /// A file or directory could not be written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The request has no nodes.
    #[error("a run without nodes")]
    NoNodes,
    /// An iceoryx2 call failed.
    #[error(transparent)]
    Iceoryx(#[from] IoxError),
    /// The run's control service could not be opened.
    #[error(transparent)]
    Open(#[from] OpenError),
    /// The supervisor's runtime could not start.
    #[error("tokio runtime: {0}")]
    Runtime(std::io::Error),
    /// A peer the run needs could not be reached.
    #[error(transparent)]
    Mesh(#[from] super::mesh::MeshError),
}
