//! Control laws: eq. `control` (with the corrected `sigmai`, `gammai`),
//! eq. `controlconstantestimate` and eq. `districontrol`; and, as a negative
//! control selected by [`ControlLaw::AsPrinted`], the observer-based laws
//! with `Σᵢ`, `Γᵢ` exactly as the paper prints them (erratum 1 of
//! `docs/paper.md`).

use crate::body::Inertia;
use crate::network::Exchanged;
use crate::observer::LeaderInput;
use crate::so3::{hat, psi};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Proportional-derivative gains of a control law: `k_R̄, k_ω̄` (eqs.
/// `control`, `controlconstantestimate`) or `k_Ř, k_ω̌` (eq. `districontrol`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ControlGains {
    /// Attitude gain, > 0.
    pub k_r: f64,
    /// Angular-velocity gain, > 0.
    pub k_w: f64,
}

/// Tracking error between agent i and its observer (Section `timevarying`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackingError {
    /// `R̄ᵢ = R̂ᵢᵀ Rᵢ` (right-invariant error).
    pub r_bar: Matrix3<f64>,
    /// `vᵢ = R̄ᵢᵀ ω̂ᵢ`, the estimate's angular velocity in agent i's body frame.
    pub v: Vector3<f64>,
    /// `ω̄ᵢ = ωᵢ − vᵢ`.
    pub w_bar: Vector3<f64>,
}

/// `R̄ᵢ`, `vᵢ` and `ω̄ᵢ` from the body `(Rᵢ, ωᵢ)` and the estimate `(R̂ᵢ, ω̂ᵢ)`.
#[must_use]
pub fn tracking_error(
    r: &Matrix3<f64>,
    w: &Vector3<f64>,
    r_hat: &Matrix3<f64>,
    w_hat: &Vector3<f64>,
) -> TrackingError {
    let r_bar = r_hat.transpose() * r;
    let v = r_bar.transpose() * w_hat;
    TrackingError {
        r_bar,
        v,
        w_bar: w - v,
    }
}

/// The skew-symmetric matrix `Σᵢ`, as corrected (erratum 1 of `docs/paper.md`).
///
/// # Equation
/// ```text
/// (sigmai, corrected)  Σᵢ = (Jᵢ ω̄ᵢ)^× + (Jᵢ vᵢ)^× − vᵢ^× Jᵢ − Jᵢ vᵢ^×
/// ```
/// # NOTE
/// The paper prints `− (Jᵢ vᵢ)^×`; differentiating `ω̄ᵢ = ωᵢ − R̄ᵢᵀ ω̂ᵢ`
/// along eq. `followeri` gives `+`, so that `Jᵢ dω̄ᵢ/dt = Σᵢ ω̄ᵢ + Γᵢ + τᵢ`
/// (eq. `controlerror1`) holds exactly.
#[must_use]
pub fn sigma_i(inertia: &Inertia, e: &TrackingError) -> Matrix3<f64> {
    let j = &inertia.j;
    let hv = hat(&e.v);
    hat(&(j * e.w_bar)) + hat(&(j * e.v)) - hv * j - j * hv
}

/// The feed-forward term `Γᵢ`, as corrected (erratum 1 of `docs/paper.md`).
///
/// # Equation
/// ```text
/// (gammai, corrected)  Γᵢ = −vᵢ × Jᵢ vᵢ − Jᵢ R̄ᵢᵀ dω̂ᵢ/dt
/// ```
/// # NOTE
/// The paper prints `+ vᵢ × Jᵢ vᵢ`; see [`sigma_i`].
#[must_use]
pub fn gamma_i(inertia: &Inertia, e: &TrackingError, w_hat_dot: &Vector3<f64>) -> Vector3<f64> {
    let j = &inertia.j;
    -e.v.cross(&(j * e.v)) - j * (e.r_bar.transpose() * w_hat_dot)
}

/// `Σᵢ` exactly as printed in the paper (wrong sign on `(Jᵢvᵢ)^×`): it
/// violates eq. `controlerror1` (shown by a test), and is run only by
/// [`ControlLaw::AsPrinted`], the negative control.
///
/// # Equation
/// ```text
/// (sigmai, as printed)  Σᵢ = (Jᵢ ω̄ᵢ)^× − (Jᵢ vᵢ)^× − vᵢ^× Jᵢ − Jᵢ vᵢ^×
/// ```
#[must_use]
pub fn sigma_i_as_printed(inertia: &Inertia, e: &TrackingError) -> Matrix3<f64> {
    let j = &inertia.j;
    let hv = hat(&e.v);
    hat(&(j * e.w_bar)) - hat(&(j * e.v)) - hv * j - j * hv
}

