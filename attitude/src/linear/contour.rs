//! Counting the zeros of an analytic `f` inside a rectangle by the argument
//! principle, from `ln f` (imaginary part known modulo 2π) and `(ln f)'`
//! only ([`super::tree::LogDet`]).
//!
//! Along every side the change of `arg f` is summed over segments refined
//! adaptively until each is resolved: with `m` its midpoint, the principal
//! values of `Im(ln f(m) − ln f(a))` and `Im(ln f(b) − ln f(m))` are each at
//! most [`MAX_TURN`], Simpson's rule on `(ln f)'` reproduces both the
//! exact `Re(ln f(b) − ln f(a))` and their sum within [`AGREE`], and the
//! segment is short against `1/|(ln f)'|` at its three points
//! ([`MAX_PULL`]). A zero close to a segment turns the argument by ≈ π
//! there, makes `(ln f)'` too sharp for Simpson's rule, or large at the
//! nearest point: the segment is split. The resolved turns are
//! principal values of differences of `Im ln f`, so around a closed contour
//! they add up to `2π k` exactly (up to rounding). (After the standard
//! practice of Kravanja & Van Barel, "Computing the zeros of analytic
//! functions", LNM 1727, 2000.)
//!
//! `f` real on the real axis (`det Δ(s)` of a real system) has conjugate
//! zeros: the count in a box symmetric about the real axis is `1/π` times
//! the turn along its upper half alone ([`count_symmetric`]).

use super::tree::LogDet;
use nalgebra::Complex;
use std::f64::consts::PI;

type C = Complex<f64>;

/// The largest turn of `arg f` accepted over half a segment, rad.
pub const MAX_TURN: f64 = 1.5;

/// Agreement of Simpson's rule with the exact change of `ln f` over a
/// segment (both parts), absolute.
pub const AGREE: f64 = 0.1;

/// The largest `h·|(ln f)'|` accepted at a segment's three points (`h` its
/// length): a cluster of `k` zeros within the segment is within `h/4` of
/// one of them, where `|(ln f)'| ≈ 4k/h`; a miscount needs two zeros
/// (one only turns `arg f` by ≈ π, which [`MAX_TURN`] catches), `8/h`.
pub const MAX_PULL: f64 = 6.0;

/// Evaluations of `f` per contour before giving up.
pub const MAX_EVALS: usize = 400_000;

/// Initial segments per side.
const START: usize = 8;

/// The principal value of an angle, in `(−π, π]`.
fn wrap(x: f64) -> f64 {
    let y = x.rem_euclid(2.0 * PI);
    if y > PI { y - 2.0 * PI } else { y }
}

/// A segment of a walk where `arg f` turned: its midpoint and the turn.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turn {
    /// The segment's midpoint.
    pub at: C,
    /// How far `arg f` turned along it, rad (a zero just inside the
    /// contour turns it forwards, one just outside backwards).
    pub turn: f64,
    /// The segment's length.
    pub span: f64,
    /// `|(ln f)'|` at the midpoint: about the inverse distance to the
    /// nearest zero, inside or outside.
    pub pull: f64,
}

/// The total turn of `arg f` along a polyline and where it turned.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Walk {
    /// The total turn, rad.
    pub turn: f64,
    /// Every resolved segment where `arg f` turned by at least 0.05 rad or
    /// `ln |f|` changed by about as much.
    pub turns: Vec<Turn>,
    /// Evaluations of `f`.
    pub evals: usize,
}

/// `f` at a point, cached with the point.
type Point = (C, LogDet);

