//! Actuator limits: the law computes `τᵢ`, the body receives `sat(τᵢ)`
//! (eq. `followeri` with the saturated torque). `PROTOCOL.md` § 10.11 gives
//! the arithmetic for plug-ins.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// How an agent's torque is limited.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Saturation {
    /// `‖τ‖ ≤ max` (N·m): a larger torque is scaled down along itself.
    Norm {
        /// The largest norm, N·m, > 0.
        max: f64,
    },
    /// `|τ_k| ≤ max_k` on each body axis (N·m): each component clamped.
    Axes {
        /// The largest magnitude per axis, N·m, each > 0.
        max: [f64; 3],
    },
}

impl Saturation {
    /// `sat(τ)`: `τ · (max / ‖τ‖)` when `‖τ‖ > max` (the norm, as
    /// § 10.1's `norm`; its result may exceed `max` by a rounding), each
    /// component clamped to `[−max_k, max_k]` per axis (exact).
    #[must_use]
    pub fn apply(&self, tau: &Vector3<f64>) -> Vector3<f64> {
        match *self {
            Saturation::Norm { max } => scale_down(tau, max),
            Saturation::Axes { max } => Vector3::new(
                tau.x.clamp(-max[0], max[0]),
                tau.y.clamp(-max[1], max[1]),
                tau.z.clamp(-max[2], max[2]),
            ),
        }
    }
}

/// A limit on how fast the applied torque changes: `‖τ(t) − τ_a‖ ≤ ρ·Δt`
/// from the torque `τ_a` applied at the last step start (`PROTOCOL.md`
/// § 10.11).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RateLimit {
    /// `ρ`, N·m/s, > 0.
    pub max: f64,
}

/// `Δt / h` from the anchor to stage `s`: the anchor of stage 0 is the
/// previous step's stage 0 (a whole step back), that of stages 1–3 the
/// current step's stage 0 (`c_s` of a step back).
const SINCE_ANCHOR: [f64; 4] = [1.0, 0.5, 0.5, 1.0];

impl RateLimit {
    /// The torque applied at stage `s` (step `h`) when `tau` is asked and
    /// `anchor` was applied at the anchor: `anchor + (tau − anchor)·(m/n)`
    /// when `n = ‖tau − anchor‖ > m = (ρ·h)·Δt/h`, else `tau`.
    #[must_use]
    pub fn apply(
        &self,
        tau: &Vector3<f64>,
        anchor: &Vector3<f64>,
        s: usize,
        h: f64,
    ) -> Vector3<f64> {
        let step = tau - anchor;
        let m = (self.max * h) * SINCE_ANCHOR[s];
        let n2 = step.norm_squared();
        if n2 < m * m * WELL_BELOW {
            return *tau;
        }
        let n = n2.sqrt();
        if n > m { anchor + step * (m / n) } else { *tau }
    }
}

/// A bound on `‖v‖²` below which `‖v‖ ≤ max` needs no square root: the
/// computed `max·max·WELL_BELOW` is below `max²` whatever its roundings,
/// so a computed `‖v‖²` under it has `sqrt` at most `max` (`sqrt` is
/// correctly rounded and `max` a double). Only a shortcut: the result is
/// the same bits as comparing `norm(v) > max` (§ 10.11); an infinite or
/// NaN `‖v‖²` fails the strict `<` and takes the long way.
const WELL_BELOW: f64 = 1.0 - 1e-6;

/// `v · (max / ‖v‖)` when `‖v‖ > max`, else `v`.
fn scale_down(v: &Vector3<f64>, max: f64) -> Vector3<f64> {
    let n2 = v.norm_squared();
    if n2 < max * max * WELL_BELOW {
        return *v;
    }
    let n = n2.sqrt();
    if n > max { v * (max / n) } else { *v }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_torque_within_the_limits_is_untouched_and_one_beyond_is_cut() {
        let tau = Vector3::new(3.0, -4.0, 0.0);
        let norm = Saturation::Norm { max: 1.0 };
        let cut = norm.apply(&tau);
        assert!((cut.norm() - 1.0).abs() <= 2.0 * f64::EPSILON);
        assert!((cut - Vector3::new(0.6, -0.8, 0.0)).norm() < 1e-15);
        assert_eq!(Saturation::Norm { max: 5.0 }.apply(&tau), tau);
        let axes = Saturation::Axes {
            max: [1.0, 10.0, 0.5],
        };
        assert_eq!(axes.apply(&tau), Vector3::new(1.0, -4.0, 0.0));
        assert_eq!(axes.apply(&-tau), Vector3::new(-1.0, 4.0, 0.0));
    }

    /// The shortcut gives the bits of the formula of § 10.11, near the
    /// limit, far from it, and for infinite and NaN torques.
    #[test]
    fn the_shortcut_below_the_limit_gives_the_formulas_bits() {
        let formula = |tau: &Vector3<f64>, max: f64| {
            let n = tau.norm();
            if n > max { tau * (max / n) } else { *tau }
        };
        let mut rng = crate::random::SplitMix64(5);
        let mut near = 0;
        for k in 0..200_000 {
            let max = [1.0, 0.3, 7.5, 1e-3, 1e200][k % 5];
            let dir = Vector3::from(rng.normal3()).normalize();
            let tau = dir * (max * (1.0 + (rng.unit() - 0.5) * 1e-5 * f64::from(k as u32 % 3)));
            near += usize::from((tau.norm() / max - 1.0).abs() < 1e-6);
            let got = Saturation::Norm { max }.apply(&tau);
            let want = formula(&tau, max);
            assert!(
                got.iter()
                    .zip(&want)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
            // the rate limit: ρ·h·1 = max at stage 0, from an anchor
            let anchor = Vector3::new(0.25, -0.5, 1.0);
            let got = RateLimit { max: max / 0.5 }.apply(&(anchor + tau), &anchor, 0, 0.5);
            let step = (anchor + tau) - anchor;
            let n = step.norm();
            let want = if n > max {
                anchor + step * (max / n)
            } else {
                anchor + tau
            };
            assert!(
                got.iter()
                    .zip(&want)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
        }
        assert!(near > 50_000, "{near} torques near the limit");
        for tau in [
            Vector3::new(f64::INFINITY, 0.0, 0.0),
            Vector3::new(f64::NAN, 1.0, 0.0),
            Vector3::new(1e160, 1e160, 0.0),
        ] {
            let got = Saturation::Norm { max: 1e200 }.apply(&tau);
            let want = formula(&tau, 1e200);
            assert!(
                got.iter()
                    .zip(&want)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
        }
    }

    #[test]
    fn a_rate_limit_moves_the_torque_at_most_rho_dt_from_its_anchor() {
        let r = RateLimit { max: 10.0 };
        let anchor = Vector3::new(1.0, 0.0, 0.0);
        let far = Vector3::new(1.0, 5.0, 0.0);
        let got = r.apply(&far, &anchor, 0, 0.01);
        assert!((got - Vector3::new(1.0, 0.1, 0.0)).norm() < 1e-15);
        let half = r.apply(&far, &anchor, 1, 0.01);
        assert!((half - Vector3::new(1.0, 0.05, 0.0)).norm() < 1e-15);
        let near = Vector3::new(1.0, 0.01, 0.0);
        assert_eq!(r.apply(&near, &anchor, 3, 0.01), near);
    }
}
