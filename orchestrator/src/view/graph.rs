//! Where the bodies stand: the follower graph laid out as a radial tree
//! around the leader, on the ground plane.

use attitude::network::Network;
use std::collections::{BTreeSet, VecDeque};
use std::f64::consts::TAU;

/// The graph of a network for drawing: node 0 the leader, node k + 1 the
/// agent at `net.agents[k]`.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Ground-plane position of every node (units: rings; ring d at radius d).
    pub pos: Vec<[f64; 2]>,
    /// BFS depth from the leader (agents it does not reach: one ring
    /// beyond the deepest).
    pub depth: Vec<u32>,
    /// Follower edges (node indices, smaller first), in agent order.
    pub edges: Vec<[usize; 2]>,
    /// Nodes of the agents that read the leader (`Ξᵢ = 1`).
    pub leader_links: Vec<usize>,
}

/// Lays out `net`: a BFS tree from the leader over leader links and
/// follower edges (neighbours by id), each subtree given an angular sector
/// in proportion to its leaves, each node at radius = its depth.
#[must_use]
pub fn layout(net: &Network) -> Layout {
    let adj = adjacency(net);
    let n = adj.len();
    let (parent, mut depth) = bfs(&adj);
    let mut children = vec![Vec::new(); n];
    for v in 1..n {
        if let Some(p) = parent[v] {
            children[p].push(v);
        }
    }
    let leaves = leaf_counts(&children);
    let mut pos = vec![[0.0; 2]; n];
    let mut stack = vec![(0usize, 0.0, TAU)];
    while let Some((v, from, width)) = stack.pop() {
        let total: usize = children[v].iter().map(|&c| leaves[c]).sum();
        let mut at = from;
        for &c in &children[v] {
            let w = width * leaves[c] as f64 / total as f64;
            let (r, a) = (depth[c] as f64, at + w / 2.0);
            pos[c] = [r * a.cos(), r * a.sin()];
            stack.push((c, at, w));
            at += w;
        }
    }
    place_unreached(&mut pos, &mut depth, &parent);
    let edges = (adj.iter().enumerate().skip(1))
        .flat_map(|(v, ns)| ns.iter().filter(move |&&u| u > v).map(move |&u| [v, u]))
        .collect();
    Layout {
        pos,
        depth: depth.iter().map(|&d| d as u32).collect(),
        edges,
        leader_links: adj[0].clone(),
    }
}

/// Neighbours of every node (0 = leader), ascending.
fn adjacency(net: &Network) -> Vec<Vec<usize>> {
    let n = net.agents.len() + 1;
    let mut adj = vec![Vec::new(); n];
    let index = net.index_by_id();
    for (k, a) in net.agents.iter().enumerate() {
        if a.model.leader_gain.is_some() {
            adj[0].push(k + 1);
            adj[k + 1].push(0);
        }
        for nb in &a.model.neighbours {
            if let Some(&j) = index.get(&nb.id) {
                adj[k + 1].push(j + 1);
            }
        }
    }
    for ns in &mut adj {
        ns.sort_unstable();
        ns.dedup();
    }
    adj
}

/// BFS parents and depths from node 0 (`usize::MAX` depth: unreached).
fn bfs(adj: &[Vec<usize>]) -> (Vec<Option<usize>>, Vec<usize>) {
    let mut parent = vec![None; adj.len()];
    let mut depth = vec![usize::MAX; adj.len()];
    depth[0] = 0;
    let mut queue = VecDeque::from([0]);
    while let Some(v) = queue.pop_front() {
        for &u in &adj[v] {
            if depth[u] == usize::MAX {
                depth[u] = depth[v] + 1;
                parent[u] = Some(v);
                queue.push_back(u);
            }
        }
    }
    (parent, depth)
}

/// Leaves under every node of the BFS tree (a leaf counts 1).
fn leaf_counts(children: &[Vec<usize>]) -> Vec<usize> {
    let n = children.len();
    let mut order = vec![0usize];
    let mut k = 0;
    while k < order.len() {
        order.extend(children[order[k]].iter().copied());
        k += 1;
    }
    let mut leaves = vec![0; n];
    for &v in order.iter().rev() {
        leaves[v] = if children[v].is_empty() {
            1
        } else {
            children[v].iter().map(|&c| leaves[c]).sum()
        };
    }
    leaves
}

