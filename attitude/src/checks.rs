//! Conditions the paper puts on gains, inertias and the leader generator.
//! Pure predicates; the orchestrator turns failures into messages.

use nalgebra::{DMatrix, Matrix3};

pub use crate::spectrum::{
    appendix_d_min_eigenvalue_from_extremes, appendix_d_smallest_pivot, xi_plus_laplacian_extremes,
};

/// Relative tolerance for symmetry checks.
const SYM_TOL: f64 = 1e-12;

/// Whether `m` is symmetric (to 1e-12 relative) and positive definite.
#[must_use]
pub fn is_spd(m: &Matrix3<f64>) -> bool {
    let scale = m.amax().max(f64::MIN_POSITIVE);
    (m - m.transpose()).amax() <= SYM_TOL * scale && m.cholesky().is_some()
}

/// Eigenvalues of a symmetric matrix, ascending.
#[must_use]
pub fn sym_eigenvalues(m: &Matrix3<f64>) -> [f64; 3] {
    let mut e: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
    e.sort_by(f64::total_cmp);
    [e[0], e[1], e[2]]
}

/// Whether the symmetric matrix `m` has three distinct eigenvalues (gaps
/// larger than 1e-9 of the largest magnitude), as the paper asks of every `A`.
#[must_use]
pub fn has_distinct_eigenvalues(m: &Matrix3<f64>) -> bool {
    let e = sym_eigenvalues(m);
    let tol = 1e-9 * e[0].abs().max(e[2].abs()).max(f64::MIN_POSITIVE);
    e[1] - e[0] > tol && e[2] - e[1] > tol
}

/// The paper's condition on the leader generator (eq. `leader`): the
/// eigenvalues on the imaginary axis are simple and non-zero, all others
/// have negative real part. Tolerance `1e-9` on the real parts.
#[must_use]
pub fn p_is_admissible(p: &Matrix3<f64>) -> bool {
    let ev = p.complex_eigenvalues();
    let tol = 1e-9 * p.amax().max(1.0);
    for (k, l) in ev.iter().enumerate() {
        if l.re > tol {
            return false;
        }
        if l.re.abs() <= tol {
            if l.im.abs() <= tol {
                return false; // zero eigenvalue
            }
            let repeated = ev
                .iter()
                .enumerate()
                .any(|(m, o)| m != k && (o - l).norm() <= 1e-6 * p.amax().max(1.0));
            if repeated {
                return false;
            }
        }
    }
    true
}

/// `Ξ + LLᵀ` (N × N, dense: the reference for small N; see
/// [`crate::spectrum`] for large N): the Laplacian of the follower graph plus the leader
/// incidence on the diagonal (`F₁` of Appendix `appenD` without `⊗ I₃`).
///
/// `edges` are pairs of indices in `0..n`; `xi[i]` is `Ξᵢ`.
#[must_use]
pub fn xi_plus_laplacian(n: usize, edges: &[(usize, usize)], xi: &[bool]) -> DMatrix<f64> {
    let mut m = DMatrix::zeros(n, n);
    for &(i, j) in edges {
        m[(i, i)] += 1.0;
        m[(j, j)] += 1.0;
        m[(i, j)] -= 1.0;
        m[(j, i)] -= 1.0;
    }
    for (i, &x) in xi.iter().enumerate() {
        if x {
            m[(i, i)] += 1.0;
        }
    }
    m
}

/// The matrix `F` of Appendix `appenD` (proof of Theorem `estimationstability`):
///
/// ```text
/// F = [ k_ω F₁   −½ I ;  −½ I   F₂ ],  F₁ = (Ξ + LLᵀ) ⊗ I₃,
/// F₂ = k_σ F₁ − ½ (I_N ⊗ (P + Pᵀ))
/// ```
#[must_use]
pub fn appendix_d_f(f1: &DMatrix<f64>, k_w: f64, k_sigma: f64, p: &Matrix3<f64>) -> DMatrix<f64> {
    let n = f1.nrows();
    let m = 3 * n;
    let f1k = f1.kronecker(&DMatrix::<f64>::identity(3, 3));
    let pp = p + p.transpose();
    let mut f = DMatrix::zeros(2 * m, 2 * m);
    f.view_mut((0, 0), (m, m)).copy_from(&(&f1k * k_w));
    let mut f2 = &f1k * k_sigma;
    for b in 0..n {
        for r in 0..3 {
            for c in 0..3 {
                f2[(3 * b + r, 3 * b + c)] -= 0.5 * pp[(r, c)];
            }
        }
    }
    f.view_mut((m, m), (m, m)).copy_from(&f2);
    for k in 0..m {
        f[(k, m + k)] = -0.5;
        f[(m + k, k)] = -0.5;
    }
    f
}

/// Scheme 1's sufficient gain condition, tested exactly: `F` (see
/// [`appendix_d_f`]) is positive definite. Returns the smallest eigenvalue of
/// `F` (the condition holds iff it is > 0).
///
/// # NOTE
/// The paper turns this into the bound
/// `k_σ > (λmin(F₁⁻¹) − 4k_ω λmin(−½(P+Pᵀ))) / (4k_ω λmin(F₁))` through a
/// misuse of Weyl's inequality; the eigenvalue of `F` itself is the exact test.
/// Dense (`6N × 6N`): the reference; [`appendix_d_min_eigenvalue_from_extremes`]
/// gives the same figure from the extremes of `Ξ + LLᵀ`.
#[must_use]
pub fn appendix_d_min_eigenvalue(
    f1: &DMatrix<f64>,
    k_w: f64,
    k_sigma: f64,
    p: &Matrix3<f64>,
) -> f64 {
    appendix_d_f(f1, k_w, k_sigma, p)
        .symmetric_eigenvalues()
        .min()
}
