//! The rightmost characteristic roots of a [`Dde`]: the pseudospectral
//! discretisation of its infinitesimal generator (Breda, Maset & Vermiglio,
//! "Pseudospectral differencing methods for characteristic roots of delay
//! differential equations", SIAM J. Sci. Comput. 27(2), 2005), whose
//! rightmost eigenvalues approximate the rightmost roots, each then refined
//! by Newton's method on the exact characteristic matrix
//! ([`Dde::refine`]).
//!
//! The state is the history `φ` on `[−τ_max, 0]`, sampled at the Chebyshev
//! extremal nodes `θ_j = (τ_max/2)(cos(jπ/M) − 1)`, `j = 0..=M`
//! (`θ_0 = 0`, `θ_M = −τ_max`). The generator `φ ↦ φ'` with the domain
//! condition `φ'(0) = A₀ φ(0) + Σ_k A_k φ(−τ_k)` becomes the
//! `n(M+1)`-square block matrix
//!
//! ```text
//! row 0:      A₀ ⊗ e₀ᵀ + Σ_k A_k ⊗ ℓ(−τ_k)ᵀ      (ℓ: the nodes' Lagrange basis)
//! rows 1..=M: (2/τ_max) D[j, :] ⊗ Iₙ              (D: Chebyshev differentiation)
//! ```
//!
//! (block `(j, m)` acts on `φ(θ_m)`). Its eigenvalues converge to the roots
//! spectrally fast in `M`, the rightmost first; `M` grows
//! ([`rightmost_with`]) until the refined rightmost root agrees at two
//! orders and the order resolves every frequency where roots right of it
//! can lie ([`needed_order`]).
//!
//! Only the components of `z` that some `A_k` reads need a history (the
//! observerless law reads its neighbours' attitudes, not their rates): with
//! `P` selecting those `p` components ([`Dde::delayed_columns`]), the
//! unknowns are `φ(0)` (`n`) and `Pφ(θ_j)`, `j = 1..=M` (`p` each), where
//! `Pφ(θ_0) = Pφ(0)`: a matrix of size `n + pM` instead of `n(M+1)`, the
//! same discretisation restricted to what the equation uses.

use super::cheb;
use super::eig::real_eigenvalues;
use super::profile::Profile;
use super::system::Dde;
use nalgebra::{Complex, DMatrix};

/// The smallest Chebyshev order `M` tried.
pub const MIN_ORDER: usize = 12;

/// The largest Chebyshev order `M` tried.
pub const MAX_ORDER: usize = 4096;

/// Chebyshev orders per radian of `ω τ_max` needed to resolve `e^{iωθ}` on
/// `[−τ_max, 0]`: the interpolation error bound `≈ (ωτ/4)^M / M! ≈
/// (e ωτ / 4M)^M` falls below 1 from `M ≈ (e/4) ωτ ≈ 0.68 ωτ`; Newton's
/// method then needs only a start in its basin.
pub const ORDER_PER_RADIAN: f64 = 0.7;

/// Fraction of `ρ(G)`'s level `e^{σ τ_max}` at the rightmost root found so
/// far down to which frequencies are resolved.
const SAFETY: f64 = 0.8;

/// The order that resolves every root at least as far right as `sigma`:
/// frequencies up to where `ρ(G(ω)) ≥ SAFETY·e^{σ τ_max}` ([`Profile`]),
/// `ORDER_PER_RADIAN` orders per radian of `ω τ_max`, at least
/// [`MIN_ORDER`].
#[must_use]
pub fn needed_order(profile: &Profile, sigma: f64, tau: f64) -> usize {
    let level = SAFETY * (sigma * tau).min(700.0).exp();
    let omega = profile.omega(level);
    ((ORDER_PER_RADIAN * omega * tau).ceil() as usize).max(MIN_ORDER)
}

/// Relative agreement of the real parts of two orders' rightmost roots
/// that ends the search (a double root is found only to ≈ 1e-8).
const AGREE: f64 = 1e-7;

