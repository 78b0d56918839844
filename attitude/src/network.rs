//! The network as the model sees it: who talks to whom, with which gains,
//! from which initial state, and how often states are exchanged.
//!
//! This is the resolved form of a scenario (rotations as matrices, gains as
//! matrices, neighbours sorted by id). Every engine builds its nodes from it.

use crate::body::Inertia;
use crate::control::{ControlGains, ControlLaw};
use crate::link::LinkModel;
use crate::observer::ObserverGains;
use crate::reference::LeaderState;
use crate::timeline::{AgentTimeline, Repoint};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// What one node makes known to its neighbours at an exchange: an attitude,
/// an angular velocity and an angular acceleration.
///
/// Which state it is depends on the scheme: the observer estimate
/// `(R̂ⱼ, ω̂ⱼ, σ̂ⱼ)` for schemes 1–2, the body `(Rⱼ, ωⱼ, 0)` for the
/// observerless scheme, `(R₀, ω₀, σ₀)` for the leader.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Exchanged {
    /// Attitude (body → inertial).
    pub r: Matrix3<f64>,
    /// Body angular velocity, rad/s.
    pub w: Vector3<f64>,
    /// Angular acceleration, rad/s².
    pub s: Vector3<f64>,
}

impl Exchanged {
    /// Identity attitude, zero rates: the value before anything is received.
    #[must_use]
    pub fn identity() -> Self {
        Self {
            r: Matrix3::identity(),
            w: Vector3::zeros(),
            s: Vector3::zeros(),
        }
    }

    /// Whether a receiver may use this value: every number finite and `r`
    /// a rotation (`‖rᵀr − I‖_F ≤` [`ROTATION_TOLERANCE`], `det r > 0`).
    /// Every engine refuses an untrusted value the same way (the receiver
    /// keeps what it had), so they stay bit-identical even when a run
    /// diverges.
    pub fn trust(&self) -> Result<(), Untrusted> {
        self.trusted_defect().map(|_| ())
    }

    /// [`Self::trust`], and when trusted the attitude's orthogonality
    /// defect `‖rᵀr − I‖_F` (what [`crate::verdict`] proves from).
    pub fn trusted_defect(&self) -> Result<f64, Untrusted> {
        let finite = Self::finite;
        if !(finite(self.r.as_slice()) && finite(self.w.as_slice()) && finite(self.s.as_slice())) {
            return Err(Untrusted::NonFinite);
        }
        let defect = crate::so3::orthogonality_defect(&self.r);
        if defect > ROTATION_TOLERANCE || self.r.determinant() <= 0.0 {
            return Err(Untrusted::NotARotation(defect));
        }
        Ok(defect)
    }

    /// Whether every value of `xs` is finite, as [`Self::trust`] decides it.
    pub(crate) fn finite(xs: &[f64]) -> bool {
        // v·0 is ±0 for a finite v and NaN for a NaN or an infinity: the sum
        // is 0 iff every value is finite (branch-free, the verdict of `is_finite`).
        xs.iter().map(|v| v * 0.0).sum::<f64>() == 0.0
    }
}

/// Largest `‖rᵀr − I‖_F` a received attitude may have. attsync's own
/// integrator keeps it near 1e-12; 1e-6 admits any honest f64 rotation.
pub const ROTATION_TOLERANCE: f64 = 1e-6;

/// Why a received state was refused.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Untrusted {
    /// A NaN or an infinity.
    NonFinite,
    /// `r` is not a rotation (its orthogonality defect, or a reflection).
    NotARotation(f64),
}

impl std::fmt::Display for Untrusted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NonFinite => write!(f, "a value is NaN or infinite"),
            Self::NotARotation(d) => write!(
                f,
                "the attitude is not a rotation (‖RᵀR − I‖ = {d:.3e}, or det R ≤ 0)"
            ),
        }
    }
}

/// The paper's three schemes and their gains.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Scheme {
    /// Scheme 1 (Section `timevarying`): observer `7a`–`7c` + law `control`.
    ObserverTimeVarying {
        /// `k_{R^l}, k_{ω^l}, k_σ̃`.
        observer: ObserverGains,
        /// `k_R̄, k_ω̄`.
        control: ControlGains,
    },
    /// Scheme 2 (Section `constant`): observer `16a`–`16b` + law `controlconstantestimate`.
    ObserverConstant {
        /// `k_{R^r}, k_{ω^r}` (`k_sigma` unused).
        observer: ObserverGains,
        /// `k_R̄, k_ω̄`.
        control: ControlGains,
    },
    /// Scheme 3 (Section `constant`): law `districontrol`, no observer.
    Observerless {
        /// `k_Ř, k_ω̌`.
        control: ControlGains,
    },
}

impl Scheme {
    /// Whether agents run an observer of the leader (schemes 1 and 2).
    #[must_use]
    pub fn has_observer(&self) -> bool {
        !matches!(self, Scheme::Observerless { .. })
    }
}

/// State of one agent: its body and its observer's estimate of the leader.
/// The observer part stays constant (and unused) in the observerless scheme.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AgentState {
    /// `Rᵢ`, body → inertial.
    pub r: Matrix3<f64>,
    /// `ωᵢ`, body frame, rad/s.
    pub w: Vector3<f64>,
    /// `R̂ᵢ`.
    pub r_hat: Matrix3<f64>,
    /// `ω̂ᵢ`, rad/s.
    pub w_hat: Vector3<f64>,
    /// `σ̂ᵢ`, rad/s².
    pub s_hat: Vector3<f64>,
}

