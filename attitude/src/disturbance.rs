//! Disturbance torques: what acts on a body besides its actuator. The body
//! obeys eq. `followeri` with `τᵢ + dᵢ(t)`, the law never sees `dᵢ`.
//! `PROTOCOL.md` § 10.12 gives the arithmetic to the bit.

use crate::random::SplitMix64;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The frame a disturbance is given in.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Frame {
    /// Fixed in the body (a thruster leak, a wheel's friction).
    #[default]
    Body,
    /// Fixed in inertial space (solar pressure over a short arc): the body
    /// feels `Rᵢᵀ d`.
    Inertial,
}

/// One disturbance torque `d(t)`, N·m, in `frame`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Disturbance {
    /// Its frame.
    #[serde(default)]
    pub frame: Frame,
    /// Its shape in time.
    #[serde(flatten)]
    pub shape: Shape,
}

/// How a disturbance varies in time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Shape {
    /// `d(t) = torque`.
    Constant {
        /// N·m.
        torque: [f64; 3],
    },
    /// `d_k(t) = amplitude_k · sin(2π f t + phase)`.
    Sine {
        /// N·m, per axis.
        amplitude: [f64; 3],
        /// `f`, Hz, > 0.
        frequency: f64,
        /// rad.
        phase: f64,
    },
    /// Band-limited noise: a first-order Gauss–Markov process per axis,
    /// stationary with standard deviation `std_k` and corner frequency
    /// `bandwidth`, drawn once per step and held over it ([`GaussMarkov`]).
    Noise {
        /// N·m, per axis, ≥ 0.
        std: [f64; 3],
        /// Hz, > 0.
        bandwidth: f64,
        /// The state of its stream (already mixed with the agent and the
        /// effect: [`crate::random::effect_seed`]).
        seed: u64,
    },
    /// An angular impulse delivered over one step: `d = impulse / dt`
    /// during step `step`, zero otherwise.
    Impulse {
        /// The step.
        step: u64,
        /// N·m·s.
        impulse: [f64; 3],
    },
}

impl Disturbance {
    /// Whether it needs a state between steps (a stream).
    #[must_use]
    pub fn is_random(&self) -> bool {
        matches!(self.shape, Shape::Noise { .. })
    }

    /// `d` in the body frame at time `t = (n + c)·h` of stage `(n, c)`
    /// with body attitude `r`; `noise` is the held value of a
    /// [`Shape::Noise`] (ignored by the others).
    #[must_use]
    pub fn torque(
        &self,
        n: u64,
        t: f64,
        h: f64,
        r: &Matrix3<f64>,
        noise: &Vector3<f64>,
    ) -> Vector3<f64> {
        let d = match self.shape {
            Shape::Constant { torque } => Vector3::from(torque),
            Shape::Sine {
                amplitude,
                frequency,
                phase,
            } => Vector3::from(amplitude) * (std::f64::consts::TAU * frequency * t + phase).sin(),
            Shape::Noise { .. } => *noise,
            Shape::Impulse { step, impulse } if step == n => Vector3::from(impulse) / h,
            Shape::Impulse { .. } => Vector3::zeros(),
        };
        match self.frame {
            Frame::Body => d,
            Frame::Inertial => r.transpose() * d,
        }
    }
}

/// The state of a [`Shape::Noise`]: `x ← φ x + s ∘ g` once per step,
/// `φ = exp(−2π · bandwidth · dt)`, `s_k = std_k · √(1 − φ²)`, `g` three
/// standard normal deviates; at step 0 `x = std ∘ g` (stationary).
#[derive(Debug, Clone, PartialEq)]
pub struct GaussMarkov {
    rng: SplitMix64,
    phi: f64,
    std: Vector3<f64>,
    s: Vector3<f64>,
    /// The value held over the current step.
    pub x: Vector3<f64>,
}

impl GaussMarkov {
    /// The process of `std`, `bandwidth` and `seed`, with step `dt`.
    #[must_use]
    pub fn new(std: [f64; 3], bandwidth: f64, seed: u64, dt: f64) -> Self {
        let phi = (-std::f64::consts::TAU * bandwidth * dt).exp();
        let std = Vector3::from(std);
        Self {
            rng: SplitMix64(seed),
            phi,
            s: std * (1.0 - phi * phi).sqrt(),
            std,
            x: Vector3::zeros(),
        }
    }

    /// Draws the value of step `n` (called at every step, in order).
    pub fn step(&mut self, n: u64) {
        let g = Vector3::from(self.rng.normal3());
        self.x = if n == 0 {
            self.std.component_mul(&g)
        } else {
            self.x * self.phi + self.s.component_mul(&g)
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gauss_markov_process_has_its_variance_and_correlation_time() {
        let dt = 0.01;
        let mut p = GaussMarkov::new([2.0, 0.0, 0.5], 1.0, 11, dt);
        let n = 400_000;
        let (mut sum2, mut lag) = (Vector3::zeros(), 0.0);
        let mut prev = 0.0;
        for k in 0..n {
            p.step(k);
            sum2 += p.x.component_mul(&p.x);
            if k > 0 {
                lag += p.x.x * prev;
            }
            prev = p.x.x;
        }
        let var = sum2 / n as f64;
        assert!((var.x / 4.0 - 1.0).abs() < 0.05, "var {}", var.x);
        assert_eq!(var.y, 0.0);
        assert!((var.z / 0.25 - 1.0).abs() < 0.05);
        // one-step autocorrelation φ = exp(−2π·1·0.01) ≈ 0.939
        let rho = lag / (n - 1) as f64 / var.x;
        assert!(
            (rho - (-std::f64::consts::TAU * dt).exp()).abs() < 0.01,
            "rho {rho}"
        );
    }

    #[test]
    fn an_impulse_acts_during_its_step_only_and_an_inertial_torque_turns_with_the_body() {
        let d = Disturbance {
            frame: Frame::Body,
            shape: Shape::Impulse {
                step: 3,
                impulse: [0.0, 0.2, 0.0],
            },
        };
        let r = Matrix3::identity();
        let z = Vector3::zeros();
        assert_eq!(d.torque(3, 0.31, 0.1, &r, &z), Vector3::new(0.0, 2.0, 0.0));
        assert_eq!(d.torque(4, 0.4, 0.1, &r, &z), z);
        let f = Disturbance {
            frame: Frame::Inertial,
            shape: Shape::Constant {
                torque: [1.0, 0.0, 0.0],
            },
        };
        // a body turned +90° about z sees the inertial x axis as its −y
        let rz = crate::so3::exp(&Vector3::new(0.0, 0.0, std::f64::consts::FRAC_PI_2));
        let b = f.torque(0, 0.0, 0.1, &rz, &z);
        assert!((b - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-15);
    }
}
