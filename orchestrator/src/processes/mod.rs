//! The process-per-agent engine: the leader and every agent run as their own
//! OS processes (`attsync-leader`, `attsync-agent`), exchanging states over
//! iceoryx2 in lockstep; the orchestrator supervises them, collects their
//! telemetry into the same snapshots the in-process engine produces, and
//! removes everything the run created.
//!
//! [`run`] is a short sequence of phases, each in its own file: open the
//! ports and start the nodes (`startup`), wait until every node is ready
//! and send `Start` (also `startup`), collect telemetry into snapshots
//! (`collect`), name the node to blame if the run failed (`blame`), and
//! stop or kill the nodes (`shutdown`).
//!
//! # Layout
//! - `configs`: each node's configuration and its name in messages.
//! - [`ports`]: the orchestrator's iceoryx2 ports of a run ([`Ports`]), also used by `conform`.
//! - `startup`: spawning the nodes, the wait for `Ready`, `Start`.
//! - `collect`: per-node bookkeeping (one `NodeSlot` per node), telemetry into snapshots.
//! - `blame`: which node made the run fail, and why.
//! - `restart`: an agent's crashed process replaced by a new one.
//! - `shutdown`: `Stop` and the exits, or killing every node.
//! - [`crate::launch`]: a node's process, its log and the run's namespace.
//! - [`placement`]: spread the nodes over the cores, or pack them onto one
//!   while the machine is busy (`load`: the CPU load it decides on).
//! - [`capacity`]: how many nodes this machine can run, checked before anything starts.

mod blame;
pub mod capacity;
mod collect;
mod configs;
mod load;
pub mod partition;
pub mod placement;
pub mod ports;
pub mod reaper;
mod restart;
mod shutdown;
pub mod site;
mod startup;

pub use configs::node_configs;
pub use ports::Ports;

use crate::launch::supervise::Supervisor;
use crate::outcome::Outcome;
use crate::scenario::plugin::Plugin;
use attitude::engine::Snapshot;
use attitude::network::Network;
use collect::Collector;
use msgs::config::WaitStrategy;
use msgs::iox::IoxError;
use msgs::open::OpenError;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use thiserror::Error;

/// Options of the process engine.
#[derive(Debug, Clone)]
pub struct ProcessOptions {
    /// How nodes wait for their inputs.
    pub wait: WaitStrategy,
    /// Longest wait of a node for one stage's inputs, s.
    pub stage_timeout: f64,
    /// Longest wait for connections and commands, s.
    pub start_timeout: f64,
    /// Real-time mode: simulated seconds per wall second (`None`: lockstep).
    pub realtime: Option<f64>,
    /// Agents run by the user's own programs.
    pub plugins: Vec<Plugin>,
    /// Where the node processes run ([`placement::Placement`]).
    pub placement: placement::Placement,
    /// Where nodes run other than here (`run --hosts`: the hosts' plan), if
    /// anywhere.
    pub hosts: Option<std::sync::Arc<dyn site::Elsewhere>>,
}

impl Default for ProcessOptions {
    fn default() -> Self {
        Self {
            wait: WaitStrategy::Adaptive,
            stage_timeout: 10.0,
            start_timeout: 30.0,
            realtime: None,
            plugins: Vec::new(),
            placement: placement::Placement::Auto,
            hosts: None,
        }
    }
}

