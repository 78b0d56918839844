//! One follower as a stage-by-stage stepper: the unit every engine runs.
//!
//! The protocol, identical in every engine:
//! 1. at an exchange (see [`Coupling::exchanges_at`](crate::network::Coupling::exchanges_at)),
//!    every node publishes [`Agent::stage_exchange`] and every receiver
//!    stores what it got with [`Agent::receive_neighbour`] /
//!    [`Agent::receive_leader`];
//! 2. every node calls [`Agent::advance`], which evaluates its vector field
//!    at its own current stage state and the last values it holds.
//!
//! Because the arithmetic depends only on the agent's own state and the held
//! values, an agent computes bit-identical results in any process.

use crate::body::omega_dot;
use crate::control::{tau_districontrol, tracking_error};
use crate::effects::{At, Body, EffectsState, Ideal};
use crate::guard::{self, Envelope, Violation};
use crate::integrate::stage_time_fraction;
use crate::integrate::{LieDerivative, LieState, Stages, Start};
use crate::law::{Law, LawInput, SharedLaw};
use crate::link::{Link, LinkModel, LinkStats};
use crate::network::{AgentModel, AgentState, Exchanged, Scheme};
use crate::observer::{
    LeaderInput, omega_hat_dot_7b, omega_hat_dot_16b, r_hat_rate, sigma_hat_dot_7c,
};
use crate::sensor::Sensing;
use crate::timeline::{Absent, Due};
use crate::verdict::Verdicts;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The closed-loop vector field of agent i and the torque it applies
/// (the law's, saturated as `model.effects` says: [`crate::actuator`]).
///
/// Scheme 1: eqs. `followeri`, `7a`–`7c`, `control`. Scheme 2: eqs.
/// `followeri`, `16a`–`16b`, `controlconstantestimate`. Scheme 3: eqs.
/// `followeri`, `districontrol`. Schemes 1–2 take `Σᵢ`, `Γᵢ` as
/// `model.law` says (corrected, or as printed: the negative control).
/// `nbrs` are in the order of `model.neighbours`; `leader` is `Some` iff
/// the agent hears the leader. `body` is the body's effects at this stage
/// ([`Ideal`] unless `model.effects` is set): the law measures `x` through
/// its sensors and assumes `Ĵᵢ`, the body receives `sat(τᵢ) + dᵢ(t)`
/// ([`crate::effects`]). With `external`, its law replaces the scheme's
/// torque ([`crate::law`]).
#[must_use]
pub fn agent_field<B: Body>(
    model: &AgentModel,
    gains: &[Matrix3<f64>],
    x: &AgentState,
    nbrs: &[Exchanged],
    leader: Option<&Exchanged>,
    (body, external): (&B, Option<&External<'_>>),
) -> (AgentDerivative, Vector3<f64>) {
    let leader = match (leader, &model.leader_gain) {
        (Some(x), Some(a)) => Some(LeaderInput { a, x }),
        _ => None,
    };
    let own = exchanged_of(&model.scheme, x);
    let measured = body.measure(x);
    let m = measured.as_ref().unwrap_or(x);
    let inertia = body.law_inertia().unwrap_or(&model.inertia);
    let (w_hat_dot, s_hat_dot, tau) = match &model.scheme {
        Scheme::ObserverTimeVarying { observer, control } => {
            let w_hat_dot = omega_hat_dot_7b(observer, &own, gains, nbrs, leader);
            let s_hat_dot = sigma_hat_dot_7c(observer, &model.p, &own, nbrs, leader);
            let e = tracking_error(&m.r, &m.w, &x.r_hat, &x.w_hat);
            let tau = model
                .law
                .tau_control(control, inertia, &model.a_bar, &e, &w_hat_dot);
            (w_hat_dot, s_hat_dot, tau)
        }
        Scheme::ObserverConstant { observer, control } => {
            let w_hat_dot = omega_hat_dot_16b(observer, &own, gains, nbrs, leader);
            let e = tracking_error(&m.r, &m.w, &x.r_hat, &x.w_hat);
            let tau = model.law.tau_control_constant_estimate(
                control,
                inertia,
                &model.a_bar,
                &e,
                &w_hat_dot,
            );
            (w_hat_dot, Vector3::zeros(), tau)
        }
        Scheme::Observerless { control } => {
            let tau = tau_districontrol(control, &m.r, &m.w, gains, nbrs, leader);
            (Vector3::zeros(), Vector3::zeros(), tau)
        }
    };
    let tau = match external {
        Some(e) => e.torque(
            model,
            (m, &w_hat_dot),
            (gains, nbrs, leader.as_ref()),
            &inertia.j,
        ),
        None => tau,
    };
    let tau = body.actuate(tau);
    let body_tau = match body.disturbance(&x.r) {
        Some(d) => tau + d,
        None => tau,
    };
    let r_hat_w = if model.scheme.has_observer() {
        r_hat_rate(&own)
    } else {
        Vector3::zeros()
    };
    let d = LieDerivative {
        omega: [x.w, r_hat_w],
        vec: [
            omega_dot(&model.inertia, &x.w, &body_tau),
            w_hat_dot,
            s_hat_dot,
        ],
    };
    (d, tau)
}

/// A law given from outside ([`crate::law`]) and the stage it is called at.
#[derive(Debug, Clone, Copy)]
pub struct External<'a> {
    /// The law.
    pub law: &'a dyn Law,
    /// The step.
    pub step: u64,
    /// The stage.
    pub stage: usize,
    /// The step size, s.
    pub dt: f64,
}

