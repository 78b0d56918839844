//! Sensor noise and bias: what the law measures of its own body. The body
//! evolves with its true `(Rᵢ, ωᵢ)` (eq. `followeri`); the law (eqs.
//! `control`, `controlconstantestimate`, `districontrol`) and, without an
//! observer, what the agent publishes, use `R̃ᵢ = Rᵢ exp(η^×)` and
//! `ω̃ᵢ = ωᵢ + ν`. `PROTOCOL.md` § 10.13 gives the arithmetic to the bit.

use crate::network::AgentState;
use crate::random::SplitMix64;
use crate::so3::exp;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// The errors of one measured quantity: `bias + std · g`, `g` three
/// standard normal deviates drawn once per step (none when `std` is 0).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Noise {
    /// Standard deviation per axis, ≥ 0.
    #[serde(default)]
    pub std: f64,
    /// Constant bias per axis.
    #[serde(default)]
    pub bias: [f64; 3],
}

impl Noise {
    /// This step's error: `bias_k + std · g_k`, drawing `g` from `rng`
    /// only when `std > 0`.
    fn draw(&self, rng: &mut SplitMix64) -> Vector3<f64> {
        let bias = Vector3::from(self.bias);
        if self.std > 0.0 {
            bias + Vector3::from(rng.normal3()) * self.std
        } else {
            bias
        }
    }
}

/// A body's sensors: attitude errors as a rotation vector `η` (rad),
/// rate errors `ν` (rad/s), both in the body frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sensor {
    /// Errors of the attitude, rad.
    #[serde(default)]
    pub attitude: Noise,
    /// Errors of the angular velocity, rad/s.
    #[serde(default)]
    pub rate: Noise,
    /// The state of its stream (already mixed with the agent:
    /// [`crate::random::effect_seed`]).
    pub seed: u64,
}

/// The errors a body's sensors make during one step (drawn at the step's
/// start, held over its stages: the sensors sample once per step).
#[derive(Debug, Clone, PartialEq)]
pub struct Sensing {
    rng: SplitMix64,
    /// `exp(η^×)`.
    e: Matrix3<f64>,
    /// `‖η‖²`, what [`crate::verdict`] proves the measured attitude from.
    eta2: f64,
    nu: Vector3<f64>,
}

impl Sensing {
    /// Sensors with `sensor`'s stream, before the first step.
    #[must_use]
    pub fn new(sensor: &Sensor) -> Self {
        Self {
            rng: SplitMix64(sensor.seed),
            e: Matrix3::identity(),
            eta2: 0.0,
            nu: Vector3::zeros(),
        }
    }

    /// Draws the errors of the next step: `η` (attitude), then `ν` (rate).
    pub fn step(&mut self, sensor: &Sensor) {
        let eta = sensor.attitude.draw(&mut self.rng);
        self.e = exp(&eta);
        self.eta2 = eta.norm_squared();
        self.nu = sensor.rate.draw(&mut self.rng);
    }

    /// `‖η‖²` of the current step: the measured attitude is the body's
    /// turned by `exp(η^×)`, a rotation of angle `‖η‖`.
    #[must_use]
    pub fn eta2(&self) -> f64 {
        self.eta2
    }

    /// What the law measures of `x`: `(Rᵢ exp(η^×), ωᵢ + ν)`, the observer
    /// part (its own computation) as it is.
    #[must_use]
    pub fn measure(&self, x: &AgentState) -> AgentState {
        AgentState {
            r: x.r * self.e,
            w: x.w + self.nu,
            ..*x
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_biased_sensor_measures_the_body_turned_by_its_bias() {
        let s = Sensor {
            attitude: Noise {
                std: 0.0,
                bias: [0.0, 0.0, 0.01],
            },
            rate: Noise {
                std: 0.0,
                bias: [0.1, 0.0, 0.0],
            },
            seed: 3,
        };
        let mut m = Sensing::new(&s);
        m.step(&s);
        let x = AgentState {
            r: Matrix3::identity(),
            w: Vector3::zeros(),
            r_hat: Matrix3::identity(),
            w_hat: Vector3::zeros(),
            s_hat: Vector3::zeros(),
        };
        let y = m.measure(&x);
        assert_eq!(y.w, Vector3::new(0.1, 0.0, 0.0));
        assert!((crate::so3::log(&y.r) - Vector3::new(0.0, 0.0, 0.01)).norm() < 1e-15);
        // no draw without noise: the stream is untouched
        assert_eq!(m.rng, SplitMix64(3));
    }
}
