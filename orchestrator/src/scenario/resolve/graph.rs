//! `[[edge]]` and `[[leader_link]]`: the follower forest and who hears the
//! leader, with their gains (Assumption 1).

use super::ctx::Ctx;
use crate::scenario::schema::{EdgeSpec, LeaderLinkSpec};
use nalgebra::Matrix3;
use std::collections::BTreeMap;
use std::fmt;

/// The follower edges that name two known, distinct agents.
#[derive(Default)]
pub(super) struct Edges {
    /// Agent-id pairs (smaller id first), in file order.
    pub(super) pairs: Vec<(u32, u32)>,
    /// The gain of every edge whose gain is valid.
    pub(super) gain: BTreeMap<(u32, u32), Matrix3<f64>>,
}

/// The agents that hear the leader.
#[derive(Default)]
pub(super) struct LeaderLinks {
    /// Agent id → index in `[[leader_link]]`, for every known agent linked.
    pub(super) seen: BTreeMap<u32, usize>,
    /// Agent id → gain, where the gain is valid.
    pub(super) gain: BTreeMap<u32, Matrix3<f64>>,
}

/// `[[edge]]` between the agents of `ids`.
pub(super) fn edges(c: &mut Ctx, specs: &[EdgeSpec], ids: &BTreeMap<u32, usize>) -> Edges {
    let mut out = Edges::default();
    let mut first_edge: BTreeMap<(u32, u32), usize> = BTreeMap::new();
    let mut dsu = Dsu::default();
    for (k, e) in specs.iter().enumerate() {
        let f = Edge(k);
        let [a, b] = e.agents;
        let key = (a.min(b), a.max(b));
        let ok = endpoints_ok(c, f, e.agents, ids) && {
            let first = first_edge.get(&key);
            if let Some(first) = first {
                c.err(
                    format!("{f}.agents"),
                    format!("duplicate edge {}–{} (also edge[{first}])", key.0, key.1),
                );
            }
            first.is_none()
        };
        let g = c.gain(format_args!("{f}.gain"), &e.gain);
        if ok {
            first_edge.insert(key, k);
            if !dsu.union(key.0, key.1) {
                c.err(
                    format!("{f}.agents"),
                    format!("edge {}–{} closes a cycle: the follower graph must be a forest (Assumption 1)", key.0, key.1),
                );
            }
            out.pairs.push(key);
            if let Some(g) = g {
                out.gain.insert(key, g);
            }
        }
    }
    out
}

/// Both ends of edge `f` are known agents, and distinct.
fn endpoints_ok(c: &mut Ctx, f: Edge, [a, b]: [u32; 2], ids: &BTreeMap<u32, usize>) -> bool {
    let mut ok = true;
    for x in [a, b] {
        if !ids.contains_key(&x) {
            c.err(
                format!("{f}.agents"),
                format!(
                    "unknown agent id {x}{}",
                    if x == 0 {
                        " (the leader is linked with [[leader_link]], not [[edge]])"
                    } else {
                        ""
                    }
                ),
            );
            ok = false;
        }
    }
    if a == b {
        c.err(format!("{f}.agents"), format!("self-loop {a}–{a}"));
        ok = false;
    }
    ok
}

/// `[[leader_link]]` to the agents of `ids`.
pub(super) fn leader_links(
    c: &mut Ctx,
    specs: &[LeaderLinkSpec],
    ids: &BTreeMap<u32, usize>,
) -> LeaderLinks {
    let mut out = LeaderLinks::default();
    for (k, l) in specs.iter().enumerate() {
        let g = c.gain(format_args!("leader_link[{k}].gain"), &l.gain);
        if !ids.contains_key(&l.agent) {
            c.err(
                format!("leader_link[{k}].agent"),
                format!("unknown agent id {}", l.agent),
            );
            continue;
        }
        if let Some(first) = out.seen.insert(l.agent, k) {
            c.err(
                format!("leader_link[{k}].agent"),
                format!(
                    "duplicate leader link to agent {} (also leader_link[{first}])",
                    l.agent
                ),
            );
            continue;
        }
        if let Some(g) = g {
            out.gain.insert(l.agent, g);
        }
    }
    if specs.is_empty() {
        c.err(
            "leader_link",
            "at least one [[leader_link]] is required: no agent hears the leader",
        );
    }
    out
}

/// `edge[k]`, written out only for a problem.
#[derive(Clone, Copy)]
struct Edge(usize);

impl fmt::Display for Edge {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "edge[{}]", self.0)
    }
}

/// Union–find over agent ids, for the forest check.
#[derive(Default)]
struct Dsu {
    parent: BTreeMap<u32, u32>,
}

impl Dsu {
    /// The representative of `x`'s set (iterative, with path halving: no
    /// recursion however deep the chain of parents).
    fn find(&mut self, mut x: u32) -> u32 {
        loop {
            let p = *self.parent.entry(x).or_insert(x);
            if p == x {
                return x;
            }
            let g = self.parent[&p];
            self.parent.insert(x, g);
            x = g;
        }
    }

    /// Joins the sets of `a` and `b`; `false` if they were already joined.
    fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.parent.insert(ra, rb);
        true
    }
}
