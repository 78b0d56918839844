//! A step size the theory allows: the fastest linear modes of each loop of a
//! scheme, and the largest `dt` for which RK4 keeps them stable.
//!
//! Every loop is linearised at the synchronised equilibrium (estimates on
//! the leader, bodies on their estimates, zero tracking error). With a
//! body-frame attitude error `δ` (`R̂ᵢ = R₀ exp(δᵢ^×)`), the attitude terms
//! linearise through
//!
//! ```text
//! ψ(A exp(δ^×)) = E(A) δ + O(|δ|²),   E(A) = ½ (tr(A) I − A)
//! ```
//!
//! and the graph enters as a matrix `M` (`Ξ + LLᵀ`, weighted by the gains).
//! Each loop then decouples, per eigenvalue `μ` of `M`, into a small block
//! (`docs/stiffness.md` derives them):
//!
//! ```text
//! observer (7a–7c):   [δ ω̃ σ̃]' = [[0, I, 0], [−k_R e μ I, −k_ω μ I, I], [0, 0, P − k_σ μ I]] [δ ω̃ σ̃]
//! observer (16a–16b): [δ ω̃]'   = [[0, I], [−k_R e μ I, −k_ω μ I]] [δ ω̃]
//! tracking (controlerror2): [ε ω̄]' = [[0, I], [−k_R̄ e/j I, −k_ω̄/j I]] [ε ω̄]
//! observerless (districontrol): [δ ω]' = [[0, I], [−k_Ř e μ/j I, −k_ω̌/j I]] [δ ω]
//! leader (leader):    σ₀' = P σ₀
//! ```
//!
//! with `e` an eigenvalue of `E(A)` over the loop's gain matrices and `j` an
//! eigenvalue of an inertia. Every block is block-triangular: its modes are
//! the roots of `s² + d s + k` and the eigenvalues of `P − k_σ μ I`. The gain matrices, inertias and `M` do not
//! commute in general, so each is replaced by the interval of its eigenvalues
//! ([`Interval`]); the blocks are evaluated on a grid over the intervals (ends
//! included) and their eigenvalues computed numerically. RK4's stability
//! region is the exact `|1 + z + z²/2 + z³/6 + z⁴/24| ≤ 1`
//! ([`rk4_amplification`]), searched along the ray of each eigenvalue
//! ([`rk4_step_limit`]).

use nalgebra::{Complex, Matrix3};

/// A closed interval `[min, max]` holding every eigenvalue of a family of
/// matrices (the extremes are what a loop's estimate depends on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interval {
    /// Smallest eigenvalue.
    pub min: f64,
    /// Largest eigenvalue.
    pub max: f64,
}

impl Interval {
    /// The interval `[x, x]`.
    #[must_use]
    pub fn point(x: f64) -> Self {
        Self { min: x, max: x }
    }

    /// The smallest interval holding `self` and `x`.
    #[must_use]
    pub fn with(self, x: f64) -> Self {
        Self {
            min: self.min.min(x),
            max: self.max.max(x),
        }
    }

    /// The smallest interval holding `self` and `other`.
    #[must_use]
    pub fn union(self, other: Self) -> Self {
        self.with(other.min).with(other.max)
    }

    /// `n ≥ 2` points from `min` to `max` (ends included), geometrically
    /// spaced when both are positive, else evenly.
    #[must_use]
    pub fn grid(&self, n: usize) -> Vec<f64> {
        if self.max <= self.min || n < 2 {
            return vec![self.min];
        }
        let t = |k: usize| k as f64 / (n - 1) as f64;
        if self.min > 0.0 {
            let r = self.max / self.min;
            (0..n).map(|k| self.min * r.powf(t(k))).collect()
        } else {
            (0..n)
                .map(|k| self.min + (self.max - self.min) * t(k))
                .collect()
        }
    }
}

