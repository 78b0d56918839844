//! Distributed observers of the leader: eqs. `7a`–`7c` (time-varying
//! reference) and `16a`–`16b` (constant reference).
//!
//! Each function takes the agent's own estimate, its neighbours' exchanged
//! estimates with their edge gains (same order), and, for a leader-connected
//! agent (`Ξᵢ = 1`), the leader's state with the gain `A_{i,0}`.

use crate::network::Exchanged;
use crate::so3::psi;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Observer gains `k_R`, `k_ω` (and `k_σ` for eq. `7c`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObserverGains {
    /// `k_{R^l}` (eq. `7b`) or `k_{R^r}` (eq. `16b`), > 0.
    pub k_r: f64,
    /// `k_{ω^l}` or `k_{ω^r}`, > 0.
    pub k_w: f64,
    /// `k_σ̃` (eq. `7c`), > 0; unused by eq. `16b`.
    pub k_sigma: f64,
}

/// A leader link seen from agent i: gain `A_{i,0}` and the leader's state.
#[derive(Debug, Clone, Copy)]
pub struct LeaderInput<'a> {
    /// `A_{i,0}`, symmetric positive definite, three distinct eigenvalues.
    pub a: &'a Matrix3<f64>,
    /// `(R₀, ω₀, σ₀)` as received.
    pub x: &'a Exchanged,
}

/// Estimate dynamics `dR̂ᵢ/dt = R̂ᵢ ω̂ᵢ^×` (eqs. `7a`, `16a`): the body-frame
/// rate of `R̂ᵢ` is `ω̂ᵢ` itself.
#[must_use]
pub fn r_hat_rate(own: &Exchanged) -> Vector3<f64> {
    own.w
}

/// Angular-velocity estimate dynamics for a time-varying reference.
///
/// # Equation
/// ```text
/// (7b)  dω̂ᵢ/dt = σ̂ᵢ − k_R R₀ᵀ ψ(A_{i,0} R̂ᵢ R₀ᵀ) − k_ω Ξᵢ (ω̂ᵢ − ω₀)
///               − k_R Σ_{j∈N(i)} R̂ⱼᵀ ψ(A_{i,j} R̂ᵢ R̂ⱼᵀ) − k_ω Σ_{j∈N(i)} (ω̂ᵢ − ω̂ⱼ)
/// ```
#[must_use]
pub fn omega_hat_dot_7b(
    g: &ObserverGains,
    own: &Exchanged,
    gains: &[Matrix3<f64>],
    nbrs: &[Exchanged],
    leader: Option<LeaderInput<'_>>,
) -> Vector3<f64> {
    let mut d = own.s;
    if let Some(l) = leader {
        d -= l.x.r.transpose() * psi(&(l.a * own.r * l.x.r.transpose())) * g.k_r;
        d -= (own.w - l.x.w) * g.k_w;
    }
    for (a, n) in gains.iter().zip(nbrs) {
        d -= n.r.transpose() * psi(&(a * own.r * n.r.transpose())) * g.k_r;
        d -= (own.w - n.w) * g.k_w;
    }
    d
}

/// Angular-acceleration estimate dynamics.
///
/// # Equation
/// ```text
/// (7c)  dσ̂ᵢ/dt = P σ̂ᵢ − k_σ Σ_{j∈N(i)} (σ̂ᵢ − σ̂ⱼ) − k_σ Ξᵢ (σ̂ᵢ − σ₀)
/// ```
#[must_use]
pub fn sigma_hat_dot_7c(
    g: &ObserverGains,
    p: &Matrix3<f64>,
    own: &Exchanged,
    nbrs: &[Exchanged],
    leader: Option<LeaderInput<'_>>,
) -> Vector3<f64> {
    let mut d = p * own.s;
    for n in nbrs {
        d -= (own.s - n.s) * g.k_sigma;
    }
    if let Some(l) = leader {
        d -= (own.s - l.x.s) * g.k_sigma;
    }
    d
}

/// Angular-velocity estimate dynamics for a constant reference.
///
/// # Equation
/// ```text
/// (16b)  dω̂ᵢ/dt = −k_R Σ_{j∈N(i)} ψ(A_{i,j} R̂ⱼᵀ R̂ᵢ) − k_ω Σ_{j∈N(i)} (ω̂ᵢ − ω̂ⱼ)
///                − k_R ψ(A_{i,0} R₀ᵀ R̂ᵢ) − k_ω Ξᵢ ω̂ᵢ
/// ```
#[must_use]
pub fn omega_hat_dot_16b(
    g: &ObserverGains,
    own: &Exchanged,
    gains: &[Matrix3<f64>],
    nbrs: &[Exchanged],
    leader: Option<LeaderInput<'_>>,
) -> Vector3<f64> {
    let mut d = Vector3::zeros();
    for (a, n) in gains.iter().zip(nbrs) {
        d -= psi(&(a * n.r.transpose() * own.r)) * g.k_r;
        d -= (own.w - n.w) * g.k_w;
    }
    if let Some(l) = leader {
        d -= psi(&(l.a * l.x.r.transpose() * own.r)) * g.k_r;
        d -= own.w * g.k_w;
    }
    d
}