/// The rightmost root of a system, and how it was found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Found {
    /// The root (of a conjugate pair, the one with `Im ≥ 0`).
    pub root: Complex<f64>,
    /// The Chebyshev order `M` it was confirmed at (0: no delay, the
    /// eigenvalues of `A₀ + Σ A_k` directly).
    pub order: usize,
    /// Whether two consecutive orders agreed (else the largest order the
    /// size limit allowed gave it, unconfirmed).
    pub converged: bool,
}

/// The size of [`discretise`]`(dde, m)`: `n + p m`.
#[must_use]
pub fn size(dde: &Dde, m: usize) -> usize {
    dde.dim() + dde.delayed_columns().len() * m
}

/// The discretised generator of `dde` at order `m` (`n + pm` square, the
/// module's docs). Panics if `dde` has no delay.
#[must_use]
pub fn discretise(dde: &Dde, m: usize) -> DMatrix<f64> {
    let tau = dde.tau_max();
    assert!(tau > 0.0, "the discretisation needs a delay");
    let n = dde.dim();
    let cols = dde.delayed_columns();
    let p = cols.len();
    let size = n + p * m;
    // Where the history component r of node j lives (node 0: in φ(0)).
    let at = |j: usize, r: usize| if j == 0 { cols[r] } else { n + (j - 1) * p + r };
    let mut b = DMatrix::zeros(size, size);
    b.view_mut((0, 0), (n, n)).copy_from(dde.a0());
    for (tau_k, a) in dde.delayed() {
        // −τ_k on [−τ, 0] is x = 1 − 2τ_k/τ on [−1, 1].
        let x = (1.0 - 2.0 * tau_k / tau).clamp(-1.0, 1.0);
        for (j, w) in cheb::lagrange(m, x).into_iter().enumerate() {
            if w != 0.0 {
                for (r, &c) in cols.iter().enumerate() {
                    let col = at(j, r);
                    for i in 0..n {
                        b[(i, col)] += w * a[(i, c)];
                    }
                }
            }
        }
    }
    let d = cheb::differentiation(m) * (2.0 / tau);
    for j in 1..=m {
        for node in 0..=m {
            let v = d[(j, node)];
            for r in 0..p {
                b[(at(j, r), at(node, r))] = v;
            }
        }
    }
    b
}

/// The eigenvalue with the largest real part (of a pair, `Im ≥ 0`).
fn largest(eigs: &[Complex<f64>]) -> Option<Complex<f64>> {
    eigs.iter()
        .map(|z| if z.im < 0.0 { z.conj() } else { *z })
        .max_by(|a, b| a.re.total_cmp(&b.re).then(a.im.total_cmp(&b.im)))
}

/// `z` with a rounding-level imaginary part set to 0 and `Im ≥ 0`.
fn canonical(z: Complex<f64>) -> Complex<f64> {
    let im = if z.im.abs() <= 1e-12 * (1.0 + z.norm()) {
        0.0
    } else {
        z.im.abs()
    };
    Complex::new(z.re, im)
}

/// Eigenvalues of a real matrix: [`real_eigenvalues`], else nalgebra's
/// Schur iteration; panics if neither converges (never seen).
pub(crate) fn eigenvalues(a: &DMatrix<f64>) -> Vec<Complex<f64>> {
    if let Some(e) = real_eigenvalues(a) {
        return e;
    }
    let n = a.nrows();
    match nalgebra::Schur::try_new(a.clone(), 1e-14, 1000 * n.max(1)) {
        Some(s) => s.complex_eigenvalues().iter().copied().collect(),
        None => panic!("no QR iteration converged on a {n}×{n} matrix"),
    }
}

/// Eigenvalues of the discretisation refined by Newton at each order (the
/// rightmost, one of each conjugate pair).
pub const CANDIDATES: usize = 8;

