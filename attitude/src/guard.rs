//! Divergence is a failure: the envelope every node's state must stay in,
//! and the check of one node's state against it.
//!
//! Every engine checks every node after every step (and at t = 0); the
//! first state outside the envelope stops the run. A diverged run is never
//! reported as complete, and the states it reached are never turned into
//! invented errors.
//!
//! The check is pure: a node's state and an [`Envelope`] in, the first
//! [`Violation`] (if any) out, in a fixed order (the state's fields in
//! order), so that both engines name the same quantity.

use crate::network::{AgentState, Network, ROTATION_TOLERANCE};
use crate::reference::LeaderState;
use crate::stiffness::Estimate;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The largest norms a state may reach before the run counts as diverged
/// (scenario table `[guard]`).
///
/// # Defaults
/// 1e4 for each: the paper's experiments stay below ~10 rad/s and ~10
/// rad/s²; 1e4 rad/s is ~95 000 rpm, beyond any rigid body attsync models,
/// and at `dt` = 1 ms it turns the body by 10 rad within one step, where
/// RK4's result means nothing any more. An unstable integration grows
/// exponentially, so it crosses any such bound within a few steps: the
/// exact value hardly moves the time reported.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Envelope {
    /// Largest `‖ωᵢ‖`, rad/s.
    pub omega: f64,
    /// Largest `‖ω̂ᵢ‖` and `‖ω₀‖` (ω̂ᵢ estimates ω₀), rad/s.
    pub omega_hat: f64,
    /// Largest `‖σ̂ᵢ‖` and `‖σ₀‖` (σ̂ᵢ estimates σ₀), rad/s².
    pub sigma_hat: f64,
}

impl Default for Envelope {
    fn default() -> Self {
        Self {
            omega: 1e4,
            omega_hat: 1e4,
            sigma_hat: 1e4,
        }
    }
}

impl Envelope {
    /// Whether this is [`Envelope::default`] (then node configurations omit it).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// A checked part of a node's state. Its wire code (PROTOCOL.md § 5,
/// `Failed` reason 4) belongs to the wire contract: `msgs::telemetry`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Quantity {
    /// An agent's attitude `Rᵢ`.
    R,
    /// An agent's angular velocity `ωᵢ`.
    Omega,
    /// An agent's observed attitude `R̂ᵢ`.
    RHat,
    /// An agent's observed angular velocity `ω̂ᵢ`.
    OmegaHat,
    /// An agent's observed angular acceleration `σ̂ᵢ`.
    SigmaHat,
    /// The leader's attitude `R₀`.
    R0,
    /// The leader's angular velocity `ω₀`.
    Omega0,
    /// The leader's angular acceleration `σ₀`.
    Sigma0,
}

impl Quantity {
    /// Every quantity, in the states' field order (agent, then leader).
    pub const ALL: [Quantity; 8] = [
        Quantity::R,
        Quantity::Omega,
        Quantity::RHat,
        Quantity::OmegaHat,
        Quantity::SigmaHat,
        Quantity::R0,
        Quantity::Omega0,
        Quantity::Sigma0,
    ];

    /// Its name in messages and `summary.json` (the state's field names).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Quantity::R => "r",
            Quantity::Omega => "omega",
            Quantity::RHat => "r_hat",
            Quantity::OmegaHat => "omega_hat",
            Quantity::SigmaHat => "sigma_hat",
            Quantity::R0 => "r0",
            Quantity::Omega0 => "omega0",
            Quantity::Sigma0 => "sigma0",
        }
    }

    /// Whether it is an attitude (checked to be a rotation, not against a bound).
    #[must_use]
    pub fn is_attitude(self) -> bool {
        matches!(self, Quantity::R | Quantity::RHat | Quantity::R0)
    }

    /// The envelope's bound on it (`None` for an attitude).
    #[must_use]
    pub fn limit(self, env: &Envelope) -> Option<f64> {
        match self {
            Quantity::Omega => Some(env.omega),
            Quantity::OmegaHat | Quantity::Omega0 => Some(env.omega_hat),
            Quantity::SigmaHat | Quantity::Sigma0 => Some(env.sigma_hat),
            Quantity::R | Quantity::RHat | Quantity::R0 => None,
        }
    }
}

