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
///
/// # NOTE
/// A diagonal matrix (every gain and inertia `gen` writes, most in files)
/// takes a shortcut with nalgebra's own arithmetic: its symmetric
/// eigensolver scales the matrix by its largest entry, finds nothing to
/// rotate and scales back, so its eigenvalues are `(dᵢ / a) · a`, bit for
/// bit (tested against it).
#[must_use]
pub fn sym_eigenvalues(m: &Matrix3<f64>) -> [f64; 3] {
    let mut e = match diagonal(m) {
        Some(d) => {
            let a = d.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
            if a == 0.0 { d } else { d.map(|x| (x / a) * a) }
        }
        None => {
            let e = m.symmetric_eigenvalues();
            [e[0], e[1], e[2]]
        }
    };
    e.sort_by(f64::total_cmp);
    e
}

/// The diagonal of `m` if every entry off it is zero and every entry is finite.
fn diagonal(m: &Matrix3<f64>) -> Option<[f64; 3]> {
    let off_zero = (0..3).all(|i| (0..3).all(|j| i == j || m[(i, j)] == 0.0));
    let d = [m[(0, 0)], m[(1, 1)], m[(2, 2)]];
    (off_zero && d.iter().all(|x| x.is_finite())).then_some(d)
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

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    /// nalgebra's eigenvalues of a symmetric matrix, ascending (the reference).
    fn reference(m: &Matrix3<f64>) -> [f64; 3] {
        let mut e: Vec<f64> = m.symmetric_eigenvalues().iter().copied().collect();
        e.sort_by(f64::total_cmp);
        [e[0], e[1], e[2]]
    }

    #[test]
    fn the_diagonal_shortcut_gives_nalgebras_eigenvalues_bit_for_bit() {
        // A SplitMix-like stream: diagonals over many scales and signs.
        let mut x = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = move || {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            (z ^ (z >> 31)) as f64 / u64::MAX as f64
        };
        for k in 0..200_000 {
            let scale = 10f64.powi((k % 13) - 6);
            let mut d = [next(), next(), next()].map(|u| (u - 0.2) * scale * 7.0);
            if k % 7 == 0 {
                d[1] = d[0]; // a repeated eigenvalue
            }
            let m = Matrix3::from_diagonal(&Vector3::from(d));
            let (fast, slow) = (sym_eigenvalues(&m), reference(&m));
            assert_eq!(fast.map(f64::to_bits), slow.map(f64::to_bits), "{d:?}");
        }
        for d in [[0.0; 3], [1.0, 0.0, -0.0], [1e-300, 1e300, 2.0]] {
            let m = Matrix3::from_diagonal(&Vector3::from(d));
            assert_eq!(
                sym_eigenvalues(&m).map(f64::to_bits),
                reference(&m).map(f64::to_bits),
                "{d:?}"
            );
        }
    }

    #[test]
    fn a_full_matrix_goes_to_nalgebra() {
        let m = Matrix3::new(2.0, 0.5, 0.0, 0.5, 3.0, 0.1, 0.0, 0.1, 4.0);
        assert_eq!(sym_eigenvalues(&m), reference(&m));
    }
}
