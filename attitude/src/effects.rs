//! What makes an agent's body other than ideal (issue 35, item 3): the
//! limits of its actuator ([`crate::actuator`]), disturbance torques
//! ([`crate::disturbance`]), its sensors' errors ([`crate::sensor`]) and
//! an inertia the law assumes other than the body's (model mismatch). One
//! box per agent, absent for an ideal body, so that an ideal agent's data
//! does not grow with every effect.
//!
//! The order within a stage (`PROTOCOL.md` § 10.8): the law measures
//! `(R̃ᵢ, ω̃ᵢ)`, computes `τᵢ` with `Ĵᵢ`, the actuator limits it to
//! `sat(τᵢ)`, and the body (true `Rᵢ, ωᵢ, Jᵢ`) receives `sat(τᵢ) + dᵢ(t)`.

use crate::actuator::{RateLimit, Saturation};
use crate::body::Inertia;
use crate::disturbance::{Disturbance, GaussMarkov, Shape};
use crate::network::AgentState;
use crate::sensor::{Sensing, Sensor};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The non-ideal effects of one agent's body.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Effects {
    /// The limits of the torque the body receives.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub saturation: Option<Saturation>,
    /// The limit on how fast the applied torque changes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_limit: Option<RateLimit>,
    /// Torques from outside, summed in this order.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub disturbances: Vec<Disturbance>,
    /// The errors of what the law measures of its own body.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<Sensor>,
    /// `Ĵᵢ`, the inertia the law assumes (eqs. `sigmai`, `gammai`; the
    /// observerless eq. `districontrol` has none), when not the body's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law_inertia: Option<Inertia>,
}

impl Effects {
    /// Whether the body is ideal (then the model has no effects at all).
    #[must_use]
    pub fn is_ideal(&self) -> bool {
        *self == Self::default()
    }
}

/// What a body's effects carry from step to step: the disturbances'
/// noise processes (one per [`Shape::Noise`], in order) and the sensors.
#[derive(Debug, Clone, PartialEq)]
pub struct EffectsState {
    noise: Vec<GaussMarkov>,
    sensing: Option<Sensing>,
}

impl EffectsState {
    /// The state of `e` with step `dt`, `None` when nothing is random.
    #[must_use]
    pub fn new(e: &Effects, dt: f64) -> Option<Self> {
        let noise: Vec<GaussMarkov> = (e.disturbances.iter())
            .filter_map(|d| match d.shape {
                Shape::Noise {
                    std,
                    bandwidth,
                    seed,
                } => Some(GaussMarkov::new(std, bandwidth, seed, dt)),
                _ => None,
            })
            .collect();
        let sensing = e.sensor.as_ref().map(Sensing::new);
        (!noise.is_empty() || sensing.is_some()).then_some(Self { noise, sensing })
    }

    /// The sensors' errors of the current step, when the body has sensors.
    #[must_use]
    pub fn sensing(&self) -> Option<&Sensing> {
        self.sensing.as_ref()
    }

    /// Draws what step `n` holds (at its start, for every step in order).
    pub fn step(&mut self, e: &Effects, n: u64) {
        for p in &mut self.noise {
            p.step(n);
        }
        if let (Some(s), Some(sensor)) = (&mut self.sensing, &e.sensor) {
            s.step(sensor);
        }
    }
}

/// What the law and the body see of a body's effects at one stage: an
/// ideal body ([`Ideal`], every method a no-op the compiler removes) or
/// the effects at a stage ([`At`]). Generic so that an ideal agent's
/// stage costs nothing for the effects it does not have.
pub trait Body {
    /// What the law measures of `x`, when not `x` itself.
    fn measure(&self, x: &AgentState) -> Option<AgentState>;
    /// The inertia the law assumes, when not the body's.
    fn law_inertia(&self) -> Option<&Inertia>;
    /// The torque the actuator delivers for `τ`.
    fn actuate(&self, tau: Vector3<f64>) -> Vector3<f64>;
    /// The disturbance on the body at attitude `r`, when any.
    fn disturbance(&self, r: &Matrix3<f64>) -> Option<Vector3<f64>>;
}