/// One loop of a scheme, with what its linearisation needs.
#[derive(Debug, Clone, PartialEq)]
pub enum Loop {
    /// The observer `7a`–`7c` (`p: Some(P)`, `k_sigma`) or `16a`–`16b` (`p: None`).
    Observer {
        /// `k_R`.
        k_r: f64,
        /// `k_ω`.
        k_w: f64,
        /// `k_σ` (eq. `7c` only).
        k_sigma: f64,
        /// The leader generator `P` (eq. `7c`), or `None` for eq. `16b`.
        p: Option<Matrix3<f64>>,
        /// Eigenvalues of `E(A)` over every `A_{i,j}` and `A_{i,0}` ([`psi_gain`]).
        e: Interval,
        /// Eigenvalues of `Ξ + LLᵀ`.
        graph: Interval,
    },
    /// The tracking loop `controlerror2`: `J dω̄/dt = −k_R̄ ψ(Ā R̄) − k_ω̄ ω̄`.
    Tracking {
        /// `k_R̄`.
        k_r: f64,
        /// `k_ω̄`.
        k_w: f64,
        /// Eigenvalues of `E(Āᵢ)` over every agent.
        e: Interval,
        /// Eigenvalues of `Jᵢ` over every agent, kg m².
        j: Interval,
    },
    /// The observerless law `districontrol` in closed loop with the bodies.
    Observerless {
        /// `k_Ř`.
        k_r: f64,
        /// `k_ω̌`.
        k_w: f64,
        /// Eigenvalues of `E(Ǎ)` over every `Ǎ_{i,j}` and `Ǎ_{i,0}`.
        e: Interval,
        /// Eigenvalues of `Jᵢ` over every agent, kg m².
        j: Interval,
        /// Eigenvalues of `Ξ + LLᵀ`.
        graph: Interval,
    },
    /// The leader's exosystem `σ̇₀ = P σ₀` (eq. `leader`).
    Leader {
        /// `P`.
        p: Matrix3<f64>,
    },
}

impl Loop {
    /// The loop's name, as `attsync check` prints it.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Loop::Observer { .. } => "observer",
            Loop::Tracking { .. } => "tracking",
            Loop::Observerless { .. } => "observerless",
            Loop::Leader { .. } => "leader",
        }
    }
}

/// One loop's fastest linear mode and the largest stable RK4 step.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopEstimate {
    /// [`Loop::name`].
    pub name: &'static str,
    /// Largest `|λ|` of the loop's linearisation, s⁻¹.
    pub fastest_rate: f64,
    /// Smallest `|Re λ|` of the loop's linearisation, s⁻¹: the decay rate of
    /// its slowest mode (at `λmin(Ξ + LLᵀ)` for the graph loops), which sets
    /// how long the loop needs to converge (`docs/stiffness.md`).
    pub slowest_rate: f64,
    /// Largest `dt` with every `dt·λ` in RK4's stability region, s
    /// (`f64::INFINITY` when no mode limits it).
    pub dt_max: f64,
}

/// Every loop's estimate and the smallest of their step limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Estimate {
    /// One entry per loop, in the order given.
    pub loops: Vec<LoopEstimate>,
    /// The smallest `dt_max` of the loops, s.
    pub dt_max: f64,
}

impl Estimate {
    /// The error loop (every loop but the leader's exosystem, which is the
    /// reference, not an error) whose slowest mode decays the slowest.
    #[must_use]
    pub fn slowest(&self) -> Option<&LoopEstimate> {
        self.loops
            .iter()
            .filter(|l| l.name != "leader")
            .min_by(|a, b| a.slowest_rate.total_cmp(&b.slowest_rate))
    }

    /// The loop whose step limit is the smallest (the one that binds).
    #[must_use]
    pub fn binding(&self) -> Option<&LoopEstimate> {
        self.loops
            .iter()
            .min_by(|a, b| a.dt_max.total_cmp(&b.dt_max))
    }
}

/// Grid points per interval (ends included).
const GRID: usize = 9;

