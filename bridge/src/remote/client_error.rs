//! [`RemoteError`]: why the orchestrator's side of a run placed over hosts
//! ([`super::Remote`]) could not connect, start, relay or go on.

use thiserror::Error;

/// Why a run placed over hosts cannot start or go on.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RemoteError {
    /// A Zenoh call failed (its text).
    #[error("zenoh: {0}")]
    Zenoh(String),
    /// The Zenoh session could not be configured or opened (its text).
    #[error("{0}")]
    Session(String),
    /// A host did not answer its ping within [`crate::remote::client::REACH_TIMEOUT`].
    #[error(
        "host {name} ({endpoint}) is unreachable: no answer within {seconds} s; is \
         `attsync host --name {name} --listen {endpoint}` running there, and its port open?"
    )]
    Unreachable {
        /// The host.
        name: String,
        /// Its endpoint.
        endpoint: String,
        /// The timeout, s.
        seconds: u64,
    },
    /// A host refused the run or did not answer (why).
    #[error("host {host} could not start its nodes: {why}")]
    NotStarted {
        /// The host.
        host: String,
        /// Its answer, or why there was none.
        why: String,
    },
    /// A host's liveliness token is gone.
    #[error(
        "host {host} was lost (its daemon or the connection to it is gone); its nodes: {}",
        nodes.join(", ")
    )]
    HostLost {
        /// The host.
        host: String,
        /// The names of its nodes.
        nodes: Vec<String>,
    },
    /// A bridge or a telemetry thread of this side failed (its text).
    #[error("{0}")]
    Bridge(String),
    /// A host reported its failure.
    #[error("host {host}: {why}")]
    HostFailed {
        /// The host.
        host: String,
        /// What it reported.
        why: String,
    },
    /// A host sent an event that does not decode.
    #[error("host {host} sent a bad event: {why}")]
    BadEvent {
        /// The host.
        host: String,
        /// The decoding error.
        why: String,
    },
}