impl External<'_> {
    /// The law's torque for agent `model` measuring `m` (with `ω̂̇`), hearing
    /// `nbrs` with `gains` and `leader`, assuming `inertia`.
    fn torque(
        &self,
        model: &AgentModel,
        (m, w_hat_dot): (&AgentState, &Vector3<f64>),
        (gains, nbrs, leader): (&[Matrix3<f64>], &[Exchanged], Option<&LeaderInput<'_>>),
        inertia: &Matrix3<f64>,
    ) -> Vector3<f64> {
        let control = match &model.scheme {
            Scheme::ObserverTimeVarying { control, .. }
            | Scheme::ObserverConstant { control, .. }
            | Scheme::Observerless { control } => control,
        };
        self.law.torque(&LawInput {
            agent: model.id,
            step: self.step,
            stage: self.stage,
            t: (self.step as f64 + stage_time_fraction(self.stage)) * self.dt,
            dt: self.dt,
            state: m,
            w_hat_dot,
            gains,
            neighbours: nbrs,
            leader: leader.map(|l| (l.a, l.x)),
            k: (control.k_r, control.k_w),
            inertia,
        })
    }
}

/// [`agent_field`] with the inputs `absent` says are out left out of
/// every sum (the leader: as if the agent did not hear it).
fn without<B: Body>(
    model: &AgentModel,
    gains: &[Matrix3<f64>],
    x: &AgentState,
    nbrs: &[Exchanged],
    leader: Option<&Exchanged>,
    absent: &mut Absent,
    body: (&B, Option<&External<'_>>),
) -> (AgentDerivative, Vector3<f64>) {
    absent.keep(gains, nbrs);
    let leader = leader.filter(|_| !absent.leader(gains.len()));
    agent_field(model, &absent.gains, x, &absent.nbrs, leader, body)
}

/// [`agent_field`] with the inputs `absent` leaves out (when any) and the
/// body's effects `at` (an ideal body without).
fn field(
    (model, gains, x): (&AgentModel, &[Matrix3<f64>], &AgentState),
    nbrs: &[Exchanged],
    leader: Option<&Exchanged>,
    (absent, at, ext): (Option<&mut Absent>, Option<&At<'_>>, Option<&External<'_>>),
) -> (AgentDerivative, Vector3<f64>) {
    match (absent, at) {
        (None, None) => agent_field(model, gains, x, nbrs, leader, (&Ideal, ext)),
        (None, Some(b)) => agent_field(model, gains, x, nbrs, leader, (b, ext)),
        (Some(a), None) => without(model, gains, x, nbrs, leader, a, (&Ideal, ext)),
        (Some(a), Some(b)) => without(model, gains, x, nbrs, leader, a, (b, ext)),
    }
}

/// The inputs left out now (when any is), the state of the body's random
/// effects and a law given from outside, from an agent's timeline box.
fn split(
    timed: Option<&mut Timed>,
) -> (Option<&mut Absent>, Option<&EffectsState>, Option<&dyn Law>) {
    match timed {
        Some(t) => (
            t.absent.as_mut().filter(|a| a.any),
            t.effects.as_ref(),
            t.law.as_deref(),
        ),
        None => (None, None, None),
    }
}

/// The body's effects at stage `s` of step `n` (`None` for an ideal body).
fn at<'a>(
    model: &'a AgentModel,
    state: Option<&'a EffectsState>,
    (n, s): (u64, usize),
    h: f64,
    anchor: Vector3<f64>,
) -> Option<At<'a>> {
    let effects = model.effects.as_deref()?;
    Some(At {
        effects,
        state,
        n,
        t: (n as f64 + stage_time_fraction(s)) * h,
        h,
        s,
        anchor,
    })
}

