//! The delay margin of a [`Tree`] (every entry delayed by one common `d`)
//! by bisection on `d` of the number of roots right of the imaginary axis,
//! then Newton's method on the crossing `(ω, d)` itself.
//!
//! For a retarded system the roots move continuously with `d` and none
//! comes from `Re s = +∞`, so the margin `d*` is where the count `n₀(d)` of
//! roots with `Re s > 0` ([`Search::right_of`]) first leaves 0
//! (Michiels & Niculescu, "Stability, Control, and Computation for
//! Time-Delay Systems", 2nd ed., SIAM 2014, §1.2 on the crossing set):
//!
//! 1. the delay-free system must be stable (`n(−10⁻¹⁰ρ) = 0` at `d = 0`),
//!    else [`Margin::UnstableWithoutDelay`];
//! 2. a root `iω` at some delay makes `e^{iωd}` an eigenvalue of `G(ω) =
//!    P(iω)⁻¹Q(iω)` (`P` the diagonal of `Δ`, `Q` the rest), so
//!    `ρ(|G(ω)|) ≥ 1`: where [`Tree::dominant`] holds at every frequency
//!    (a log grid, 200 per decade, up to [`Tree::radius`]), no root ever
//!    reaches the axis ([`Margin::DelayIndependent`]); else the lowest
//!    such frequency `ω_lo` bounds the first crossing: every crossing
//!    frequency `ω ≥ ω_lo` has a crossing delay `d ≤ 2π/ω ≤ 2π/ω_lo`;
//! 3. `d` doubles from `2π/(64 ρ)` until `n₀(d) > 0` (past `2π/ω_lo`: delay
//!    independent), then bisects to 2 % relative and until one pair is
//!    right of the axis;
//! 4. that pair, the rightmost root at the upper end
//!    ([`Search::rightmost`]), is continued by Newton's method on
//!    `det Δ(iω; d) = 0` in the two real unknowns `(ω, d)`
//!    ([`Tree::eval_delay`] gives `∂/∂d ln det Δ`) to the crossing, and
//!    confirmed as [`super::margin`] does (Newton on `s` from `iω`).
//!
//! # Limits
//! A window of instability that opens and closes again between two
//! doublings of step 3 is missed (the frequency sweep of the dense path has
//! the like limit between two samples).

use super::Root;
use super::margin::Margin;
use super::tree::Tree;
use super::tree_roots::Search;
use nalgebra::Complex;
use std::f64::consts::PI;

type C = Complex<f64>;

/// Frequency samples per decade of the dominance grid.
const PER_DECADE: usize = 200;

/// Decades of the dominance grid below its top.
const DECADES: usize = 6;

/// Relative width of the delay bracket before Newton's method.
const BRACKET: f64 = 0.02;

/// Newton iterations on `(ω, d)`.
const NEWTON_MAX: usize = 50;

/// The system with every entry delayed by `d`.
fn common(tree: &Tree, d: f64) -> Search<'_> {
    let delays = tree
        .entries()
        .iter()
        .map(|(_, _, e)| e.delay + 1)
        .max()
        .unwrap_or(0);
    Search::new(tree, vec![d; delays])
}

/// The lowest frequency of the grid below which `tree` is dominant
/// (`None`: dominant everywhere).
fn lowest_crossing_frequency(tree: &Tree, top: f64) -> Option<f64> {
    let lo = top * 10f64.powi(-(DECADES as i32));
    let count = PER_DECADE * DECADES;
    let grid = (0..=count).map(|k| lo * (top / lo).powf(k as f64 / count as f64));
    let mut prev = 0.0;
    for w in grid {
        if !tree.dominant(w) {
            return Some(prev);
        }
        prev = w;
    }
    None
}

/// How many roots are right of the axis at common delay `d` (`None`: no
/// contour resolved).
fn unstable(tree: &Tree, d: f64) -> Option<usize> {
    common(tree, d).right_of(0.0).map(|r| r.count)
}

