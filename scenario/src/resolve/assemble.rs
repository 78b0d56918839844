//! The last phase: a [`Network`] from the parts the other phases resolved,
//! once there are no errors.

use super::agents::Body;
use super::body::BodyEffects;
use super::graph::{Adjacency, Edges, LeaderLinks};
use super::ids::Ids;
use super::leader::Leader;
use super::simulation::Timing;
use attitude::control::ControlLaw;
use attitude::guard::Envelope;
use attitude::link::LinkModel;
use attitude::network::{AgentModel, AgentSpec, Neighbour, Network, Scheme};
use attitude::reference::LeaderState;
use attitude::timeline::{AgentTimeline, Crash, InputOutages, Outage, Repoint, Retune};
use std::collections::BTreeMap;

/// Everything resolved, error-free.
pub(super) struct Parts {
    pub(super) scheme: Option<Scheme>,
    pub(super) time: Timing,
    pub(super) leader: Leader,
    /// By rank of the agents' ids.
    pub(super) bodies: Vec<Option<Body>>,
    pub(super) impaired: BTreeMap<(u32, u32), LinkModel>,
    pub(super) guard: Envelope,
    pub(super) law: ControlLaw,
    /// The bodies' effects, by rank of the agents' ids.
    pub(super) effects: Vec<BodyEffects>,
    pub(super) timeline: Timed,
}

/// What the events do, in steps.
#[derive(Debug, Default)]
pub(super) struct Timed {
    /// Outages by directed link (sender, receiver): of one mode disjoint,
    /// ascending.
    pub(super) down: BTreeMap<(u32, u32), Vec<Outage>>,
    /// Scheme gains from a step on, ascending; the same for every agent.
    pub(super) retune: Vec<Retune>,
    /// Jumps of the constant reference, ascending: the leader's.
    pub(super) repoint: Vec<Repoint>,
    /// Crashes by agent, ascending.
    pub(super) crashes: BTreeMap<u32, Vec<Crash>>,
}

impl Timed {
    /// Agent `id`'s part.
    fn of(&self, id: u32, inputs: impl Iterator<Item = u32>) -> Option<Box<AgentTimeline>> {
        let down = inputs
            .filter_map(|from| {
                let outages = self.down.get(&(from, id))?.clone();
                Some(InputOutages { from, outages })
            })
            .collect();
        let t = AgentTimeline {
            down,
            retune: self.retune.clone(),
            crashes: self.crashes.get(&id).cloned().unwrap_or_default(),
        };
        (!t.is_empty()).then(|| Box::new(t))
    }
}

/// The graph the agents are wired by.
pub(super) struct Graph<'a> {
    pub(super) ids: &'a Ids,
    pub(super) edges: &'a Edges,
    pub(super) adjacency: &'a Adjacency,
    /// The one-way edges into each agent ([`Edges::incoming`]).
    pub(super) incoming: &'a [Vec<(u32, usize)>],
    pub(super) links: &'a LeaderLinks,
}

/// The network of `parts` over `graph`.
///
/// # Panics
/// If a part is missing: call it only when no phase reported an error.
pub(super) fn network(parts: Parts, graph: &Graph<'_>) -> Network {
    let Parts {
        scheme,
        time,
        leader,
        bodies,
        impaired,
        guard,
        law,
        effects,
        timeline,
    } = parts;
    let scheme = scheme.expect("no errors");
    let p = leader.p;
    let agents = bodies
        .into_iter()
        .zip(effects)
        .enumerate()
        .map(|(r, (body, effects))| {
            let (inertia, a_bar, initial) = body.expect("no errors");
            let id = graph.ids.id(r);
            let neighbours = neighbours(id, r, graph, &impaired);
            let inputs = neighbours.iter().map(|n| n.id).chain(std::iter::once(0));
            AgentSpec {
                model: AgentModel {
                    timeline: timeline.of(id, inputs),
                    effects: effects.of(&inertia),
                    id,
                    inertia,
                    a_bar,
                    neighbours,
                    leader_gain: graph.links.gain[r],
                    leader_link: impaired.get(&(0, id)).copied(),
                    scheme,
                    p,
                    law,
                },
                initial,
            }
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
        repoint: timeline.repoint,
    }
}

/// The neighbours of agent `id` (rank `r`), by ascending id, with the link
/// each of their messages to `id` crosses.
fn neighbours(
    id: u32,
    r: usize,
    graph: &Graph<'_>,
    impaired: &BTreeMap<(u32, u32), LinkModel>,
) -> Vec<Neighbour> {
    let mut neighbours: Vec<Neighbour> = graph
        .adjacency
        .of(r)
        .iter()
        .map(|&(other, e)| {
            let other = graph.ids.id(other);
            Neighbour {
                link: impaired.get(&(other, id)).copied(),
                id: other,
                a: graph.edges.gain[e].expect("no errors"),
            }
        })
        .collect();
    let one_way = graph.incoming.get(r).into_iter().flatten();
    neighbours.extend(one_way.map(|&(from, k)| Neighbour {
        link: impaired.get(&(from, id)).copied(),
        id: from,
        a: graph.edges.arc_gain[k].expect("no errors"),
    }));
    neighbours.sort_by_key(|n| n.id);
    neighbours
}
