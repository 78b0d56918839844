//! Bodies that aren't ideal: `[[disturbance]]`, `[sensor]` / `agent.sensor`,
//! `[controller]` / `agent.controller` (with `[actuator]`, resolved in
//! `agents`), per agent.

use super::ctx::Ctx;
use super::ids::Ids;
use crate::body::{ControllerSpec, DisturbanceKind, DisturbanceSpec, SensorSpec};
use crate::schema::{AgentSpec, SchemeKind};
use attitude::actuator::{RateLimit, Saturation};
use attitude::body::Inertia;
use attitude::disturbance::{Disturbance, Shape};
use attitude::effects::Effects;
use attitude::random::effect_seed;
use attitude::sensor::{Noise, Sensor};
use nalgebra::Matrix3;
use std::fmt::Display;

/// The slot of an agent's sensor stream in [`effect_seed`] (its noise
/// disturbances take their index in `[[disturbance]]`).
pub const SENSOR_SLOT: u32 = u32::MAX;

/// One agent's effects, but for the inertia its law assumes, which needs
/// its body's.
#[derive(Debug, Clone, Default)]
pub(super) struct BodyEffects {
    pub(super) saturation: Option<Saturation>,
    pub(super) rate_limit: Option<RateLimit>,
    pub(super) disturbances: Vec<Disturbance>,
    pub(super) sensor: Option<Sensor>,
    pub(super) law: Option<LawInertia>,
}

/// `[controller]`'s `Ĵᵢ`.
#[derive(Debug, Clone, Copy)]
pub(super) enum LawInertia {
    Scale(f64),
    Given(Matrix3<f64>),
}

impl BodyEffects {
    /// The effects of a body of inertia `j`, `None` for an ideal one.
    pub(super) fn of(self, j: &Inertia) -> Option<Box<Effects>> {
        let law_inertia = self.law.map(|l| match l {
            LawInertia::Scale(s) => Inertia::new(j.j * s),
            LawInertia::Given(m) => Inertia::new(m),
        });
        let e = Effects {
            saturation: self.saturation,
            rate_limit: self.rate_limit,
            disturbances: self.disturbances,
            sensor: self.sensor,
            law_inertia,
        };
        (!e.is_ideal()).then(|| Box::new(e))
    }
}

/// What the scenario says of every agent's body, by rank of its id.
pub(super) struct Sources<'a> {
    pub(super) agents: &'a [AgentSpec],
    pub(super) disturbances: &'a [DisturbanceSpec],
    pub(super) sensor: Option<&'a SensorSpec>,
    pub(super) controller: Option<&'a ControllerSpec>,
    pub(super) seed: u64,
    pub(super) dt: f64,
    pub(super) steps: u64,
    pub(super) kind: SchemeKind,
}

/// Every agent's effects, by rank, `actuators` from `[actuator]`.
pub(super) fn effects(
    c: &mut Ctx,
    src: &Sources<'_>,
    ids: &Ids,
    actuators: Vec<super::agents::Limits>,
) -> Vec<BodyEffects> {
    let mut out: Vec<BodyEffects> = (actuators.into_iter())
        .map(|(saturation, rate_limit)| BodyEffects {
            saturation,
            rate_limit,
            ..BodyEffects::default()
        })
        .collect();
    for (k, d) in src.disturbances.iter().enumerate() {
        let f = format!("disturbance[{k}]");
        let Some(shape) = shape(c, &f, d, src) else {
            continue;
        };
        for r in targets(c, &f, d.agents.as_deref(), ids) {
            let shape = match shape {
                Shape::Noise { std, bandwidth, .. } => Shape::Noise {
                    std,
                    bandwidth,
                    seed: effect_seed(src.seed, ids.id(r), k as u32),
                },
                s => s,
            };
            out[r].disturbances.push(Disturbance {
                frame: d.frame,
                shape,
            });
        }
    }
    let every_sensor = src.sensor.and_then(|s| sensor(c, "sensor", s));
    let every_law = src
        .controller
        .and_then(|s| controller(c, "controller", s, src.kind));
    for e in &mut out {
        e.sensor = every_sensor;
        e.law = every_law;
    }
    for (k, a) in src.agents.iter().enumerate() {
        let Some(r) = ids.rank(a.id) else { continue };
        if let Some(s) = &a.sensor {
            out[r].sensor = sensor(c, format_args!("agent[{k}].sensor"), s);
        }
        if let Some(s) = &a.controller {
            out[r].law = controller(c, format_args!("agent[{k}].controller"), s, src.kind);
        }
    }
    for (r, e) in out.iter_mut().enumerate() {
        if let Some(s) = &mut e.sensor {
            s.seed = effect_seed(src.seed, ids.id(r), SENSOR_SLOT);
        }
    }
    out
}

