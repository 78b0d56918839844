//! [`Placement`]: a hosts file checked against a scenario's network — the
//! nodes of each host, the nodes left on the orchestrator's machine, and
//! the cut edges (links whose two ends run on different machines).
//!
//! Node ids are the process engine's (`attsync/<run>/node/<id>/…`): 0 is the
//! leader, an agent's is its `[[agent]] id`. Links are directed as the
//! process engine wires inputs (`processes::node_configs`): the leader to
//! every agent with `Ξᵢ = 1` (eq. `7a`'s leader term), and each follower
//! edge both ways (`A_{i,j} = A_{j,i}`).

use super::{Host, Hosts, HostsError};
use attitude::network::Network;
use scenario::Issue;
use std::collections::HashMap;

/// The leader's node id.
pub const LEADER: u32 = 0;

/// A directed link between two machines: `from`'s state is an input of `to`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CutEdge {
    /// The sender's node id (0: the leader).
    pub from: u32,
    /// The receiver's node id.
    pub to: u32,
    /// The sender's host (index into [`Placement::hosts`]; `None`: local).
    pub from_host: Option<usize>,
    /// The receiver's host (`None`: local).
    pub to_host: Option<usize>,
}

/// Which machine runs each node of one network.
#[derive(Debug, Clone)]
pub struct Placement {
    hosts: Vec<Host>,
    /// Node id → host index, for the placed nodes only.
    host_of: HashMap<u32, usize>,
    /// Per host, its node ids ascending (the leader's 0 first).
    nodes: Vec<Vec<u32>>,
    /// The nodes on no host, ascending.
    local: Vec<u32>,
    /// Sorted by (from_host, to_host, from, to): grouped per pair of machines.
    cut: Vec<CutEdge>,
}

impl Placement {
    /// `hosts` placed on `net`: every agent of the file must be one of the
    /// network's (every one that is not is reported, at once).
    pub fn of(hosts: &Hosts, net: &Network) -> Result<Placement, HostsError> {
        let mut host_of = HashMap::new();
        let mut issues = Vec::new();
        for (h, host) in hosts.hosts.iter().enumerate() {
            if host.leader {
                host_of.insert(LEADER, h);
            }
            for (k, &id) in host.agents.iter().enumerate() {
                // `net.agents` is sorted by id.
                match net.agents.binary_search_by_key(&id, |a| a.model.id) {
                    Ok(_) => {
                        host_of.insert(id, h);
                    }
                    Err(_) => issues.push(Issue {
                        field: format!("host[{h}].agents[{k}]"),
                        reason: format!("agent {id} does not exist ({})", agents_are(net)),
                    }),
                }
            }
        }
        if !issues.is_empty() {
            return Err(HostsError::Invalid(hosts.path.clone(), issues));
        }
        Ok(Self::assemble(hosts.hosts.clone(), host_of, net))
    }

    /// The nodes per host, the local ones and the cut edges of `host_of`.
    fn assemble(hosts: Vec<Host>, host_of: HashMap<u32, usize>, net: &Network) -> Placement {
        let mut nodes = vec![Vec::new(); hosts.len()];
        let mut local = Vec::new();
        let ids = std::iter::once(LEADER).chain(net.agents.iter().map(|a| a.model.id));
        for id in ids {
            match host_of.get(&id) {
                Some(&h) => nodes[h].push(id),
                None => local.push(id),
            }
        }
        let mut placement = Placement {
            hosts,
            host_of,
            nodes,
            local,
            cut: Vec::new(),
        };
        placement.cut = placement.links(net);
        placement
    }

    /// Every link of `net` whose ends are on different machines, sorted.
    fn links(&self, net: &Network) -> Vec<CutEdge> {
        let mut cut = Vec::new();
        for a in &net.agents {
            let to = a.model.id;
            let leader = a.model.leader_gain.is_some().then_some(LEADER);
            for from in a.model.neighbours.iter().map(|n| n.id).chain(leader) {
                let (from_host, to_host) = (self.host_of(from), self.host_of(to));
                if from_host != to_host {
                    cut.push(CutEdge {
                        from,
                        to,
                        from_host,
                        to_host,
                    });
                }
            }
        }
        cut.sort_unstable_by_key(|e| (e.from_host, e.to_host, e.from, e.to));
        cut
    }

    /// The host that runs node `node` (0: the leader), or `None` when it
    /// runs on the orchestrator's machine (or is no node of the network).
    #[must_use]
    pub fn host_of(&self, node: u32) -> Option<usize> {
        self.host_of.get(&node).copied()
    }

    /// The node ids host `host` runs, ascending (the leader's 0 first).
    /// Panics if `host` is not an index into [`Self::hosts`].
    #[must_use]
    pub fn nodes_on(&self, host: usize) -> &[u32] {
        &self.nodes[host]
    }

