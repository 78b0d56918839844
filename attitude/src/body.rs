//! Rigid-body rotational dynamics, eq. `followeri`.

use crate::integrate::{LieDerivative, LieState};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Inertia of one rigid body, with its inverse computed once.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Inertia {
    /// `J`, symmetric positive definite, body frame, kg·m².
    pub j: Matrix3<f64>,
    /// `J⁻¹`.
    pub j_inv: Matrix3<f64>,
}

impl Inertia {
    /// Wraps `J`. Panics if `J` is singular (validate SPD before).
    #[must_use]
    pub fn new(j: Matrix3<f64>) -> Self {
        let j_inv = j.try_inverse().expect("inertia must be invertible");
        Self { j, j_inv }
    }
}

/// Euler's equation solved for `ω̇`.
///
/// # Equation
/// ```text
/// (followeri)  J ω̇ = −ω × Jω + τ
/// ```
/// `ω` body-frame angular velocity (rad/s), `τ` body-frame torque (N·m).
#[must_use]
pub fn omega_dot(inertia: &Inertia, w: &Vector3<f64>, tau: &Vector3<f64>) -> Vector3<f64> {
    inertia.j_inv * (tau - w.cross(&(inertia.j * w)))
}

/// The full vector field of one body with a given torque, as a
/// [`LieDerivative`] of the state `(R; ω)`.
///
/// # Equation
/// ```text
/// (followeri)  Ṙ = R ω^×,   J ω̇ = −ω × Jω + τ
/// ```
#[must_use]
pub fn body_field(
    inertia: &Inertia,
    x: &LieState<1, 1>,
    tau: &Vector3<f64>,
) -> LieDerivative<1, 1> {
    LieDerivative {
        omega: [x.vec[0]],
        vec: [omega_dot(inertia, &x.vec[0], tau)],
    }
}

/// Inertial-frame angular momentum `R J ω` (conserved when τ = 0).
#[must_use]
pub fn angular_momentum(inertia: &Inertia, r: &Matrix3<f64>, w: &Vector3<f64>) -> Vector3<f64> {
    r * (inertia.j * w)
}

/// Rotational kinetic energy `½ ωᵀ J ω` (conserved when τ = 0).
#[must_use]
pub fn kinetic_energy(inertia: &Inertia, w: &Vector3<f64>) -> f64 {
    0.5 * w.dot(&(inertia.j * w))
}