/// The ranks `agents` names (every agent without it), each id checked.
fn targets(c: &mut Ctx, f: &str, agents: Option<&[u32]>, ids: &Ids) -> Vec<usize> {
    let Some(agents) = agents else {
        return (0..ids.len()).collect();
    };
    if agents.is_empty() {
        c.err(
            format!("{f}.agents"),
            "is empty: leave it out to mean every agent",
        );
    }
    let mut ranks = Vec::new();
    for &id in agents {
        match ids.rank(id) {
            Some(r) if ranks.contains(&r) => {
                c.err(format!("{f}.agents"), format!("agent {id} is listed twice"));
            }
            Some(r) => ranks.push(r),
            None => c.err(format!("{f}.agents"), format!("agent {id} does not exist")),
        }
    }
    ranks
}

/// The shape of `d` (seed 0 for noise: per agent later), or `None` with
/// errors.
fn shape(c: &mut Ctx, f: &str, d: &DisturbanceSpec, src: &Sources<'_>) -> Option<Shape> {
    let before = c.errors.len();
    foreign_keys(c, f, d);
    let shape = match d.kind {
        DisturbanceKind::Constant => constant(c, f, d),
        DisturbanceKind::Sine => sine(c, f, d),
        DisturbanceKind::Noise => noise(c, f, d),
        DisturbanceKind::Impulse => impulse(c, f, d, src),
    };
    (c.errors.len() == before).then_some(shape)
}

/// An error for every key of `d` its kind does not take.
fn foreign_keys(c: &mut Ctx, f: &str, d: &DisturbanceSpec) {
    let given: [(&str, bool); 8] = [
        ("torque", d.torque.is_some()),
        ("amplitude", d.amplitude.is_some()),
        ("frequency", d.frequency.is_some()),
        ("phase", d.phase.is_some()),
        ("std", d.std.is_some()),
        ("bandwidth", d.bandwidth.is_some()),
        ("t", d.t.is_some()),
        ("impulse", d.impulse.is_some()),
    ];
    let own: &[&str] = match d.kind {
        DisturbanceKind::Constant => &["torque"],
        DisturbanceKind::Sine => &["amplitude", "frequency", "phase"],
        DisturbanceKind::Noise => &["std", "bandwidth"],
        DisturbanceKind::Impulse => &["t", "impulse"],
    };
    for (key, set) in given {
        if set && !own.contains(&key) {
            let kind = d.kind.name();
            c.err(
                format!("{f}.{key}"),
                format!(
                    "does not apply to kind = \"{kind}\" (it takes {})",
                    own.join(", ")
                ),
            );
        }
    }
}

/// An error unless `key` of `d` is `given`.
fn need(c: &mut Ctx, f: &str, d: &DisturbanceSpec, key: &str, given: bool) {
    if !given {
        let kind = d.kind.name();
        c.err(
            format!("{f}.{key}"),
            format!("is required by kind = \"{kind}\""),
        );
    }
}

fn constant(c: &mut Ctx, f: &str, d: &DisturbanceSpec) -> Shape {
    need(c, f, d, "torque", d.torque.is_some());
    let torque = d.torque.unwrap_or_default();
    c.vec3(format_args!("{f}.torque"), &torque);
    Shape::Constant { torque }
}

fn sine(c: &mut Ctx, f: &str, d: &DisturbanceSpec) -> Shape {
    need(c, f, d, "amplitude", d.amplitude.is_some());
    need(c, f, d, "frequency", d.frequency.is_some());
    let amplitude = d.amplitude.unwrap_or_default();
    c.vec3(format_args!("{f}.amplitude"), &amplitude);
    let frequency = d
        .frequency
        .map_or(1.0, |x| c.positive(format_args!("{f}.frequency"), x));
    let phase = d.phase.unwrap_or(0.0);
    c.finite(format_args!("{f}.phase"), phase);
    Shape::Sine {
        amplitude,
        frequency,
        phase,
    }
}

