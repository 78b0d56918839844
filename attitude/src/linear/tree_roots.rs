//! The rightmost root of a [`Tree`]'s `det Δ(s)` at given delays, without
//! any discretisation: counting by the argument principle ([`contour`])
//! brackets the rightmost real part, Newton's method on `ln det Δ`
//! ([`Tree::eval`], `O(N)` per step) finds the roots.
//!
//! - **Box.** Every root with `Re s ≥ σ` has `|s| ≤ ρ(σ)` ([`Tree::radius`]),
//!   so the roots right of `σ` are those in `[σ, R] × [−R, R]`, `R > ρ(σ)`:
//!   `n(σ)` ([`Search::right_of`], one contour).
//! - **Bracket.** `n(ρ(0)) = 0`; from `σ = 0`, then `σ = ∓10⁻⁶ρ·4ᵏ` down
//!   until `n(σ) > 0` (or up until `n(σ) = 0`). Then `lo` (`n(lo) > 0`)
//!   and `hi` (`n(hi) = 0`) are bisected.
//! - **Roots.** Once at most [`MAX_LOCAL`] roots are right of `lo`, the
//!   contour's left side passes close to each: `arg det Δ` turns forwards
//!   fast there, or `|det Δ|` dips ([`contour::Walk::turns`]), and Newton's
//!   method from those points finds them. When the roots found with `Re s > lo` (a pair counting
//!   twice) are `n(lo)` in number, the rightmost of them is *the* rightmost
//!   root: the count certifies that none was missed. Else the bisection
//!   goes on (`lo` nearer the rightmost roots).

use super::contour::{self, Walk};
use super::tree::{LogDet, Tree};
use nalgebra::Complex;

type C = Complex<f64>;

/// Roots right of `lo` sought by Newton's method at most.
pub const MAX_LOCAL: usize = 8;

/// Newton iterations before giving up.
const NEWTON_MAX: usize = 60;

/// Bisection steps on `σ` at most.
const BISECT_MAX: usize = 200;

/// The rightmost root of one [`Tree`] at fixed delays.
#[derive(Debug, Clone)]
pub struct Search<'a> {
    tree: &'a Tree,
    taus: Vec<f64>,
    /// `ρ(0)`: the size of the region where the roots that matter lie.
    scale: f64,
}

/// How many roots are right of `sigma`, and the contour's walk.
#[derive(Debug, Clone)]
pub struct Right {
    /// The abscissa actually used (nudged left where a root was on the
    /// contour).
    pub sigma: f64,
    /// The roots with `Re s > sigma`, with multiplicity (both of a pair).
    pub count: usize,
    /// The walk along the upper half of the contour.
    pub walk: Walk,
}

/// `z` with `Im ≥ 0` and a rounding-level imaginary part set to 0.
fn canonical(z: C) -> C {
    let im = if z.im.abs() <= 1e-12 * (1.0 + z.norm()) {
        0.0
    } else {
        z.im.abs()
    };
    C::new(z.re, im)
}

impl<'a> Search<'a> {
    /// The roots of `tree` with delays `taus` (indexed by
    /// [`super::tree::Entry::delay`]).
    #[must_use]
    pub fn new(tree: &'a Tree, taus: Vec<f64>) -> Self {
        let scale = tree.radius(0.0, &taus).max(f64::MIN_POSITIVE);
        Self { tree, taus, scale }
    }

    /// `ρ(0)`, the scale of the roots that matter, s⁻¹.
    #[must_use]
    pub fn scale(&self) -> f64 {
        self.scale
    }