/// The estimate for `loops`: each loop's eigenvalues, fastest rate and RK4
/// step limit.
#[must_use]
pub fn estimate(loops: &[Loop]) -> Estimate {
    let loops: Vec<LoopEstimate> = loops
        .iter()
        .map(|l| {
            let eigs = eigenvalues(l);
            LoopEstimate {
                name: l.name(),
                fastest_rate: eigs.iter().map(|z| z.norm()).fold(0.0, f64::max),
                slowest_rate: slowest_rate(&eigs),
                dt_max: rk4_dt_max(&eigs),
            }
        })
        .collect();
    let dt_max = loops.iter().map(|l| l.dt_max).fold(f64::INFINITY, f64::min);
    Estimate { loops, dt_max }
}

/// The linear gain of `ψ(A ·)` at the identity: `ψ(A exp(δ^×)) ≈ E(A) δ`,
/// `E(A) = ½ (tr(A) I − A)`. For `A = diag(a₁, a₂, a₃)`,
/// `E(A) = ½ diag(a₂ + a₃, a₁ + a₃, a₁ + a₂)`.
///
/// ```
/// # use attitude::stiffness::psi_gain;
/// # use attitude::so3::{psi, hat};
/// # use nalgebra::{Matrix3, Vector3};
/// let a = Matrix3::from_diagonal(&Vector3::new(10.0, 11.0, 12.0));
/// let d = Vector3::new(1e-7, -2e-7, 3e-7);
/// let lin = psi_gain(&a) * d;
/// let exact = psi(&(a * (Matrix3::identity() + hat(&d))));
/// assert!((lin - exact).norm() < 1e-12);
/// ```
#[must_use]
pub fn psi_gain(a: &Matrix3<f64>) -> Matrix3<f64> {
    (Matrix3::identity() * a.trace() - a) * 0.5
}

/// The eigenvalues of every block of `l` on the grid over its intervals
/// (each distinct root once).
#[must_use]
pub fn eigenvalues(l: &Loop) -> Vec<Complex<f64>> {
    let mut out = Vec::new();
    match *l {
        Loop::Observer {
            k_r,
            k_w,
            k_sigma,
            p,
            e,
            graph,
        } => {
            for mu in graph.grid(GRID) {
                for e in e.grid(3) {
                    let s = p.map(|p| p - Matrix3::identity() * (k_sigma * mu));
                    out.extend(second_order(k_r * e * mu, k_w * mu, s.as_ref()));
                }
            }
        }
        Loop::Tracking { k_r, k_w, e, j } => {
            for j in j.grid(3) {
                for e in e.grid(3) {
                    out.extend(second_order(k_r * e / j, k_w / j, None));
                }
            }
        }
        Loop::Observerless {
            k_r,
            k_w,
            e,
            j,
            graph,
        } => {
            for mu in graph.grid(GRID) {
                for j in j.grid(3) {
                    for e in e.grid(3) {
                        out.extend(second_order(k_r * e * mu / j, k_w / j, None));
                    }
                }
            }
        }
        Loop::Leader { p } => out.extend(p.complex_eigenvalues().iter().copied()),
    }
    out
}

/// Eigenvalues of `[[0, I, 0], [−k I, −d I, I], [0, 0, S]]` (6×6 without
/// `S`, 9×9 with it): `ẍ + d ẋ + k x = σ`, `σ̇ = S σ`. The block is upper
/// block-triangular, so its spectrum is that of `S` (3×3, computed
/// numerically) and, three times over, the roots of `s² + d s + k`.
///
/// # NOTE
/// Not `DMatrix::complex_eigenvalues` of the 9×9 block: nalgebra's Schur
/// iteration has no iteration limit there and does not converge on such
/// blocks with repeated eigenvalues (it hung on the paper's scenarios).
fn second_order(k: f64, d: f64, s: Option<&Matrix3<f64>>) -> Vec<Complex<f64>> {
    let mut out = quadratic_roots(d, k).to_vec();
    if let Some(s) = s {
        out.extend(s.complex_eigenvalues().iter().copied());
    }
    out
}

