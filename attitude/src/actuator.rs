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
            Saturation::Norm { max } => {
                let n = tau.norm();
                if n > max { tau * (max / n) } else { *tau }
            }
            Saturation::Axes { max } => Vector3::new(
                tau.x.clamp(-max[0], max[0]),
                tau.y.clamp(-max[1], max[1]),
                tau.z.clamp(-max[2], max[2]),
            ),
        }
    }
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
}
