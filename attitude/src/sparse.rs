//! Sparse symmetric matrices on a graph (its [`Adjacency`]): an
//! elimination order (minimum degree) with its filled pattern, a scalar
//! `LDLᵀ` that counts negative pivots (Sylvester's law of inertia) and a
//! block Cholesky.
//!
//! On a forest the minimum-degree order eliminates leaves first and never
//! creates fill-in: every node keeps at most one later neighbour (its
//! parent), so a factorisation is `O(N)`. Other graphs get the fill-in the
//! order creates; the factorisations stay exact (only slower).

use std::cmp::Reverse;
use std::collections::{BTreeSet, BinaryHeap};

/// An elimination order of a graph and the filled graph it implies, in
/// compressed rows over *positions* in the order: the later neighbours of
/// the node at position `k` are `later[start[k]..start[k + 1]]`, ascending.
#[derive(Debug, Clone)]
pub struct Elimination {
    /// Nodes in elimination order (position → node).
    order: Vec<usize>,
    /// Position of every node in `order` (node → position).
    pos: Vec<usize>,
    /// Row starts into `later` (length `n + 1`).
    start: Vec<usize>,
    /// Positions of the neighbours eliminated after each position, in the filled graph.
    later: Vec<usize>,
    /// Every row of `later` holds at most one entry.
    forest: bool,
}

impl Elimination {
    /// An elimination order of the graph on `0..n` with `edges` (self-loops
    /// ignored): on a forest leaves first (peeling, `O(N)`, no fill-in);
    /// otherwise minimum degree, ties by node index (repeated pairs count once).
    ///
    /// # Panics
    /// If an edge names a node `≥ n`.
    #[must_use]
    pub fn min_degree(n: usize, edges: &[(usize, usize)]) -> Self {
        if let Some((order, parent)) = forest_order(n, edges) {
            return Self::from_parents(order, &parent);
        }
        Self::from_rows(min_degree_rows(n, edges))
    }

    /// From a leaves-first order and each node's one later neighbour (its
    /// parent, `usize::MAX` for none): the pattern [`Self::from_rows`]
    /// builds from one-entry rows, without a row per node.
    fn from_parents(order: Vec<usize>, parent: &[usize]) -> Self {
        let mut pos = vec![0; order.len()];
        for (k, &v) in order.iter().enumerate() {
            pos[v] = k;
        }
        let mut start = Vec::with_capacity(order.len() + 1);
        start.push(0);
        let mut later = Vec::with_capacity(order.len());
        for &v in &order {
            if parent[v] != usize::MAX {
                later.push(pos[parent[v]]);
            }
            start.push(later.len());
        }
        Self {
            order,
            pos,
            start,
            later,
            forest: true,
        }
    }

    /// From the order and each eliminated node's later neighbours.
    fn from_rows((order, rows): (Vec<usize>, Vec<Vec<usize>>)) -> Self {
        let mut pos = vec![0; order.len()];
        for (k, &v) in order.iter().enumerate() {
            pos[v] = k;
        }
        let mut start = Vec::with_capacity(order.len() + 1);
        start.push(0);
        let mut later = Vec::new();
        for &v in &order {
            let first = later.len();
            later.extend(rows[v].iter().map(|&w| pos[w]));
            later[first..].sort_unstable();
            start.push(later.len());
        }
        let forest = start.windows(2).all(|w| w[1] - w[0] <= 1);
        Self {
            order,
            pos,
            start,
            later,
            forest,
        }
    }

    /// Number of nodes.
    #[must_use]
    pub fn len(&self) -> usize {
        self.order.len()
    }

    /// Whether every node has at most one later neighbour in the filled
    /// pattern (a forest eliminated leaves first).
    #[must_use]
    pub fn is_forest(&self) -> bool {
        self.forest
    }