/// An ideal body: exact sensors, the body's inertia, every torque
/// delivered, nothing from outside.
#[derive(Debug, Clone, Copy)]
pub struct Ideal;

impl Body for Ideal {
    #[inline(always)]
    fn measure(&self, _: &AgentState) -> Option<AgentState> {
        None
    }
    #[inline(always)]
    fn law_inertia(&self) -> Option<&Inertia> {
        None
    }
    #[inline(always)]
    fn actuate(&self, tau: Vector3<f64>) -> Vector3<f64> {
        tau
    }
    #[inline(always)]
    fn disturbance(&self, _: &Matrix3<f64>) -> Option<Vector3<f64>> {
        None
    }
}

impl Body for At<'_> {
    fn measure(&self, x: &AgentState) -> Option<AgentState> {
        At::measure(self, x)
    }
    fn law_inertia(&self) -> Option<&Inertia> {
        At::law_inertia(self)
    }
    fn actuate(&self, tau: Vector3<f64>) -> Vector3<f64> {
        self.saturate(&tau)
    }
    fn disturbance(&self, r: &Matrix3<f64>) -> Option<Vector3<f64>> {
        At::disturbance(self, r)
    }
}

/// A body's effects at one stage `(n, c)`, `t = (n + c)·h`.
#[derive(Debug, Clone, Copy)]
pub struct At<'a> {
    /// The effects.
    pub effects: &'a Effects,
    /// Their state (`None` when nothing is random).
    pub state: Option<&'a EffectsState>,
    /// Step.
    pub n: u64,
    /// Time of the stage, s.
    pub t: f64,
    /// Step size, s.
    pub h: f64,
    /// The stage, 0..4.
    pub s: usize,
    /// The torque applied at the last step start (the rate limit's anchor:
    /// the previous step's at stage 0, the current step's at stages 1–3;
    /// zero before the first step).
    pub anchor: Vector3<f64>,
}

impl At<'_> {
    /// What the law measures of `x`, when the body has sensors.
    #[must_use]
    pub fn measure(&self, x: &AgentState) -> Option<AgentState> {
        let s = self.state?.sensing.as_ref()?;
        Some(s.measure(x))
    }

    /// The inertia the law assumes, when not the body's.
    #[must_use]
    pub fn law_inertia(&self) -> Option<&Inertia> {
        self.effects.law_inertia.as_ref()
    }

    /// The torque the actuator delivers for `τ`: `sat(τ)`, then moved at
    /// most `ρ·Δt` from the anchor.
    #[must_use]
    pub fn saturate(&self, tau: &Vector3<f64>) -> Vector3<f64> {
        let tau = match &self.effects.saturation {
            Some(s) => s.apply(tau),
            None => *tau,
        };
        match &self.effects.rate_limit {
            Some(r) => r.apply(&tau, &self.anchor, self.s, self.h),
            None => tau,
        }
    }

    /// `dᵢ(t)` in the body frame at attitude `r`: `0 + d₁ + d₂ + …` in
    /// order, or `None` without disturbances.
    #[must_use]
    pub fn disturbance(&self, r: &Matrix3<f64>) -> Option<Vector3<f64>> {
        let all = &self.effects.disturbances;
        if all.is_empty() {
            return None;
        }
        let noise = self.state.map_or(&[][..], |s| &s.noise[..]);
        let mut held = noise.iter();
        let zero = Vector3::zeros();
        let mut d = Vector3::zeros();
        for one in all {
            let x = if one.is_random() {
                held.next().map_or(&zero, |p| &p.x)
            } else {
                &zero
            };
            d += one.torque(self.n, self.t, self.h, r, x);
        }
        Some(d)
    }
}
