//! The exact delay margin of `z' = A₀ z + A₁ z(t − d)` (one common delay):
//! the smallest `d` at which a characteristic root reaches the imaginary
//! axis, by a frequency sweep (after Chen, Gu & Nett, "A new method for
//! computing delay margins for stability of linear delay systems", Systems
//! & Control Letters 26, 1995).
//!
//! A root `s = iω` (`ω > 0`; `ω = 0` would be a root at every delay, which
//! the delay-free stability excludes) needs `det(iω I − A₀ − e^{−iωd} A₁) = 0`,
//! i.e. `μ = e^{iωd}` an eigenvalue of
//!
//! ```text
//! G(ω) = (iω I − A₀)⁻¹ A₁   with |μ| = 1,   then d = arg(μ)/ω ∈ (0, 2π/ω] (+ 2πk/ω).
//! ```
//!
//! For `ω > ‖A₀‖`, `|μ| ≤ ‖A₁‖ / (ω − ‖A₀‖)`: no crossing beyond
//! `‖A₀‖ + ‖A₁‖`. The sweep takes the samples of the [`Profile`] (0, then
//! log-spaced beyond that bound, and densely around every resonance
//! `Im λ(A₀)`, where `|μ|` can peak sharply), where the eigenvalues of `G`
//! outside the unit circle were counted, bisects every interval where the
//! count changes (to 1e-6 relative; then, in increasing order of their
//! delay, to the rounding), and takes the smallest `d` over every eigenvalue
//! on the circle there (several cross at once on a symmetric graph, e.g.
//! `±μ` on a bipartite one). The crossing is checked by Newton's method on
//! `Δ(s; d)` from `s = iω`: the root found must be on the axis
//! ([`Margin::Crossing`]'s `axis_distance`).
//!
//! # Limits
//! Two crossings of the unit circle between two samples that cancel in the
//! count (an eigenvalue leaving and coming back, or two crossing opposite
//! ways) are missed: the grid is 100 points per decade, refined around the
//! resonances.

use super::Root;
use super::profile::{Profile, Sweep};
use super::roots::eigenvalues;
use super::system::Dde;
use nalgebra::{Complex, DMatrix};
use std::f64::consts::PI;

/// The delay margin of a system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Margin {
    /// Not asymptotically stable even without delay (its rightmost root has
    /// `Re ≥ 0` up to rounding): the margin is 0.
    UnstableWithoutDelay {
        /// The rightmost root without delay.
        rightmost: Root,
    },
    /// Stable for every common delay below `delay`; at `delay` a root is on
    /// the imaginary axis at `±i omega`.
    Crossing {
        /// The delay margin, s.
        delay: f64,
        /// The crossing frequency, rad/s.
        omega: f64,
        /// `|Re s|` of the root Newton's method finds on `Δ(s; delay)` from
        /// `s = i omega` (≈ 1e-12 and below: the crossing is confirmed;
        /// `f64::INFINITY` if Newton did not converge).
        axis_distance: f64,
    },
    /// No root ever reaches the imaginary axis: stable for every delay
    /// (delay-independent stability).
    DelayIndependent,
}

/// Relative width of a crossing's frequency interval after the first
/// bisection.
const COARSE: f64 = 1e-6;

/// Distance to the unit circle of an eigenvalue taken as crossing, after
/// the first bisection.
const NEAR_COARSE: f64 = 1e-3;

/// Distance to the unit circle of an eigenvalue taken as crossing, after
/// the last bisection.
const NEAR_FINE: f64 = 1e-8;

/// `arg(μ)/ω` in `(0, 2π/ω]`.
fn delay_of(mu: Complex<f64>, w: f64) -> f64 {
    let mut phi = mu.arg();
    if phi <= 0.0 {
        phi += 2.0 * PI;
    }
    phi / w
}

/// Every interval `[lo, hi]` (`hi − lo ≤ tol · hi`) inside `[a, b]`
/// where the count of eigenvalues of `G` outside the unit circle changes,
/// given the counts at the ends (bisection).
fn locate(
    sweep: &Sweep,
    (a, ca): (f64, usize),
    (b, cb): (f64, usize),
    tol: f64,
    out: &mut Vec<(f64, f64)>,
) {
    if ca == cb {
        return;
    }
    let mid = 0.5 * (a + b);
    if b - a <= tol * b || mid <= a || mid >= b {
        out.push((a, b));
        return;
    }
    let Some(cm) = sweep.count(mid) else {
        out.push((a, b));
        return;
    };
    locate(sweep, (a, ca), (mid, cm), tol, out);
    locate(sweep, (mid, cm), (b, cb), tol, out);
}

/// The crossings in `[lo, hi]`: its frequency and the delays of every
/// eigenvalue within `tol` of the unit circle there (several cross at
/// once where the graph is symmetric, e.g. `±μ` on a bipartite graph),
/// or of the nearest one if none is.
fn crossings(sweep: &Sweep, (lo, hi): (f64, f64), tol: f64) -> Option<(f64, Vec<f64>)> {
    let w = 0.5 * (lo + hi);
    if w <= 0.0 {
        return None;
    }
    let eigs = sweep.eigs(w)?;
    let gap = |z: &Complex<f64>| (z.norm() - 1.0).abs();
    let nearest = eigs.iter().map(gap).fold(f64::INFINITY, f64::min);
    let delays = eigs
        .iter()
        .filter(|z| gap(z) <= tol.max(10.0 * nearest))
        .map(|&z| delay_of(z, w))
        .collect();
    Some((w, delays))
}