/// `Γᵢ` exactly as printed in the paper (wrong sign on `vᵢ × Jᵢvᵢ`): see
/// [`sigma_i_as_printed`].
///
/// # Equation
/// ```text
/// (gammai, as printed)  Γᵢ = vᵢ × Jᵢ vᵢ − Jᵢ R̄ᵢᵀ dω̂ᵢ/dt
/// ```
#[must_use]
pub fn gamma_i_as_printed(
    inertia: &Inertia,
    e: &TrackingError,
    w_hat_dot: &Vector3<f64>,
) -> Vector3<f64> {
    let j = &inertia.j;
    e.v.cross(&(j * e.v)) - j * (e.r_bar.transpose() * w_hat_dot)
}

/// Observer-based tracking torque for a time-varying reference, with the
/// corrected `Σᵢ`, `Γᵢ` ([`ControlLaw::tau_control`] for either law).
///
/// # Equation
/// ```text
/// (control)  τᵢ = −Σᵢ ω̄ᵢ − Γᵢ − k_R̄ ψ(Āᵢ R̄ᵢ) − k_ω̄ ω̄ᵢ
/// ```
/// With it the tracking error obeys eq. `controlerror2`:
/// `Jᵢ dω̄ᵢ/dt = −k_R̄ ψ(Āᵢ R̄ᵢ) − k_ω̄ ω̄ᵢ`.
#[must_use]
pub fn tau_control(
    g: &ControlGains,
    inertia: &Inertia,
    a_bar: &Matrix3<f64>,
    e: &TrackingError,
    w_hat_dot: &Vector3<f64>,
) -> Vector3<f64> {
    ControlLaw::Corrected.tau_control(g, inertia, a_bar, e, w_hat_dot)
}

/// Observer-based torque without the passive `Σᵢ ω̄ᵢ` compensation (Remark
/// `re1`; used with the constant-reference observer `16a`–`16b`), with the
/// corrected `Γᵢ` ([`ControlLaw::tau_control_constant_estimate`] for either law).
///
/// # Equation
/// ```text
/// (controlconstantestimate)  τᵢ = −Γᵢ − k_R̄ ψ(Āᵢ R̄ᵢ) − k_ω̄ ω̄ᵢ
/// ```
#[must_use]
pub fn tau_control_constant_estimate(
    g: &ControlGains,
    inertia: &Inertia,
    a_bar: &Matrix3<f64>,
    e: &TrackingError,
    w_hat_dot: &Vector3<f64>,
) -> Vector3<f64> {
    ControlLaw::Corrected.tau_control_constant_estimate(g, inertia, a_bar, e, w_hat_dot)
}

/// Which signs of `Σᵢ` (eq. `sigmai`) and `Γᵢ` (eq. `gammai`) the
/// observer-based laws (schemes 1–2) use; scheme 3's `districontrol` has
/// neither. Scenario key `scheme.law`, carried in every `AgentModel`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ControlLaw {
    /// The signs derived from the plant (erratum 1 of `docs/paper.md`):
    /// eq. `control` gives eq. `controlerror2` exactly.
    #[default]
    Corrected,
    /// The signs as the paper prints them, known wrong: a negative control.
    /// Scheme 1's tracking error then obeys
    /// `Jᵢ dω̄ᵢ/dt = −k_R̄ ψ(Āᵢ R̄ᵢ) − k_ω̄ ω̄ᵢ − 2 ωᵢ × Jᵢ vᵢ` instead of eq.
    /// `controlerror2`, and the residual does not vanish while the reference
    /// rotates: the paper's scheme-1 experiment stalls near 1e-2. Scheme 2
    /// (the paper defines its `Γᵢ` by eq. `gammai` too) gains
    /// `−2 vᵢ × Jᵢ vᵢ`; with a constant reference `ω̂ᵢ → 0`, so `vᵢ → 0` and
    /// the residual fades: it still converges.
    AsPrinted,
}