/// The turn of `arg f` along the segment `a → b` (adaptive, the module's
/// docs), appended to `walk`; `None` if a segment shrinks to the rounding
/// (a zero on the contour) or the evaluations run out.
fn segment(f: &impl Fn(C) -> Option<LogDet>, a: Point, b: Point, walk: &mut Walk) -> Option<()> {
    let mut stack = vec![(a, b)];
    while let Some((a, b)) = stack.pop() {
        let h = b.0 - a.0;
        if h.norm() <= 1e-14 * (a.0.norm() + b.0.norm()) || walk.evals >= MAX_EVALS {
            return None;
        }
        let m = 0.5 * (a.0 + b.0);
        let fm = (m, f(m)?);
        walk.evals += 1;
        let t1 = wrap(fm.1.value.im - a.1.value.im);
        let t2 = wrap(b.1.value.im - fm.1.value.im);
        let exact_re = b.1.value.re - a.1.value.re;
        let q = h / 6.0 * (a.1.slope + fm.1.slope * 4.0 + b.1.slope);
        let pull =
            a.1.slope
                .norm()
                .max(fm.1.slope.norm())
                .max(b.1.slope.norm());
        let resolved = pull * h.norm() <= MAX_PULL
            && t1.abs() <= MAX_TURN
            && t2.abs() <= MAX_TURN
            && (q.re - exact_re).abs() <= AGREE
            && (q.im - (t1 + t2)).abs() <= AGREE;
        if resolved {
            walk.turn += t1 + t2;
            let pull = fm.1.slope.norm();
            if (t1 + t2).abs() >= 0.05 || pull * h.norm() >= 0.05 {
                walk.turns.push(Turn {
                    at: m,
                    turn: t1 + t2,
                    span: h.norm(),
                    pull,
                });
            }
        } else {
            // Left half on top: the walk goes in order.
            stack.push((fm, b));
            stack.push((a, fm));
        }
    }
    Some(())
}

/// The turn of `arg f` along the polyline through `vertices`.
pub fn walk(f: &impl Fn(C) -> Option<LogDet>, vertices: &[C]) -> Option<Walk> {
    let mut w = Walk::default();
    walk_into(f, vertices, &mut w).map(|()| w)
}

/// [`walk`] into `w`.
fn walk_into(f: &impl Fn(C) -> Option<LogDet>, vertices: &[C], w: &mut Walk) -> Option<()> {
    let mut prev: Option<Point> = None;
    for pair in vertices.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        let mut last = match prev {
            Some(p) => p,
            None => {
                w.evals += 1;
                (a, f(a)?)
            }
        };
        for k in 1..=START {
            let z = a + (b - a) * (k as f64 / START as f64);
            let fz = (z, f(z)?);
            w.evals += 1;
            segment(f, last, fz, w)?;
            last = fz;
        }
        prev = Some(last);
    }
    Some(())
}

/// The zeros of `f` (real on the real axis) in `[x0, x1] × [−y, y]`, with
/// multiplicity, and the walk along the upper half `x1 → x1 + iy → x0 + iy
/// → x0`; `None` if a zero is on the contour (or too near to resolve).
pub fn count_symmetric(
    f: &impl Fn(C) -> Option<LogDet>,
    x0: f64,
    x1: f64,
    y: f64,
) -> Option<(usize, Walk)> {
    let v = [
        C::new(x1, 0.0),
        C::new(x1, y),
        C::new(x0, y),
        C::new(x0, 0.0),
    ];
    let w = walk(f, &v)?;
    let k = w.turn / PI;
    let n = k.round();
    ((k - n).abs() < 0.25 && n >= 0.0).then_some((n as usize, w))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `f(s) = Π (s − z_k)` for given zeros (and their conjugates).
    fn poly(zeros: &[C]) -> impl Fn(C) -> Option<LogDet> + '_ {
        move |s: C| {
            let mut value = C::new(0.0, 0.0);
            let mut slope = C::new(0.0, 0.0);
            for z in zeros {
                let both = [*z, z.conj()];
                let ws = if z.im == 0.0 { &both[..1] } else { &both[..] };
                for w in ws {
                    let d = s - w;
                    value += d.ln();
                    slope += d.inv();
                }
            }
            let value = C::new(value.re, wrap(value.im));
            Some(LogDet { value, slope })
        }
    }

    #[test]
    fn counts_zeros_close_to_the_contour() {
        let zeros = [
            C::new(-0.5, 3.0),
            C::new(1e-7, 2.0),
            C::new(1e-7, 2.0 + 1e-6),
            C::new(-1e-7, 5.0),
            C::new(0.3, 0.0),
            C::new(-0.2, 0.0),
        ];
        let f = poly(&zeros);
        let (n, w) = count_symmetric(&f, 0.0, 10.0, 10.0).expect("resolves");
        // 0.3 (real), the pairs at 1e-7 ± 2i and 1e-7 ± (2+1e-6)i.
        assert_eq!(n, 5, "{w:?}");
        let (n, _) = count_symmetric(&f, -1.0, 10.0, 10.0).expect("resolves");
        assert_eq!(n, 10);
        let (n, _) = count_symmetric(&f, -1.0, 10.0, 2.5).expect("resolves");
        assert_eq!(n, 6);
    }
}