/// The delay margin of `z' = a0 z + a1 z(t − d)` over the common delay `d`.
///
/// First the delay-free system `a0 + a1` must be asymptotically stable
/// (else [`Margin::UnstableWithoutDelay`]); then the sweep of the module's
/// docs. Panics unless `a0`, `a1` are square of one size.
#[must_use]
pub fn common_delay(a0: &DMatrix<f64>, a1: &DMatrix<f64>) -> Margin {
    common_delay_with(a0, a1, &Profile::of(a0, a1))
}

/// [`common_delay`] with `profile = Profile::of(a0, a1)` computed before.
#[must_use]
pub fn common_delay_with(a0: &DMatrix<f64>, a1: &DMatrix<f64>, profile: &Profile) -> Margin {
    assert!(
        a0.is_square() && a1.shape() == a0.shape(),
        "A₀ and A₁ must be square of one size"
    );
    let scale = a0.norm() + a1.norm();
    let free = eigenvalues(&(a0 + a1));
    if let Some(r) = free.iter().max_by(|x, y| x.re.total_cmp(&y.re)) {
        if r.re >= -1e-12 * scale {
            return Margin::UnstableWithoutDelay {
                rightmost: Root::from(Complex::new(r.re, r.im.abs())),
            };
        }
    }
    if a1.norm() == 0.0 {
        return Margin::DelayIndependent;
    }
    let sweep = Sweep::new(a0, a1);
    let samples: Vec<(f64, usize)> = profile
        .samples()
        .iter()
        .map(|x| (x.omega, x.outside))
        .collect();
    let mut coarse = Vec::new();
    for pair in samples.windows(2) {
        locate(&sweep, pair[0], pair[1], COARSE, &mut coarse);
    }
    // Each interval with its smallest candidate delay (to ≈ COARSE); then
    // in increasing order, to the rounding, until no interval can beat the
    // best (a true crossing's coarse delay is within ≈ COARSE of its own).
    let mut found: Vec<((f64, f64), f64)> = coarse
        .iter()
        .filter_map(|&iv| {
            let (_, ds) = crossings(&sweep, iv, NEAR_COARSE)?;
            ds.into_iter().min_by(f64::total_cmp).map(|d| (iv, d))
        })
        .collect();
    found.sort_by(|x, y| x.1.total_cmp(&y.1));
    let mut best: Option<(f64, f64)> = None;
    for &((lo, hi), d) in &found {
        if best.is_some_and(|(b, _)| d > b * (1.0 + 1e3 * COARSE)) {
            break;
        }
        let (Some(clo), Some(chi)) = (sweep.count(lo), sweep.count(hi)) else {
            continue;
        };
        let mut fine = Vec::new();
        locate(&sweep, (lo, clo), (hi, chi), 4.0 * f64::EPSILON, &mut fine);
        for iv in fine {
            let Some((w, ds)) = crossings(&sweep, iv, NEAR_FINE) else {
                continue;
            };
            for d in ds {
                if best.is_none_or(|(b, _)| d < b) {
                    best = Some((d, w));
                }
            }
        }
    }
    let Some((delay, omega)) = best else {
        return Margin::DelayIndependent;
    };
    let dde = Dde::new(a0.clone(), vec![(delay, a1.clone())]);
    let axis_distance = dde
        .refine(Complex::new(0.0, omega))
        .map_or(f64::INFINITY, |s| s.re.abs());
    Margin::Crossing {
        delay,
        omega,
        axis_distance,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m1(v: f64) -> DMatrix<f64> {
        DMatrix::from_element(1, 1, v)
    }

    #[test]
    fn a_pure_delay_loses_stability_at_pi_over_2a() {
        for a in [0.5, 1.0, 3.0, 100.0] {
            match common_delay(&m1(0.0), &m1(-a)) {
                Margin::Crossing {
                    delay,
                    omega,
                    axis_distance,
                } => {
                    assert!((omega - a).abs() <= 1e-13 * a, "{a}: ω = {omega}");
                    let want = PI / (2.0 * a);
                    assert!(
                        (delay - want).abs() <= 1e-13 * want,
                        "{a}: d = {delay} vs {want}"
                    );
                    assert!(axis_distance <= 1e-10 * a, "{axis_distance}");
                }
                other => panic!("{a}: {other:?}"),
            }
        }
    }

    #[test]
    fn with_damping_the_margin_is_arccos_over_omega_or_none() {
        for (a, b) in [(2.0f64, 1.0f64), (1.0, 0.1), (5.0, 4.9), (10.0, 0.0)] {
            let w: f64 = (a * a - b * b).sqrt();
            let want = (-b / a).acos() / w;
            match common_delay(&m1(-b), &m1(-a)) {
                Margin::Crossing { delay, omega, .. } => {
                    assert!(
                        (omega - w).abs() <= 1e-12 * w,
                        "{a} {b}: ω = {omega} vs {w}"
                    );
                    assert!(
                        (delay - want).abs() <= 1e-12 * want,
                        "{a} {b}: {delay} vs {want}"
                    );
                }
                other => panic!("{a} {b}: {other:?}"),
            }
        }
        for (a, b) in [(1.0, 1.5), (1.0, 10.0), (0.3, 0.31), (1.0, 1.0)] {
            assert_eq!(
                common_delay(&m1(-b), &m1(-a)),
                Margin::DelayIndependent,
                "{a} {b}"
            );
        }
    }

    #[test]
    fn an_unstable_system_has_no_margin() {
        match common_delay(&m1(1.0), &m1(-0.5)) {
            Margin::UnstableWithoutDelay { rightmost } => {
                assert!((rightmost.re - 0.5).abs() < 1e-15);
            }
            other => panic!("{other:?}"),
        }
        // x' = −x(t − d) − ... with a zero root: not asymptotically stable.
        assert!(matches!(
            common_delay(&m1(-1.0), &m1(1.0)),
            Margin::UnstableWithoutDelay { .. }
        ));
    }
}