    /// Whether the graph has no node.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.order.is_empty()
    }

    /// Position of node `v` in the order.
    #[must_use]
    pub fn position(&self, v: usize) -> usize {
        self.pos[v]
    }

    /// Number of entries of the filled pattern off the diagonal (upper half):
    /// the number of edges on a forest (no fill-in).
    #[must_use]
    pub fn filled_entries(&self) -> usize {
        self.later.len()
    }

    /// The later neighbours of position `k`, as a range of `later`.
    fn row(&self, k: usize) -> std::ops::Range<usize> {
        self.start[k]..self.start[k + 1]
    }

    /// Index into `later` of the entry between positions `a` and `b`.
    fn entry(&self, a: usize, b: usize) -> usize {
        let (x, y) = (a.min(b), a.max(b));
        let r = self.row(x);
        r.start
            + self.later[r]
                .binary_search(&y)
                .expect("an entry of the filled pattern")
    }

    /// Index into `later` of the entry `(i, j)` (nodes) of the filled
    /// pattern (every edge is one), and whether `i` is eliminated first (so
    /// that the slot holds `A_{i,j}`, not its transpose).
    ///
    /// # Panics
    /// If `(i, j)` is not in the pattern.
    #[must_use]
    pub fn slot(&self, i: usize, j: usize) -> (usize, bool) {
        let (a, b) = (self.pos[i], self.pos[j]);
        (self.entry(a, b), a < b)
    }
}

/// The edges at every node of a graph, in compressed rows: `(other end,
/// edge index)` in the order of the edges (self-loops left out).
#[derive(Debug, Clone)]
pub struct Adjacency {
    start: Vec<usize>,
    at: Vec<(usize, usize)>,
}

impl Adjacency {
    /// Both directions of every edge `(i, j)`, `i ≠ j`, among nodes `0..n`.
    ///
    /// # Panics
    /// If an edge names a node `≥ n`.
    #[must_use]
    pub fn new(n: usize, edges: &[(usize, usize)]) -> Self {
        let edges = || edges.iter().enumerate().filter(|(_, (i, j))| i != j);
        let mut start = vec![0; n + 1];
        for (_, &(i, j)) in edges() {
            start[i + 1] += 1;
            start[j + 1] += 1;
        }
        for v in 0..n {
            start[v + 1] += start[v];
        }
        let mut fill = start.clone();
        let mut at = vec![(0, 0); start[n]];
        for (e, &(i, j)) in edges() {
            at[fill[i]] = (j, e);
            fill[i] += 1;
            at[fill[j]] = (i, e);
            fill[j] += 1;
        }
        Self { start, at }
    }

    /// `(other end, edge index)` of every edge at node `v`.
    #[must_use]
    pub fn of(&self, v: usize) -> &[(usize, usize)] {
        &self.at[self.start[v]..self.start[v + 1]]
    }
}

/// Leaves first, if the graph is a forest (`None` otherwise): the order and
/// each node's later neighbour, its one remaining neighbour when it is
/// peeled (`usize::MAX` for a root).
fn forest_order(n: usize, edges: &[(usize, usize)]) -> Option<(Vec<usize>, Vec<usize>)> {
    let adj = Adjacency::new(n, edges);
    let mut degree: Vec<usize> = (0..n).map(|v| adj.of(v).len()).collect();
    let mut queue: std::collections::VecDeque<usize> = (0..n).filter(|&v| degree[v] <= 1).collect();
    let mut done = vec![false; n];
    let (mut order, mut parent) = (Vec::with_capacity(n), vec![usize::MAX; n]);
    while let Some(v) = queue.pop_front() {
        done[v] = true;
        order.push(v);
        let mut later = adj.of(v).iter().map(|&(u, _)| u).filter(|&u| !done[u]);
        let Some(u) = later.next() else { continue };
        if later.next().is_some() {
            return None; // a repeated pair: not a forest
        }
        parent[v] = u;
        degree[u] -= 1;
        if degree[u] == 1 {
            queue.push_back(u);
        }
    }
    (order.len() == n).then_some((order, parent))
}

/// Minimum degree with explicit fill-in (any graph).
fn min_degree_rows(n: usize, edges: &[(usize, usize)]) -> (Vec<usize>, Vec<Vec<usize>>) {
    let mut adj: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for &(i, j) in edges.iter().filter(|(i, j)| i != j) {
        adj[i].insert(j);
        adj[j].insert(i);
    }
    let mut heap: BinaryHeap<Reverse<(usize, usize)>> =
        (0..n).map(|v| Reverse((adj[v].len(), v))).collect();
    let mut done = vec![false; n];
    let (mut order, mut rows) = (Vec::with_capacity(n), vec![Vec::new(); n]);
    while let Some(Reverse((d, v))) = heap.pop() {
        if done[v] || d != adj[v].len() {
            continue; // a stale entry
        }
        done[v] = true;
        let nb: Vec<usize> = std::mem::take(&mut adj[v]).into_iter().collect();
        for &a in &nb {
            adj[a].remove(&v);
            adj[a].extend(nb.iter().copied().filter(|&b| b != a));
            heap.push(Reverse((adj[a].len(), a)));
        }
        order.push(v);
        rows[v] = nb;
    }
    (order, rows)
}