    fn f(&self) -> impl Fn(C) -> Option<LogDet> + '_ {
        move |s| self.eval(s)
    }

    /// `ln det Δ(s)` and its derivative ([`Tree::eval`]) at these delays.
    #[must_use]
    pub fn eval(&self, s: C) -> Option<LogDet> {
        self.tree.eval(s, &self.taus)
    }

    /// The roots right of `sigma` (nudged left by up to `4·10⁻⁹ρ` where a
    /// root is on the contour); `None` if no contour resolves.
    #[must_use]
    pub fn right_of(&self, sigma: f64) -> Option<Right> {
        let f = self.f();
        for k in 0..5 {
            let x0 = sigma - f64::from(k) * 1e-9 * self.scale;
            let r = 1.1 * self.tree.radius(x0, &self.taus) + 1e-9 * self.scale;
            if x0 >= r {
                return Some(Right {
                    sigma: x0,
                    count: 0,
                    walk: Walk::default(),
                });
            }
            if let Some((count, walk)) = contour::count_symmetric(&f, x0, r, r) {
                return Some(Right {
                    sigma: x0,
                    count,
                    walk,
                });
            }
        }
        None
    }

    /// A root near `s0` by Newton's method on `ln det Δ`:
    /// `s ← s − 1/(ln det Δ)'(s)`; `None` if it does not settle (the
    /// criteria of [`super::system::Dde::refine`]).
    #[must_use]
    pub fn newton(&self, s0: C) -> Option<C> {
        let mut s = s0;
        let mut last = f64::INFINITY;
        for _ in 0..NEWTON_MAX {
            let Some(e) = self.tree.eval(s, &self.taus) else {
                return Some(s);
            };
            if e.slope.norm() == 0.0 {
                return None;
            }
            let step = e.slope.inv();
            s -= step;
            if !(s.re.is_finite() && s.im.is_finite()) {
                return None;
            }
            let size = step.norm();
            let scale = 1.0 + s.norm();
            if size <= 1e-15 * scale || (size <= 1e-10 * scale && size >= last) {
                return Some(s);
            }
            last = size;
        }
        (last <= 1e-6 * (1.0 + s.norm())).then_some(s)
    }

    /// Where Newton's method should start to find the roots right of
    /// `r.sigma`: first where the contour's left side turned forwards
    /// fastest (next to a root inside; one outside turns it backwards),
    /// then, a root inside and one outside at one height cancelling in the
    /// turn, where it passed nearest to any root, moved right by that
    /// distance.
    fn starts(&self, r: &Right) -> Vec<C> {
        let lo = r.sigma;
        let tol = 1e-12 * (lo.abs() + self.scale);
        let left: Vec<_> = r
            .walk
            .turns
            .iter()
            .filter(|t| (t.at.re - lo).abs() <= tol)
            .collect();
        let mut forward: Vec<_> = left.iter().filter(|t| t.turn > 0.0).collect();
        forward.sort_by(|a, b| (b.turn / b.span).total_cmp(&(a.turn / a.span)));
        let mut near = left.clone();
        near.sort_by(|a, b| b.pull.total_cmp(&a.pull));
        let k = 2 * r.count + 6;
        forward
            .iter()
            .take(k)
            .map(|t| t.at)
            .chain(near.iter().take(k).map(|t| t.at + 1.0 / t.pull))
            .collect()
    }

    /// The roots right of `r.sigma` that Newton's method finds from
    /// [`Self::starts`], if they are all `r.count` of them.
    fn localise(&self, r: &Right) -> Option<Vec<C>> {
        let mut roots: Vec<C> = Vec::new();
        let mut found = 0;
        for s0 in self.starts(r) {
            let Some(z) = self.newton(s0).map(canonical) else {
                continue;
            };
            let new = !roots
                .iter()
                .any(|q| (q - z).norm() <= 1e-8 * (1.0 + z.norm()));
            if new && z.re > r.sigma {
                roots.push(z);
                found += if z.im > 0.0 { 2 } else { 1 };
                if found >= r.count {
                    return Some(roots);
                }
            }
        }
        None
    }

    /// The roots right of `sigma` (all of them, `Im ≥ 0`), if at most
    /// [`MAX_LOCAL`] and Newton's method finds them all.
    #[must_use]
    pub fn roots_right_of(&self, sigma: f64) -> Option<Vec<C>> {
        let r = self.right_of(sigma)?;
        if r.count == 0 {
            return Some(Vec::new());
        }
        if r.count > MAX_LOCAL {
            return None;
        }
        self.localise(&r)
    }

    /// The rightmost root (`Im ≥ 0`), the module's docs; `None` if no
    /// contour resolves or no bracket is found within `10⁶ρ` of the axis.
    #[must_use]
    pub fn rightmost(&self) -> Option<C> {
        let radius = self.tree.radius(0.0, &self.taus) * 1.01 + 1e-9 * self.scale;
        let first = self.right_of(0.0)?;
        let mut step = 1e-6 * self.scale;
        let (mut lo, mut hi) = if first.count == 0 {
            // Down from the axis until a root is right of σ.
            let mut hi = first.sigma;
            loop {
                if step > 1e6 * self.scale {
                    return None;
                }
                let r = self.right_of(-step)?;
                step *= 4.0;
                if r.count > 0 {
                    break (r, hi);
                }
                hi = r.sigma;
            }
        } else {
            // Up from the axis until none is.
            let mut lo = first;
            loop {
                if step >= radius {
                    break (lo, radius);
                }
                let r = self.right_of(step)?;
                if r.count == 0 {
                    break (lo, r.sigma);
                }
                lo = r;
                step *= 4.0;
            }
        };
        for _ in 0..BISECT_MAX {
            if lo.count <= MAX_LOCAL {
                if let Some(roots) = self.localise(&lo) {
                    return roots.into_iter().max_by(|a, b| a.re.total_cmp(&b.re));
                }
            }
            let mid = 0.5 * (lo.sigma + hi);
            if hi - lo.sigma <= 1e-15 * (lo.sigma.abs() + hi.abs()) {
                break;
            }
            let r = self.right_of(mid)?;
            if r.count > 0 {
                lo = r;
            } else {
                hi = r.sigma;
            }
        }
        None
    }
}
