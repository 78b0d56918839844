//! The paper's conditions on gains, graphs and the leader generator
//! (module `checks`).
//!
//! - Gain matrices must be symmetric positive definite with three distinct
//!   eigenvalues (Section `timevarying`): `is_spd`, `has_distinct_eigenvalues`,
//!   on the paper's own gains and on matrices that violate each half.
//! - The leader generator (eq. `leader`) must have simple, non-zero
//!   eigenvalues on the imaginary axis and all others in the open left
//!   half-plane: the paper's `P` (eigenvalues −1, ±i/√2) passes; `P = 0`,
//!   a zero eigenvalue, or an eigenvalue with positive real part fail. (A
//!   repeated imaginary pair needs four dimensions, so it cannot occur in 3×3.)
//! - Lemma `le1`: `Ξ + LLᵀ` is positive definite when every follower is
//!   reachable from the leader; on the paper's graph (N = 7, L = {1, 2},
//!   edges 1–3, 2–7, 3–5, 3–6, 4–5, stored 0-based) it equals the matrix
//!   built from the oriented incidence matrix `L` of eq. `LG`, and it becomes
//!   singular when a component loses its path to the leader.
//! - Appendix `appenD`: Theorem `estimationstability` needs
//!   ```text
//!   F = [ k_ω F₁  −½I ; −½I  F₂ ] ≻ 0,  F₁ = (Ξ + LLᵀ) ⊗ I₃,  F₂ = k_σ F₁ − ½ I_N ⊗ (P + Pᵀ).
//!   ```
//!   F is rebuilt here by hand and tested with a Cholesky attempt: positive
//!   definite for the paper's `k_ω = 14, k_σ = 12`, not for
//!   `k_ω = k_σ = 1e-3`. The sign of `λmin(F)` agrees with the congruence
//!   `HᵀFH = diag(k_ω F₁, F₂ − F₁⁻¹/(4k_ω))` used in the proof. The paper's
//!   closed-form bound on `k_σ` is shown to be insufficient (it uses
//!   `λmin(F₁⁻¹)` where Weyl's inequality needs `λmax(F₁⁻¹)`), as the
//!   crate's `NOTE` says.

use attitude::checks::{
    appendix_d_f, appendix_d_min_eigenvalue, has_distinct_eigenvalues, is_spd, p_is_admissible,
    sym_eigenvalues, xi_plus_laplacian,
};
use attitude::so3::rot;
use nalgebra::{DMatrix, Matrix3, Vector3};
use std::f64::consts::PI;

const N: usize = 7;
/// Follower edges of the paper (1–3, 2–7, 3–5, 3–6, 4–5), 0-based.
const EDGES: [(usize, usize); 5] = [(0, 2), (1, 6), (2, 4), (2, 5), (3, 4)];
/// Ξ: agents 1 and 2 hear the leader.
const XI: [bool; N] = [true, true, false, false, false, false, false];

fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(a, b, c))
}

fn paper_p() -> Matrix3<f64> {
    let a = 3.0 * PI / 4.0;
    Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, a.cos(), 0.0, a.sin(), 0.0)
}

fn paper_f1() -> DMatrix<f64> {
    xi_plus_laplacian(N, &EDGES, &XI)
}

fn min_eig(m: &DMatrix<f64>) -> f64 {
    m.clone().symmetric_eigenvalues().min()
}

fn max_eig(m: &DMatrix<f64>) -> f64 {
    m.clone().symmetric_eigenvalues().max()
}

// ---------------------------------------------------------------- SPD, distinct eigenvalues

#[test]
fn paper_gain_matrices_are_spd_with_distinct_eigenvalues() {
    let mut gains = Vec::new();
    for i in 1..=N {
        let i = i as f64;
        gains.push(("A_i0", diag(14.0 + i, 15.0 + i, 16.0 + i)));
        gains.push(("Ā_i", diag(10.0 + i, 11.0 + i, 12.0 + i)));
        gains.push(("Ǎ_i0", diag(5.0 + i, 6.0 + i, 7.0 + i)));
    }
    for (i, j) in EDGES {
        let (lo, hi) = ((i.min(j) + 1) as f64, (i.max(j) + 1) as f64);
        gains.push(("A_ij", diag(10.0 + hi, 11.0 + hi, 12.0 + hi)));
        gains.push(("Ǎ_ij", diag(10.0 - lo, 9.0 - lo, 8.0 - lo)));
    }
    for (name, a) in gains {
        assert!(is_spd(&a), "{name} = {a} should be SPD");
        assert!(
            has_distinct_eigenvalues(&a),
            "{name} = {a} has distinct eigenvalues"
        );
    }
}

