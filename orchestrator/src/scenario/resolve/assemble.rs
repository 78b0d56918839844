//! The last phase: a [`Network`] from the parts the other phases resolved,
//! once there are no errors.

use super::agents::Body;
use super::graph::{Edges, LeaderLinks};
use super::leader::Leader;
use super::simulation::Timing;
use attitude::control::ControlLaw;
use attitude::guard::Envelope;
use attitude::link::LinkModel;
use attitude::network::{AgentModel, AgentSpec, Neighbour, Network, Scheme};
use attitude::reference::LeaderState;
use std::collections::BTreeMap;

/// Everything resolved, error-free.
pub(super) struct Parts {
    pub(super) scheme: Option<Scheme>,
    pub(super) time: Timing,
    pub(super) leader: Leader,
    pub(super) bodies: BTreeMap<u32, Body>,
    pub(super) impaired: BTreeMap<(u32, u32), LinkModel>,
    pub(super) guard: Envelope,
    pub(super) law: ControlLaw,
}

/// The network of `parts` over `edges` and `links`.
///
/// # Panics
/// If a part is missing: call it only when no phase reported an error.
pub(super) fn network(parts: Parts, edges: &Edges, links: &LeaderLinks) -> Network {
    let Parts {
        scheme,
        time,
        leader,
        bodies,
        impaired,
        guard,
        law,
    } = parts;
    let scheme = scheme.expect("no errors");
    let p = leader.p;
    let incident = incident_edges(edges);
    let agents = bodies
        .into_iter()
        .map(|(id, (inertia, a_bar, initial))| AgentSpec {
            model: AgentModel {
                id,
                inertia,
                a_bar,
                neighbours: neighbours(
                    id,
                    incident.get(&id).map_or(&[], Vec::as_slice),
                    edges,
                    &impaired,
                ),
                leader_gain: links.gain.get(&id).copied(),
                leader_link: impaired.get(&(0, id)).copied(),
                scheme,
                p,
                law,
            },
            initial,
        })
        .collect();
    Network {
        agents,
        p,
        leader: LeaderState {
            r0: leader.r0.expect("no errors"),
            w0: leader.w0,
            s0: leader.s0,
        },
        dt: time.dt,
        steps: time.steps.expect("no errors"),
        coupling: time.coupling.expect("no errors"),
        sample_every: time.sample_every.expect("no errors"),
        guard,
    }
}

/// The neighbours of agent `id`, by ascending id, with the link each of
/// their messages to `id` crosses (`incident`: the edges at `id`).
fn neighbours(
    id: u32,
    incident: &[(u32, u32)],
    edges: &Edges,
    impaired: &BTreeMap<(u32, u32), LinkModel>,
) -> Vec<Neighbour> {
    let mut neighbours: Vec<Neighbour> = incident
        .iter()
        .map(|&(a, b)| {
            let other = if a == id { b } else { a };
            Neighbour {
                link: impaired.get(&(other, id)).copied(),
                id: other,
                a: edges.gain[&(a, b)],
            }
        })
        .collect();
    neighbours.sort_by_key(|n| n.id);
    neighbours
}

/// The edges at every agent, in file order (one pass over the edges).
fn incident_edges(edges: &Edges) -> BTreeMap<u32, Vec<(u32, u32)>> {
    let mut at: BTreeMap<u32, Vec<(u32, u32)>> = BTreeMap::new();
    for &(a, b) in &edges.pairs {
        at.entry(a).or_default().push((a, b));
        at.entry(b).or_default().push((a, b));
    }
    at
}
