//! The leader's reference trajectory, eq. `leader`.

use crate::integrate::{LieDerivative, LieState, Rkmk4};
use crate::network::Exchanged;
use crate::timeline::{Due, Repoint};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// State of the virtual leader 0: `(R₀, ω₀, σ₀)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LeaderState {
    /// Reference attitude `R₀` (body → inertial).
    pub r0: Matrix3<f64>,
    /// Reference body angular velocity `ω₀`, rad/s.
    pub w0: Vector3<f64>,
    /// Reference angular acceleration `σ₀`, rad/s².
    pub s0: Vector3<f64>,
}

impl LeaderState {
    /// A constant reference attitude (`ω₀ = σ₀ = 0`).
    #[must_use]
    pub fn constant(r0: Matrix3<f64>) -> Self {
        Self {
            r0,
            w0: Vector3::zeros(),
            s0: Vector3::zeros(),
        }
    }

    fn to_lie(self) -> LieState<1, 2> {
        LieState {
            rot: [self.r0],
            vec: [self.w0, self.s0],
        }
    }

    fn from_lie(x: &LieState<1, 2>) -> Self {
        Self {
            r0: x.rot[0],
            w0: x.vec[0],
            s0: x.vec[1],
        }
    }

    /// What the leader publishes to its followers.
    #[must_use]
    pub fn exchanged(&self) -> Exchanged {
        Exchanged {
            r: self.r0,
            w: self.w0,
            s: self.s0,
        }
    }
}

/// The leader's vector field.
///
/// # Equation
/// ```text
/// (leader)  Ṙ₀ = R₀ ω₀^×,   ω̇₀ = σ₀,   σ̇₀ = P σ₀
/// ```
/// With `ω₀(0) = σ₀(0) = 0` this is a constant reference for any `P`.
#[must_use]
pub fn leader_field(p: &Matrix3<f64>, x: &LeaderState) -> LieDerivative<1, 2> {
    LieDerivative {
        omega: [x.w0],
        vec: [x.s0, p * x.s0],
    }
}

/// The leader as a stage-by-stage stepper, the same RKMK4 as the agents so
/// that the whole network is one integration of the closed loop.
#[derive(Debug, Clone)]
pub struct Leader {
    p: Matrix3<f64>,
    state: LeaderState,
    step: Rkmk4<1, 2>,
    /// `step`'s current stage state, computed once per stage (published
    /// and evaluated at).
    stage_x: LeaderState,
    dt: f64,
    /// Jumps of a constant reference, by ascending step ([`Repoint`]).
    repoint: Vec<Repoint>,
    /// Current step index, and the jumps taken so far.
    n: u64,
    repointed: Due,
}

impl Leader {
    /// A leader with generator `P` starting from `state`, step `dt`.
    #[must_use]
    pub fn new(p: Matrix3<f64>, state: LeaderState, dt: f64) -> Self {
        Self {
            p,
            state,
            step: Rkmk4::new(state.to_lie(), dt),
            stage_x: state,
            dt,
            repoint: Vec::new(),
            n: 0,
            repointed: Due::default(),
        }
    }

    /// This leader, with its constant reference jumping as `repoint` says
    /// (by ascending step; a jump at step 0 replaces the initial `R₀`).
    #[must_use]
    pub fn with_repoints(mut self, repoint: Vec<Repoint>) -> Self {
        self.repoint = repoint;
        self.jump();
        self
    }

    /// Takes the jump due at the current step, if any: the reference
    /// restarts from the new `R₀` (at a step's start only).
    fn jump(&mut self) {
        if let Some(j) = self.repointed.at(&self.repoint, self.n, |j| j.step) {
            self.state.r0 = j.r0;
            self.step = Rkmk4::new(self.state.to_lie(), self.dt);
            self.stage_x = self.state;
        }
    }

    /// State at the start of the current step.
    #[must_use]
    pub fn state(&self) -> &LeaderState {
        &self.state
    }

    /// The leader's state at the current stage, as published.
    #[must_use]
    pub fn stage_exchange(&self) -> Exchanged {
        self.stage_x.exchanged()
    }

    /// Evaluates the current stage and moves on; returns `true` when a step completed.
    pub fn advance(&mut self) -> bool {
        match self
            .step
            .push_derivative(&leader_field(&self.p, &self.stage_x))
        {
            Some(next) => {
                self.state = LeaderState::from_lie(&next);
                self.step = Rkmk4::new(next, self.dt);
                self.stage_x = self.state;
                self.n += 1;
                if !self.repoint.is_empty() {
                    self.jump();
                }
                true
            }
            None => {
                self.stage_x = LeaderState::from_lie(&self.step.stage_state());
                false
            }
        }
    }
}