/// Tangent vector of an agent's state: rates of `(Rᵢ, R̂ᵢ)` and `(ωᵢ, ω̂ᵢ, σ̂ᵢ)`.
pub type AgentDerivative = LieDerivative<2, 3>;

/// What agent i publishes under `scheme`: `(R̂ᵢ, ω̂ᵢ, σ̂ᵢ)` with an observer,
/// `(Rᵢ, ωᵢ, 0)` without.
#[must_use]
pub fn exchanged_of(scheme: &Scheme, x: &AgentState) -> Exchanged {
    if scheme.has_observer() {
        Exchanged {
            r: x.r_hat,
            w: x.w_hat,
            s: x.s_hat,
        }
    } else {
        Exchanged {
            r: x.r,
            w: x.w,
            s: Vector3::zeros(),
        }
    }
}

/// `x` as the start of an RKMK4 step (by reference: the agent keeps its
/// state once).
fn start(x: &AgentState) -> Start<'_, 2, 3> {
    Start {
        rot: [&x.r, &x.r_hat],
        vec: [&x.w, &x.w_hat, &x.s_hat],
    }
}

fn from_lie(y: &LieState<2, 3>) -> AgentState {
    AgentState {
        r: y.rot[0],
        w: y.vec[0],
        r_hat: y.rot[1],
        w_hat: y.vec[1],
        s_hat: y.vec[2],
    }
}

/// A follower stepping its closed loop with RKMK4, stage by stage.
/// Aligned to a cache line (64 B): an engine sweeps many agents at every
/// stage, and an agent then touches only its own lines.
#[derive(Debug, Clone)]
#[repr(align(64))]
pub struct Agent {
    model: AgentModel,
    gains: Vec<Matrix3<f64>>,
    /// State at the start of the current step (RKMK4's `y₀`).
    state: AgentState,
    step: Stages<2, 3>,
    /// `step`'s current stage state, computed once per stage (published
    /// and evaluated at).
    stage_x: AgentState,
    held_nbrs: Vec<Exchanged>,
    /// The leader's value, for an agent that hears it (boxed: most agents
    /// do not, and the agents' data is swept at every stage).
    held_leader: Option<Box<Exchanged>>,
    /// Impaired links, per input (neighbours, then the leader), boxed so
    /// that an agent without any (the common case) steps over a few
    /// pointers, not over whole links, at every stage.
    links: Vec<Option<Box<Link>>>,
    /// Whether any input is impaired (else `links` is not looked at while
    /// stepping: one allocation fewer touched per stage).
    impaired: bool,
    /// Values refused as untrusted, per input (neighbours, then the leader).
    rejected: Box<[u64]>,
    /// Current step index.
    n: u64,
    peak_torque: f64,
    /// The torque applied at stage 0 of step `n` (zero before it is evaluated).
    tau0: Vector3<f64>,
    /// What proves the verdicts of this step's published values.
    verdicts: Verdicts,
    /// What its timeline has done so far, for an agent with one (boxed:
    /// most agents have none).
    timed: Option<Box<Timed>>,
}

/// The state of an agent's timeline ([`crate::timeline`]) and of its
/// body's random effects ([`crate::effects`]).
#[derive(Debug, Clone)]
struct Timed {
    /// The retunes taken so far.
    retuned: Due,
    /// The inputs left out of the law now, for an agent with outages that
    /// `forget`.
    absent: Option<Absent>,
    /// What the body's noise and sensors hold this step.
    effects: Option<EffectsState>,
    /// While the agent is down (crashed, [`crate::timeline::Crash`]).
    down: Option<Down>,
    /// The state at t = 0, for a restart from it.
    initial: AgentState,
    /// A control law given from outside, in place of the scheme's.
    law: Option<SharedLaw>,
}

