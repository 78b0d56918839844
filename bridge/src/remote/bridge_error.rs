//! [`BridgeError`]: why a bridge thread of a run's cut edges, or of a
//! host's telemetry, stopped
//! (the run's failure then names the bridge: [`super::local::Shared::fail`]).

use super::link::LinkError;
use msgs::bytes::WrongSize;
use msgs::iox::IoxError;
use msgs::open::OpenError;
use thiserror::Error;

/// Why a bridge thread stopped.
#[derive(Debug, Error)]
pub enum BridgeError {
    /// An iceoryx2 node or port could not be created, or a send failed.
    #[error(transparent)]
    Iceoryx(#[from] IoxError),
    /// A state or wake service could not be opened.
    #[error(transparent)]
    Open(#[from] OpenError),
    /// The Zenoh link failed.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// A message off the link is not a state.
    #[error(transparent)]
    Decode(#[from] WrongSize),
    /// A state subscriber could not receive (iceoryx2's error, debug-printed).
    #[error("{0}")]
    Receive(String),
    /// The wait set could not be created or attached to.
    #[error("iceoryx2 waitset: {0}")]
    WaitSet(String),
    /// A state subscriber could not connect to its publisher.
    #[error("bridge state subscriber: {0}")]
    Connect(String),
    /// A frame off a host's telemetry link does not decode.
    #[error(transparent)]
    Frame(#[from] super::telemetry::FrameError),
    /// Telemetry came for a node the host does not run.
    #[error("telemetry of node {0}, which is not placed on it")]
    NotPlaced(u32),
    /// A state reached only some of its receivers here (lockstep cannot lose one).
    #[error("step {step} stage {stage} reached {got} of its {want} receivers here")]
    Partial {
        /// The state's step.
        step: u64,
        /// Its stage.
        stage: u32,
        /// The receivers it reached.
        got: usize,
        /// The receivers it had to reach.
        want: usize,
    },
    /// A state reached none of its receivers within the stage timeout.
    #[error("step {step} stage {stage} reached none of its receivers here in {seconds:.1} s")]
    Undelivered {
        /// The state's step.
        step: u64,
        /// Its stage.
        stage: u32,
        /// The stage timeout, s.
        seconds: f64,
    },
}

/// Debug text of an iceoryx2 error (its errors print nothing else).
pub(super) fn debug(e: impl std::fmt::Debug) -> String {
    format!("{e:?}")
}