fn noise(c: &mut Ctx, f: &str, d: &DisturbanceSpec) -> Shape {
    need(c, f, d, "std", d.std.is_some());
    need(c, f, d, "bandwidth", d.bandwidth.is_some());
    let std = d.std.map_or([0.0; 3], |s| s.axes());
    if std.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
        c.err(
            format!("{f}.std"),
            format!("must be finite and ≥ 0 N·m, got {std:?}"),
        );
    }
    let bandwidth = d
        .bandwidth
        .map_or(1.0, |x| c.positive(format_args!("{f}.bandwidth"), x));
    Shape::Noise {
        std,
        bandwidth,
        seed: 0,
    }
}

fn impulse(c: &mut Ctx, f: &str, d: &DisturbanceSpec, src: &Sources<'_>) -> Shape {
    need(c, f, d, "t", d.t.is_some());
    need(c, f, d, "impulse", d.impulse.is_some());
    let impulse = d.impulse.unwrap_or_default();
    c.vec3(format_args!("{f}.impulse"), &impulse);
    let step = d.t.and_then(|t| step_of(c, format_args!("{f}.t"), t, src));
    Shape::Impulse {
        step: step.unwrap_or(0),
        impulse,
    }
}

/// `t` as a step of the run: a whole multiple of `dt` in `[0, duration)`.
fn step_of(c: &mut Ctx, f: impl Display + Copy, t: f64, src: &Sources<'_>) -> Option<u64> {
    if !c.finite(f, t) || src.dt.is_nan() || src.dt <= 0.0 {
        return None;
    }
    let n = (t / src.dt).round();
    if (n * src.dt - t).abs() > 1e-9 * t.abs().max(src.dt) {
        c.err(
            f.to_string(),
            format!(
                "must be a whole multiple of simulation.dt = {}, got {t}",
                src.dt
            ),
        );
        return None;
    }
    if n < 0.0 || n >= src.steps as f64 {
        let end = src.steps as f64 * src.dt;
        c.err(
            f.to_string(),
            format!("must be in [0, {end}) s (the run), got {t}"),
        );
        return None;
    }
    Some(n as u64)
}

/// The sensor `s` (seed set per agent later), or `None` with errors.
fn sensor(c: &mut Ctx, f: impl Display + Copy, s: &SensorSpec) -> Option<Sensor> {
    let before = c.errors.len();
    let mut noise = |key: &str, std: Option<f64>, bias: Option<[f64; 3]>| {
        let std = std.unwrap_or(0.0);
        if !(std.is_finite() && std >= 0.0) {
            c.err(
                format!("{f}.{key}_noise"),
                format!("must be finite and ≥ 0, got {std}"),
            );
        }
        let bias = bias.unwrap_or_default();
        c.vec3(format_args!("{f}.{key}_bias"), &bias);
        Noise { std, bias }
    };
    let attitude = noise("attitude", s.attitude_noise, s.attitude_bias);
    let rate = noise("rate", s.rate_noise, s.rate_bias);
    (c.errors.len() == before).then_some(Sensor {
        attitude,
        rate,
        seed: 0,
    })
}

/// The law's inertia `s` says, or `None` (with an error, or a warning for
/// the observerless law, which has none).
fn controller(
    c: &mut Ctx,
    f: impl Display + Copy,
    s: &ControllerSpec,
    kind: SchemeKind,
) -> Option<LawInertia> {
    let law = match (s.inertia_scale, &s.inertia) {
        (Some(_), Some(_)) => {
            c.err(f.to_string(), "give inertia_scale or inertia, not both");
            return None;
        }
        (None, None) => {
            c.err(f.to_string(), "needs inertia_scale or inertia");
            return None;
        }
        (Some(x), None) => {
            let before = c.errors.len();
            c.positive(format_args!("{f}.inertia_scale"), x);
            (c.errors.len() == before).then_some(LawInertia::Scale(x))?
        }
        (None, Some(m)) => {
            LawInertia::Given(c.spd(format_args!("{f}.inertia"), m, "the law's inertia Ĵ")?)
        }
    };
    if kind == SchemeKind::Observerless {
        c.warn(
            f.to_string(),
            "ignored: the observerless law (eq. districontrol) does not use the inertia",
        );
        return None;
    }
    Some(law)
}
