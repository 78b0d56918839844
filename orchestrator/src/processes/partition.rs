//! Which core each node keeps while the machine is idle and the run has
//! more nodes than cores ([`super::placement`]): the communication graph
//! cut into one balanced part per core, with few edges between parts.
//!
//! Why: with 100 processes on 2 cores the scheduler migrates nodes between
//! the cores; every migration resumes a node with cold caches and every
//! hand-off to a node on the other core is an inter-processor wake-up. A
//! node pinned to the core of most of its neighbours keeps its caches and
//! hands its turn on locally (BENCHMARKS.md: tree-100 spread 343–522 µs
//! per exchange, pinned by id parity 329, by a depth-first cut 290–329).
//!
//! How: the nodes in depth-first preorder from the leader (neighbours by
//! increasing index, unreached components after, by index), cut into
//! `parts` runs of equal length (±1). In a tree a run of a preorder is a
//! few subtrees, so most edges stay inside a part.

/// The part (`0..parts`) of each of the `adjacency.len()` nodes;
/// `adjacency[i]` lists node `i`'s neighbours (either direction). Every part
/// gets ⌊n/parts⌋ or ⌈n/parts⌉ nodes.
#[must_use]
pub fn partition(adjacency: &[Vec<usize>], parts: usize) -> Vec<usize> {
    let n = adjacency.len();
    let parts = parts.max(1);
    let mut part = vec![0; n];
    for (rank, &node) in preorder(adjacency).iter().enumerate() {
        part[node] = rank * parts / n.max(1);
    }
    part
}

/// The nodes in depth-first preorder, each once (iterative: a path graph of
/// 10⁵ nodes must not overflow the stack).
fn preorder(adjacency: &[Vec<usize>]) -> Vec<usize> {
    let n = adjacency.len();
    let mut seen = vec![false; n];
    let mut order = Vec::with_capacity(n);
    let mut stack = Vec::new();
    for root in 0..n {
        stack.push(root);
        while let Some(v) = stack.pop() {
            if std::mem::replace(&mut seen[v], true) {
                continue;
            }
            order.push(v);
            let mut next: Vec<usize> = (adjacency[v].iter().copied())
                .filter(|&w| w < n && !seen[w])
                .collect();
            next.sort_unstable_by(|a, b| b.cmp(a));
            stack.extend(next);
        }
    }
    order
}

/// Edges (counted once) whose ends are in different parts.
#[must_use]
pub fn cut_edges(adjacency: &[Vec<usize>], part: &[usize]) -> usize {
    let crossing: usize = (adjacency.iter().enumerate())
        .map(|(v, ws)| ws.iter().filter(|&&w| part[v] != part[w]).count())
        .sum();
    crossing / 2
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Undirected adjacency of `edges` over `n` nodes.
    fn graph(n: usize, edges: &[(usize, usize)]) -> Vec<Vec<usize>> {
        let mut adj = vec![Vec::new(); n];
        for &(a, b) in edges {
            adj[a].push(b);
            adj[b].push(a);
        }
        adj
    }

    fn sizes(part: &[usize], parts: usize) -> Vec<usize> {
        (0..parts)
            .map(|p| part.iter().filter(|&&q| q == p).count())
            .collect()
    }

    #[test]
    fn every_part_gets_an_equal_share_give_or_take_one() {
        let adj = graph(7, &[(0, 1), (1, 2), (2, 3), (3, 4), (4, 5), (5, 6)]);
        for parts in 1..=8 {
            let s = sizes(&partition(&adj, parts), parts);
            let (lo, hi) = (s.iter().min().unwrap(), s.iter().max().unwrap());
            assert!(hi - lo <= 1, "{parts} parts: {s:?}");
            assert_eq!(s.iter().sum::<usize>(), 7);
        }
    }

    #[test]
    fn two_subtrees_joined_at_the_leader_are_cut_at_the_leader() {
        // 0 — 1 — {2, 3}, 0 — 4 — {5, 6}, plus 7 under 6: halves of 4.
        let adj = graph(8, &[(0, 1), (1, 2), (1, 3), (0, 4), (4, 5), (4, 6), (6, 7)]);
        let part = partition(&adj, 2);
        assert_eq!(part, vec![0, 0, 0, 0, 1, 1, 1, 1]);
        assert_eq!(cut_edges(&adj, &part), 1);
    }

    #[test]
    fn a_random_tree_is_cut_in_far_fewer_edges_than_by_alternating_ids() {
        // A deterministic random tree: node i attaches to an earlier node.
        let mut x: u64 = 12345;
        let edges: Vec<(usize, usize)> = (1..100)
            .map(|i| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((x >> 33) as usize % i, i)
            })
            .collect();
        let adj = graph(100, &edges);
        let parity: Vec<usize> = (0..100).map(|i| i % 2).collect();
        let dfs = cut_edges(&adj, &partition(&adj, 2));
        assert!(dfs * 2 < cut_edges(&adj, &parity), "{dfs} against parity");
    }

    #[test]
    fn unreached_nodes_and_a_long_path_are_placed_too() {
        let n = 100_000;
        let mut edges: Vec<(usize, usize)> = (1..n - 10).map(|i| (i - 1, i)).collect();
        edges.push((n - 5, n - 4)); // a component the leader does not reach
        let adj = graph(n, &edges);
        let part = partition(&adj, 3);
        assert_eq!(part.len(), n);
        assert!(part.iter().all(|&p| p < 3));
        assert!(cut_edges(&adj, &part) <= 2 + 1);
    }
}
