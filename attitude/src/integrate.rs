//! Fourth-order Runge–Kutta–Munthe-Kaas (RKMK4) integration on
//! SO(3)ⁿ × ℝ³ᵐ, driven one stage at a time.
//!
//! A state holds `NR` rotations and `NV` vectors. Each rotation `R` moves as
//! `Ṙ = R ω^×` with a body-frame `ω` given by the vector field; each vector
//! moves as `ẋ = f`. Rotations are updated as `R = Rₙ exp(u)`, so they stay on
//! SO(3) by construction (no re-orthonormalisation); vectors follow the
//! classical RK4 tableau with the same stages.
//!
//! The stepper is explicit about stages because the network exchanges states
//! *at every stage* in continuous coupling: a caller asks for
//! [`Rkmk4::stage_state`], evaluates the vector field there (possibly after
//! talking to other processes) and hands the result to
//! [`Rkmk4::push_derivative`]. After the fourth derivative the step is done.
//!
//! ```text
//! stage 1: y                        k₁ = f(y)
//! stage 2: Rₙ exp(h/2 U₁), xₙ + h/2 k₁   U₁ = k₁ᴿ
//! stage 3: Rₙ exp(h/2 U₂), xₙ + h/2 k₂   U₂ = dexp⁻¹(h/2 U₁, k₂ᴿ)
//! stage 4: Rₙ exp(h U₃),   xₙ + h k₃     U₃ = dexp⁻¹(h/2 U₂, k₃ᴿ), U₄ = dexp⁻¹(h U₃, k₄ᴿ)
//! Rₙ₊₁ = Rₙ exp(h/6 (U₁ + 2U₂ + 2U₃ + U₄)),  xₙ₊₁ = xₙ + h/6 (k₁ + 2k₂ + 2k₃ + k₄)
//! ```
//! Source: H. Munthe-Kaas, "High order Runge–Kutta methods on manifolds",
//! Appl. Numer. Math. 29 (1999).

use crate::so3::{dexp_inv, exp};
use nalgebra::{Matrix3, Vector3};

/// A point of SO(3)^NR × (ℝ³)^NV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LieState<const NR: usize, const NV: usize> {
    /// Rotations.
    pub rot: [Matrix3<f64>; NR],
    /// Vectors.
    pub vec: [Vector3<f64>; NV],
}

/// A tangent vector at a [`LieState`]: body angular velocities of the
/// rotations and time derivatives of the vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LieDerivative<const NR: usize, const NV: usize> {
    /// `ω` with `Ṙ = R ω^×`, one per rotation.
    pub omega: [Vector3<f64>; NR],
    /// `ẋ`, one per vector.
    pub vec: [Vector3<f64>; NV],
}

impl<const NR: usize, const NV: usize> LieDerivative<NR, NV> {
    /// The zero tangent vector.
    #[must_use]
    pub fn zero() -> Self {
        Self {
            omega: [Vector3::zeros(); NR],
            vec: [Vector3::zeros(); NV],
        }
    }
}

/// Stage weights of RK4's tableau: `c` of stages 2–4 (the `a` matrix is diagonal below).
const A: [f64; 3] = [0.5, 0.5, 1.0];

/// One RKMK4 step in progress.
#[derive(Debug, Clone)]
pub struct Rkmk4<const NR: usize, const NV: usize> {
    y0: LieState<NR, NV>,
    stages: Stages<NR, NV>,
}

impl<const NR: usize, const NV: usize> Rkmk4<NR, NV> {
    /// Starts a step of size `h` from `y0`.
    #[must_use]
    pub fn new(y0: LieState<NR, NV>, h: f64) -> Self {
        let stages = Stages::new(&y0.vec, h);
        Self { y0, stages }
    }

    /// Index of the stage whose derivative is expected next (0..4).
    #[must_use]
    pub fn stage(&self) -> usize {
        self.stages.stage()
    }

    /// The state at which the current stage's vector field is evaluated.
    #[must_use]
    pub fn stage_state(&self) -> LieState<NR, NV> {
        self.stages.stage_state(Start::of(&self.y0))
    }

    /// Hands in the vector field at [`Self::stage_state`]. Returns the new
    /// state after the fourth stage, `None` before.
    pub fn push_derivative(&mut self, k: &LieDerivative<NR, NV>) -> Option<LieState<NR, NV>> {
        self.stages.push_derivative(Start::of(&self.y0), k)
    }
}