/// The first part of a state found outside the envelope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// Which part.
    pub quantity: Quantity,
    /// Its value: a vector's norm, an attitude's first non-finite entry or
    /// else its orthogonality defect `‖RᵀR − I‖_F`.
    pub value: f64,
}

impl Violation {
    /// What is wrong, after the node's name: `sigma_hat = 3.2e5 exceeds
    /// the envelope 1e4`, `omega is NaN`, `r is not a rotation (…)`.
    #[must_use]
    pub fn describe(&self, env: &Envelope) -> String {
        let q = self.quantity.name();
        match self.quantity.limit(env) {
            _ if !self.value.is_finite() => format!("{q} is {} (not finite)", self.value),
            Some(limit) => format!("{q} = {:.1e} exceeds the envelope {limit:.0e}", self.value),
            None => format!(
                "{q} is not a rotation (‖RᵀR − I‖ = {:.1e}, or det R ≤ 0)",
                self.value
            ),
        }
    }
}

/// An attitude's violation: a non-finite entry, or not a rotation to
/// [`ROTATION_TOLERANCE`] (as a received state is checked).
fn attitude(quantity: Quantity, r: &Matrix3<f64>) -> Option<Violation> {
    attitude_defect(quantity, r).err()
}

/// [`attitude`], and for a rotation its orthogonality defect.
fn attitude_defect(quantity: Quantity, r: &Matrix3<f64>) -> Result<f64, Violation> {
    if let Some(&value) = r.iter().find(|v| !v.is_finite()) {
        return Err(Violation { quantity, value });
    }
    let defect = crate::so3::orthogonality_defect(r);
    if defect > ROTATION_TOLERANCE || r.determinant() <= 0.0 {
        return Err(Violation {
            quantity,
            value: defect,
        });
    }
    Ok(defect)
}

/// A vector's violation: its norm not finite, or above `limit`.
fn vector(quantity: Quantity, v: &Vector3<f64>, limit: f64) -> Option<Violation> {
    let value = v.norm();
    (!value.is_finite() || value > limit).then_some(Violation { quantity, value })
}

/// The first violation of an agent's state, in field order
/// (`r, omega, r_hat, omega_hat, sigma_hat`).
#[must_use]
pub fn check_agent(x: &AgentState, env: &Envelope) -> Option<Violation> {
    check_agent_defects(x, env).err()
}

/// [`check_agent`], and for a state inside the envelope the orthogonality
/// defects `‖RᵀR − I‖_F` of `r` and `r_hat` it computed (what
/// [`crate::verdict`] proves the next published values' verdicts from).
pub fn check_agent_defects(x: &AgentState, env: &Envelope) -> Result<[f64; 2], Violation> {
    let within = |v: Option<Violation>| v.map_or(Ok(()), Err);
    let r = attitude_defect(Quantity::R, &x.r)?;
    within(vector(Quantity::Omega, &x.w, env.omega))?;
    let r_hat = attitude_defect(Quantity::RHat, &x.r_hat)?;
    within(vector(Quantity::OmegaHat, &x.w_hat, env.omega_hat))?;
    within(vector(Quantity::SigmaHat, &x.s_hat, env.sigma_hat))?;
    Ok([r, r_hat])
}

/// The first violation of the leader's state (`r0, omega0, sigma0`).
#[must_use]
pub fn check_leader(l: &LeaderState, env: &Envelope) -> Option<Violation> {
    attitude(Quantity::R0, &l.r0)
        .or_else(|| vector(Quantity::Omega0, &l.w0, env.omega_hat))
        .or_else(|| vector(Quantity::Sigma0, &l.s0, env.sigma_hat))
}

