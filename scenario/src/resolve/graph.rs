//! `[[edge]]` and `[[leader_link]]`: the follower forest and who hears the
//! leader, with their gains (Assumption 1).

use super::ctx::Ctx;
use super::ids::Ids;
use super::theory::Departure;
use crate::schema::{EdgeSpec, LeaderLinkSpec};
pub(super) use attitude::sparse::Adjacency;
use nalgebra::Matrix3;
use std::collections::{HashMap, HashSet};
use std::fmt;

/// The follower edges that name two known, distinct agents.
#[derive(Default)]
pub(super) struct Edges {
    /// Agent-id pairs (smaller id first), in file order.
    pub(super) pairs: Vec<(u32, u32)>,
    /// The gain of each pair, where the gain is valid.
    pub(super) gain: Vec<Option<Matrix3<f64>>>,
    /// One-way edges (sender, receiver), in file order (`[graph]
    /// assumptions = "off"` only).
    pub(super) arcs: Vec<(u32, u32)>,
    /// The gain of each one-way edge, where the gain is valid.
    pub(super) arc_gain: Vec<Option<Matrix3<f64>>>,
}

/// The agents that hear the leader, by rank of their ids.
pub(super) struct LeaderLinks {
    /// Index in `[[leader_link]]` of the link to each agent, if linked.
    pub(super) seen: Vec<Option<usize>>,
    /// The gain of each linked agent, where the gain is valid.
    pub(super) gain: Vec<Option<Matrix3<f64>>>,
}

impl LeaderLinks {
    /// Ranks of the linked agents, ascending.
    pub(super) fn linked(&self) -> impl Iterator<Item = usize> + '_ {
        self.seen
            .iter()
            .enumerate()
            .filter_map(|(r, k)| k.map(|_| r))
    }
}

impl Edges {
    /// The one-way edges into each agent, by the receiver's rank: the
    /// sender's id and the edge's index in `arcs`.
    pub(super) fn incoming(&self, ids: &Ids) -> Vec<Vec<(u32, usize)>> {
        let mut into = vec![Vec::new(); if self.arcs.is_empty() { 0 } else { ids.len() }];
        for (k, &(from, to)) in self.arcs.iter().enumerate() {
            into[ids.rank(to).expect("a known receiver")].push((from, k));
        }
        into
    }

    /// The one-way edges as (sender, receiver) ranks.
    pub(super) fn arc_ranks(&self, ids: &Ids) -> Vec<(usize, usize)> {
        let rank = |id| ids.rank(id).expect("an edge between known agents");
        self.arcs.iter().map(|&(a, b)| (rank(a), rank(b))).collect()
    }

    /// The pairs as pairs of ranks (every pair names known agents).
    pub(super) fn ranks(&self, ids: &Ids) -> Vec<(usize, usize)> {
        let rank = |id| ids.rank(id).expect("an edge between known agents");
        self.pairs
            .iter()
            .map(|&(a, b)| (rank(a), rank(b)))
            .collect()
    }
}

/// `[[edge]]` between the agents of `ids`.
pub(super) fn edges(c: &mut Ctx, specs: &[EdgeSpec], ids: &Ids) -> Edges {
    let mut out = Edges::default();
    // The file index of every pair in `out`; the first index of each pair
    // only once two ends were found connected already (never on a forest).
    let mut index: Vec<usize> = Vec::with_capacity(specs.len());
    let mut first_edge: Option<HashMap<(u32, u32), usize>> = None;
    let mut dsu = Dsu::new(ids.len());
    let mut one_way: Vec<(usize, &EdgeSpec)> = Vec::new();
    for (k, e) in specs.iter().enumerate() {
        let f = Edge(k);
        let [a, b] = match (e.agents, e.from, e.to) {
            (Some(pair), None, None) => pair,
            (None, Some(_), Some(_)) => {
                one_way.push((k, e));
                continue;
            }
            _ => {
                let why = "give `agents = [i, j]` (both hear each other) or `from = i` and `to = j` (j hears i)";
                c.err(format!("{f}"), why);
                continue;
            }
        };
        let key = (a.min(b), a.max(b));
        let ends = endpoints_ok(c, f, [a, b], ids).then(|| {
            let (ra, rb) = (ids.rank(key.0), ids.rank(key.1));
            (ra.expect("known"), rb.expect("known"))
        });
        // A repeated pair is connected already: look it up only then.
        let joined = ends.is_some_and(|(ra, rb)| dsu.find(ra) == dsu.find(rb));
        let ok = ends.is_some() && {
            let first = joined
                .then(|| {
                    let map = first_edge.get_or_insert_with(|| pairs_at(&out.pairs, &index));
                    map.get(&key).copied()
                })
                .flatten();
            if let Some(first) = first {
                c.err(
                    format!("{f}.agents"),
                    format!("duplicate edge {}–{} (also edge[{first}])", key.0, key.1),
                );
            }
            first.is_none()
        };
        let g = c.gain(format_args!("{f}.gain"), &e.gain);
        if let (true, Some((ra, rb))) = (ok, ends) {
            if let Some(map) = first_edge.as_mut() {
                map.insert(key, k);
            }
            if joined {
                let reason = format!(
                    "edge {}–{} closes a cycle: the follower graph must be a forest",
                    key.0, key.1
                );
                let cycle = Departure::Cycle {
                    edge: [key.0, key.1],
                };
                c.departs(format!("{f}.agents"), cycle, reason);
            } else {
                dsu.union(ra, rb);
            }
            out.pairs.push(key);
            out.gain.push(g);
            index.push(k);
        }
    }
    if !one_way.is_empty() {
        arcs(c, &one_way, ids, &mut dsu, &mut out);
    }
    out
}

