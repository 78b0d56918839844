//! The sparse spectrum of `Ξ + LLᵀ` and Appendix `appenD`'s test against
//! their dense references (module `spectrum`, `sparse`).
//!
//! - `λmin`, `λmax` of `Ξ + LLᵀ` by bisection on Sylvester counts equal the
//!   dense eigenvalues to 1e-9 relative, on the paper's graph, random trees
//!   up to N = 300, paths, stars, forests with several leader links, a graph
//!   with a cycle (fill-in) and repeated edges; a component without a leader
//!   link gives `λmin = 0`.
//! - The count of eigenvalues below `t` equals the dense count.
//! - On a forest the elimination order makes no fill-in.
//! - `λmin(F)` from the extremes (the Kronecker/commuting argument of
//!   `appendix_d_min_eigenvalue_from_extremes`) equals the dense `λmin(F)`,
//!   and the block Cholesky decides `F ≻ 0` exactly as the dense one, over a
//!   grid of gains and general (not only the paper's) `P`.

use attitude::checks::{
    appendix_d_f, appendix_d_min_eigenvalue, appendix_d_min_eigenvalue_from_extremes,
    appendix_d_smallest_pivot, xi_plus_laplacian, xi_plus_laplacian_extremes,
};
use attitude::sparse::Elimination;
use attitude::spectrum::XiPlusLaplacian;
use nalgebra::{DMatrix, Matrix3};

/// A graph: order, edges, Ξ.
type Graph = (usize, Vec<(usize, usize)>, Vec<bool>);

/// xorshift64*, deterministic.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }

    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A random recursive tree on `n` nodes (labels shuffled) with `links`
/// random leader links (node of the first link always linked).
fn random_tree(rng: &mut Rng, n: usize, links: usize) -> Graph {
    let mut perm: Vec<usize> = (0..n).collect();
    for k in (1..n).rev() {
        perm.swap(k, rng.below(k + 1));
    }
    let edges = (1..n).map(|k| (perm[rng.below(k)], perm[k])).collect();
    let mut xi = vec![false; n];
    xi[perm[rng.below(n)]] = true;
    for _ in 1..links {
        xi[rng.below(n)] = true;
    }
    (n, edges, xi)
}

fn path(n: usize) -> Graph {
    let mut xi = vec![false; n];
    xi[0] = true;
    (n, (1..n).map(|k| (k - 1, k)).collect(), xi)
}

fn star(n: usize) -> Graph {
    let mut xi = vec![false; n];
    xi[n - 1] = true;
    (n, (1..n).map(|k| (0, k)).collect(), xi)
}

/// Three paths and a star, each with its own leader links.
fn forest() -> Graph {
    let mut edges = Vec::new();
    let mut xi = vec![false; 40];
    for (s, len) in [(0, 10), (10, 7), (17, 13)] {
        edges.extend((s + 1..s + len).map(|k| (k - 1, k)));
        xi[s + len / 2] = true;
    }
    edges.extend((31..40).map(|k| (30, k)));
    xi[0] = true;
    xi[33] = true;
    xi[39] = true;
    (40, edges, xi)
}

/// A wheel-like graph with cycles (and a chord), one leader link.
fn with_cycles() -> Graph {
    let n = 25;
    let mut edges: Vec<(usize, usize)> = (1..n).map(|k| (k - 1, k)).collect();
    edges.extend([(n - 1, 0), (0, 12), (5, 20), (3, 9), (9, 15)]);
    let mut xi = vec![false; n];
    xi[7] = true;
    (n, edges, xi)
}

fn dense_eigs((n, edges, xi): &Graph) -> Vec<f64> {
    let mut e: Vec<f64> = xi_plus_laplacian(*n, edges, xi)
        .symmetric_eigenvalues()
        .iter()
        .copied()
        .collect();
    e.sort_by(f64::total_cmp);
    e
}

fn assert_close(got: f64, want: f64, rel: f64, what: &str) {
    assert!(
        (got - want).abs() <= rel * want.abs().max(1e-300),
        "{what}: sparse {got:e}, dense {want:e}, relative {:e}",
        ((got - want) / want).abs()
    );
}

fn assert_extremes_match(g: &Graph, what: &str) {
    let (n, edges, xi) = g;
    let e = dense_eigs(g);
    let (lo, hi) = xi_plus_laplacian_extremes(*n, edges, xi);
    assert_close(lo, e[0], 1e-9, &format!("{what} λmin"));
    assert_close(hi, e[n - 1], 1e-9, &format!("{what} λmax"));
}

fn paper() -> Graph {
    let mut xi = vec![false; 7];
    xi[0] = true;
    xi[1] = true;
    (7, vec![(0, 2), (1, 6), (2, 4), (2, 5), (3, 4)], xi)
}

#[test]
fn extremes_match_dense_on_the_paper_graph_paths_stars_and_forests() {
    assert_extremes_match(&paper(), "paper");
    for n in [1, 2, 3, 10, 100, 300] {
        assert_extremes_match(&path(n), &format!("path {n}"));
    }
    for n in [2, 5, 50, 300] {
        assert_extremes_match(&star(n), &format!("star {n}"));
    }
    assert_extremes_match(&forest(), "forest");
}