/// A follower edge seen from one end: the neighbour's id and the gain `A_{i,j}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Neighbour {
    /// The neighbour's agent id.
    pub id: u32,
    /// `A_{i,j} = A_{j,i}` (or `Ǎ_{i,j}` for the observerless scheme).
    pub a: Matrix3<f64>,
    /// Impairments of the link from this neighbour to the agent (`None`: ideal).
    #[serde(default)]
    pub link: Option<LinkModel>,
}

/// Everything agent i knows: its body, gains, neighbourhood and the shared
/// scheme parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AgentModel {
    /// Agent id (≥ 1; 0 is the leader).
    pub id: u32,
    /// Inertia `Jᵢ`.
    pub inertia: Inertia,
    /// Control gain matrix `Āᵢ` (schemes 1–2; unused by the observerless scheme).
    pub a_bar: Matrix3<f64>,
    /// Follower neighbours, sorted by id.
    pub neighbours: Vec<Neighbour>,
    /// `A_{i,0}` if the agent hears the leader (`Ξᵢ = 1`).
    pub leader_gain: Option<Matrix3<f64>>,
    /// Impairments of the link from the leader to the agent (`None`: ideal).
    #[serde(default)]
    pub leader_link: Option<LinkModel>,
    /// Scheme and its gains (the same for every agent).
    pub scheme: Scheme,
    /// The leader's generator `P` (known to every observer, eq. `7c`).
    pub p: Matrix3<f64>,
    /// The signs of `Σᵢ`, `Γᵢ` in the law of schemes 1–2 (the same for every
    /// agent; absent: corrected, and then not written).
    #[serde(default, skip_serializing_if = "ControlLaw::is_corrected")]
    pub law: ControlLaw,
    /// What the scenario's events do to this agent: outages of its inputs,
    /// changes of its gains (`None`, and then not written, without events;
    /// boxed: the agents' models are swept at every stage).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timeline: Option<Box<AgentTimeline>>,
    /// What makes the body non-ideal: actuator limits (`None`, and then not
    /// written, for an ideal body; boxed like `timeline`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effects: Option<Box<crate::effects::Effects>>,
}

/// How often neighbours exchange states.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "mode", rename_all = "kebab-case")]
pub enum Coupling {
    /// At every integrator stage: the network is one centralised integration
    /// of the continuous-time closed loop.
    Continuous,
    /// At the first stage of every `every`-th step; received values are held
    /// in between (a digital network with period `every · dt`).
    Sampled {
        /// Exchange period in steps (≥ 1).
        every: u64,
    },
}

impl Coupling {
    /// Whether nodes exchange states at stage `stage` (0..4) of step `step`.
    #[must_use]
    pub fn exchanges_at(&self, step: u64, stage: usize) -> bool {
        match *self {
            Coupling::Continuous => true,
            Coupling::Sampled { every } => stage == 0 && step % every == 0,
        }
    }
}

/// One agent: its model and initial state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AgentSpec {
    /// What the agent knows.
    pub model: AgentModel,
    /// State at t = 0.
    pub initial: AgentState,
}

/// A whole network, resolved and validated, ready for any engine.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Network {
    /// Agents, sorted by id.
    pub agents: Vec<AgentSpec>,
    /// Leader generator `P`.
    pub p: Matrix3<f64>,
    /// Leader state at t = 0.
    pub leader: LeaderState,
    /// Integrator step, s.
    pub dt: f64,
    /// Number of steps.
    pub steps: u64,
    /// Exchange schedule.
    pub coupling: Coupling,
    /// Output sample period, in steps.
    pub sample_every: u64,
    /// The envelope every node's state must stay in ([`crate::guard`]).
    #[serde(default)]
    pub guard: crate::guard::Envelope,
    /// Jumps of the constant reference, by ascending step (`set = {
    /// "leader.attitude" = … }` events).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub repoint: Vec<Repoint>,
}

impl Network {
    /// Index in `agents` of the agent with id `id`.
    #[must_use]
    pub fn index_of(&self, id: u32) -> Option<usize> {
        self.agents.iter().position(|a| a.model.id == id)
    }

    /// The index in `agents` of every agent id, built once: what a caller
    /// that looks up many ids uses instead of [`Self::index_of`] (a scan).
    /// A repeated id maps to its first agent, as [`Self::index_of`] does.
    #[must_use]
    pub fn index_by_id(&self) -> HashMap<u32, usize> {
        let mut index = HashMap::with_capacity(self.agents.len());
        for (k, a) in self.agents.iter().enumerate() {
            index.entry(a.model.id).or_insert(k);
        }
        index
    }

    /// For each agent, the index in `agents` of each of its neighbours (in
    /// the order of its `model.neighbours`), in time linear in the number of
    /// edges. Panics on an unvalidated network whose neighbour ids are
    /// unknown.
    #[must_use]
    pub fn neighbour_indices(&self) -> Vec<Vec<usize>> {
        let index = self.index_by_id();
        self.agents
            .iter()
            .map(|a| {
                a.model
                    .neighbours
                    .iter()
                    .map(|n| *index.get(&n.id).expect("validated network"))
                    .collect()
            })
            .collect()
    }
}
