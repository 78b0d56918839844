//! A linear retarded delay system, its characteristic matrix and Newton's
//! method on its determinant.
//!
//! ```text
//! z'(t) = A₀ z(t) + Σ_k A_k z(t − τ_k),   τ_k > 0 distinct
//! Δ(s)  = s I − A₀ − Σ_k A_k e^{−s τ_k}     (characteristic matrix)
//! Δ'(s) = I + Σ_k τ_k A_k e^{−s τ_k}
//! ```
//!
//! The characteristic roots are the `s` with `det Δ(s) = 0`; Newton's
//! method on `det Δ` needs only `(det Δ)'/det Δ = tr(Δ(s)⁻¹ Δ'(s))`.

use nalgebra::{Complex, DMatrix};

/// A linear retarded delay system `z' = A₀ z + Σ_k A_k z(t − τ_k)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Dde {
    a0: DMatrix<f64>,
    /// `(τ_k, A_k)`, `τ_k > 0` distinct, increasing.
    delayed: Vec<(f64, DMatrix<f64>)>,
}

/// Newton iterations before giving up.
const NEWTON_MAX: usize = 60;

impl Dde {
    /// The system `z' = a0 z + Σ a_k z(t − τ_k)` for `delayed = [(τ_k, a_k)]`.
    /// Terms with `τ = 0` are added to `a0`, terms with equal delays summed.
    /// Panics unless every matrix is square of one size and every delay is
    /// finite and ≥ 0.
    #[must_use]
    pub fn new(a0: DMatrix<f64>, delayed: Vec<(f64, DMatrix<f64>)>) -> Self {
        assert!(a0.is_square(), "A₀ must be square");
        let n = a0.nrows();
        let mut a0 = a0;
        let mut out: Vec<(f64, DMatrix<f64>)> = Vec::with_capacity(delayed.len());
        for (tau, a) in delayed {
            assert!(
                a.nrows() == n && a.ncols() == n,
                "a delayed matrix is {}×{}, A₀ is {n}×{n}",
                a.nrows(),
                a.ncols()
            );
            assert!(
                tau.is_finite() && tau >= 0.0,
                "delay {tau} must be finite and ≥ 0"
            );
            if tau == 0.0 {
                a0 += a;
            } else if let Some(k) = out.iter().position(|(t, _)| *t == tau) {
                out[k].1 += a;
            } else {
                out.push((tau, a));
            }
        }
        out.sort_by(|x, y| x.0.total_cmp(&y.0));
        Self { a0, delayed: out }
    }

    /// The dimension `n` of `z`.
    #[must_use]
    pub fn dim(&self) -> usize {
        self.a0.nrows()
    }

    /// `A₀`.
    #[must_use]
    pub fn a0(&self) -> &DMatrix<f64> {
        &self.a0
    }

    /// `(τ_k, A_k)`, delays increasing.
    #[must_use]
    pub fn delayed(&self) -> &[(f64, DMatrix<f64>)] {
        &self.delayed
    }

    /// The largest delay (0 without any).
    #[must_use]
    pub fn tau_max(&self) -> f64 {
        self.delayed.last().map_or(0.0, |(t, _)| *t)
    }

    /// The components of `z` that some `A_k` reads (columns not all zero):
    /// only their history matters.
    #[must_use]
    pub fn delayed_columns(&self) -> Vec<usize> {
        (0..self.dim())
            .filter(|&j| {
                self.delayed
                    .iter()
                    .any(|(_, a)| a.column(j).iter().any(|&v| v != 0.0))
            })
            .collect()
    }

    /// `A₀ + Σ_k A_k`: the system with every delay set to 0.
    #[must_use]
    pub fn undelayed(&self) -> DMatrix<f64> {
        let mut a = self.a0.clone();
        for (_, ak) in &self.delayed {
            a += ak;
        }
        a
    }

