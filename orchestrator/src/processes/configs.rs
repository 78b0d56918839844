//! What each node of a run is told: its configuration (`node-<id>.json`)
//! and its name in logs and messages.

use super::ProcessOptions;
use crate::scenario::plugin::Plugin;
use attitude::network::Network;
use msgs::config::{NodeConfig, Role};
use msgs::{Limits, PROTOCOL_VERSION};
use std::path::Path;

/// Node names: `leader`, `agent-<id>`.
pub(super) fn node_name(net: &Network, index: usize) -> String {
    if index == 0 {
        "leader".into()
    } else {
        format!("agent-{}", net.agents[index - 1].model.id)
    }
}

/// Node id of node index `index` (0 = the leader, then agents in network order).
pub(super) fn node_id(net: &Network, index: usize) -> u32 {
    if index == 0 {
        0
    } else {
        net.agents[index - 1].model.id
    }
}

/// Node names for messages: a plug-in's name says so, with its command.
pub(super) fn node_label(net: &Network, plugins: &[Plugin], index: usize) -> String {
    let name = node_name(net, index);
    match plugin_of(net, plugins, index) {
        Some(p) => format!("{name} (plug-in `{}`)", p.display()),
        None => name,
    }
}

/// The plug-in that runs node index `index`, if one does.
pub(super) fn plugin_of<'a>(
    net: &Network,
    plugins: &'a [Plugin],
    index: usize,
) -> Option<&'a Plugin> {
    let id = (index > 0).then(|| net.agents[index - 1].model.id)?;
    plugins.iter().find(|p| p.agent == id)
}

/// How much longer than the orchestrator a node waits for connections and
/// `Start`, s. The orchestrator starts its own wait only once every node is
/// spawned, so with equal timeouts the first node spawned gave up first —
/// and the run blamed it, a node left waiting, instead of the silent node
/// the orchestrator names when its own timeout ends (it sees every node).
pub const NODE_START_GRACE: f64 = 5.0;

/// The agents that read each agent's state, ascending: those that count it
/// among their neighbours (its own neighbours on an undirected graph; with
/// one-way edges, only its edges' receivers).
fn readers(net: &Network) -> std::collections::HashMap<u32, Vec<u32>> {
    let mut by: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::new();
    for a in &net.agents {
        for n in &a.model.neighbours {
            by.entry(n.id).or_default().push(a.model.id);
        }
    }
    for ids in by.values_mut() {
        ids.sort_unstable();
    }
    by
}

/// The per-node configurations of `net`.
#[must_use]
pub fn node_configs(
    net: &Network,
    run: &str,
    root: &Path,
    opts: &ProcessOptions,
) -> Vec<NodeConfig> {
    let limits = Limits::of(net);
    let linked: Vec<u32> = net
        .agents
        .iter()
        .filter(|a| a.model.leader_gain.is_some())
        .map(|a| a.model.id)
        .collect();
    let contention = super::placement::contention(opts.placement);
    let base = |id: u32, inputs: Vec<u32>, outputs: Vec<u32>, role: Role| NodeConfig {
        protocol_version: PROTOCOL_VERSION,
        run: run.to_string(),
        iox_root: root.to_string_lossy().into_owned(),
        id,
        dt: net.dt,
        steps: net.steps,
        coupling: net.coupling,
        sample_every: net.sample_every,
        inputs,
        outputs,
        limits,
        wait: opts.wait,
        stage_timeout: opts.stage_timeout,
        start_timeout: opts.start_timeout + NODE_START_GRACE,
        realtime: opts.realtime,
        guard: net.guard,
        contention,
        role,
        resume: None,
    };
    let mut out = vec![base(
        0,
        Vec::new(),
        linked,
        Role::Leader {
            p: net.p,
            initial: net.leader,
            repoint: net.repoint.clone(),
        },
    )];
    let readers = readers(net);
    for a in &net.agents {
        let mut inputs: Vec<u32> = a.model.neighbours.iter().map(|n| n.id).collect();
        if a.model.leader_gain.is_some() {
            inputs.push(0);
        }
        let outputs = readers.get(&a.model.id).cloned().unwrap_or_default();
        out.push(base(
            a.model.id,
            inputs,
            outputs,
            Role::Agent {
                model: Box::new(a.model.clone()),
                initial: a.initial,
            },
        ));
    }
    out
}