/// The roots of `s² + d s + k` (real roots without cancellation).
#[must_use]
pub fn quadratic_roots(d: f64, k: f64) -> [Complex<f64>; 2] {
    let disc = d * d - 4.0 * k;
    if disc >= 0.0 {
        let q = -0.5 * (d + d.signum() * disc.sqrt());
        let other = if q == 0.0 { 0.0 } else { k / q };
        [Complex::new(q, 0.0), Complex::new(other, 0.0)]
    } else {
        let im = 0.5 * (-disc).sqrt();
        [Complex::new(-0.5 * d, im), Complex::new(-0.5 * d, -im)]
    }
}

/// RK4's amplification factor `|1 + z + z²/2 + z³/6 + z⁴/24|` (one step of
/// `ẋ = λ x` multiplies `x` by the polynomial at `z = λ dt`).
#[must_use]
pub fn rk4_amplification(z: Complex<f64>) -> f64 {
    let one = Complex::new(1.0, 0.0);
    (one + z * (one + z * (one / 2.0 + z * (one / 6.0 + z / 24.0)))).norm()
}

/// Tolerance on the amplification factor (round-off on the imaginary axis).
const AMP_TOL: f64 = 1e-12;

/// Farthest `|z|` of RK4's stability region (≈ 2.96); the search stops past it.
const MAX_Z: f64 = 3.2;