/// An agent that is down: the stage it is at, and how it comes back.
#[derive(Debug, Clone, Copy)]
struct Down {
    stage: usize,
    until: Option<u64>,
    initial: bool,
}

/// Stages of a step (RKMK4).
const STAGES: usize = 4;

/// What a new process of a crashed agent takes over from the one that
/// crashed ([`Agent::resumed`]): where it is, and the counters that carry on.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Carried {
    /// The step it crashed at.
    pub step: u64,
    /// Its state at the start of that step.
    pub state: AgentState,
    /// Its peak torque so far, N·m.
    pub peak_torque: f64,
    /// The counters of its inputs so far: (sender id, stats), as
    /// [`Agent::link_stats`] gives them.
    pub links: Vec<(u32, LinkStats)>,
}

impl Agent {
    /// An agent with `model`, starting at `initial`, step `dt` (s).
    #[must_use]
    pub fn new(model: AgentModel, initial: AgentState, dt: f64) -> Self {
        let gains = model.neighbours.iter().map(|n| n.a).collect();
        let held_nbrs = vec![Exchanged::identity(); model.neighbours.len()];
        let held_leader = model.leader_gain.map(|_| Box::new(Exchanged::identity()));
        let timeline = model.timeline.as_deref();
        let links = links_of(&model);
        let rejected = vec![0; links.len()].into_boxed_slice();
        let impaired = links.iter().any(Option::is_some);
        let forgets = links.iter().flatten().any(|l| l.ever_forgets());
        let effects = (model.effects.as_deref()).and_then(|e| EffectsState::new(e, dt));
        let timed = (timeline.is_some() || effects.is_some()).then(|| {
            Box::new(Timed {
                retuned: Due::default(),
                absent: forgets.then(|| Absent {
                    now: vec![false; links.len()],
                    ..Absent::default()
                }),
                effects,
                down: None,
                initial,
                law: None,
            })
        });
        let mut agent = Self {
            timed,
            model,
            gains,
            rejected,
            state: initial,
            step: Stages::new(&[initial.w, initial.w_hat, initial.s_hat], dt),
            stage_x: initial,
            held_nbrs,
            held_leader,
            links,
            impaired,
            n: 0,
            peak_torque: 0.0,
            tau0: Vector3::zeros(),
            verdicts: Verdicts::default(),
        };
        agent.step_started();
        agent
    }

    /// A new process's agent taking over from one that crashed at step
    /// `from.step` ([`Carried`]): down from there as the crashed one would
    /// be, restarting as its timeline says, bit-identical to an agent that
    /// ran through the crash in one process.
    #[must_use]
    pub fn resumed(model: AgentModel, initial: AgentState, dt: f64, from: &Carried) -> Self {
        let mut a = Self::new(model, initial, dt);
        a.n = from.step;
        a.state = from.state;
        a.stage_x = from.state;
        a.step = Stages::new(&[from.state.w, from.state.w_hat, from.state.s_hat], dt);
        a.peak_torque = from.peak_torque;
        let ids: Vec<u32> = (a.model.neighbours.iter().map(|n| n.id))
            .chain(a.model.leader_gain.map(|_| 0))
            .collect();
        for &(id, s) in &from.links {
            let Some(k) = ids.iter().position(|&i| i == id) else {
                continue;
            };
            a.rejected[k] = s.rejected;
            if let Some(l) = a.links[k].take() {
                a.links[k] = Some(Box::new(l.counting_from(LinkStats { rejected: 0, ..s })));
            }
        }
        a.step_started();
        a
    }

    /// What happens at the start of a step: a crash or a restart, a
    /// retune, the inputs left out, the body's random draws.
    fn step_started(&mut self) {
        if self.timed.is_none() {
            return;
        }
        self.crash_or_restart();
        self.retune();
        self.left_out();
        self.draw();
    }