/// The one-way edges `specs` (with their file indices) into `out`: each
/// a departure from Assumption 1; one that repeats an edge is refused,
/// one that closes a cycle of the undirected skeleton (not its own
/// reverse) is another departure.
fn arcs(c: &mut Ctx, specs: &[(usize, &EdgeSpec)], ids: &Ids, dsu: &mut Dsu, out: &mut Edges) {
    let both: HashSet<(u32, u32)> = out.pairs.iter().copied().collect();
    let mut seen: HashMap<(u32, u32), usize> = HashMap::new();
    for &(k, e) in specs {
        let f = Edge(k);
        let (from, to) = (e.from.expect("one-way"), e.to.expect("one-way"));
        let g = c.gain(format_args!("{f}.gain"), &e.gain);
        if !endpoints_ok(c, f, [from, to], ids) {
            continue;
        }
        let key = (from.min(to), from.max(to));
        if let Some(first) = seen.insert((from, to), k) {
            c.err(
                format!("{f}.to"),
                format!("duplicate edge {from}→{to} (also edge[{first}])"),
            );
            continue;
        }
        if both.contains(&key) {
            let why = format!(
                "agent {to} already hears agent {from} through an edge `agents = [{}, {}]`",
                key.0, key.1
            );
            c.err(format!("{f}.to"), why);
            continue;
        }
        let reason = format!("edge {from}→{to} is one-way: the paper's edges are undirected");
        c.departs(
            format!("{f}.from"),
            Departure::OneWay { edge: [from, to] },
            reason,
        );
        let (ra, rb) = (ids.rank(from).expect("known"), ids.rank(to).expect("known"));
        let reverse = seen.contains_key(&(to, from));
        if !reverse && dsu.find(ra) == dsu.find(rb) {
            let cycle = Departure::Cycle {
                edge: [key.0, key.1],
            };
            c.departs(
                format!("{f}.from"),
                cycle,
                format!("edge {from}→{to} closes a cycle"),
            );
        } else {
            dsu.union(ra, rb);
        }
        out.arcs.push((from, to));
        out.arc_gain.push(g);
    }
}

/// The undirected skeleton of `pairs` and one-way `arcs` (by rank): every
/// pair, then each arc's pair once unless a pair or its reverse is there.
pub(super) fn skeleton(pairs: &[(usize, usize)], arcs: &[(usize, usize)]) -> Vec<(usize, usize)> {
    if arcs.is_empty() {
        return pairs.to_vec();
    }
    let key = |(a, b): (usize, usize)| (a.min(b), a.max(b));
    let mut seen: HashSet<(usize, usize)> = pairs.iter().map(|&p| key(p)).collect();
    let mut out = pairs.to_vec();
    out.extend(arcs.iter().filter(|&&a| seen.insert(key(a))).copied());
    out
}

/// Pair → first file index, of the pairs kept so far.
fn pairs_at(pairs: &[(u32, u32)], index: &[usize]) -> HashMap<(u32, u32), usize> {
    let mut map = HashMap::with_capacity(pairs.len());
    for (&key, &k) in pairs.iter().zip(index) {
        map.entry(key).or_insert(k);
    }
    map
}

/// Both ends of edge `f` are known agents, and distinct.
fn endpoints_ok(c: &mut Ctx, f: Edge, [a, b]: [u32; 2], ids: &Ids) -> bool {
    let mut ok = true;
    for x in [a, b] {
        if !ids.contains(x) {
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
pub(super) fn leader_links(c: &mut Ctx, specs: &[LeaderLinkSpec], ids: &Ids) -> LeaderLinks {
    let mut out = LeaderLinks {
        seen: vec![None; ids.len()],
        gain: vec![None; ids.len()],
    };
    for (k, l) in specs.iter().enumerate() {
        let g = c.gain(format_args!("leader_link[{k}].gain"), &l.gain);
        let Some(r) = ids.rank(l.agent) else {
            c.err(
                format!("leader_link[{k}].agent"),
                format!("unknown agent id {}", l.agent),
            );
            continue;
        };
        // `seen` keeps the latest index: a third link to an agent names the second.
        if let Some(first) = out.seen[r].replace(k) {
            c.err(
                format!("leader_link[{k}].agent"),
                format!(
                    "duplicate leader link to agent {} (also leader_link[{first}])",
                    l.agent
                ),
            );
            continue;
        }
        out.gain[r] = g;
    }
    if specs.is_empty() {
        let reason = "at least one [[leader_link]] is required: no agent hears the leader";
        c.departs("leader_link", Departure::NoLeaderLink, reason.into());
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

/// Union–find over agent ranks, for the forest check.
struct Dsu {
    parent: Vec<usize>,
}

impl Dsu {
    /// `n` singletons.
    fn new(n: usize) -> Self {
        Self {
            parent: (0..n).collect(),
        }
    }

    /// The representative of `x`'s set (iterative, with path halving: no
    /// recursion however deep the chain of parents).
    fn find(&mut self, mut x: usize) -> usize {
        while self.parent[x] != x {
            let g = self.parent[self.parent[x]];
            self.parent[x] = g;
            x = g;
        }
        x
    }

    /// Joins the sets of `a` and `b` (not joined yet).
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        self.parent[ra] = rb;
    }
}
