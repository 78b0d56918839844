//! The scenario keys of bodies that aren't ideal (besides `[actuator]`):
//! `[[disturbance]]`, `[sensor]` / `agent.sensor` and `[controller]` /
//! `agent.controller`. See `docs/scenarios.md` "Bodies that aren't ideal".

use crate::schema::MatrixSpec;
use attitude::actuator::Saturation;
use attitude::disturbance::{Disturbance, Frame, Shape};
use attitude::effects::Effects;
use serde::{Deserialize, Serialize};

/// `[[disturbance]]`: a torque from outside on every agent, or on
/// `agents`. Which keys it takes depends on `kind`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DisturbanceSpec {
    /// Its shape in time.
    pub kind: DisturbanceKind,
    /// `constant`: N·m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque: Option<[f64; 3]>,
    /// `sine`: N·m per axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<[f64; 3]>,
    /// `sine`: Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frequency: Option<f64>,
    /// `sine`: rad (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phase: Option<f64>,
    /// `noise`: standard deviation, N·m, one number (every axis) or three.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<PerAxis>,
    /// `noise`: corner frequency, Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bandwidth: Option<f64>,
    /// `impulse`: when, s (a whole multiple of `simulation.dt`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t: Option<f64>,
    /// `impulse`: the angular impulse, N·m·s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub impulse: Option<[f64; 3]>,
    /// `"body"` (default) or `"inertial"`.
    #[serde(default, skip_serializing_if = "is_body")]
    pub frame: Frame,
    /// The agents it acts on (default: every agent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agents: Option<Vec<u32>>,
}

fn is_body(f: &Frame) -> bool {
    *f == Frame::Body
}

/// `[[disturbance]] kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DisturbanceKind {
    /// `torque`.
    Constant,
    /// `amplitude`, `frequency`, `phase`.
    Sine,
    /// `std`, `bandwidth` (seeded by `network.seed`).
    Noise,
    /// `t`, `impulse`.
    Impulse,
}

impl DisturbanceKind {
    /// Its name in the file.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Constant => "constant",
            Self::Sine => "sine",
            Self::Noise => "noise",
            Self::Impulse => "impulse",
        }
    }
}

/// One number for every axis, or one per axis.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number (every axis) or 3 numbers (one per body axis)"
)]
pub enum PerAxis {
    /// The same on every axis.
    One(f64),
    /// x, y, z.
    Three([f64; 3]),
}

impl PerAxis {
    /// The three values.
    #[must_use]
    pub fn axes(self) -> [f64; 3] {
        match self {
            Self::One(x) => [x; 3],
            Self::Three(x) => x,
        }
    }
}

/// `[sensor]` or `agent.sensor`: the errors of what the law measures of
/// its own body (per axis, body frame). Noise is drawn once per step,
/// seeded by `network.seed`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorSpec {
    /// Standard deviation of the attitude error (a rotation vector), rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attitude_noise: Option<f64>,
    /// Constant attitude error (a rotation vector), rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attitude_bias: Option<[f64; 3]>,
    /// Standard deviation of the rate error, rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_noise: Option<f64>,
    /// Constant rate error, rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rate_bias: Option<[f64; 3]>,
}

/// `[controller]` or `agent.controller`: what the law assumes of the body
/// (model mismatch), one of the two keys.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControllerSpec {
    /// `Ĵᵢ = inertia_scale · Jᵢ`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia_scale: Option<f64>,
    /// `Ĵᵢ`, kg·m²: 3 numbers (diagonal) or 3 rows of 3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<MatrixSpec>,
}

/// One line of what a body's effects are, for `check`.
#[must_use]
pub fn describe(e: &Effects) -> String {
    let mut parts = Vec::new();
    match e.saturation {
        Some(Saturation::Norm { max }) => parts.push(format!("‖τ‖ ≤ {max} N·m")),
        Some(Saturation::Axes { max }) => parts.push(format!("|τ_k| ≤ {max:?} N·m")),
        None => {}
    }
    if let Some(r) = e.rate_limit {
        parts.push(format!("‖dτ/dt‖ ≤ {} N·m/s", r.max));
    }
    parts.extend(e.disturbances.iter().map(disturbance));
    if let Some(s) = &e.sensor {
        let (a, r) = (&s.attitude, &s.rate);
        parts.push(format!(
            "sensors: attitude σ {} rad, bias {:?}; rate σ {} rad/s, bias {:?}",
            a.std, a.bias, r.std, r.bias
        ));
    }
    if let Some(j) = &e.law_inertia {
        let d = j.j.diagonal();
        parts.push(format!(
            "the law assumes Ĵ diag [{:?}, {:?}, {:?}]",
            d.x, d.y, d.z
        ));
    }
    parts.join("; ")
}

fn disturbance(d: &Disturbance) -> String {
    let frame = match d.frame {
        Frame::Body => "body",
        Frame::Inertial => "inertial",
    };
    let what = match d.shape {
        Shape::Constant { torque } => format!("constant {torque:?} N·m"),
        Shape::Sine {
            amplitude,
            frequency,
            phase,
        } => format!("sine {amplitude:?} N·m at {frequency} Hz, phase {phase} rad"),
        Shape::Noise { std, bandwidth, .. } => {
            format!("noise σ {std:?} N·m, bandwidth {bandwidth} Hz")
        }
        Shape::Impulse { step, impulse } => format!("impulse {impulse:?} N·m·s at step {step}"),
    };
    format!("disturbance {what} ({frame} frame)")
}