/// Newton's method on `det Δ(iω; d) = 0` in `(ω, d)` from `(w, d)`:
/// `1 + (∂ ln F/∂ω) δω + (∂ ln F/∂d) δd = 0` (real and imaginary parts),
/// `∂/∂ω = i ∂/∂s`.
fn crossing(tree: &Tree, mut w: f64, mut d: f64) -> Option<(f64, f64)> {
    let mut last = f64::INFINITY;
    for _ in 0..NEWTON_MAX {
        let s = C::new(0.0, w);
        let Some(by_d) = tree.eval_delay(s, d) else {
            return Some((w, d));
        };
        let by_s = common(tree, d).eval(s)?;
        let gw = C::new(0.0, 1.0) * by_s.slope;
        let gd = by_d.slope;
        let det = gw.re * gd.im - gd.re * gw.im;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let (dw, dd) = (-gd.im / det, gw.im / det);
        w += dw;
        d += dd;
        if !(w.is_finite() && d.is_finite()) || w <= 0.0 || d <= 0.0 {
            return None;
        }
        let size = (dw / w).abs().max((dd / d).abs());
        if size <= 1e-15 || (size <= 1e-10 && size >= last) {
            return Some((w, d));
        }
        last = size;
    }
    (last <= 1e-8).then_some((w, d))
}

/// The delay margin of `tree` over a common delay on every entry (the
/// module's docs); `rightmost_free` gives the rightmost root at `d = 0` for
/// [`Margin::UnstableWithoutDelay`]. Crossings beyond `cap` (a margin
/// already found elsewhere) are not sought: if none is below it,
/// [`Margin::DelayIndependent`].
#[must_use]
pub fn margin(tree: &Tree, rightmost_free: impl Fn() -> Root, cap: Option<f64>) -> Margin {
    let free = common(tree, 0.0);
    let scale = free.scale();
    if free.right_of(-1e-10 * scale).is_none_or(|r| r.count > 0) {
        return Margin::UnstableWithoutDelay {
            rightmost: rightmost_free(),
        };
    }
    if tree.entries().is_empty() {
        return Margin::DelayIndependent;
    }
    let Some(w_lo) = lowest_crossing_frequency(tree, 1.01 * scale) else {
        return Margin::DelayIndependent;
    };
    let d_max = 2.0 * PI / w_lo.max(1e-300);
    match bracket(tree, 2.0 * PI / (64.0 * scale), d_max, cap) {
        Some((d_lo, d_hi)) => settle(tree, d_lo, d_hi),
        None => Margin::DelayIndependent,
    }
}

/// `d` doubling from `d0` until a root is right of the axis (at most up to
/// `cap`, and past `d_max`: `None`), then bisected: a stable and an
/// unstable delay within [`BRACKET`].
fn bracket(tree: &Tree, d0: f64, d_max: f64, cap: Option<f64>) -> Option<(f64, f64)> {
    let cap = cap.unwrap_or(f64::INFINITY);
    let (mut d_lo, mut d_hi) = (0.0, d0.min(cap));
    let mut count = loop {
        let n = unstable(tree, d_hi)?;
        if n > 0 {
            break n;
        }
        if d_hi >= cap || d_hi > d_max {
            return None;
        }
        (d_lo, d_hi) = (d_hi, (2.0 * d_hi).min(cap));
    };
    // Until one pair (a real root cannot cross at ω > 0) is right of the axis.
    while (d_hi - d_lo > BRACKET * d_hi || count > 2) && d_hi - d_lo > 1e-12 * d_hi {
        let mid = 0.5 * (d_lo + d_hi);
        match unstable(tree, mid) {
            Some(n) if n > 0 => (d_hi, count) = (mid, n),
            _ => d_lo = mid,
        }
    }
    Some((d_lo, d_hi))
}

/// Bisections of the bracket at most while Newton's method on `(ω, d)`
/// does not land in it.
const SETTLE_MAX: usize = 40;

/// The crossing between `d_lo` (stable) and `d_hi` (unstable): Newton's
/// method on `(ω, d)` from the rightmost root at `d_hi`, the bracket
/// bisected (the root nearer the axis) until it lands inside.
fn settle(tree: &Tree, mut d_lo: f64, mut d_hi: f64) -> Margin {
    let mut guess = (f64::NAN, d_hi);
    for _ in 0..SETTLE_MAX {
        if let Some(z) = common(tree, d_hi).rightmost() {
            guess = (z.im.abs(), d_hi);
            let inside = |d: f64| d >= d_lo * (1.0 - 1e-9) && d <= d_hi * (1.0 + 1e-9);
            if let Some((w, d)) = crossing(tree, z.im.abs(), d_hi).filter(|c| inside(c.1)) {
                guess = (w, d);
                break;
            }
        }
        let mid = 0.5 * (d_lo + d_hi);
        match unstable(tree, mid) {
            Some(n) if n > 0 => d_hi = mid,
            _ => d_lo = mid,
        }
    }
    let (omega, delay) = guess;
    let axis_distance = common(tree, delay)
        .newton(C::new(0.0, omega))
        .map_or(f64::INFINITY, |s| s.re.abs());
    Margin::Crossing {
        delay,
        omega,
        axis_distance,
    }
}
