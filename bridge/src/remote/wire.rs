//! What the orchestrator and the daemons say to each other besides the
//! payloads (JSON over Zenoh queries and puts).

use super::Side;
use msgs::config::NodeConfig;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// A node placed on a host.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RemoteNode {
    /// `leader`, `agent-<id>`: its log's name.
    pub name: String,
    /// Its configuration; the daemon sets `run` and `iox_root` to its own
    /// namespace's.
    pub config: NodeConfig,
    /// A plug-in's command, environment and directory (on the host), if the
    /// node is one; else the host's `attsync-agent` / `attsync-leader`.
    pub plugin: Option<PluginCommand>,
}

/// A plug-in's command as the daemon starts it (same rules as a local run).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PluginCommand {
    /// Program and arguments (`--config FILE` is appended).
    pub command: Vec<String>,
    /// Extra environment variables.
    pub env: BTreeMap<String, String>,
    /// Working directory.
    pub dir: PathBuf,
}

impl PluginCommand {
    /// The command of plug-in `p`, as a host starts it.
    #[must_use]
    pub fn of(p: &scenario::plugin::Plugin) -> Self {
        Self {
            command: p.command.clone(),
            env: p.env.clone(),
            dir: p.dir.clone(),
        }
    }
}

/// One node's states towards one other side: the receivers there.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct StateLink {
    /// The sender's node id.
    pub from: u32,
    /// Where the sender runs.
    pub from_side: Side,
    /// Where its receivers run.
    pub to_side: Side,
    /// The receivers there, ascending.
    pub receivers: Vec<u32>,
    /// How many steps ahead of its receivers there the sender may run:
    /// the least lookahead of this input among them (its link's delay,
    /// PROTOCOL § 10.9); 0 (lockstep) when absent.
    #[serde(default)]
    pub ahead: u64,
}

/// A run offered to a host (`attsync/host/<name>/run`): the host fetches
/// its [`RunRequest`] from `attsync/<run>/request/<host>` (in pieces: it may
/// exceed a Zenoh batch), starts its nodes, then answers.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct RunOffer {
    /// The orchestrator's run id (Zenoh keys).
    pub run: String,
    /// The host's name.
    pub host: String,
}

/// A run handed to a host, fetched after its [`RunOffer`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct RunRequest {
    /// The orchestrator's run id (Zenoh keys).
    pub run: String,
    /// The host's name.
    pub host: String,
    /// Its nodes.
    pub nodes: Vec<RemoteNode>,
    /// Every state link touching this host.
    pub links: Vec<StateLink>,
    /// The hosts it dials for the run ([`super::mesh`]).
    #[serde(default)]
    pub dial: Vec<Peer>,
}

/// A host another dials for a run: its name and its daemon's endpoint
/// (HOSTS.toml's).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Peer {
    /// Its name.
    pub host: String,
    /// Its daemon's endpoint.
    pub endpoint: String,
}

/// A daemon's answer to a request: accepted, or refused with why (on the
/// wire as serde writes a `Result`: `{"Ok":null}`, `{"Err":"…"}`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum Answer {
    /// Accepted.
    Ok(()),
    /// Refused: why, for a message.
    Err(String),
}

/// Ends a run on a host (`attsync/host/<name>/end`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EndRequest {
    /// The orchestrator's run id.
    pub run: String,
    /// Kill the nodes at once (the run failed), else wait for them to exit
    /// (the run is complete: it implies `Stop`, which the daemon relays
    /// again in case the end overtook it).
    pub kill: bool,
}

/// How a node on a host ended, and its log.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct NodeEnd {
    /// Its node id.
    pub id: u32,
    /// Its exit, described (`exit code 0`, `killed by signal 9 (SIGKILL)`).
    pub status: String,
    /// It exited with code 0.
    pub clean: bool,
    /// The end of its log (stdout and stderr, capped as in a local run):
    /// at most its last [`launch::node_log::TAIL_BYTES`], from a
    /// line's start, so that a host's reply stays bounded.
    pub log: Vec<u8>,
    /// How many bytes of its log before [`Self::log`] stayed on the host.
    pub cut: u64,
}

/// A daemon's reply to [`EndRequest`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EndReply {
    /// Every node of the run on this host.
    pub nodes: Vec<NodeEnd>,
    /// Files of the run still on the host after clean-up (should be none).
    pub leftovers: Vec<String>,
}

/// Something the orchestrator must know at once (`attsync/<run>/events/<host>`).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub enum HostEvent {
    /// A node's process ended.
    Exited {
        /// Its node id.
        id: u32,
        /// Its exit, described.
        status: String,
        /// It exited with code 0.
        clean: bool,
        /// The last lines of its log.
        tail: String,
    },
    /// The host cannot go on with the run (a bridge failed, its orchestrator is gone…).
    Failed(String),
}
