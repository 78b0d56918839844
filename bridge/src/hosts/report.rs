//! The text `attsync check SCENARIO --hosts FILE` prints after the
//! scenario's: each host (name, endpoint, its nodes), the orchestrator's
//! machine's nodes, and the cut edges (count, then per pair of machines).

use super::Placement;
use std::fmt::Write as _;

/// `placement` of the hosts file `file`, as text.
#[must_use]
pub fn describe(file: &std::path::Path, placement: &Placement) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "placement ({}, node 0 is the leader):", file.display());
    for (h, host) in placement.hosts().iter().enumerate() {
        let _ = writeln!(
            s,
            "  host {}  {}  nodes [{}]",
            host.name,
            host.endpoint,
            ids(placement.nodes_on(h))
        );
    }
    let _ = writeln!(
        s,
        "  {LOCAL}  nodes [{}]  (the orchestrator's machine)",
        ids(placement.local_nodes())
    );
    let cut = placement.cut_edges();
    let _ = writeln!(s, "cut edges: {}", cut.len());
    for group in cut.chunk_by(|a, b| (a.from_host, a.to_host) == (b.from_host, b.to_host)) {
        let (from, to) = (group[0].from_host, group[0].to_host);
        let links: Vec<String> = group
            .iter()
            .map(|e| format!("{}→{}", e.from, e.to))
            .collect();
        let _ = writeln!(
            s,
            "  {} → {} ({}): {}",
            machine(placement, from),
            machine(placement, to),
            group.len(),
            links.join(", ")
        );
    }
    s
}

/// How the orchestrator's machine is shown (no host name has parentheses).
const LOCAL: &str = "(local)";

/// A host's name, or [`LOCAL`] for the orchestrator's machine.
fn machine(placement: &Placement, host: Option<usize>) -> &str {
    host.map_or(LOCAL, |h| placement.hosts()[h].name.as_str())
}

fn ids(nodes: &[u32]) -> String {
    nodes
        .iter()
        .map(u32::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}