/// Nodes the leader does not reach (a network `resolve` refuses, but
/// `states.bin` may come from elsewhere): evenly on a ring beyond the rest.
fn place_unreached(pos: &mut [[f64; 2]], depth: &mut [usize], parent: &[Option<usize>]) {
    let reached = |v: usize| v == 0 || parent[v].is_some();
    let outer = (0..pos.len())
        .filter(|&v| reached(v))
        .map(|v| depth[v])
        .max()
        .unwrap_or(0)
        + 1;
    let lost: Vec<usize> = (0..pos.len()).filter(|&v| !reached(v)).collect();
    for (k, &v) in lost.iter().enumerate() {
        let a = TAU * k as f64 / lost.len() as f64;
        let r = outer as f64;
        pos[v] = [r * a.cos(), r * a.sin()];
        depth[v] = outer;
    }
}

/// The smallest distance between two nodes of `pos` (1 for fewer than two,
/// or when all coincide; coincident nodes do not count): a sweep in x
/// keeping the nodes within the best distance so far ordered by y,
/// O(N log N) (a 10⁵-agent view is laid out in milliseconds, not in the
/// minutes of all pairs).
#[must_use]
pub fn min_distance(pos: &[[f64; 2]]) -> f64 {
    let mut by_x: Vec<[f64; 2]> = pos
        .iter()
        .copied()
        .filter(|p| p[0].is_finite() && p[1].is_finite())
        .collect();
    by_x.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    // Without coincident nodes, few lie within d of a node (they are d apart).
    by_x.dedup();
    let mut d = f64::INFINITY;
    let mut near: BTreeSet<(i64, usize)> = BTreeSet::new();
    let mut tail = 0;
    for (i, p) in by_x.iter().enumerate() {
        while tail < i && p[0] - by_x[tail][0] > d {
            near.remove(&(ordered(by_x[tail][1]), tail));
            tail += 1;
        }
        let (lo, hi) = (ordered(p[1] - d), ordered(p[1] + d));
        for &(_, j) in near.range((lo, 0)..=(hi, usize::MAX)) {
            d = d.min((p[0] - by_x[j][0]).hypot(p[1] - by_x[j][1]));
        }
        near.insert((ordered(p[1]), i));
    }
    if d.is_finite() { d } else { 1.0 }
}

/// `y` as an integer in the order of [`f64::total_cmp`] (the same bit
/// trick), a key of the sweep's ordered set.
fn ordered(y: f64) -> i64 {
    // Reinterpreting casts, on purpose (the bits of y as a signed integer).
    let bits = y.to_bits() as i64;
    bits ^ (((bits >> 63) as u64) >> 1) as i64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paper_graph_is_a_radial_tree_around_the_leader() {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenarios/paper/timevarying.toml");
        let loaded = crate::scenario::load(&file, &[]).expect("valid");
        let l = layout(&loaded.resolved.network);
        // L = {1, 2}; edges 1–3, 2–7, 3–5, 3–6, 4–5 (node k = agent k here).
        assert_eq!(l.leader_links, [1, 2]);
        assert_eq!(l.edges, [[1, 3], [2, 7], [3, 5], [3, 6], [4, 5]]);
        assert_eq!(l.depth, [0, 1, 1, 2, 4, 3, 3, 2]);
        for (v, p) in l.pos.iter().enumerate() {
            let r = p[0].hypot(p[1]);
            assert!(
                (r - f64::from(l.depth[v])).abs() < 1e-12,
                "node {v} at {p:?}"
            );
        }
        assert!(min_distance(&l.pos) > 0.5, "{:?}", l.pos);
    }

    /// All pairs, the definition the sweep must agree with.
    fn min_distance_of_all_pairs(pos: &[[f64; 2]]) -> f64 {
        let mut d = f64::INFINITY;
        for (i, a) in pos.iter().enumerate() {
            for b in &pos[i + 1..] {
                let r = (a[0] - b[0]).hypot(a[1] - b[1]);
                if r > 0.0 {
                    d = d.min(r);
                }
            }
        }
        if d.is_finite() { d } else { 1.0 }
    }

    #[test]
    fn the_sweep_finds_the_closest_pair_of_all_pairs() {
        // Points on rings (as laid out), on a line, repeated and scattered.
        let mut seed = 7u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for n in [0, 1, 2, 3, 10, 200, 1000] {
            let mut pos: Vec<[f64; 2]> = (0..n)
                .map(|k| {
                    let (r, a) = ((k % 7) as f64, next() * TAU);
                    [r * a.cos(), r * a.sin()]
                })
                .collect();
            assert_eq!(
                min_distance(&pos),
                min_distance_of_all_pairs(&pos),
                "rings {n}"
            );
            pos.iter_mut().for_each(|p| p[1] = 0.0);
            assert_eq!(
                min_distance(&pos),
                min_distance_of_all_pairs(&pos),
                "line {n}"
            );
            let same = vec![[0.5, 0.5]; n];
            assert_eq!(min_distance(&same), 1.0);
        }
    }
}