/// A step's start state `y₀`, by reference (its owner may keep it in any layout).
#[derive(Debug, Clone, Copy)]
pub struct Start<'a, const NR: usize, const NV: usize> {
    /// Rotations.
    pub rot: [&'a Matrix3<f64>; NR],
    /// Vectors.
    pub vec: [&'a Vector3<f64>; NV],
}

impl<'a, const NR: usize, const NV: usize> Start<'a, NR, NV> {
    /// The parts of `y`.
    #[must_use]
    pub fn of(y: &'a LieState<NR, NV>) -> Self {
        Self {
            rot: std::array::from_fn(|i| &y.rot[i]),
            vec: std::array::from_fn(|i| &y.vec[i]),
        }
    }

    fn owned(&self) -> LieState<NR, NV> {
        LieState {
            rot: self.rot.map(|r| *r),
            vec: self.vec.map(|v| *v),
        }
    }
}

/// An RKMK4 step in progress without its start state, which the caller
/// keeps and hands in ([`Start`]) — what [`Rkmk4`] is made of; a node that
/// keeps its state anyway (an agent) keeps it once.
#[derive(Debug, Clone)]
pub struct Stages<const NR: usize, const NV: usize> {
    h: f64,
    stage: usize,
    /// Lie-algebra increments `uₛ` of the current stage (one per rotation).
    u: [Vector3<f64>; NR],
    /// Accumulated `U₁ + 2U₂ + 2U₃ + U₄`.
    sum_u: [Vector3<f64>; NR],
    /// Accumulated `k₁ + 2k₂ + 2k₃ + k₄` of the vectors.
    sum_k: [Vector3<f64>; NV],
    /// Vector part of the current stage.
    x: [Vector3<f64>; NV],
}

impl<const NR: usize, const NV: usize> Stages<NR, NV> {
    /// Starts a step of size `h` from a state whose vectors are `vec`.
    #[must_use]
    pub fn new(vec: &[Vector3<f64>; NV], h: f64) -> Self {
        Self {
            h,
            stage: 0,
            u: [Vector3::zeros(); NR],
            sum_u: [Vector3::zeros(); NR],
            sum_k: [Vector3::zeros(); NV],
            x: *vec,
        }
    }

    /// Starts the next step, of the same size, from a state whose vectors
    /// are `vec` (in place: [`Self::new`] without building a new one).
    pub fn restart(&mut self, vec: &[Vector3<f64>; NV]) {
        self.stage = 0;
        self.u = [Vector3::zeros(); NR];
        self.sum_u = [Vector3::zeros(); NR];
        self.sum_k = [Vector3::zeros(); NV];
        self.x = *vec;
    }

    /// Index of the stage whose derivative is expected next (0..4).
    #[must_use]
    pub fn stage(&self) -> usize {
        self.stage
    }

    /// The step size `h`.
    #[must_use]
    pub fn h(&self) -> f64 {
        self.h
    }

    /// The Lie-algebra increments `u` of the current stage, one per
    /// rotation: the stage point's rotations are `R₀ exp(u)` (zero at stage 0).
    #[must_use]
    pub fn increments(&self) -> &[Vector3<f64>; NR] {
        &self.u
    }

    /// The state at which the current stage's vector field is evaluated,
    /// for a step that started at `y0`.
    #[must_use]
    pub fn stage_state(&self, y0: Start<'_, NR, NV>) -> LieState<NR, NV> {
        if self.stage == 0 {
            return y0.owned();
        }
        let mut rot = y0.rot.map(|r| *r);
        for (r, u) in rot.iter_mut().zip(&self.u) {
            *r *= exp(u);
        }
        LieState { rot, vec: self.x }
    }

    /// Hands in the vector field at [`Self::stage_state`] of a step that
    /// started at `y0`. Returns the new state after the fourth stage,
    /// `None` before.
    pub fn push_derivative(
        &mut self,
        y0: Start<'_, NR, NV>,
        k: &LieDerivative<NR, NV>,
    ) -> Option<LieState<NR, NV>> {
        let s = self.stage;
        assert!(s < 4, "RKMK4 step already complete");
        let weight = if s == 0 || s == 3 { 1.0 } else { 2.0 };
        for i in 0..NR {
            let big_u = dexp_inv(&self.u[i], &k.omega[i]);
            self.sum_u[i] += big_u * weight;
            if s < 3 {
                self.u[i] = big_u * (self.h * A[s]);
            }
        }
        for i in 0..NV {
            self.sum_k[i] += k.vec[i] * weight;
            if s < 3 {
                self.x[i] = y0.vec[i] + k.vec[i] * (self.h * A[s]);
            }
        }
        self.stage += 1;
        if self.stage < 4 {
            return None;
        }
        let h6 = self.h / 6.0;
        let rot = std::array::from_fn(|i| y0.rot[i] * exp(&(self.sum_u[i] * h6)));
        let vec = std::array::from_fn(|i| y0.vec[i] + self.sum_k[i] * h6);
        Some(LieState { rot, vec })
    }
}

/// One complete RKMK4 step of an autonomous-in-stages field `f(stage_time, y)`.
///
/// `t` is the time at the start of the step; stages are evaluated at
/// `t, t + h/2, t + h/2, t + h`.
pub fn rkmk4_step<const NR: usize, const NV: usize>(
    y: &LieState<NR, NV>,
    t: f64,
    h: f64,
    mut f: impl FnMut(f64, &LieState<NR, NV>) -> LieDerivative<NR, NV>,
) -> LieState<NR, NV> {
    let mut step = Rkmk4::new(*y, h);
    loop {
        let ts = t + stage_time_fraction(step.stage()) * h;
        let k = f(ts, &step.stage_state());
        if let Some(next) = step.push_derivative(&k) {
            return next;
        }
    }
}

/// Fraction of the step at which stage `s` is evaluated: 0, ½, ½, 1.
#[must_use]
pub fn stage_time_fraction(s: usize) -> f64 {
    [0.0, 0.5, 0.5, 1.0][s]
}