/// A run's divergence: the state of node `node` at step `step` left the
/// envelope.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Divergence {
    /// The step (t = step · dt).
    pub step: u64,
    /// The node id (0 = the leader).
    pub node: u32,
    /// What left the envelope.
    pub violation: Violation,
}

impl Divergence {
    /// The node's name in messages: `leader` or `agent-<id>`.
    #[must_use]
    pub fn node_name(&self) -> String {
        match self.node {
            0 => "leader".into(),
            id => format!("agent-{id}"),
        }
    }

    /// The run's failure message: `diverged at t = 0.012 s: agent-17's
    /// sigma_hat = 3.2e5 exceeds the envelope 1e4 (probable cause: …)`.
    #[must_use]
    pub fn message(&self, net: &Network, stiffness: Option<&Estimate>) -> String {
        let cause = probable_cause(net.dt, stiffness)
            .map_or(String::new(), |c| format!(" (probable cause: {c})"));
        // 9 decimals, trimmed: no binary noise (0.3 s, not 0.30000000000000004 s).
        let t = format!("{:.9}", self.step as f64 * net.dt);
        let t = t.trim_end_matches('0').trim_end_matches('.');
        format!(
            "diverged at t = {} s: {}'s {}{cause}",
            if t.is_empty() { "0" } else { t },
            self.node_name(),
            self.violation.describe(&net.guard)
        )
    }
}

/// The first divergence at step `step`, nodes in engine order: the leader,
/// then the agents in network order.
#[must_use]
pub fn first(
    net: &Network,
    step: u64,
    leader: &LeaderState,
    agents: &[AgentState],
) -> Option<Divergence> {
    let at = |node: u32, v: Option<Violation>| {
        v.map(|violation| Divergence {
            step,
            node,
            violation,
        })
    };
    at(0, check_leader(leader, &net.guard)).or_else(|| {
        (net.agents.iter().zip(agents))
            .find_map(|(a, x)| at(a.model.id, check_agent(x, &net.guard)))
    })
}

/// Why a network probably diverged, for the failure message: its `dt`
/// against the largest stable RK4 step of the linearised loops
/// ([`crate::stiffness`], when the scenario had an estimate).
#[must_use]
pub fn probable_cause(dt: f64, stiffness: Option<&Estimate>) -> Option<String> {
    let est = stiffness?;
    let b = est.binding()?;
    if dt > est.dt_max {
        Some(format!(
            "dt = {dt} s exceeds the largest stable RK4 step ≈ {:.2e} s of the {} loop (fastest mode {:.2e} 1/s); \
             try --set simulation.dt={}",
            est.dt_max,
            b.name,
            b.fastest_rate,
            round_down_1(est.dt_max / 2.0)
        ))
    } else {
        Some(format!(
            "not the step size: dt = {dt} s is within RK4's stable step ≈ {:.2e} s of the linearised loops; \
             look at the gains (Theorem 1's condition), the initial states, or the [guard] envelope",
            est.dt_max
        ))
    }
}