/// A symmetric scalar matrix on an [`Elimination`]'s pattern, stored as its
/// off-diagonal entries and its row sums ("excess" `rᵥ = Σ_w a_vw`),
/// as in the GTH variant of Gaussian elimination: on a Laplacian plus a
/// non-negative diagonal every pivot below the smallest eigenvalue is then
/// computed without cancellation.
#[derive(Debug, Clone)]
pub struct ScalarSym {
    /// Row sums `rᵥ` (diagonal plus off-diagonal entries), by position in
    /// the order ([`Elimination::position`]).
    pub excess: Vec<f64>,
    /// Off-diagonal entries, one per slot of the filled pattern (0 for fill).
    pub off: Vec<f64>,
}

impl ScalarSym {
    /// Number of negative pivots of `LDLᵀ = A − t I` in the order of `g`,
    /// which is the number of eigenvalues of `A` below `t` (Sylvester's law
    /// of inertia; a zero pivot counts as negative, as if `t` were a hair
    /// larger).
    #[must_use]
    pub fn eigenvalues_below(&self, g: &Elimination, t: f64) -> usize {
        let mut r: Vec<f64> = self.excess.iter().map(|x| x - t).collect();
        let mut off = self.off.clone();
        let mut negative = 0;
        for v in 0..g.len() {
            let row = g.row(v);
            let mut d = r[v] - off[row.clone()].iter().sum::<f64>();
            if d <= 0.0 {
                negative += 1;
                if d == 0.0 {
                    d = -f64::EPSILON * (1.0 + t.abs());
                }
            }
            for ia in row.clone() {
                let (a, f) = (g.later[ia], off[ia] / d);
                r[a] -= f * r[v];
                for ib in ia + 1..row.end {
                    let k = g.entry(a, g.later[ib]);
                    off[k] -= f * off[ib];
                }
            }
        }
        negative
    }
}

impl ScalarSym {
    /// The same matrix laid out for a forest's pattern ([`ForestSym`]), if
    /// every position of `g` has at most one later neighbour.
    #[must_use]
    pub fn on_forest(&self, g: &Elimination) -> Option<ForestSym> {
        if !g.is_forest() {
            return None;
        }
        let n = g.len();
        let up = (0..n)
            .map(|v| {
                let row = g.row(v);
                match row.len() {
                    0 => (n, 0.0),
                    _ => (g.later[row.start], self.off[row.start]),
                }
            })
            .collect();
        Some(ForestSym {
            up,
            excess: self.excess.clone(),
        })
    }
}

/// A [`ScalarSym`] on a forest eliminated leaves first, by position: each
/// position's one later neighbour and the entry to it. Nothing is filled
/// in, so a count reads the entries in place, in one pass.
#[derive(Debug, Clone)]
pub struct ForestSym {
    /// Per position: the later neighbour's position and the entry `a_vp`
    /// (a root: `(n, 0)`, `n` a scratch slot).
    up: Vec<(usize, f64)>,
    /// Row sums, by position.
    excess: Vec<f64>,
}

impl ForestSym {
    /// [`ScalarSym::eigenvalues_below`], operation for operation (`d = r_v −
    /// a_vp`, `r_p −= (a_vp / d) r_v`; a root's `d = r_v − 0 = r_v`), so the
    /// same count.
    #[must_use]
    pub fn eigenvalues_below(&self, t: f64) -> usize {
        let mut r = Vec::with_capacity(self.excess.len() + 1);
        r.extend(self.excess.iter().map(|x| x - t));
        r.push(0.0); // the roots' scratch slot
        let mut negative = 0;
        for (v, &(p, a)) in self.up.iter().enumerate() {
            let rv = r[v];
            let mut d = rv - a;
            if d <= 0.0 {
                negative += 1;
                if d == 0.0 {
                    d = -f64::EPSILON * (1.0 + t.abs());
                }
            }
            let f = a / d;
            r[p] -= f * rv;
        }
        negative
    }
}