/// The largest `h` with `|R(h' λ)| ≤ 1` for every `h' ≤ h`: the first exit of
/// the ray `h λ` from RK4's stability region (sampled, then bisected).
/// `f64::INFINITY` for `λ = 0` and for a growing mode (`Re λ > 0`), which no
/// step size stabilises (nor makes worse than the continuous system).
#[must_use]
pub fn rk4_step_limit(lambda: Complex<f64>) -> f64 {
    let r = lambda.norm();
    if r == 0.0 || !r.is_finite() || lambda.re > 1e-12 * r {
        return f64::INFINITY;
    }
    let dir = lambda / r;
    let inside = |t: f64| rk4_amplification(dir * t) <= 1.0 + AMP_TOL;
    const SAMPLES: usize = 640;
    let mut lo = 0.0;
    let mut hi = MAX_Z;
    for k in 1..=SAMPLES {
        let t = MAX_Z * k as f64 / SAMPLES as f64;
        if !inside(t) {
            hi = t;
            break;
        }
        lo = t;
    }
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if inside(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo / r
}

/// The decay rate of the slowest of `eigs`: the smallest `|Re λ|`
/// (`f64::INFINITY` for none).
#[must_use]
pub fn slowest_rate(eigs: &[Complex<f64>]) -> f64 {
    eigs.iter()
        .map(|z| z.re.abs())
        .fold(f64::INFINITY, f64::min)
}

/// The largest stable RK4 step for a set of modes: the smallest
/// [`rk4_step_limit`] (`f64::INFINITY` for none).
#[must_use]
pub fn rk4_dt_max(eigs: &[Complex<f64>]) -> f64 {
    eigs.iter()
        .map(|&z| rk4_step_limit(z))
        .fold(f64::INFINITY, f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn c(re: f64, im: f64) -> Complex<f64> {
        Complex::new(re, im)
    }

    #[test]
    fn rk4_region_crosses_the_real_axis_at_2_7853() {
        let h = rk4_step_limit(c(-1.0, 0.0));
        assert!((h - 2.785_293_563).abs() < 1e-6, "{h}");
        assert!((rk4_step_limit(c(-1000.0, 0.0)) * 1000.0 - h).abs() < 1e-9);
    }

    #[test]
    fn rk4_region_crosses_the_imaginary_axis_at_2_sqrt_2() {
        let h = rk4_step_limit(c(0.0, 1.0));
        assert!((h - 2.0 * 2f64.sqrt()).abs() < 1e-6, "{h}");
        assert!((rk4_step_limit(c(0.0, -2.0)) * 2.0 - h).abs() < 1e-6);
    }

    #[test]
    fn growing_and_zero_modes_do_not_limit_the_step() {
        assert_eq!(rk4_step_limit(c(0.0, 0.0)), f64::INFINITY);
        assert_eq!(rk4_step_limit(c(1.0, 1.0)), f64::INFINITY);
        assert_eq!(rk4_dt_max(&[]), f64::INFINITY);
    }

    #[test]
    fn a_scalar_loop_has_its_known_eigenvalue() {
        // Overdamped tracking loop with j = 1: s² + 10 s + 9 = 0 → s = −1, −9.
        let l = Loop::Tracking {
            k_r: 9.0,
            k_w: 10.0,
            e: Interval::point(1.0),
            j: Interval::point(1.0),
        };
        let eigs = eigenvalues(&l);
        let fast = eigs.iter().map(|z| z.norm()).fold(0.0, f64::max);
        assert!((fast - 9.0).abs() < 1e-9, "{eigs:?}");
        let est = estimate(&[l]);
        assert!((est.dt_max - 2.785_293_563 / 9.0).abs() < 1e-6);
        assert_eq!(est.binding().map(|b| b.name), Some("tracking"));
    }

    #[test]
    fn the_sigma_mode_of_the_observer_is_k_sigma_times_lambda_max() {
        let p = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, -0.5, 0.0, 0.5, 0.0);
        let l = Loop::Observer {
            k_r: 1e-3,
            k_w: 1e-3,
            k_sigma: 1000.0,
            p: Some(p),
            e: Interval::point(1.0),
            graph: Interval { min: 0.5, max: 4.0 },
        };
        let est = estimate(&[l]);
        // σ̃ modes: eig(P) − 4000 → fastest ≈ 4001.
        assert!((est.loops[0].fastest_rate - 4001.0).abs() < 1e-6, "{est:?}");
        assert!((est.dt_max - 2.785_293_563 / 4001.0).abs() < 1e-8);
    }

    #[test]
    fn quadratic_roots_solve_the_quadratic() {
        for (d, k) in [(10.0, 9.0), (1.0, 100.0), (1e4, 1e-2), (0.0, 4.0)] {
            for r in quadratic_roots(d, k) {
                let v = r * r + r * d + Complex::new(k, 0.0);
                assert!(v.norm() <= 1e-9 * (d * d + k), "{d} {k} {r}");
            }
        }
    }

    #[test]
    fn psi_gain_of_a_diagonal_matrix() {
        let a = Matrix3::from_diagonal(&nalgebra::Vector3::new(1.0, 2.0, 4.0));
        let e = psi_gain(&a);
        assert_eq!(
            e,
            Matrix3::from_diagonal(&nalgebra::Vector3::new(3.0, 2.5, 1.5))
        );
    }

    #[test]
    fn grid_includes_both_ends() {
        let g = Interval {
            min: 0.1,
            max: 10.0,
        }
        .grid(5);
        assert_eq!(g.len(), 5);
        assert!((g[0] - 0.1).abs() < 1e-15 && (g[4] - 10.0).abs() < 1e-12);
        assert_eq!(Interval::point(3.0).grid(5), vec![3.0]);
    }

    /// The observer's slowest mode sits at `λmin(Ξ + LLᵀ)`: underdamped
    /// there, it decays at `k_ω λmin / 2`; the leader is not an error loop.
    #[test]
    fn slowest_rate_of_an_underdamped_observer_is_half_k_w_lambda_min() {
        let obs = Loop::Observer {
            k_r: 9.0,
            k_w: 14.0,
            k_sigma: 12.0,
            p: None,
            e: Interval::point(10.5),
            graph: Interval {
                min: 0.01,
                max: 5.0,
            },
        };
        let leader = Loop::Leader {
            p: Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0),
        };
        let est = estimate(&[leader, obs]);
        let slow = est.slowest().expect("an error loop");
        assert_eq!(slow.name, "observer");
        assert!((slow.slowest_rate - 0.07).abs() < 1e-12, "{slow:?}");
        assert_eq!(est.loops[0].slowest_rate, 0.0);
    }
}
