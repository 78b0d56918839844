//! `G(ω) = (iω I − A₀)⁻¹ A₁` over frequency, for `z' = A₀ z + A₁ z(t − d)`:
//! a root `s = σ + iω` of `det(s I − A₀ − e^{−sd} A₁)` makes `e^{sd}` an
//! eigenvalue of `(s I − A₀)⁻¹ A₁`, so
//! - on the axis (`σ = 0`) an eigenvalue of `G(ω)` is on the unit circle
//!   (the margin sweep, [`super::margin`], counts those outside);
//! - near the axis, `σ ≈ ln ρ(G(ω)) / d`: the roots with `Re s ≥ σ` have
//!   frequencies where `ρ(G(ω)) ≳ e^{σd}` (for a long delay they line up
//!   along this curve, the asymptotic continuous spectrum), which tells the
//!   root search ([`super::roots`]) up to which frequency it must resolve.
//!
//! With `A₁ = B P` (`P` selecting the `p` columns of `A₁` that are not zero),
//! the nonzero eigenvalues of `G` are those of the `p × p` matrix
//! `P (iω I − A₀)⁻¹ B`.

use super::eig::complex_eigenvalues;
use super::roots::eigenvalues;
use nalgebra::{Complex, DMatrix};

/// Samples per decade of the log-spaced grid.
const PER_DECADE: usize = 100;

/// Decades of the grid below its top (the first sample is `ω = 0`).
const DECADES: usize = 5;

/// The smallest spectral radius the profile resolves: it reaches up to the
/// frequency beyond which `ρ(G) < RHO_MIN` for certain.
pub const RHO_MIN: f64 = 0.25;

/// `A₀` and the nonzero columns `B` of `A₁` as complex matrices, and which
/// columns they are: what `G(ω)`'s eigenvalues are computed from.
#[derive(Debug, Clone, PartialEq)]
pub struct Sweep {
    a0: DMatrix<Complex<f64>>,
    b: DMatrix<Complex<f64>>,
    cols: Vec<usize>,
}

impl Sweep {
    /// For `z' = a0 z + a1 z(t − d)`.
    #[must_use]
    pub fn new(a0: &DMatrix<f64>, a1: &DMatrix<f64>) -> Self {
        let cols: Vec<usize> = (0..a1.ncols())
            .filter(|&j| a1.column(j).iter().any(|&v| v != 0.0))
            .collect();
        Self {
            a0: a0.map(|v| Complex::new(v, 0.0)),
            b: a1.select_columns(cols.iter()).map(|v| Complex::new(v, 0.0)),
            cols,
        }
    }

    /// The nonzero eigenvalues of `G(ω)` (`None` where `iω I − A₀` is
    /// singular or QR does not converge).
    #[must_use]
    pub fn eigs(&self, w: f64) -> Option<Vec<Complex<f64>>> {
        let n = self.a0.nrows();
        let mut m = -self.a0.clone();
        for i in 0..n {
            m[(i, i)] += Complex::new(0.0, w);
        }
        let x = m.lu().solve(&self.b)?;
        complex_eigenvalues(&x.select_rows(self.cols.iter()))
    }

    /// How many eigenvalues of `G(ω)` are outside the unit circle.
    #[must_use]
    pub fn count(&self, w: f64) -> Option<usize> {
        self.eigs(w)
            .map(|e| e.iter().filter(|z| z.norm() > 1.0).count())
    }
}

/// The frequencies to sample: 0, a log-spaced grid up to `w_max`, and a
/// dense patch around each resonance `Im λ(A₀)` (where `|μ|` can peak
/// sharply: a quarter of the resonance's width apart, 16 each side).
fn grid(a0: &DMatrix<f64>, w_max: f64) -> Vec<f64> {
    let lo = w_max * 10f64.powi(-(DECADES as i32));
    let count = PER_DECADE * DECADES;
    let mut w: Vec<f64> = std::iter::once(0.0)
        .chain((0..=count).map(|k| lo * (w_max / lo).powf(k as f64 / count as f64)))
        .collect();
    for z in eigenvalues(a0) {
        if z.im > 0.0 && z.im < w_max {
            let width = z.re.abs().max(1e-9 * z.norm());
            for k in -16i32..=16 {
                let x = z.im + f64::from(k) * 0.25 * width;
                if x > 0.0 && x < w_max {
                    w.push(x);
                }
            }
        }
    }
    w.sort_by(f64::total_cmp);
    w.dedup();
    w
}

