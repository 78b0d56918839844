//! The actuator limit: the torque's norm scaled down to `τ_max`.

use nalgebra::Vector3;

/// Torque-norm saturation: the direction of `τ` is kept, its norm is
/// limited to `τ_max`.
///
/// # Equation
/// ```text
/// sat(τ) = τ · min(1, τ_max / ‖τ‖)
/// ```
/// `τ` body-frame torque (N·m); `τ_max` > 0 the largest torque norm the
/// actuators deliver (N·m; `f64::INFINITY` turns the limit off).
///
/// # NOTE
/// Norm scaling, not per-component clipping: it keeps the direction the
/// districontrol law asks for, and it bounds exactly the quantity attsync
/// reports (`peak_torque` = max ‖τᵢ‖). Clipping each component to ±τ_max
/// would allow ‖τ‖ up to √3·τ_max. A torque within the limit is returned
/// unchanged (bit for bit), so with an infinite limit the agent reproduces
/// the built-in one exactly. The scaled torque is nudged down by an ulp if
/// round-off would put its computed norm above `τ_max`.
///
/// ```
/// use nalgebra::Vector3;
/// use saturated_agent::saturate;
/// let tau = Vector3::new(3.0, -4.0, 12.0); // ‖τ‖ = 13
/// let s = saturate(&tau, 6.5);
/// assert!(s.norm() <= 6.5 && (s.norm() - 6.5).abs() < 1e-12);
/// assert!((s - tau * 0.5).norm() < 1e-12); // same direction, half the norm
/// assert_eq!(saturate(&tau, 20.0), tau); // within the limit: untouched
/// ```
#[must_use]
pub fn saturate(tau: &Vector3<f64>, tau_max: f64) -> Vector3<f64> {
    assert!(tau_max > 0.0, "τ_max must be positive, got {tau_max}");
    let norm = tau.norm();
    if norm <= tau_max {
        return *tau;
    }
    let mut s = tau * (tau_max / norm);
    while s.norm() > tau_max {
        s *= 1.0 - f64::EPSILON;
    }
    s
}
