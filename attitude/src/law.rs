//! A control law given from outside the model: a user's own (the Python
//! package's `attsync.run(scenario, law=f)`), in place of the scheme's
//! torque (eqs. `control`, `controlconstantestimate`, `districontrol`).
//!
//! The agent hands it exactly what the built-in law receives, at every
//! stage ([`LawInput`]); the torque it returns goes through the actuator's
//! limits and into the body as the built-in one would. The observers (eqs.
//! `7a`–`7c`, `16a`–`16b`) stay the model's. The model calls it and knows
//! nothing else of it: a law that fails returns a non-finite torque, which
//! the divergence guard then stops the run on.

use crate::network::{AgentState, Exchanged};
use nalgebra::{Matrix3, Vector3};
use std::sync::Arc;

/// What a control law receives at one stage of one agent.
#[derive(Debug, Clone, Copy)]
pub struct LawInput<'a> {
    /// The agent's id.
    pub agent: u32,
    /// The step (t = step · dt at its start).
    pub step: u64,
    /// The RKMK4 stage, 0..=3.
    pub stage: usize,
    /// The stage's time, s.
    pub t: f64,
    /// The step, s.
    pub dt: f64,
    /// The agent's state as its sensors measure it (`R`, `ω`; and its
    /// observer's `R̂`, `ω̂`, `σ̂`).
    pub state: &'a AgentState,
    /// `ω̂̇`, the observer's rate (zero without an observer), which the
    /// built-in laws of schemes 1–2 use.
    pub w_hat_dot: &'a Vector3<f64>,
    /// The gains `a_ij` of the neighbours heard now, in id order.
    pub gains: &'a [Matrix3<f64>],
    /// Their values as received (held, delayed, as the links deliver).
    pub neighbours: &'a [Exchanged],
    /// The leader's gain `a_i0` and value, if the agent hears it now.
    pub leader: Option<(&'a Matrix3<f64>, &'a Exchanged)>,
    /// The scheme's control gains `(k_R, k_ω)` now.
    pub k: (f64, f64),
    /// The inertia the law assumes (`Ĵᵢ`).
    pub inertia: &'a Matrix3<f64>,
}

/// A control law: the torque `τᵢ` before the actuator's limits, N·m, body frame.
pub trait Law: Send + Sync + std::fmt::Debug {
    /// The torque at `input`'s stage.
    fn torque(&self, input: &LawInput<'_>) -> Vector3<f64>;
}

/// A law shared by every agent of a run.
pub type SharedLaw = Arc<dyn Law>;