/// The refined rightmost root at order `m`: the [`CANDIDATES`] rightmost
/// eigenvalues of [`discretise`] (`Im ≥ 0`), each refined by Newton, the
/// rightmost result.
fn at_order(dde: &Dde, m: usize) -> Option<Complex<f64>> {
    let mut eigs: Vec<Complex<f64>> = eigenvalues(&discretise(dde, m))
        .into_iter()
        .filter(|z| z.im >= 0.0)
        .collect();
    eigs.sort_by(|a, b| b.re.total_cmp(&a.re));
    let k = CANDIDATES.min(eigs.len());
    let mut roots: Vec<Complex<f64>> = Vec::with_capacity(k);
    for z in &eigs[..k] {
        if let Some(r) = dde.refine(*z) {
            let r = canonical(r);
            if !roots
                .iter()
                .any(|q| (q - r).norm() <= 1e-8 * (1.0 + r.norm()))
            {
                roots.push(r);
            }
        }
    }
    largest(&roots)
}

/// The rightmost characteristic root of `dde`: [`rightmost_with`] the
/// profile of `A₀` and `Σ A_k` (as if every delay were `τ_max`).
#[must_use]
pub fn rightmost(dde: &Dde, limit: usize) -> Found {
    let a1 = dde
        .delayed()
        .iter()
        .fold(DMatrix::zeros(dde.dim(), dde.dim()), |acc, (_, a)| acc + a);
    rightmost_with(dde, &Profile::of(dde.a0(), &a1), limit)
}