    /// Goes down at a crash due now, or comes back at its restart.
    fn crash_or_restart(&mut self) {
        let (Some(timeline), Some(t)) = (self.model.timeline.as_deref(), self.timed.as_deref_mut())
        else {
            return;
        };
        match t.down {
            Some(d) if d.until == Some(self.n) => self.restart(d.initial),
            Some(_) => {}
            None => {
                if let Some(c) = timeline.crash_at(self.n) {
                    t.down = Some(Down {
                        stage: 0,
                        until: c.to,
                        initial: c.initial,
                    });
                }
            }
        }
    }

    /// Starts afresh at the current step ([`crate::timeline`]'s crash):
    /// from the initial state or the one it had, links as at t = 0 but
    /// counting on, held values the identity, the body's effects reset.
    fn restart(&mut self, initial: bool) {
        let Some(t) = self.timed.as_deref_mut() else {
            return;
        };
        t.down = None;
        let x = if initial { t.initial } else { self.state };
        let h = self.step.h();
        t.effects = (self.model.effects.as_deref()).and_then(|e| EffectsState::new(e, h));
        self.state = x;
        self.stage_x = x;
        self.step = Stages::new(&[x.w, x.w_hat, x.s_hat], h);
        self.held_nbrs.fill(Exchanged::identity());
        if let Some(l) = &mut self.held_leader {
            **l = Exchanged::identity();
        }
        let fresh = links_of(&self.model);
        for (old, new) in self.links.iter_mut().zip(fresh) {
            let stats = old.as_deref().map(Link::stats).unwrap_or_default();
            *old = new.map(|l| Box::new(l.counting_from(stats)));
        }
        self.tau0 = Vector3::zeros();
        self.verdicts = Verdicts::default();
    }

    /// The agent with `law` in place of its scheme's torque ([`crate::law`]).
    #[must_use]
    pub fn with_law(mut self, law: SharedLaw) -> Self {
        let timed = self.timed.get_or_insert_with(|| {
            Box::new(Timed {
                retuned: Due::default(),
                absent: None,
                effects: None,
                down: None,
                initial: self.state,
                law: None,
            })
        });
        timed.law = Some(law);
        self
    }

    /// Whether the agent is down (crashed) at the current step.
    #[must_use]
    pub fn is_down(&self) -> bool {
        self.timed.as_deref().is_some_and(|t| t.down.is_some())
    }

    /// One stage of a down agent: nothing is evaluated; `Some(true)` when a
    /// step completed, `None` if the agent is up.
    fn pass_down(&mut self) -> Option<bool> {
        let d = self.timed.as_deref_mut()?.down.as_mut()?;
        d.stage += 1;
        if d.stage < STAGES {
            return Some(false);
        }
        d.stage = 0;
        self.n += 1;
        self.step_started();
        Some(true)
    }

    /// Draws what the body's random effects hold over the current step,
    /// at a step's start only.
    fn draw(&mut self) {
        let (Some(e), Some(t)) = (self.model.effects.as_deref(), self.timed.as_deref_mut()) else {
            return;
        };
        if let Some(s) = &mut t.effects {
            s.step(e, self.n);
        }
    }

    /// Which inputs the law leaves out at the current step (outages that
    /// `forget`), at a step's start only.
    fn left_out(&mut self) {
        let Some(absent) = self.timed.as_deref_mut().and_then(|t| t.absent.as_mut()) else {
            return;
        };
        for (out, link) in absent.now.iter_mut().zip(&self.links) {
            *out = link.as_deref().is_some_and(|l| l.forgotten_at(self.n));
        }
        absent.any = absent.now.iter().any(|&o| o);
    }

    /// Takes the gains of a retune due at the current step
    /// ([`crate::timeline::Retune`]), at a step's start only.
    fn retune(&mut self) {
        let (Some(timeline), Some(timed)) = (self.model.timeline.as_deref(), &mut self.timed)
        else {
            return;
        };
        if let Some(r) = timed.retuned.at(&timeline.retune, self.n, |r| r.step) {
            self.model.scheme = r.scheme;
        }
    }

    /// The agent's model.
    #[must_use]
    pub fn model(&self) -> &AgentModel {
        &self.model
    }

    /// State at the start of the current step.
    #[must_use]
    pub fn state(&self) -> &AgentState {
        &self.state
    }

    /// Largest `‖τᵢ‖` applied at the start of any step so far, N·m.
    #[must_use]
    pub fn peak_torque(&self) -> f64 {
        self.peak_torque
    }

