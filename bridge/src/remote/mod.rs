//! A run across hosts, over Zenoh: the daemon of each machine
//! (`attsync host`, [`daemon`]), the orchestrator's side of a run placed
//! over hosts ([`Remote`]), and, on both, the bridge of the cut edges
//! ([`bridge`]) and of telemetry ([`telemetry`]) on credit-windowed links
//! ([`link`]). Within a machine nodes keep talking over iceoryx2; only cut
//! edges cross, through one Zenoh session per machine.
//!
//! # Layout
//! - [`keys`]: every Zenoh key; [`wire`]: requests, replies, events (JSON).
//! - [`zconfig`]: the explicit Zenoh configuration (peer, endpoints, no
//!   scouting, the low-latency transport).
//! - [`pieces`]: payloads larger than one Zenoh batch, as replies in pieces.
//! - [`link`]: a lossless, ordered, bounded stream (data + acknowledgements).
//! - [`trunk`]: every cut edge between two sides on one key, bundled, a
//!   window per edge, acknowledgements batched.
//! - [`local`]: a run's namespace on one side, the stop flag and first failure.
//! - [`bridge`], [`telemetry`]: the threads that carry states and telemetry.
//! - [`plan`]: which host runs which node; the state links between sides.
//! - [`mesh`]: the links between hosts the orchestrator wires for a run.
//! - [`client`]: the orchestrator's side ([`Remote`]; its errors [`RemoteError`]).
//! - [`daemon`], [`host_run`]: the host's side; [`report`]: what it says
//!   on its stdout.

pub mod bridge;
mod bridge_error;
pub mod client;
mod client_error;
pub mod daemon;
pub mod host_run;
mod host_run_error;
pub mod keys;
pub mod link;
pub mod local;
pub mod mesh;
pub mod pieces;
pub mod plan;
pub mod report;
pub mod telemetry;
pub mod trunk;
pub mod wire;
pub mod zconfig;

pub use client::Remote;
pub use client_error::RemoteError;
pub use plan::{Plan, PlannedHost};

use serde::{Deserialize, Serialize};
use std::fmt;

/// Where a node runs: the orchestrator's machine or a named host.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Side {
    /// The machine `attsync run` runs on.
    Orchestrator,
    /// A host of HOSTS.toml, by name.
    Host(String),
}

impl Side {
    /// Its chunk in Zenoh keys: `orchestrator`, `host-<name>`.
    #[must_use]
    pub fn key(&self) -> String {
        match self {
            Self::Orchestrator => "orchestrator".into(),
            Self::Host(h) => format!("host-{h}"),
        }
    }
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Orchestrator => f.write_str("the orchestrator's machine"),
            Self::Host(h) => write!(f, "host {h}"),
        }
    }
}
