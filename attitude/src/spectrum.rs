//! The spectrum of `Ξ + LLᵀ` (`F₁` of Appendix `appenD` without `⊗ I₃`)
//! and Appendix `appenD`'s condition `F ≻ 0`, without a dense matrix.
//!
//! `L` is the oriented incidence matrix of the follower graph (eq. `LG`),
//! so `LLᵀ` is its graph Laplacian and `Ξ + LLᵀ` a Laplacian plus a 0/1
//! diagonal: its rows sum to `Ξᵢ`. On a forest (Assumption 1) the
//! factorisations of [`crate::sparse`] run leaves first with no fill-in, so
//! a count of eigenvalues below a threshold is `O(N)` and the extremes,
//! found by bisection on that count, `O(N log(1/ε))`. Other graphs work too
//! (with fill-in).

use crate::sparse::{Block, BlockSym, Elimination, ForestSym, ScalarSym};
use nalgebra::Matrix3;

/// Relative width at which a bisection stops (a few ulps).
const REL: f64 = 4.0 * f64::EPSILON;

/// `Ξ + LLᵀ` as a sparse matrix with its elimination order.
#[derive(Debug, Clone)]
pub struct XiPlusLaplacian {
    g: Elimination,
    a: ScalarSym,
    /// `a` laid out for a forest (every graph of Assumption 1): its counts
    /// take one pass, the same arithmetic.
    forest: Option<ForestSym>,
    /// Smallest and largest diagonal entry (`λmin ≤` the first, `λmax ≥` the second).
    diag: (f64, f64),
    /// Gershgorin's bound on `λmax`.
    gershgorin: f64,
}

impl XiPlusLaplacian {
    /// The matrix of [`crate::checks::xi_plus_laplacian`], sparse: `edges`
    /// are pairs of indices in `0..n` (a repeated pair counts twice, a
    /// self-loop not at all, as in the dense matrix); `xi[i]` is `Ξᵢ`.
    ///
    /// # Panics
    /// If an edge names an index `≥ n`, or `xi` is shorter than `n`.
    #[must_use]
    pub fn new(n: usize, edges: &[(usize, usize)], xi: &[bool]) -> Self {
        let g = Elimination::min_degree(n, edges);
        let mut off = vec![0.0; g.filled_entries()];
        let mut degree = vec![0.0; n];
        for &(i, j) in edges.iter().filter(|(i, j)| i != j) {
            off[g.slot(i, j).0] -= 1.0;
            degree[i] += 1.0;
            degree[j] += 1.0;
        }
        let mut excess = vec![0.0; n];
        for i in 0..n {
            excess[g.position(i)] = f64::from(u8::from(xi[i]));
        }
        let xi_i = |i: usize| f64::from(u8::from(xi[i]));
        let diag = (0..n).fold((f64::INFINITY, 0.0_f64), |(lo, hi), i| {
            (lo.min(degree[i] + xi_i(i)), hi.max(degree[i] + xi_i(i)))
        });
        let gershgorin = (0..n)
            .map(|i| 2.0 * degree[i] + xi_i(i))
            .fold(0.0, f64::max);
        let a = ScalarSym { excess, off };
        Self {
            forest: a.on_forest(&g),
            g,
            a,
            diag,
            gershgorin,
        }
    }

    /// Order `N`.
    #[must_use]
    pub fn len(&self) -> usize {
        self.g.len()
    }

    /// Whether `N = 0`.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.g.is_empty()
    }

    /// Number of eigenvalues below `t` (Sylvester's law of inertia on `LDLᵀ`).
    #[must_use]
    pub fn eigenvalues_below(&self, t: f64) -> usize {
        match &self.forest {
            Some(f) => f.eigenvalues_below(t),
            None => self.a.eigenvalues_below(&self.g, t),
        }
    }

    /// `(λmin, λmax)`, each to a few ulps of the bisection (the count's own
    /// rounding aside); `λmin = 0` when the matrix is singular (a component
    /// without a leader link). `(NaN, NaN)` when `N = 0`.
    #[must_use]
    pub fn extremes(&self) -> (f64, f64) {
        let n = self.len();
        if n == 0 {
            return (f64::NAN, f64::NAN);
        }
        let lambda_min = if self.eigenvalues_below(0.0) > 0 {
            0.0
        } else {
            bisect(0.0, self.diag.0, |t| self.eigenvalues_below(t) > 0)
        };
        let lambda_max = bisect(self.diag.1, self.gershgorin, |t| {
            self.eigenvalues_below(t) == n
        });
        (lambda_min, lambda_max)
    }
}