    /// The torque `τᵢ` the body received (after the actuator's limits) at
    /// stage 0 of the current step, that is at `t = n·dt` from the state at
    /// the step's start: valid once that stage was evaluated (after the
    /// step's first [`Self::advance`]); zero before the first step.
    #[must_use]
    pub fn torque(&self) -> Vector3<f64> {
        if self.is_down() {
            return Vector3::repeat(f64::NAN);
        }
        self.tau0
    }

    /// What the agent publishes at the current stage.
    #[must_use]
    pub fn stage_exchange(&self) -> Exchanged {
        if self.is_down() {
            // Nobody receives it: the receivers' timelines drop it.
            return exchanged_of(&self.model.scheme, &self.state);
        }
        match self.sensed() {
            Some(s) => exchanged_of(&self.model.scheme, &s.measure(&self.stage_x)),
            None => exchanged_of(&self.model.scheme, &self.stage_x),
        }
    }

    /// The sensors whose measurement an observerless agent publishes (it
    /// knows nothing better of itself; with an observer it publishes the
    /// observer's state, which it knows exactly).
    fn sensed(&self) -> Option<&Sensing> {
        if self.model.scheme.has_observer() {
            return None;
        }
        self.timed.as_deref()?.effects.as_ref()?.sensing()
    }

    /// The guard's check of the state at the start of the current step
    /// ([`guard::check_agent`]). A state inside the envelope also settles
    /// the verdict on the step's stage-0 value ([`Verdicts::checked`]).
    pub fn check(&mut self, env: &Envelope) -> Option<Violation> {
        match guard::check_agent_defects(&self.state, env) {
            Ok(defects) => {
                if self.step.stage() == 0 {
                    let published = usize::from(self.model.scheme.has_observer());
                    self.verdicts.checked(self.n, defects[published]);
                }
                None
            }
            Err(v) => Some(v),
        }
    }

    /// [`Self::stage_exchange`] and whether a receiver may use it: always
    /// `x.trust().is_ok()`, proven instead of checked where it can be
    /// ([`crate::verdict`]; an engine that hands one value to many
    /// receivers judges it once, here).
    pub fn stage_exchange_judged(&mut self) -> (Exchanged, bool) {
        let mut x = Exchanged::identity();
        let trusted = self.publish_into(&mut x);
        (x, trusted)
    }

    /// [`Self::stage_exchange_judged`] written where it is published:
    /// the value into `out`, the verdict returned.
    #[inline]
    pub(crate) fn publish_into(&mut self, out: &mut Exchanged) -> bool {
        *out = self.stage_exchange();
        if self.is_down() {
            return out.trust().is_ok();
        }
        // a measured attitude is the stage point turned by the sensors' `exp(η^×)`
        let turned = self.sensed().map(Sensing::eta2);
        let published = usize::from(self.model.scheme.has_observer());
        let u = &self.step.increments()[published];
        let slot = (self.n, self.step.stage());
        (self.verdicts).judge(out, slot, u, turned)
    }

    /// Stores the value received from the `k`-th neighbour (order of `model.neighbours`).
    /// On an impaired link the message goes through the link's filter (see [`crate::link`]).
    /// An untrusted value ([`Exchanged::trust`]) is refused and counted; the
    /// agent keeps what it had, in every engine alike.
    pub fn receive_neighbour(&mut self, k: usize, x: Exchanged) {
        self.receive_neighbour_judged(k, x, x.trust().is_ok());
    }

    /// [`Self::receive_neighbour`] with `trusted = x.trust().is_ok()`
    /// already evaluated (once per sender, by an engine that hands one
    /// value to many receivers).
    pub fn receive_neighbour_judged(&mut self, k: usize, x: Exchanged, trusted: bool) {
        let now = (self.n, self.step.stage() as u32);
        self.hold_neighbour(k, &x, trusted, now);
    }

    /// [`Self::receive_neighbour_judged`] of a message stamped `stamp`
    /// taken before its receiver's slot (lookahead, [`Self::lookahead`]):
    /// the link places it by its stamp, so the result is the one of taking
    /// it at that slot (PROTOCOL.md § 10.9).
    pub fn receive_neighbour_stamped(
        &mut self,
        k: usize,
        x: Exchanged,
        trusted: bool,
        stamp: (u64, u32),
    ) {
        self.hold_neighbour(k, &x, trusted, stamp);
    }