/// `x > 0` rounded down to one significant digit (2.37e-4 → 2e-4).
fn round_down_1(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    let v = (x / p).floor() * p;
    // Print without binary noise.
    format!("{v:.1e}").parse().unwrap_or(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn agent() -> AgentState {
        AgentState {
            r: crate::so3::rot(0.3, &Vector3::new(0.6, 0.0, 0.8)),
            w: Vector3::new(1.0, 2.0, 0.0),
            r_hat: Matrix3::identity(),
            w_hat: Vector3::new(0.0, 9e3, 0.0),
            s_hat: Vector3::new(1.0, 0.0, 0.0),
        }
    }

    #[test]
    fn a_sane_state_passes() {
        let env = Envelope::default();
        assert_eq!(check_agent(&agent(), &env), None);
        let l = LeaderState {
            r0: agent().r,
            w0: Vector3::new(1.0, 2.0, 0.0),
            s0: Vector3::new(1.0, 0.0, 0.0),
        };
        assert_eq!(check_leader(&l, &env), None);
    }

    #[test]
    fn a_norm_beyond_the_envelope_is_named_with_its_value() {
        let mut x = agent();
        x.s_hat = Vector3::new(3.0e5, 0.0, 4.0e5);
        let v = check_agent(&x, &Envelope::default()).expect("beyond 1e4");
        assert_eq!(v.quantity, Quantity::SigmaHat);
        assert_eq!(v.value, 5.0e5);
        let text = v.describe(&Envelope::default());
        assert_eq!(text, "sigma_hat = 5.0e5 exceeds the envelope 1e4");
        // The envelope is configurable.
        let wide = Envelope {
            sigma_hat: 1e6,
            ..Envelope::default()
        };
        assert_eq!(check_agent(&x, &wide), None);
    }

    #[test]
    fn the_first_violation_in_field_order_is_reported() {
        let mut x = agent();
        x.w = Vector3::new(f64::NAN, 0.0, 0.0);
        x.s_hat = Vector3::repeat(f64::INFINITY);
        let v = check_agent(&x, &Envelope::default()).expect("NaN");
        assert_eq!(v.quantity, Quantity::Omega);
        assert!(v.value.is_nan());
        assert_eq!(
            v.describe(&Envelope::default()),
            "omega is NaN (not finite)"
        );
        x.r[(1, 2)] = f64::NEG_INFINITY;
        let v = check_agent(&x, &Envelope::default()).expect("-inf");
        assert_eq!((v.quantity, v.value), (Quantity::R, f64::NEG_INFINITY));
    }

    #[test]
    fn an_attitude_that_is_not_a_rotation_is_named() {
        let mut x = agent();
        x.r_hat = Matrix3::identity() * 2.0;
        let v = check_agent(&x, &Envelope::default()).expect("2·I");
        assert_eq!(v.quantity, Quantity::RHat);
        assert!((v.value - 3.0 * 3f64.sqrt()).abs() < 1e-12, "{v:?}");
        assert!(
            v.describe(&Envelope::default())
                .starts_with("r_hat is not a rotation")
        );
        // A reflection has no orthogonality defect but det = −1.
        x.r_hat = -Matrix3::identity();
        let v = check_agent(&x, &Envelope::default()).expect("−I");
        assert_eq!((v.quantity, v.value), (Quantity::RHat, 0.0));
    }

    #[test]
    fn leader_quantities_are_held_to_the_observer_bounds() {
        let mut l = LeaderState {
            r0: Matrix3::identity(),
            w0: Vector3::new(0.0, 0.0, 2e4),
            s0: Vector3::zeros(),
        };
        let v = check_leader(&l, &Envelope::default()).expect("ω₀ beyond 1e4");
        assert_eq!((v.quantity, v.value), (Quantity::Omega0, 2e4));
        l.w0 = Vector3::zeros();
        l.s0 = Vector3::new(f64::NAN, 0.0, 0.0);
        assert_eq!(
            check_leader(&l, &Envelope::default()).map(|v| v.quantity),
            Some(Quantity::Sigma0)
        );
    }

    #[test]
    fn the_probable_cause_weighs_dt_against_the_stable_step() {
        use crate::stiffness::LoopEstimate;
        let est = Estimate {
            loops: vec![LoopEstimate {
                name: "observer",
                fastest_rate: 1.3e4,
                dt_max: 2.37e-4,
                slowest_rate: 1.0,
            }],
            dt_max: 2.37e-4,
        };
        let c = probable_cause(0.001, Some(&est)).unwrap();
        assert!(c.contains("exceeds the largest stable RK4 step"), "{c}");
        assert!(c.contains("observer loop"), "{c}");
        assert!(c.contains("--set simulation.dt=0.0001"), "{c}");
        let c = probable_cause(1e-4, Some(&est)).unwrap();
        assert!(c.starts_with("not the step size"), "{c}");
        assert_eq!(probable_cause(0.001, None), None);
    }
}