#[test]
fn is_spd_accepts_rotated_positive_matrices_and_tiny_asymmetry() {
    let q = rot(1.1, &Vector3::new(1.0, 2.0, 3.0).normalize());
    let a = q * diag(0.5, 3.0, 7.0) * q.transpose();
    let a = (a + a.transpose()) * 0.5;
    assert!(is_spd(&a));
    let mut b = diag(10.0, 11.0, 12.0);
    b[(0, 1)] = 1e-13; // far below the 1e-12 relative symmetry tolerance
    assert!(is_spd(&b));
}

#[test]
fn is_spd_rejects_indefinite_singular_and_non_symmetric() {
    assert!(!is_spd(&diag(1.0, -1.0, 2.0)), "indefinite");
    assert!(!is_spd(&diag(1.0, 1.0, 0.0)), "singular");
    assert!(!is_spd(&Matrix3::zeros()), "zero");
    assert!(!is_spd(&-Matrix3::identity()), "negative definite");
    // xᵀMx > 0 for all x ≠ 0, but M is not symmetric.
    let m = Matrix3::new(2.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0);
    assert!(!is_spd(&m), "non-symmetric");
    // Symmetric with positive diagonal but a negative eigenvalue.
    let m = Matrix3::new(1.0, 2.0, 0.0, 2.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert_eq!(sym_eigenvalues(&m)[0], -1.0);
    assert!(!is_spd(&m), "indefinite with positive diagonal");
}

#[test]
fn repeated_eigenvalues_are_detected_in_any_basis() {
    let q = rot(0.9, &Vector3::new(-1.0, 0.3, 2.0).normalize());
    let rotated = |d: Matrix3<f64>| q * d * q.transpose();
    assert!(has_distinct_eigenvalues(&rotated(diag(1.0, 2.0, 3.0))));
    assert!(has_distinct_eigenvalues(&diag(1.0, 1.0 + 1e-6, 2.0)));
    assert!(!has_distinct_eigenvalues(&diag(1.0, 1.0, 2.0)));
    assert!(!has_distinct_eigenvalues(&rotated(diag(2.0, 5.0, 5.0))));
    assert!(!has_distinct_eigenvalues(&rotated(diag(4.0, 4.0, 4.0))));
    let e = sym_eigenvalues(&rotated(diag(3.0, 1.0, 2.0)));
    for (got, want) in e.iter().zip([1.0, 2.0, 3.0]) {
        assert!((got - want).abs() < 1e-14, "eigenvalues {e:?}");
    }
}

// ---------------------------------------------------------------- P

#[test]
fn paper_p_is_admissible() {
    let p = paper_p();
    // Eigenvalues −1 and ±i cos(π/4): an oscillator and a decaying mode.
    let mut ev: Vec<_> = p.complex_eigenvalues().iter().copied().collect();
    ev.sort_by(|a, b| a.im.total_cmp(&b.im));
    let s = 0.5f64.sqrt();
    assert!(
        ev[0].re.abs() < 1e-14 && (ev[0].im + s).abs() < 1e-14,
        "{ev:?}"
    );
    assert!(
        (ev[1].re + 1.0).abs() < 1e-14 && ev[1].im.abs() < 1e-14,
        "{ev:?}"
    );
    assert!(
        ev[2].re.abs() < 1e-14 && (ev[2].im - s).abs() < 1e-14,
        "{ev:?}"
    );
    assert!(p_is_admissible(&p));
    let oscillator = Matrix3::new(0.0, -2.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, -0.5);
    assert!(p_is_admissible(&oscillator));
}

#[test]
fn inadmissible_generators_are_rejected() {
    let rejected = [
        ("P = 0", Matrix3::zeros()),
        ("zero eigenvalue", diag(-1.0, -2.0, 0.0)),
        (
            "oscillator + zero eigenvalue",
            Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0),
        ),
        (
            "nilpotent Jordan block",
            Matrix3::new(0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0),
        ),
        (
            "positive real eigenvalue",
            Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.5),
        ),
        (
            "growing oscillation",
            Matrix3::new(0.1, -1.0, 0.0, 1.0, 0.1, 0.0, 0.0, 0.0, -1.0),
        ),
        ("unstable diagonal", diag(-1.0, 2.0, -3.0)),
    ];
    for (name, p) in rejected {
        assert!(!p_is_admissible(&p), "{name}: {p} should be rejected");
    }
}

// ---------------------------------------------------------------- Ξ + LLᵀ