    /// How many steps ahead of its receiver the `k`-th input (the leader
    /// after the neighbours) may be taken: its link's delay, whose values
    /// are used that many steps after they are sent (eq. `districontrol`
    /// with `Rⱼ(t − τ)`); 0 for an undelayed input, and for every input of
    /// an agent with a timeline (a crash, an outage or a retune is decided
    /// at the receiver's own slot).
    #[must_use]
    pub fn lookahead(&self, k: usize) -> u64 {
        if self.model.timeline.is_some() {
            return 0;
        }
        (self.links.get(k))
            .and_then(|l| l.as_deref())
            .map_or(0, Link::delay)
    }

    /// What an engine that keeps the neighbours' values itself (the
    /// in-process engine's board) tells the agent of the `k`-th
    /// neighbour's value at an exchange: a refusal is counted, an impaired
    /// link gets the value; an unimpaired input's value is not copied
    /// (it is handed to [`Self::advance_with`] from where it lies).
    #[inline]
    pub(crate) fn hear_neighbour(&mut self, k: usize, x: &Exchanged, trusted: bool) {
        if self.timed.is_some() && self.is_down() {
            return;
        }
        if !trusted {
            self.rejected[k] += 1;
            return;
        }
        if !self.impaired {
            return;
        }
        if let Some(link) = &mut self.links[k] {
            link.offer(self.n, self.step.stage() as u32, *x);
        }
    }

    /// [`Self::receive_neighbour_judged`] from where the value lies (one
    /// copy, into the held value), of a message stamped `(m, s)`.
    fn hold_neighbour(&mut self, k: usize, x: &Exchanged, trusted: bool, (m, s): (u64, u32)) {
        if self.is_down() {
            return;
        }
        if !trusted {
            self.rejected[k] += 1;
            return;
        }
        match &mut self.links[k] {
            Some(link) => link.offer(m, s, *x),
            None => self.held_nbrs[k] = *x,
        }
    }

    /// Stores the value received from the leader (ignored if not connected;
    /// refused and counted if untrusted).
    pub fn receive_leader(&mut self, x: Exchanged) {
        let trusted = self.held_leader.is_none() || x.trust().is_ok();
        self.receive_leader_judged(x, trusted);
    }

    /// [`Self::receive_leader`] with `trusted = x.trust().is_ok()` already
    /// evaluated (see [`Self::receive_neighbour_judged`]).
    pub fn receive_leader_judged(&mut self, x: Exchanged, trusted: bool) {
        let now = (self.n, self.step.stage() as u32);
        self.receive_leader_stamped(x, trusted, now);
    }

    /// [`Self::receive_leader_judged`] of a message stamped `(m, s)` (see
    /// [`Self::receive_neighbour_stamped`]).
    pub fn receive_leader_stamped(&mut self, x: Exchanged, trusted: bool, (m, s): (u64, u32)) {
        let k = self.model.neighbours.len();
        if self.is_down() {
            return;
        }
        if self.held_leader.is_some() && !trusted {
            self.rejected[k] += 1;
            return;
        }
        match (&mut self.held_leader, self.links.get_mut(k)) {
            (Some(_), Some(Some(link))) => link.offer(m, s, x),
            (Some(h), _) => **h = x,
            (None, _) => {}
        }
    }

    /// Counters of every impaired incoming link and of every link on which
    /// a value was refused: (sender id, stats); the leader is 0.
    #[must_use]
    pub fn link_stats(&self) -> Vec<(u32, LinkStats)> {
        let ids = self
            .model
            .neighbours
            .iter()
            .map(|n| n.id)
            .chain(std::iter::once(0));
        ids.zip(self.links.iter().zip(&self.rejected))
            .filter(|(_, (l, r))| l.is_some() || **r > 0)
            .map(|(id, (l, &rejected))| {
                let base = l.as_deref().map(Link::stats).unwrap_or_default();
                (id, LinkStats { rejected, ..base })
            })
            .collect()
    }