/// The engine could not start.
#[derive(Debug, Error)]
pub enum ProcessError {
    /// A node binary is missing.
    #[error(transparent)]
    MissingBinary(#[from] crate::launch::supervise::MissingBinaries),
    /// An iceoryx2 call failed.
    #[error(transparent)]
    Iceoryx(#[from] IoxError),
    /// A service of the run could not be opened.
    #[error("iceoryx2: {0}")]
    Open(#[from] OpenError),
    /// A host of the run cannot be reached or used.
    #[error(transparent)]
    Remote(#[from] crate::failure::RemoteError),
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// Maps an I/O error at `path` to a [`ProcessError`].
pub(crate) fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> ProcessError + use<> {
    let path = path.to_owned();
    move |source| ProcessError::Io { path, source }
}

/// A run in progress: what every phase works on.
struct Session<'a> {
    net: &'a Network,
    opts: &'a ProcessOptions,
    logs: &'a Path,
    interrupt: &'a AtomicBool,
    /// `attsync-agent` and `attsync-leader`.
    binaries: (PathBuf, PathBuf),
    /// Where nodes run other than here (dropped before the ports: their
    /// bridges use the namespace).
    sites: Vec<Box<dyn site::Site>>,
    /// Dropped before the supervisor: the namespace goes first, as it always did.
    ports: Ports,
    sup: Supervisor,
    nodes: Collector,
}

/// Runs `net` as processes. `logs` receives one log file per node.
/// `on_sample` gets every snapshot in step order (return `false` to stop).
/// Failures after start-up (a node dies, a timeout, `interrupt`) end the run
/// early with [`Outcome::failure`] set; everything is cleaned up in all cases.
pub fn run(
    net: &Network,
    opts: &ProcessOptions,
    logs: &Path,
    interrupt: &AtomicBool,
    mut on_sample: impl FnMut(&Snapshot<'_>) -> bool,
) -> Result<Outcome, ProcessError> {
    // Declared first, dropped last (after the session's supervisor): kills
    // whatever a plug-in left behind outside its process group.
    let _reaper = reaper::Reaper::start();
    let mut s = Session::open(net, opts, logs, interrupt)?;
    tracing::debug!(
        nodes = net.agents.len() + 1,
        "processes: ports open, spawning"
    );
    s.spawn_nodes()?;
    let sites_started = s.start_sites();
    let graph = local_graph(net, s.sup.indices());
    let placer = placement::Placer::start(opts.placement, s.sup.pids().to_vec(), &graph);
    tracing::debug!("processes: spawned, waiting for Ready");
    let failure = sites_started
        .and_then(|()| s.await_ready())
        .and_then(|()| {
            tracing::debug!("processes: all ready, Start");
            s.start()
        })
        .and_then(|()| s.collect(&mut on_sample))
        .err()
        .map(|f| s.blame(f));
    drop(placer);
    tracing::debug!(failure = ?failure, "processes: stepping over, shutting down");
    let failure = s.shutdown(failure);
    tracing::debug!("processes: shut down, namespace removed");
    Ok(s.nodes.outcome(failure))
}

/// The graph of the nodes started here, `indices[k]` being node `k`'s index
/// (0 the leader, `i + 1` agent `net.agents[i]`): for each, the positions in
/// `indices` of its neighbours and, for the leader, of the agents it leads.
fn local_graph(net: &Network, indices: &[usize]) -> Vec<Vec<usize>> {
    let index_of_id: std::collections::HashMap<u32, usize> = (net.agents.iter().enumerate())
        .map(|(i, a)| (a.model.id, i + 1))
        .collect();
    let mut position = vec![usize::MAX; net.agents.len() + 1];
    for (k, &i) in indices.iter().enumerate() {
        position[i] = k;
    }
    let mut adj = vec![Vec::new(); indices.len()];
    let mut link = |a: usize, b: usize| {
        if position[a] != usize::MAX && position[b] != usize::MAX {
            adj[position[a]].push(position[b]);
        }
    };
    for (i, a) in net.agents.iter().enumerate() {
        for n in &a.model.neighbours {
            if let Some(&j) = index_of_id.get(&n.id) {
                link(i + 1, j);
                link(j, i + 1);
            }
        }
        if a.model.leader_gain.is_some() {
            link(i + 1, 0);
            link(0, i + 1);
        }
    }
    for ws in &mut adj {
        ws.sort_unstable();
        ws.dedup();
    }
    adj
}