#[test]
fn xi_plus_laplacian_of_the_paper_graph() {
    let m = paper_f1();
    // Written out: degree (+1 for a leader link) on the diagonal, −1 per edge.
    #[rustfmt::skip]
    let expected = DMatrix::from_row_slice(N, N, &[
         2.0,  0.0, -1.0,  0.0,  0.0,  0.0,  0.0,
         0.0,  2.0,  0.0,  0.0,  0.0,  0.0, -1.0,
        -1.0,  0.0,  3.0,  0.0, -1.0, -1.0,  0.0,
         0.0,  0.0,  0.0,  1.0, -1.0,  0.0,  0.0,
         0.0,  0.0, -1.0, -1.0,  2.0,  0.0,  0.0,
         0.0,  0.0, -1.0,  0.0,  0.0,  1.0,  0.0,
         0.0, -1.0,  0.0,  0.0,  0.0,  0.0,  1.0,
    ]);
    assert_eq!(m, expected);

    // The same from eq. `LG`: L ∈ ℝ^{N×(N−n)}, +1 at the tail, −1 at the head
    // of each oriented follower edge (either orientation gives LLᵀ).
    let mut l = DMatrix::zeros(N, EDGES.len());
    for (k, &(i, j)) in EDGES.iter().enumerate() {
        l[(i, k)] = 1.0;
        l[(j, k)] = -1.0;
    }
    let xi = DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(
        N,
        XI.iter().map(|&x| f64::from(u8::from(x))),
    ));
    assert_eq!(m, &xi + &l * l.transpose());

    // Lemma le1.
    assert!(
        m.clone().cholesky().is_some(),
        "Ξ + LLᵀ is positive definite"
    );
    assert!(min_eig(&m) > 0.05, "λmin(Ξ + LLᵀ) = {}", min_eig(&m));
}

#[test]
fn xi_plus_laplacian_is_singular_without_a_path_to_the_leader() {
    // Without edge 3–5, agents 4 and 5 form a component the leader cannot reach.
    let edges: Vec<_> = EDGES.iter().copied().filter(|&e| e != (2, 4)).collect();
    let m = xi_plus_laplacian(N, &edges, &XI);
    let lmin = min_eig(&m);
    assert!(lmin.abs() < 1e-12, "λmin = {lmin}");
    // Without any leader link the matrix is the plain Laplacian, also singular.
    let m = xi_plus_laplacian(N, &EDGES, &[false; N]);
    assert!(min_eig(&m).abs() < 1e-12);
}

// ---------------------------------------------------------------- Appendix D

/// F assembled entry by entry from its definition in Appendix `appenD`.
fn f_by_hand(f1: &DMatrix<f64>, k_w: f64, k_s: f64, p: &Matrix3<f64>) -> DMatrix<f64> {
    let n = f1.nrows();
    let m = 3 * n;
    let pp = p + p.transpose();
    let mut f = DMatrix::zeros(2 * m, 2 * m);
    for a in 0..n {
        for b in 0..n {
            for r in 0..3 {
                for c in 0..3 {
                    let i3 = if r == c { 1.0 } else { 0.0 };
                    let ip = if a == b { pp[(r, c)] } else { 0.0 };
                    f[(3 * a + r, 3 * b + c)] = k_w * f1[(a, b)] * i3;
                    f[(m + 3 * a + r, m + 3 * b + c)] = k_s * f1[(a, b)] * i3 - 0.5 * ip;
                }
            }
        }
    }
    for k in 0..m {
        f[(k, m + k)] = -0.5;
        f[(m + k, k)] = -0.5;
    }
    f
}

#[test]
fn appendix_d_matrix_matches_its_definition() {
    let f1 = paper_f1();
    for (k_w, k_s) in [(14.0, 12.0), (1e-3, 1e-3), (0.7, 3.0)] {
        let crate_f = appendix_d_f(&f1, k_w, k_s, &paper_p());
        let hand = f_by_hand(&f1, k_w, k_s, &paper_p());
        assert!(
            (&crate_f - &hand).amax() < 1e-15,
            "k_ω = {k_w}, k_σ = {k_s}"
        );
        assert_eq!(crate_f, crate_f.transpose());
    }
}

#[test]
fn paper_gains_satisfy_the_appendix_d_condition() {
    let f1 = paper_f1();
    let lmin = appendix_d_min_eigenvalue(&f1, 14.0, 12.0, &paper_p());
    assert!(lmin > 0.01, "λmin(F) = {lmin}");
    assert!(f_by_hand(&f1, 14.0, 12.0, &paper_p()).cholesky().is_some());
}