    /// Evaluates the current stage with the held inputs and moves on.
    /// Returns `true` when a step completed.
    pub fn advance(&mut self) -> bool {
        if let Some(done) = self.pass_down() {
            return done;
        }
        self.update_links();
        let leader = self.held_leader.as_deref();
        let (absent, state, law) = split(self.timed.as_deref_mut());
        let slot = (self.n, self.step.stage());
        let at = at(&self.model, state, slot, self.step.h(), self.tau0);
        let ext = law.map(|law| External {
            law,
            step: slot.0,
            stage: slot.1,
            dt: self.step.h(),
        });
        let own = (&self.model, &self.gains[..], &self.stage_x);
        let (d, tau) = field(
            own,
            &self.held_nbrs,
            leader,
            (absent, at.as_ref(), ext.as_ref()),
        );
        self.finish_stage(&d, &tau)
    }

    /// [`Self::advance`] for an agent told of its inputs by
    /// [`Self::hear_neighbour`]: `nbrs[k]` is what the `k`-th neighbour's
    /// unimpaired input holds (the engine keeps it: the sender's last
    /// trusted value, identical for every receiver); an impaired input's
    /// entry is replaced by its link's held value. The same arithmetic on
    /// the same values as [`Self::advance`], bit for bit.
    pub(crate) fn advance_with(&mut self, nbrs: &mut [Exchanged]) -> bool {
        if let Some(done) = self.pass_down() {
            return done;
        }
        if self.impaired {
            self.update_links();
            for ((x, link), held) in nbrs.iter_mut().zip(&self.links).zip(&self.held_nbrs) {
                if link.is_some() {
                    *x = *held;
                }
            }
        }
        let leader = self.held_leader.as_deref();
        let (absent, state, law) = split(self.timed.as_deref_mut());
        let slot = (self.n, self.step.stage());
        let at = at(&self.model, state, slot, self.step.h(), self.tau0);
        let ext = law.map(|law| External {
            law,
            step: slot.0,
            stage: slot.1,
            dt: self.step.h(),
        });
        let own = (&self.model, &self.gains[..], &self.stage_x);
        let (d, tau) = field(own, nbrs, leader, (absent, at.as_ref(), ext.as_ref()));
        self.finish_stage(&d, &tau)
    }

    /// The held value of every impaired input whose link delivers one at
    /// this stage ([`Link::value_at`]).
    fn update_links(&mut self) {
        let stage = self.step.stage() as u32;
        let dt = self.step.h();
        let n_nbrs = self.held_nbrs.len();
        for (k, link) in self.links.iter_mut().enumerate() {
            if let Some(x) = link.as_mut().and_then(|l| l.value_at(self.n, stage, dt)) {
                if k < n_nbrs {
                    self.held_nbrs[k] = x;
                } else if let Some(h) = &mut self.held_leader {
                    **h = x;
                }
            }
        }
    }

    /// Hands the stage's derivative `d` (and torque `tau`) to RKMK4 and
    /// moves to the next stage state; `true` when a step completed.
    fn finish_stage(&mut self, d: &AgentDerivative, tau: &Vector3<f64>) -> bool {
        if self.step.stage() == 0 {
            self.peak_torque = self.peak_torque.max(tau.norm());
            self.tau0 = *tau;
        }
        match self.step.push_derivative(start(&self.state), d) {
            Some(next) => {
                self.state = from_lie(&next);
                self.step.restart(&next.vec);
                self.stage_x = self.state;
                self.n += 1;
                self.step_started();
                true
            }
            None => {
                self.stage_x = from_lie(&self.step.stage_state(start(&self.state)));
                false
            }
        }
    }
}

/// The receiving ends of `model`'s impaired inputs (neighbours, then the
/// leader): a link with impairments or outages, `None` for a plain one.
fn links_of(model: &AgentModel) -> Vec<Option<Box<Link>>> {
    let timeline = model.timeline.as_deref();
    let impaired = |l: &Option<LinkModel>, from: u32| {
        let outages = timeline.map_or(&[][..], |t| t.outages_of(from));
        match l.filter(LinkModel::is_impaired) {
            None if outages.is_empty() => None,
            m => Some(Box::new(Link::with_outages(
                m.unwrap_or_else(LinkModel::ideal),
                outages.to_vec(),
            ))),
        }
    };
    let mut links: Vec<Option<Box<Link>>> = (model.neighbours.iter())
        .map(|n| impaired(&n.link, n.id))
        .collect();
    if model.leader_gain.is_some() {
        links.push(impaired(&model.leader_link, 0));
    }
    links
}
