//! Checks on the whole graph: every agent reachable from the leader
//! (Assumption 1), the spectrum of `Ξ + LLᵀ` and Theorem 1's gain condition
//! (Appendix D).

use super::ctx::Ctx;
use super::graph::{Adjacency, LeaderLinks};
use super::ids::Ids;
use super::theory::Departure;
use attitude::checks::{
    appendix_d_min_eigenvalue_from_extremes, xi_plus_laplacian, xi_plus_laplacian_extremes,
};
use attitude::network::Scheme;
use nalgebra::{DMatrix, Matrix3};

/// Every agent of `ids` must be reachable from the leader through edges
/// (both ways) and one-way edges `arcs` (sender to receiver, by rank);
/// checked only when there is a leader link at all.
pub(super) fn reachability(
    c: &mut Ctx,
    ids: &Ids,
    (adj, arcs): (&Adjacency, &[(usize, usize)]),
    links: &LeaderLinks,
    any_link: bool,
) {
    if !any_link {
        return;
    }
    let mut reached = vec![false; ids.len()];
    let mut stack: Vec<usize> = links.linked().collect();
    for &r in &stack {
        reached[r] = true;
    }
    let mut out: Vec<Vec<usize>> = vec![Vec::new(); if arcs.is_empty() { 0 } else { ids.len() }];
    for &(a, b) in arcs {
        out[a].push(b);
    }
    while let Some(x) = stack.pop() {
        let one_way = out.get(x).into_iter().flatten().copied();
        for y in adj.of(x).iter().map(|&(y, _)| y).chain(one_way) {
            if !reached[y] {
                reached[y] = true;
                stack.push(y);
            }
        }
    }
    let mut unreachable = Vec::new();
    for (r, (id, k)) in ids.iter().enumerate() {
        if !reached[r] && !c.theory_off {
            c.err(
                format!("agent[{k}]"),
                format!("agent {id} is not reachable from the leader: no [[leader_link]] in its connected component (Assumption 1; `[graph] assumptions = \"off\"` allows it)"),
            );
        } else if !reached[r] {
            unreachable.push(id);
        }
    }
    if !unreachable.is_empty() {
        unreachable.sort_unstable();
        let d = Departure::Unreachable {
            agents: unreachable,
        };
        c.departures.push(d);
    }
}

/// Up to this many agents the full spectrum of `Ξ + LLᵀ` is computed
/// (dense) and printed; beyond, only its extremes and count.
pub(super) const FULL_SPECTRUM_UP_TO: usize = 50;

/// What the graph's matrices say (`Ξ + LLᵀ` has one eigenvalue per agent).
pub(super) struct Spectrum {
    /// Smallest eigenvalue of `Ξ + LLᵀ` (`NaN` without agents).
    pub(super) lambda_min: f64,
    /// Largest eigenvalue of `Ξ + LLᵀ` (`NaN` without agents).
    pub(super) lambda_max: f64,
    /// Every eigenvalue of `Ξ + LLᵀ`, ascending, only up to
    /// [`FULL_SPECTRUM_UP_TO`] agents (empty beyond).
    pub(super) eigenvalues: Vec<f64>,
    /// Smallest eigenvalue of Appendix D's `F` (scheme 1 without errors).
    pub(super) appendix_d_min_eig: Option<f64>,
}

/// The spectrum of `Ξ + LLᵀ` (sparse: extremes by bisection, no dense
/// matrix beyond [`FULL_SPECTRUM_UP_TO`] agents), and (scheme 1, only on a
/// consistent scenario) Appendix D's condition, a warning when it fails.
pub(super) fn spectrum(
    c: &mut Ctx,
    idx_edges: &[(usize, usize)],
    links: &LeaderLinks,
    scheme: Option<&Scheme>,
    p: &Matrix3<f64>,
) -> Spectrum {
    let xi: Vec<bool> = links.seen.iter().map(Option::is_some).collect();
    let n = xi.len();
    let (lambda_min, lambda_max) = xi_plus_laplacian_extremes(n, idx_edges, &xi);
    let mut appendix_d_min_eig = None;
    if let Some(Scheme::ObserverTimeVarying { observer, .. }) = scheme {
        if c.errors.is_empty() {
            let m = appendix_d_min_eigenvalue_from_extremes(
                (lambda_min, lambda_max),
                observer.k_w,
                observer.k_sigma,
                p,
            );
            appendix_d_min_eig = Some(m);
            if m <= 0.0 {
                c.warn(
                    "scheme.observer",
                    format!("the sufficient gain condition of Theorem 1 fails: the matrix F of Appendix D is not positive definite (smallest eigenvalue {m:.3e}); convergence is not guaranteed (raise k_omega or k_sigma)"),
                );
            }
        }
    }
    let eigenvalues = if n <= FULL_SPECTRUM_UP_TO {
        sorted_eigs(&xi_plus_laplacian(n, idx_edges, &xi))
    } else {
        Vec::new()
    };
    Spectrum {
        lambda_min,
        lambda_max,
        eigenvalues,
        appendix_d_min_eig,
    }
}

fn sorted_eigs(m: &DMatrix<f64>) -> Vec<f64> {
    if m.nrows() == 0 {
        return Vec::new();
    }
    let mut e: Vec<f64> = m.clone().symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    e
}