#[test]
fn extremes_match_dense_on_random_trees() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for k in 0..40 {
        let n = 1 + rng.below(300);
        let links = 1 + rng.below(4);
        let g = random_tree(&mut rng, n, links);
        assert_extremes_match(&g, &format!("tree #{k} (N = {n}, {links} links)"));
    }
}

#[test]
fn extremes_match_dense_with_cycles_and_repeated_edges() {
    let g = with_cycles();
    assert!(Elimination::min_degree(g.0, &g.1).filled_entries() > g.1.len() - 5);
    assert_extremes_match(&g, "cycles");
    let (n, mut edges, xi) = path(12);
    edges.extend([(3, 4), (3, 4), (7, 7)]);
    assert_extremes_match(&(n, edges, xi), "repeated edges and a self-loop");
}

#[test]
fn a_component_without_a_leader_link_has_lambda_min_zero() {
    let (n, mut edges, mut xi) = path(6);
    edges.push((6, 7));
    xi.extend([false, false]);
    let (lo, hi) = xi_plus_laplacian_extremes(n + 2, &edges, &xi);
    assert_eq!(lo, 0.0);
    assert_close(
        hi,
        *dense_eigs(&(n + 2, edges, xi)).last().unwrap(),
        1e-9,
        "λmax",
    );
}

#[test]
fn forests_eliminate_without_fill_in() {
    let mut rng = Rng(7);
    for g in [
        path(200),
        star(200),
        forest(),
        random_tree(&mut rng, 500, 3),
    ] {
        let e = Elimination::min_degree(g.0, &g.1);
        assert_eq!(e.filled_entries(), g.1.len());
    }
}

#[test]
fn counts_below_a_threshold_match_dense() {
    let mut rng = Rng(42);
    for g in [
        paper(),
        forest(),
        with_cycles(),
        random_tree(&mut rng, 150, 2),
    ] {
        let e = dense_eigs(&g);
        let m = XiPlusLaplacian::new(g.0, &g.1, &g.2);
        for _ in 0..50 {
            let t = rng.unit() * (e[e.len() - 1] + 1.0) - 0.5;
            if e.iter().any(|x| (x - t).abs() < 1e-9) {
                continue;
            }
            let want = e.iter().filter(|&&x| x < t).count();
            assert_eq!(m.eigenvalues_below(t), want, "t = {t}");
        }
    }
}

fn random_p(rng: &mut Rng) -> Matrix3<f64> {
    Matrix3::from_fn(|_, _| 2.0 * rng.unit() - 1.0)
}

fn paper_p() -> Matrix3<f64> {
    let a = 3.0 * std::f64::consts::PI / 4.0;
    Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, a.cos(), 0.0, a.sin(), 0.0)
}

/// Closed form and block Cholesky against the dense `F`, one graph, one `P`.
fn check_appendix_d(g: &Graph, p: &Matrix3<f64>, seen: &mut [bool; 2]) {
    let (n, edges, xi) = g;
    let f1: DMatrix<f64> = xi_plus_laplacian(*n, edges, xi);
    let ext = xi_plus_laplacian_extremes(*n, edges, xi);
    for k_w in [1e-3, 0.1, 1.0, 14.0] {
        for k_s in [1e-3, 0.1, 1.0, 12.0, 100.0, 1e4] {
            let dense = appendix_d_min_eigenvalue(&f1, k_w, k_s, p);
            let fast = appendix_d_min_eigenvalue_from_extremes(ext, k_w, k_s, p);
            let scale = appendix_d_f(&f1, k_w, k_s, p).amax();
            let what = format!("N = {n}, k_ω = {k_w}, k_σ = {k_s}");
            assert!(
                (fast - dense).abs() <= 1e-9 * scale,
                "{what}: {fast:e} vs {dense:e}"
            );
            let pd = appendix_d_f(&f1, k_w, k_s, p).cholesky().is_some();
            let pivot = appendix_d_smallest_pivot(*n, edges, xi, k_w, k_s, p);
            if dense.abs() > 1e-9 * scale {
                assert_eq!(pivot.is_some(), pd, "{what}: block vs dense Cholesky");
                assert_eq!(fast > 0.0, pd, "{what}: closed form vs dense Cholesky");
            }
            seen[usize::from(pd)] = true;
        }
    }
}

#[test]
fn appendix_d_fast_tests_match_dense() {
    let mut rng = Rng(2026);
    let mut seen = [false; 2];
    check_appendix_d(&paper(), &paper_p(), &mut seen);
    check_appendix_d(&forest(), &random_p(&mut rng), &mut seen);
    check_appendix_d(&with_cycles(), &random_p(&mut rng), &mut seen);
    for _ in 0..6 {
        let n = 1 + rng.below(30);
        let links = 1 + rng.below(3);
        let g = random_tree(&mut rng, n, links);
        check_appendix_d(&g, &random_p(&mut rng), &mut seen);
    }
    assert_eq!(seen, [true, true], "the grid must straddle the boundary");
}