/// The rightmost characteristic root of `dde`. Without delays, the
/// rightmost eigenvalue of `A₀ + Σ A_k`. With delays, from [`MIN_ORDER`]
/// the order grows (by half, or at once to [`needed_order`] for the
/// rightmost root found so far and `profile`) while the discretisation's
/// [`size`] is at most `limit`, until two consecutive orders agree on the
/// rightmost root and the last is at least the order it needs
/// (`converged`); else the last order's root, not `converged`.
#[must_use]
pub fn rightmost_with(dde: &Dde, profile: &Profile, limit: usize) -> Found {
    if dde.delayed_columns().is_empty() {
        let root = largest(&eigenvalues(&dde.undelayed()))
            .map_or(Complex::new(f64::NEG_INFINITY, 0.0), canonical);
        return Found {
            root,
            order: 0,
            converged: true,
        };
    }
    let tau = dde.tau_max();
    let mut m = MIN_ORDER;
    let mut prev: Option<Complex<f64>> = None;
    let mut last = Found {
        root: Complex::new(f64::NAN, f64::NAN),
        order: 0,
        converged: false,
    };
    loop {
        let root = at_order(dde, m);
        let need = root.map_or(m, |r| needed_order(profile, r.re, tau));
        if let (Some(p), Some(r)) = (prev, root) {
            if m >= need && (p.re - r.re).abs() <= AGREE * (1.0 + r.norm()) {
                return Found {
                    root: if p.re > r.re { p } else { r },
                    order: m,
                    converged: true,
                };
            }
        }
        if let Some(r) = root {
            last = Found {
                root: r,
                order: m,
                converged: false,
            };
        }
        prev = root;
        let next = (m + m / 2).max(need);
        if size(dde, next) > limit || next > MAX_ORDER {
            return last;
        }
        m = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scalar(a0: f64, delayed: &[(f64, f64)]) -> Dde {
        Dde::new(
            DMatrix::from_element(1, 1, a0),
            delayed
                .iter()
                .map(|&(t, a)| (t, DMatrix::from_element(1, 1, a)))
                .collect(),
        )
    }

    /// The generator applied to the samples of `φ(θ) = e^{sθ} v` gives
    /// `s φ` on rows 1..=M (spectral accuracy), and row 0 is the domain
    /// condition's right-hand side.
    #[test]
    fn the_discretised_generator_differentiates_exponentials() {
        let dde = Dde::new(
            DMatrix::from_row_slice(2, 2, &[-1.0, 0.5, 0.0, -2.0]),
            vec![
                (0.3, DMatrix::from_row_slice(2, 2, &[0.1, 0.0, 0.2, 0.3])),
                (1.0, DMatrix::from_row_slice(2, 2, &[-0.4, 0.1, 0.0, 0.2])),
            ],
        );
        let m = 24;
        let b = discretise(&dde, m);
        assert_eq!(b.nrows(), 2 * 25);
        assert_eq!(size(&dde, m), 2 * 25);
        let s = 0.7;
        let v = [1.0, -2.0];
        let theta: Vec<f64> = cheb::nodes(m).iter().map(|x| 0.5 * (x - 1.0)).collect();
        let phi =
            nalgebra::DVector::from_fn(2 * (m + 1), |k, _| (s * theta[k / 2]).exp() * v[k % 2]);
        let out = &b * &phi;
        for k in 2..2 * (m + 1) {
            assert!((out[k] - s * phi[k]).abs() < 1e-10, "{k}");
        }
        // Row 0: A₀ φ(0) + A₁ φ(−0.3) + A₂ φ(−1).
        let at = |t: f64| nalgebra::Vector2::new((s * t).exp() * v[0], (s * t).exp() * v[1]);
        let a0 = nalgebra::Matrix2::new(-1.0, 0.5, 0.0, -2.0);
        let a1 = nalgebra::Matrix2::new(0.1, 0.0, 0.2, 0.3);
        let a2 = nalgebra::Matrix2::new(-0.4, 0.1, 0.0, 0.2);
        let want = a0 * at(0.0) + a1 * at(-0.3) + a2 * at(-1.0);
        assert!((out[0] - want[0]).abs() < 1e-12 && (out[1] - want[1]).abs() < 1e-12);
    }

    /// `x'' + b x' + a x(t − τ) = 0` as `[x, v]`: only `x` is delayed
    /// (`p = 1`); the rightmost root is the rightmost of
    /// `s² + b s + a e^{−sτ} = 0` found by Newton from a grid of starts.
    #[test]
    fn only_the_delayed_components_carry_a_history() {
        let (a, b, tau) = (4.0, 0.7, 0.6);
        let dde = Dde::new(
            DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 0.0, -b]),
            vec![(tau, DMatrix::from_row_slice(2, 2, &[0.0, 0.0, -a, 0.0]))],
        );
        assert_eq!(dde.delayed_columns(), vec![0]);
        assert_eq!(size(&dde, 16), 2 + 16);
        let f = rightmost(&dde, 10_000);
        let char = |s: Complex<f64>| s * s + s * b + (-s * tau).exp() * a;
        assert!(char(f.root).norm() < 1e-11, "{f:?}");
        let mut best = f64::NEG_INFINITY;
        for re in -8..=4 {
            for im in 0..=40 {
                if let Some(s) = dde.refine(Complex::new(f64::from(re) * 0.5, f64::from(im) * 0.5))
                {
                    if char(s).norm() < 1e-9 {
                        best = best.max(s.re);
                    }
                }
            }
        }
        assert!((f.root.re - best).abs() < 1e-10, "{} vs {best}", f.root);
    }

    #[test]
    fn without_delay_the_rightmost_root_is_an_eigenvalue() {
        let f = rightmost(&scalar(-2.0, &[(0.0, 0.5)]), 10_000);
        assert_eq!(f.root, Complex::new(-1.5, 0.0));
        assert_eq!(f.order, 0);
    }

    #[test]
    fn the_rightmost_root_of_a_delay_equation_is_a_root() {
        let dde = scalar(-1.0, &[(1.0, -3.0)]);
        let f = rightmost(&dde, 10_000);
        assert!(f.converged && f.order > MIN_ORDER);
        let s = f.root;
        assert!((s + 1.0 + (-s).exp() * 3.0).norm() < 1e-12, "{s}");
        assert!(s.im > 0.0);
    }
}