/// The point where the monotone predicate `above` turns true in `[lo, hi]`
/// (`above(lo)` false or `lo` the answer, `above(hi)` true or `hi` the answer).
fn bisect(mut lo: f64, mut hi: f64, above: impl Fn(f64) -> bool) -> f64 {
    if !above(hi) {
        return hi;
    }
    loop {
        let mid = 0.5 * (lo + hi);
        if hi - lo <= REL * hi.abs() || mid <= lo || mid >= hi {
            return 0.5 * (lo + hi);
        }
        if above(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
}

/// `(λmin, λmax)` of `Ξ + LLᵀ` (see [`XiPlusLaplacian::extremes`]), with
/// `O(N)` memory and `O(N)` work per bisection step on a forest.
#[must_use]
pub fn xi_plus_laplacian_extremes(n: usize, edges: &[(usize, usize)], xi: &[bool]) -> (f64, f64) {
    XiPlusLaplacian::new(n, edges, xi).extremes()
}

/// `λmin(F)` of Appendix `appenD`, exactly, from the extremes of `Ξ + LLᵀ`.
///
/// # Equation
/// ```text
/// F = [ k_ω M ⊗ I₃   −½ I ;  −½ I   k_σ M ⊗ I₃ − I_N ⊗ Q ],   M = Ξ + LLᵀ,  Q = ½(P + Pᵀ)
/// ```
/// `M ⊗ I₃` and `I_N ⊗ Q` commute, so on the common eigenvectors
/// `u ⊗ q` (`Mu = μu`, `Qq = θq`) `F` is the 2 × 2 matrix
/// `G(μ, θ) = [k_ω μ, −½; −½, k_σ μ − θ]`. `λmin(G)` falls as `θ` grows,
/// so the worst `θ` is `λmax(Q)`, and it is concave in `μ` (the smallest
/// eigenvalue of a matrix affine in `μ`), so its minimum over
/// `μ ∈ [λmin(M), λmax(M)]` lies at an end:
/// `λmin(F) = min(λmin G(λmin M, λmax Q), λmin G(λmax M, λmax Q))`.
#[must_use]
pub fn appendix_d_min_eigenvalue_from_extremes(
    (lambda_min, lambda_max): (f64, f64),
    k_w: f64,
    k_sigma: f64,
    p: &Matrix3<f64>,
) -> f64 {
    let theta = worst_theta(p);
    let g_min = |mu: f64| {
        let (a, b) = (k_w * mu, k_sigma * mu - theta);
        let (mean, radius) = (0.5 * (a + b), (0.25 * (a - b) * (a - b) + 0.25).sqrt());
        if mean > 0.0 {
            (a * b - 0.25) / (mean + radius) // the product of the two, without cancellation
        } else {
            mean - radius
        }
    };
    g_min(lambda_min).min(g_min(lambda_max))
}

/// `λmax(Q)`, `Q = ½(P + Pᵀ)`: the `θ` at which `λmin G(μ, θ)` is smallest
/// ([`appendix_d_min_eigenvalue_from_extremes`]).
fn worst_theta(p: &Matrix3<f64>) -> f64 {
    ((p + p.transpose()) * 0.5).symmetric_eigenvalues().max()
}

/// The boundary `k_σ*` of Appendix `appenD`'s `F ≻ 0` at `k_ω > 0`: `F ≻ 0`
/// iff `k_σ > k_σ*` (the sign of [`appendix_d_min_eigenvalue_from_extremes`]).
///
/// # Equation
/// ```text
/// G(μ, θ) ≻ 0  ⇔  k_ω μ > 0  and  det G = k_ω μ (k_σ μ − θ) − ¼ > 0
///             ⇔  k_σ > (θ + 1/(4 k_ω μ)) / μ
/// k_σ* = max over μ ∈ {λmin, λmax} of that (0 if negative), θ = λmax(Q)
/// ```
/// The bound is convex in `μ > 0` (`a/μ² + θ/μ`, `a > 0`: a minimum and no
/// interior maximum), so its maximum over `[λmin, λmax]` is at an end.
/// Infinite when `λmin = 0` (a component without a leader link).
///
/// ```
/// # use attitude::spectrum::*;
/// # use nalgebra::Matrix3;
/// let p = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.3, -0.5, 0.0, 0.5, 0.0); // θ = 0.3
/// let (ext, k_w) = ((0.05, 3.9), 14.0);
/// let k = appendix_d_k_sigma_threshold(ext, k_w, &p);
/// assert!(appendix_d_min_eigenvalue_from_extremes(ext, k_w, k * 1.001, &p) > 0.0);
/// assert!(appendix_d_min_eigenvalue_from_extremes(ext, k_w, k * 0.999, &p) < 0.0);
/// ```
#[must_use]
pub fn appendix_d_k_sigma_threshold(extremes: (f64, f64), k_w: f64, p: &Matrix3<f64>) -> f64 {
    let theta = worst_theta(p);
    [extremes.0, extremes.1]
        .iter()
        .map(|&mu| {
            if mu > 0.0 {
                (1.0 / (4.0 * k_w * mu) + theta) / mu
            } else {
                f64::INFINITY
            }
        })
        .fold(0.0, f64::max)
}

/// The smallest `k` with `k ≥ margin · k_σ*(k_ω = k)`
/// ([`appendix_d_k_sigma_threshold`]): equal gains `k_σ = k_ω = k` that
/// satisfy `F ≻ 0` with `k_σ` to spare by the factor `margin ≥ 1`.
///
/// # Equation
/// ```text
/// per μ, x = k μ:  x ≥ margin (θ + 1/(4x))  ⇔  x² − margin θ x − margin/4 ≥ 0
///                  ⇔  k μ ≥ (margin θ + √(margin² θ² + margin)) / 2
/// ```
/// The largest over the two ends is at `λmin`. For `θ = 0` the condition is
/// on the product, `k_σ k_ω λmin² ≥ margin/4`: `k = √margin / (2 λmin)`.
/// Infinite when `λmin = 0`.
///
/// ```
/// # use attitude::spectrum::*;
/// # use nalgebra::Matrix3;
/// let p = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.3, -0.5, 0.0, 0.5, 0.0); // θ = 0.3
/// let ext = (0.01, 3.9);
/// let k = appendix_d_balanced_gain(ext, &p, 1.25);
/// approx::assert_relative_eq!(k, 1.25 * appendix_d_k_sigma_threshold(ext, k, &p), max_relative = 1e-12);
/// ```
#[must_use]
pub fn appendix_d_balanced_gain(extremes: (f64, f64), p: &Matrix3<f64>, margin: f64) -> f64 {
    let theta = worst_theta(p);
    let x = 0.5 * (margin * theta + (margin * margin * theta * theta + margin).sqrt());
    [extremes.0, extremes.1]
        .iter()
        .map(|&mu| if mu > 0.0 { x / mu } else { f64::INFINITY })
        .fold(0.0, f64::max)
}

/// Appendix `appenD`'s test `F ≻ 0` by a block Cholesky of `F` with one
/// 6 × 6 block per agent (`[xᵢ; σᵢ]`), in the elimination order of the
/// graph: leaves first, no fill-in on a forest. Returns the smallest pivot
/// (see [`BlockSym::smallest_cholesky_pivot`]), `None` when `F` is not
/// positive definite. Arguments as in [`xi_plus_laplacian_extremes`].
#[must_use]
pub fn appendix_d_smallest_pivot(
    n: usize,
    edges: &[(usize, usize)],
    xi: &[bool],
    k_w: f64,
    k_sigma: f64,
    p: &Matrix3<f64>,
) -> Option<f64> {
    let g = Elimination::min_degree(n, edges);
    let mut m: Vec<f64> = (0..n).map(|i| f64::from(u8::from(xi[i]))).collect();
    for &(i, j) in edges.iter().filter(|(i, j)| i != j) {
        m[i] += 1.0;
        m[j] += 1.0;
    }
    let pp = p + p.transpose();
    let mut by_position = vec![0.0; n];
    for (i, &mii) in m.iter().enumerate() {
        by_position[g.position(i)] = mii;
    }
    let diag = by_position
        .iter()
        .map(|&mii| {
            let mut b: Block<6> = [[0.0; 6]; 6];
            for r in 0..3 {
                b[r][r] = k_w * mii;
                b[r][r + 3] = -0.5;
                b[r + 3][r] = -0.5;
                for c in 0..3 {
                    b[r + 3][c + 3] =
                        f64::from(u8::from(r == c)) * k_sigma * mii - 0.5 * pp[(r, c)];
                }
            }
            b
        })
        .collect();
    let mut f = BlockSym::new(&g, diag);
    for &(i, j) in edges.iter().filter(|(i, j)| i != j) {
        let (k, _) = g.slot(i, j);
        for r in 0..3 {
            f.off[k][r][r] -= k_w;
            f.off[k][r + 3][r + 3] -= k_sigma;
        }
    }
    f.smallest_cholesky_pivot(&g)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random forest on `n` nodes (each node's parent a uniformly chosen
    /// earlier node, or none) and a random `Ξ`, from a SplitMix stream.
    fn forest(n: usize, seed: u64) -> (Vec<(usize, usize)>, Vec<bool>) {
        let mut x = seed;
        let mut next = move || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let edges = (1..n)
            .filter_map(|k| {
                let p = (next() % (k as u64 + 1)) as usize;
                (p < k).then_some((p, k))
            })
            .collect();
        let xi = (0..n).map(|_| next() % 5 == 0).collect();
        (edges, xi)
    }

    /// The forest loop counts what the general loop counts, at every
    /// threshold a bisection visits (and at the extremes themselves).
    #[test]
    fn the_forest_count_is_the_general_count() {
        for (n, seed) in [(1, 1), (2, 2), (7, 3), (60, 4), (500, 5), (3000, 6)] {
            let (edges, xi) = forest(n, seed);
            let m = XiPlusLaplacian::new(n, &edges, &xi);
            assert!(m.forest.is_some(), "{n}");
            let (lo, hi) = m.extremes();
            let mut ts = vec![0.0, lo, hi, -1.0, m.gershgorin, m.diag.0, m.diag.1];
            ts.extend((0..200).map(|k| lo + (hi - lo) * f64::from(k) / 199.0));
            ts.extend([lo * (1.0 + 1e-15), lo * (1.0 - 1e-15), hi * (1.0 + 1e-15)]);
            for t in ts {
                assert_eq!(
                    m.eigenvalues_below(t),
                    m.a.eigenvalues_below(&m.g, t),
                    "n = {n}, t = {t}"
                );
            }
        }
    }
}