/// One sample of the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The frequency, rad/s.
    pub omega: f64,
    /// `ρ(G(ω))`.
    pub rho: f64,
    /// How many eigenvalues of `G(ω)` are outside the unit circle.
    pub outside: usize,
}

/// `ρ(G(ω))` and the count outside the unit circle, sampled from 0 to the
/// frequency beyond which `ρ(G) < RHO_MIN` (`‖A₀‖ + ‖A₁‖/RHO_MIN`: there
/// `ρ(G) ≤ ‖A₁‖/(ω − ‖A₀‖)`).
#[derive(Debug, Clone, PartialEq)]
pub struct Profile {
    samples: Vec<Sample>,
    top: f64,
}

impl Profile {
    /// The profile of `z' = a0 z + a1 z(t − d)` (no sample if `a1 = 0`).
    #[must_use]
    pub fn of(a0: &DMatrix<f64>, a1: &DMatrix<f64>) -> Self {
        if a1.norm() == 0.0 {
            return Self {
                samples: Vec::new(),
                top: 0.0,
            };
        }
        let sweep = Sweep::new(a0, a1);
        let top = 1.01 * (a0.norm() + a1.norm() / RHO_MIN);
        let samples = grid(a0, top)
            .into_iter()
            .filter_map(|omega| {
                let e = sweep.eigs(omega)?;
                Some(Sample {
                    omega,
                    rho: e.iter().map(|z| z.norm()).fold(0.0, f64::max),
                    outside: e.iter().filter(|z| z.norm() > 1.0).count(),
                })
            })
            .collect();
        Self { samples, top }
    }

    /// The samples, by increasing frequency.
    #[must_use]
    pub fn samples(&self) -> &[Sample] {
        &self.samples
    }

    /// The frequency up to which `ρ(G) ≥ threshold` (the sample after the
    /// last one that reaches it; 0 if none does). `threshold` below
    /// [`RHO_MIN`] counts as [`RHO_MIN`].
    #[must_use]
    pub fn omega(&self, threshold: f64) -> f64 {
        let t = threshold.max(RHO_MIN);
        match self.samples.iter().rposition(|x| x.rho >= t) {
            Some(k) => self.samples.get(k + 1).map_or(self.top, |x| x.omega),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `x' = −a x(t − d)`: `G(ω) = −a/(iω)`, `ρ = a/ω`.
    #[test]
    fn the_profile_of_a_pure_delay() {
        let a = 3.0;
        let p = Profile::of(
            &DMatrix::from_element(1, 1, 0.0),
            &DMatrix::from_element(1, 1, -a),
        );
        for x in p.samples().iter().filter(|x| x.omega > 0.0) {
            assert!((x.rho - a / x.omega).abs() < 1e-12 * x.rho, "{x:?}");
            assert_eq!(x.outside, usize::from(x.omega < a));
        }
        // ρ ≥ 1/2 up to 2a, the next sample just above.
        let w = p.omega(0.5);
        assert!(w > 2.0 * a && w < 2.0 * a * 1.03, "{w}");
        assert_eq!(p.omega(0.1), p.omega(RHO_MIN));
        assert_eq!(
            Profile::of(&DMatrix::from_element(1, 1, -1.0), &DMatrix::zeros(1, 1)).omega(0.5),
            0.0
        );
    }

    /// Only the nonzero columns of `A₁` enter: `G`'s nonzero eigenvalues
    /// are those of the small matrix.
    #[test]
    fn g_is_reduced_to_the_delayed_columns() {
        let a0 = DMatrix::from_row_slice(3, 3, &[-1.0, 1.0, 0.0, -2.0, -3.0, 0.5, 0.0, 1.0, -4.0]);
        let a1 = DMatrix::from_row_slice(3, 3, &[0.0, 0.0, 0.3, 0.0, 0.0, -1.0, 0.0, 0.0, 0.7]);
        let s = Sweep::new(&a0, &a1);
        let w = 1.3;
        let e = s.eigs(w).expect("regular");
        assert_eq!(e.len(), 1);
        let m = DMatrix::from_fn(3, 3, |i, j| {
            let diag = if i == j { w } else { 0.0 };
            Complex::new(-a0[(i, j)], diag)
        });
        let g = m
            .lu()
            .solve(&a1.map(|v| Complex::new(v, 0.0)))
            .expect("regular");
        // G has rank 1: its one nonzero eigenvalue is its trace.
        assert!((e[0] - g.trace()).norm() < 1e-14);
    }
}
