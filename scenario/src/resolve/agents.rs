//! `[[agent]]`: ids, bodies, initial states and control gains `Āᵢ`.

use super::ctx::Ctx;
use super::ids::Ids;
use super::kind_name;
use crate::schema::{ActuatorSpec, AgentSpec, ObserverInit, SchemeKind, TorqueLimit};
use attitude::actuator::{RateLimit, Saturation};
use attitude::body::Inertia;
use attitude::network::AgentState;
use nalgebra::{Matrix3, Vector3};
use std::fmt::Display;

/// An agent's body, `Āᵢ` and initial state.
pub(super) type Body = (Inertia, Matrix3<f64>, AgentState);

/// The observer's initial state `(R̂ᵢ, ω̂ᵢ, σ̂ᵢ)`.
type ObserverState = (Matrix3<f64>, Vector3<f64>, Vector3<f64>);

/// The agents' ids ([`Ids`]), with an error for id 0 and for every
/// repeated id, in file order.
pub(super) fn ids(c: &mut Ctx, agents: &[AgentSpec]) -> Ids {
    let pairs = agents
        .iter()
        .enumerate()
        .filter(|(_, a)| a.id != 0)
        .map(|(k, a)| (a.id, k))
        .collect();
    let (ids, repeats) = Ids::new(pairs);
    let mut repeats = repeats.into_iter().peekable();
    if repeats.peek().is_some() || agents.iter().any(|a| a.id == 0) {
        for (k, a) in agents.iter().enumerate() {
            if a.id == 0 {
                c.err(format!("agent[{k}].id"), "must be ≥ 1 (id 0 is the leader)");
            } else if let Some((_, first)) = repeats.next_if(|&(later, _)| later == k) {
                c.err(
                    format!("agent[{k}].id"),
                    format!("duplicate id {} (also agent[{first}])", a.id),
                );
            }
        }
    }
    if agents.is_empty() {
        c.err("agent", "at least one [[agent]] is required");
    }
    ids
}

/// Every valid agent's body, by rank of its id (`None` where invalid).
pub(super) fn bodies(
    c: &mut Ctx,
    agents: &[AgentSpec],
    kind: SchemeKind,
    ids: &Ids,
) -> Vec<Option<Body>> {
    let mut bodies: Vec<Option<Body>> = vec![None; ids.len()];
    for (k, a) in agents.iter().enumerate() {
        let b = body(c, format_args!("agent[{k}]"), a, kind);
        if let (Some(b), Some(r)) = (b, ids.rank(a.id)) {
            bodies[r] = Some(b);
        }
    }
    bodies
}

/// Agent `a` (at field `f`), or `None` if any of its fields is invalid.
fn body(c: &mut Ctx, f: impl Display + Copy, a: &AgentSpec, kind: SchemeKind) -> Option<Body> {
    let j = c.spd(format_args!("{f}.inertia"), &a.inertia, "the inertia J");
    let r = c.rotation(format_args!("{f}.attitude"), &a.attitude);
    let w = c.vec3(format_args!("{f}.omega"), &a.omega);
    let (a_bar, obs) = if kind == SchemeKind::Observerless {
        for (set, name) in [
            (a.control_gain.is_some(), "control_gain"),
            (a.observer.is_some(), "observer"),
        ] {
            if set {
                c.warn(format!("{f}.{name}"), "ignored by the observerless scheme");
            }
        }
        (
            Some(Matrix3::identity()),
            Some((Matrix3::identity(), Vector3::zeros(), Vector3::zeros())),
        )
    } else {
        let a_bar = match &a.control_gain {
            Some(m) => c.gain(format_args!("{f}.control_gain"), m),
            None => {
                c.err(
                    format!("{f}.control_gain"),
                    format!("Āᵢ is required by scheme {}", kind_name(kind)),
                );
                None
            }
        };
        (a_bar, observer(c, f, a.observer.as_ref(), kind))
    };
    let (j, r, a_bar, (r_hat, w_hat, s_hat)) = (j?, r?, a_bar?, obs?);
    let initial = AgentState {
        r,
        w,
        r_hat,
        w_hat,
        s_hat,
    };
    Some((Inertia::new(j), a_bar, initial))
}