    /// The node ids on no host (they run on the orchestrator's machine), ascending.
    #[must_use]
    pub fn local_nodes(&self) -> &[u32] {
        &self.local
    }

    /// Every directed link whose ends run on different machines, grouped
    /// per (sender's machine, receiver's machine), local first, then by
    /// sender and receiver.
    #[must_use]
    pub fn cut_edges(&self) -> &[CutEdge] {
        &self.cut
    }

    /// The hosts, in file order.
    #[must_use]
    pub fn hosts(&self) -> &[Host] {
        &self.hosts
    }
}

/// "the scenario has N agents", and their range when the ids are not 1..=N.
fn agents_are(net: &Network) -> String {
    let n = net.agents.len();
    let dense = net
        .agents
        .iter()
        .enumerate()
        .all(|(k, a)| u64::from(a.model.id) == k as u64 + 1);
    match (net.agents.first(), net.agents.last()) {
        (Some(lo), Some(hi)) if !dense => format!(
            "the scenario has {n} agents, ids {} to {}",
            lo.model.id, hi.model.id
        ),
        _ => format!("the scenario has {n} agents"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    /// The paper's scheme-1 scenario: leader → 1, 2; edges 1–3, 2–7, 3–5, 3–6, 4–5.
    const PAPER: &str = include_str!("../../../scenarios/paper/timevarying.toml");

    fn paper() -> Network {
        let loaded = scenario::load_str(Path::new("paper.toml"), PAPER, &[]);
        loaded.unwrap_or_else(|e| panic!("{e}")).resolved.network
    }

    fn hosts(text: &str) -> Hosts {
        super::super::load_str(Path::new("h.toml"), text).unwrap_or_else(|e| panic!("{e}"))
    }

    fn edge(from: u32, to: u32, from_host: Option<usize>, to_host: Option<usize>) -> CutEdge {
        CutEdge {
            from,
            to,
            from_host,
            to_host,
        }
    }

    #[test]
    fn cut_edges_are_the_links_between_machines_both_ways() {
        let h = hosts(
            "[[host]]\nname = \"a\"\nendpoint = \"tcp/127.0.0.1:7001\"\nagents = [3, 1]\nleader = true\n\
             [[host]]\nname = \"b\"\nendpoint = \"tcp/127.0.0.1:7002\"\nagents = [5, 4]\n",
        );
        let p = Placement::of(&h, &paper()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(p.nodes_on(0), [0, 1, 3]);
        assert_eq!(p.nodes_on(1), [4, 5]);
        assert_eq!(p.local_nodes(), [2, 6, 7]);
        assert_eq!(
            (p.host_of(0), p.host_of(5), p.host_of(7)),
            (Some(0), Some(1), None)
        );
        // 0→1, 1↔3 stay on a; 4↔5 on b; 2↔7 local.
        let (a, b) = (Some(0), Some(1));
        let expected = [
            edge(6, 3, None, a),
            edge(0, 2, a, None),
            edge(3, 6, a, None),
            edge(3, 5, a, b),
            edge(5, 3, b, a),
        ];
        assert_eq!(p.cut_edges(), expected);
    }

    #[test]
    fn nothing_is_cut_when_every_node_is_on_one_machine() {
        let h = hosts(
            "[[host]]\nname = \"all\"\nendpoint = \"tcp/localhost:7001\"\n\
             agents = [1, 2, 3, 4, 5, 6, 7]\nleader = true\n",
        );
        let p = Placement::of(&h, &paper()).unwrap_or_else(|e| panic!("{e}"));
        assert!(p.cut_edges().is_empty(), "{:?}", p.cut_edges());
        assert!(p.local_nodes().is_empty());
        assert_eq!(p.nodes_on(0), [0, 1, 2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn a_lone_leader_host_cuts_exactly_its_links() {
        let h = hosts("[[host]]\nname = \"l\"\nendpoint = \"tcp/[::1]:7001\"\nleader = true\n");
        let p = Placement::of(&h, &paper()).unwrap_or_else(|e| panic!("{e}"));
        let l = Some(0);
        assert_eq!(p.cut_edges(), [edge(0, 1, l, None), edge(0, 2, l, None)]);
        assert_eq!(p.local_nodes(), [1, 2, 3, 4, 5, 6, 7]);
    }

    #[test]
    fn unknown_agents_are_all_reported() {
        let h = hosts(
            "[[host]]\nname = \"a\"\nendpoint = \"tcp/127.0.0.1:7001\"\nagents = [1, 9, 12]\n",
        );
        let e = Placement::of(&h, &paper()).expect_err("agents 9 and 12 do not exist");
        assert_eq!(
            e.to_string(),
            "h.toml: host[0].agents[1]: agent 9 does not exist (the scenario has 7 agents)\n\
             h.toml: host[0].agents[2]: agent 12 does not exist (the scenario has 7 agents)"
        );
    }
}