/// A `B × B` block.
pub type Block<const B: usize> = [[f64; B]; B];

/// A symmetric block matrix on an [`Elimination`]'s pattern.
#[derive(Debug, Clone)]
pub struct BlockSym<const B: usize> {
    /// Diagonal blocks, one per node, by position in the order.
    pub diag: Vec<Block<B>>,
    /// Off-diagonal blocks `A_{x,y}` (x eliminated first), one per slot of
    /// the filled pattern (0 for fill).
    pub off: Vec<Block<B>>,
}

impl<const B: usize> BlockSym<B> {
    /// The matrix with diagonal blocks `diag` (by position) and no
    /// off-diagonal block yet.
    #[must_use]
    pub fn new(g: &Elimination, diag: Vec<Block<B>>) -> Self {
        Self {
            diag,
            off: vec![[[0.0; B]; B]; g.filled_entries()],
        }
    }

    /// Sets the off-diagonal block `A_{i,j}` (and so `A_{j,i} = A_{i,j}ᵀ`).
    pub fn set(&mut self, g: &Elimination, i: usize, j: usize, a: &Block<B>) {
        let (k, first) = g.slot(i, j);
        self.off[k] = if first { *a } else { transpose(a) };
    }

    /// Whether the matrix is positive definite: a block Cholesky in the
    /// order of `g` succeeds. Returns the smallest diagonal entry of the
    /// Cholesky factor, squared (a pivot), or `None` when a pivot block is
    /// not positive definite.
    #[must_use]
    pub fn smallest_cholesky_pivot(&self, g: &Elimination) -> Option<f64> {
        let mut diag = self.diag.clone();
        let mut off = self.off.clone();
        let mut smallest = f64::INFINITY;
        for v in 0..g.len() {
            let l = cholesky(&diag[v])?;
            (0..B).for_each(|k| smallest = smallest.min(l[k][k] * l[k][k]));
            let row = g.row(v);
            let w: Vec<Block<B>> = off[row.clone()]
                .iter()
                .map(|m| forward_solve(&l, m))
                .collect();
            for ia in row.clone() {
                let wa = &w[ia - row.start];
                let a = g.later[ia];
                subtract_at_b(&mut diag[a], wa, wa);
                for ib in ia + 1..row.end {
                    let b = g.later[ib];
                    let wb = &w[ib - row.start];
                    let k = g.entry(a, b);
                    if a < b {
                        subtract_at_b(&mut off[k], wa, wb);
                    } else {
                        subtract_at_b(&mut off[k], wb, wa);
                    }
                }
            }
        }
        Some(smallest)
    }
}

/// Lower Cholesky factor of a symmetric block, `None` unless positive definite.
fn cholesky<const B: usize>(s: &Block<B>) -> Option<Block<B>> {
    let mut l = [[0.0; B]; B];
    for j in 0..B {
        let d = s[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        l[j][j] = d.sqrt();
        for i in j + 1..B {
            let x = s[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = x / l[j][j];
        }
    }
    Some(l)
}

/// `L⁻¹ M` for a lower triangular `L`.
fn forward_solve<const B: usize>(l: &Block<B>, m: &Block<B>) -> Block<B> {
    let mut x = [[0.0; B]; B];
    for c in 0..B {
        for i in 0..B {
            let s = m[i][c] - (0..i).map(|k| l[i][k] * x[k][c]).sum::<f64>();
            x[i][c] = s / l[i][i];
        }
    }
    x
}

/// `acc −= Aᵀ B`.
fn subtract_at_b<const B: usize>(acc: &mut Block<B>, a: &Block<B>, b: &Block<B>) {
    for (i, row) in acc.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x -= (0..B).map(|k| a[k][i] * b[k][j]).sum::<f64>();
        }
    }
}

fn transpose<const B: usize>(a: &Block<B>) -> Block<B> {
    let mut t = [[0.0; B]; B];
    for (i, row) in a.iter().enumerate() {
        for (j, x) in row.iter().enumerate() {
            t[j][i] = *x;
        }
    }
    t
}