/// The observer's initial state of agent `f` under a scheme with an observer.
fn observer(
    c: &mut Ctx,
    f: impl Display + Copy,
    o: Option<&ObserverInit>,
    kind: SchemeKind,
) -> Option<ObserverState> {
    let Some(o) = o else {
        c.err(
            format!("{f}.observer"),
            format!(
                "the observer's initial state is required by scheme {}",
                kind_name(kind)
            ),
        );
        return None;
    };
    let rh = c.rotation(format_args!("{f}.observer.attitude"), &o.attitude);
    let wh = c.vec3(format_args!("{f}.observer.omega"), &o.omega);
    let sh = match (&o.sigma, kind) {
        (Some(sg), SchemeKind::ObserverTimeVarying) => {
            c.vec3(format_args!("{f}.observer.sigma"), sg)
        }
        (None, SchemeKind::ObserverTimeVarying) => {
            c.err(
                format!("{f}.observer.sigma"),
                "σ̂ᵢ(0) is required by scheme observer-time-varying",
            );
            Vector3::zeros()
        }
        (Some(_), _) => {
            c.warn(
                format!("{f}.observer.sigma"),
                "ignored: observer 16a-16b has no σ̂",
            );
            Vector3::zeros()
        }
        (None, _) => Vector3::zeros(),
    };
    rh.map(|rh| (rh, wh, sh))
}

/// An actuator's limits: on the torque, on its rate of change.
pub(super) type Limits = (Option<Saturation>, Option<RateLimit>);

/// Every agent's actuator limits, by rank of its id: its own
/// `agent.actuator`, else `[actuator]`, else none.
pub(super) fn actuators(
    c: &mut Ctx,
    all: Option<&ActuatorSpec>,
    agents: &[AgentSpec],
    ids: &Ids,
) -> Vec<Limits> {
    let every = all.map_or((None, None), |a| limits(c, "actuator", a));
    let mut out = vec![every; ids.len()];
    for (k, a) in agents.iter().enumerate() {
        let Some(own) = a.actuator.as_ref() else {
            continue;
        };
        let own = limits(c, format_args!("agent[{k}].actuator"), own);
        if let Some(r) = ids.rank(a.id) {
            out[r] = own;
        }
    }
    out
}

/// The limits of `a` (at field `f`); each `None` with an error unless
/// every bound is finite and > 0, and one of them is given.
fn limits(c: &mut Ctx, f: impl Display + Copy, a: &ActuatorSpec) -> Limits {
    if a.max_torque.is_none() && a.max_torque_rate.is_none() {
        c.err(f.to_string(), "needs max_torque, max_torque_rate or both");
    }
    let saturation = a
        .max_torque
        .and_then(|m| saturation(c, format_args!("{f}.max_torque"), m));
    let rate = a.max_torque_rate.and_then(|m| {
        let ok = m.is_finite() && m > 0.0;
        if !ok {
            let reason = format!("a torque rate bound must be finite and > 0 N·m/s, got {m}");
            c.err(format!("{f}.max_torque_rate"), reason);
        }
        ok.then_some(RateLimit { max: m })
    });
    (saturation, rate)
}

/// The limits of `m` (at field `f`), or `None` (with an error) unless every
/// bound is finite and > 0.
fn saturation(c: &mut Ctx, f: impl Display + Copy, m: TorqueLimit) -> Option<Saturation> {
    let bounds: &[f64] = match &m {
        TorqueLimit::Norm(m) => std::slice::from_ref(m),
        TorqueLimit::Axes(m) => m,
    };
    if let Some(bad) = bounds.iter().find(|m| !(m.is_finite() && **m > 0.0)) {
        c.err(
            f.to_string(),
            format!("a torque bound must be finite and > 0 N·m, got {bad}"),
        );
        return None;
    }
    Some(match m {
        TorqueLimit::Norm(max) => Saturation::Norm { max },
        TorqueLimit::Axes(max) => Saturation::Axes { max },
    })
}