#[test]
fn tiny_gains_violate_the_appendix_d_condition() {
    let f1 = paper_f1();
    let lmin = appendix_d_min_eigenvalue(&f1, 1e-3, 1e-3, &paper_p());
    // The off-diagonal −½I dominates: λmin ≈ −½.
    assert!(lmin < -0.4, "λmin(F) = {lmin}");
    assert!(f_by_hand(&f1, 1e-3, 1e-3, &paper_p()).cholesky().is_none());
}

/// The proof's congruence `HᵀFH = diag(k_ω F₁, F̄₂)`, `F̄₂ = F₂ − F₁⁻¹/(4k_ω)`,
/// `H = [I, F₁⁻¹/(2k_ω); 0, I]`, and the resulting exact test, over a grid of gains.
#[test]
fn appendix_d_sign_agrees_with_the_schur_complement() {
    let f1n = paper_f1();
    let p = paper_p();
    let m = 3 * N;
    let f1 = f1n.kronecker(&DMatrix::<f64>::identity(3, 3));
    let f1_inv = f1.clone().try_inverse().expect("Ξ + LLᵀ is invertible");
    let (mut seen_pos, mut seen_neg) = (false, false);
    for k_w in [1e-3, 1e-2, 0.1, 1.0, 14.0] {
        for k_s in [1e-3, 1e-2, 0.1, 1.0, 12.0, 100.0] {
            let f = appendix_d_f(&f1n, k_w, k_s, &p);
            let mut h = DMatrix::identity(2 * m, 2 * m);
            h.view_mut((0, m), (m, m))
                .copy_from(&(&f1_inv / (2.0 * k_w)));
            let congruent = h.transpose() * &f * &h;
            let f2 = f.view((m, m), (m, m)).clone_owned();
            let f2_bar = &f2 - &f1_inv / (4.0 * k_w);
            let mut block = DMatrix::zeros(2 * m, 2 * m);
            block.view_mut((0, 0), (m, m)).copy_from(&(&f1 * k_w));
            block.view_mut((m, m), (m, m)).copy_from(&f2_bar);
            let d = (&congruent - &block).amax();
            assert!(d < 1e-9 * (1.0 + block.amax()), "HᵀFH − diag = {d:e}");

            let lmin = appendix_d_min_eigenvalue(&f1n, k_w, k_s, &p);
            let schur = min_eig(&f2_bar);
            assert_eq!(
                lmin > 0.0,
                schur > 0.0,
                "k_ω = {k_w}, k_σ = {k_s}: λmin(F) = {lmin}, λmin(F̄₂) = {schur}"
            );
            assert_eq!(lmin > 0.0, f.clone().cholesky().is_some());
            seen_pos |= lmin > 0.0;
            seen_neg |= lmin <= 0.0;
        }
    }
    assert!(seen_pos && seen_neg, "the grid must straddle the boundary");
}

/// The paper's closed-form bound
/// `k_σ > (λmin(F₁⁻¹) − 4k_ω λmin(−½(P+Pᵀ))) / (4k_ω λmin(F₁))`
/// is not sufficient: on the paper's graph and P, a `k_σ` just above it
/// leaves F indefinite, because the components where `P + Pᵀ` vanishes need
/// `k_σ > 1/(4k_ω λmin(F₁)²)`.
#[test]
fn paper_closed_form_bound_is_not_sufficient() {
    let f1 = paper_f1();
    let p = paper_p();
    let (lo, hi) = (min_eig(&f1), max_eig(&f1));
    let k_w = 1.0;
    let neg_sym_min = {
        let e = sym_eigenvalues(&(-(p + p.transpose()) * 0.5));
        e[0]
    };
    let paper_bound = ((1.0 / hi - 4.0 * k_w * neg_sym_min) / (4.0 * k_w * lo)).max(0.0);
    let exact = 1.0 / (4.0 * k_w * lo * lo);
    assert!(exact > 2.0 * paper_bound, "bounds {paper_bound} vs {exact}");
    let k_s = (paper_bound * exact).sqrt();
    let lmin = appendix_d_min_eigenvalue(&f1, k_w, k_s, &p);
    assert!(
        lmin < 0.0,
        "k_σ = {k_s} > paper bound {paper_bound}, yet λmin(F) = {lmin}"
    );
    // Just above the exact threshold of those components F is positive definite.
    assert!(appendix_d_min_eigenvalue(&f1, k_w, 1.01 * exact, &p) > 0.0);
}