impl ControlLaw {
    /// Whether this is the default, [`ControlLaw::Corrected`] (then it is not
    /// written out).
    #[must_use]
    pub fn is_corrected(&self) -> bool {
        *self == ControlLaw::Corrected
    }

    /// The name as written in scenario files and configurations.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            ControlLaw::Corrected => "corrected",
            ControlLaw::AsPrinted => "as-printed",
        }
    }

    /// `Σᵢ` under this law: [`sigma_i`] or [`sigma_i_as_printed`].
    #[must_use]
    pub fn sigma_i(self, inertia: &Inertia, e: &TrackingError) -> Matrix3<f64> {
        match self {
            ControlLaw::Corrected => sigma_i(inertia, e),
            ControlLaw::AsPrinted => sigma_i_as_printed(inertia, e),
        }
    }

    /// `Γᵢ` under this law: [`gamma_i`] or [`gamma_i_as_printed`].
    #[must_use]
    pub fn gamma_i(
        self,
        inertia: &Inertia,
        e: &TrackingError,
        w_hat_dot: &Vector3<f64>,
    ) -> Vector3<f64> {
        match self {
            ControlLaw::Corrected => gamma_i(inertia, e, w_hat_dot),
            ControlLaw::AsPrinted => gamma_i_as_printed(inertia, e, w_hat_dot),
        }
    }

    /// Scheme 1's torque with this law's `Σᵢ`, `Γᵢ`.
    ///
    /// # Equation
    /// ```text
    /// (control)  τᵢ = −Σᵢ ω̄ᵢ − Γᵢ − k_R̄ ψ(Āᵢ R̄ᵢ) − k_ω̄ ω̄ᵢ
    /// ```
    #[must_use]
    pub fn tau_control(
        self,
        g: &ControlGains,
        inertia: &Inertia,
        a_bar: &Matrix3<f64>,
        e: &TrackingError,
        w_hat_dot: &Vector3<f64>,
    ) -> Vector3<f64> {
        -self.sigma_i(inertia, e) * e.w_bar - self.gamma_i(inertia, e, w_hat_dot) - pd(g, a_bar, e)
    }

    /// Scheme 2's torque with this law's `Γᵢ`.
    ///
    /// # Equation
    /// ```text
    /// (controlconstantestimate)  τᵢ = −Γᵢ − k_R̄ ψ(Āᵢ R̄ᵢ) − k_ω̄ ω̄ᵢ
    /// ```
    #[must_use]
    pub fn tau_control_constant_estimate(
        self,
        g: &ControlGains,
        inertia: &Inertia,
        a_bar: &Matrix3<f64>,
        e: &TrackingError,
        w_hat_dot: &Vector3<f64>,
    ) -> Vector3<f64> {
        -self.gamma_i(inertia, e, w_hat_dot) - pd(g, a_bar, e)
    }
}

/// `k_R̄ ψ(Āᵢ R̄ᵢ) + k_ω̄ ω̄ᵢ`, the part shared by both observer-based laws.
fn pd(g: &ControlGains, a_bar: &Matrix3<f64>, e: &TrackingError) -> Vector3<f64> {
    psi(&(a_bar * e.r_bar)) * g.k_r + e.w_bar * g.k_w
}

/// Observerless distributed torque for a constant reference.
///
/// # Equation
/// ```text
/// (districontrol)  τᵢ = −k_Ř ψ(Ǎ_{i,0} R₀ᵀ Rᵢ) − k_Ř Σ_{j∈N(i)} ψ(Ǎ_{i,j} Rⱼᵀ Rᵢ) − k_ω̌ ωᵢ
/// ```
/// `nbrs` carry the neighbours' actual attitudes `Rⱼ`.
#[must_use]
pub fn tau_districontrol(
    g: &ControlGains,
    r: &Matrix3<f64>,
    w: &Vector3<f64>,
    gains: &[Matrix3<f64>],
    nbrs: &[Exchanged],
    leader: Option<LeaderInput<'_>>,
) -> Vector3<f64> {
    let mut tau = -w * g.k_w;
    if let Some(l) = leader {
        tau -= psi(&(l.a * l.x.r.transpose() * r)) * g.k_r;
    }
    for (a, n) in gains.iter().zip(nbrs) {
        tau -= psi(&(a * n.r.transpose() * r)) * g.k_r;
    }
    tau
}