    /// `Δ(s)` and `Δ'(s)`.
    #[must_use]
    pub fn characteristic(
        &self,
        s: Complex<f64>,
    ) -> (DMatrix<Complex<f64>>, DMatrix<Complex<f64>>) {
        let n = self.dim();
        let mut d = DMatrix::from_fn(n, n, |i, j| {
            let v = Complex::new(-self.a0[(i, j)], 0.0);
            if i == j { v + s } else { v }
        });
        let mut dp = DMatrix::identity(n, n);
        for (tau, a) in &self.delayed {
            let e = (-s * *tau).exp();
            for j in 0..n {
                for i in 0..n {
                    let v = a[(i, j)];
                    if v != 0.0 {
                        d[(i, j)] -= e * v;
                        dp[(i, j)] += e * (v * *tau);
                    }
                }
            }
        }
        (d, dp)
    }

    /// A scale of `Δ(s)`'s entries: `|s| + ‖A₀‖ + Σ ‖A_k‖ |e^{−s τ_k}|`
    /// (Frobenius norms), what [`Self::residual`] is relative to.
    #[must_use]
    pub fn scale(&self, s: Complex<f64>) -> f64 {
        s.norm()
            + self.a0.norm()
            + self
                .delayed
                .iter()
                .map(|(tau, a)| a.norm() * (-s.re * tau).exp())
                .sum::<f64>()
    }

    /// How far `s` is from a characteristic root: `1 / (‖Δ(s)⁻¹‖₁ ·`
    /// [`Self::scale`]`)`, which is within a factor `n` of the smallest
    /// singular value of `Δ(s)` relative to its scale (0 where `Δ(s)` is
    /// exactly singular, ≈ 1e-16 at a root found to machine precision).
    #[must_use]
    pub fn residual(&self, s: Complex<f64>) -> f64 {
        let (d, _) = self.characteristic(s);
        let Some(inv) = d.lu().try_inverse() else {
            return 0.0;
        };
        let norm1 = (0..inv.ncols())
            .map(|j| inv.column(j).iter().map(|z| z.norm()).sum::<f64>())
            .fold(0.0, f64::max);
        1.0 / (norm1 * self.scale(s))
    }

    /// A characteristic root near `s0`, by Newton's method on `det Δ`:
    /// `s ← s − 1 / tr(Δ(s)⁻¹ Δ'(s))`. `None` if the iteration leaves the
    /// finite numbers or does not settle (within 1e-6 relative) in 60
    /// steps. A double root converges linearly, to about the square root of
    /// the rounding (≈ 1e-8 relative).
    #[must_use]
    pub fn refine(&self, s0: Complex<f64>) -> Option<Complex<f64>> {
        let mut s = s0;
        let mut last = f64::INFINITY;
        for _ in 0..NEWTON_MAX {
            let (d, dp) = self.characteristic(s);
            let Some(x) = d.lu().solve(&dp) else {
                // Δ(s) exactly singular: s is a root.
                return Some(s);
            };
            let tr = x.trace();
            if !(tr.re.is_finite() && tr.im.is_finite()) || tr.norm() == 0.0 {
                return None;
            }
            let step = tr.inv();
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

    #[test]
    fn zero_delays_fold_into_a0_and_equal_delays_add() {
        let d = scalar(-1.0, &[(0.0, -2.0), (0.5, -3.0), (0.2, 1.0), (0.5, 0.5)]);
        assert_eq!(d.a0()[(0, 0)], -3.0);
        assert_eq!(d.delayed().len(), 2);
        assert_eq!(d.delayed()[0].0, 0.2);
        assert_eq!(d.delayed()[1].1[(0, 0)], -2.5);
        assert_eq!(d.tau_max(), 0.5);
        assert_eq!(d.undelayed()[(0, 0)], -4.5);
    }

    #[test]
    fn newton_finds_the_roots_of_a_scalar_delay_equation() {
        // s + 1 + e^{−s} = 0 (x' = −x − x(t − 1)), from near its pair.
        let d = scalar(-1.0, &[(1.0, -1.0)]);
        let s = d.refine(Complex::new(-0.5, 1.7)).expect("converges");
        let f = s + 1.0 + (-s).exp();
        assert!(f.norm() < 1e-13, "{s} {f}");
        assert!(d.residual(s) < 1e-14, "{}", d.residual(s));
        assert!(d.residual(Complex::new(0.0, 1.0)) > 1e-3);
    }

    #[test]
    #[should_panic(expected = "finite and ≥ 0")]
    fn a_negative_delay_is_refused() {
        let _ = scalar(-1.0, &[(-1.0, -1.0)]);
    }
}
