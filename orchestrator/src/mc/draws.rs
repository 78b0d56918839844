//! One trial's draws: made in a fixed order from the trial's stream, and
//! written as the `--set` overrides that put them into the scenario (so
//! `attsync run SCENARIO --set …` runs exactly the trial).
//!
//! Order (every value is drawn whether dispersed or not, so switching one
//! quantity off leaves the others' draws unchanged): for each `[[agent]]`
//! in file order `Rᵢ(0)`, `ωᵢ(0)`, `R̂ᵢ(0)`, `ω̂ᵢ(0)`, `σ̂ᵢ(0)`; then
//! `R₀(0)`, `ω₀(0)`, `σ₀(0)`. Each attitude takes 3 uniforms, each vector 3.

use super::dispersion::{Dispersion, LeaderDispersion, Quantity};
use super::haar::{bounded_vector, haar_quaternion};
use rand::Rng;
use std::fmt::Write as _;

/// One node's draws: an attitude (unit quaternion `[w, x, y, z]`), a rate
/// and the observer's (or, for the leader, `σ₀(0)` in `sigma_hat`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NodeDraws {
    /// `R(0)`.
    pub attitude: [f64; 4],
    /// `ω(0)`, rad/s.
    pub omega: [f64; 3],
    /// `R̂(0)`.
    pub attitude_hat: [f64; 4],
    /// `ω̂(0)`, rad/s.
    pub omega_hat: [f64; 3],
    /// `σ̂(0)` (the leader: `σ₀(0)`), rad/s².
    pub sigma_hat: [f64; 3],
}

/// Every draw of one trial.
#[derive(Debug, Clone, PartialEq)]
pub struct Draws {
    /// Per `[[agent]]`, in file order.
    pub agents: Vec<NodeDraws>,
    /// The leader's (`attitude_hat`, `omega_hat` unused).
    pub leader: NodeDraws,
}

/// The draws of one trial of `dispersion`, from its stream `rng`.
pub fn draw(dispersion: &Dispersion, rng: &mut impl Rng) -> Draws {
    let (w, s) = (dispersion.omega_max, dispersion.sigma_max);
    let mut node = || NodeDraws {
        attitude: haar_quaternion(rng),
        omega: bounded_vector(rng, w),
        attitude_hat: haar_quaternion(rng),
        omega_hat: bounded_vector(rng, w),
        sigma_hat: bounded_vector(rng, s),
    };
    let agents = (0..dispersion.agents).map(|_| node()).collect();
    let leader = NodeDraws {
        attitude_hat: [1.0, 0.0, 0.0, 0.0],
        omega_hat: [0.0; 3],
        ..node()
    };
    Draws { agents, leader }
}

/// The `--set` overrides that put `dispersion`'s dispersed draws `d` into
/// the scenario (numbers in Rust's shortest round-trip form: exact).
#[must_use]
pub fn overrides(dispersion: &Dispersion, d: &Draws) -> Vec<String> {
    let mut out = Vec::new();
    for (k, a) in d.agents.iter().enumerate() {
        let f = format!("agent[{k}]");
        let mut set = |q: Quantity, key: &str, value: String| {
            if dispersion.has(q) {
                out.push(format!("{f}.{key}={value}"));
            }
        };
        set(Quantity::Attitude, "attitude", rotation(&a.attitude));
        set(Quantity::Omega, "omega", vector(&a.omega));
        set(
            Quantity::AttitudeHat,
            "observer.attitude",
            rotation(&a.attitude_hat),
        );
        set(Quantity::OmegaHat, "observer.omega", vector(&a.omega_hat));
        set(Quantity::SigmaHat, "observer.sigma", vector(&a.sigma_hat));
    }
    let l = &d.leader;
    if dispersion.leader != LeaderDispersion::None {
        out.push(format!("leader.attitude={}", rotation(&l.attitude)));
    }
    if dispersion.leader == LeaderDispersion::State {
        out.push(format!("leader.omega={}", vector(&l.omega)));
        out.push(format!("leader.sigma={}", vector(&l.sigma_hat)));
    }
    out
}

/// `[x,y,z]` (TOML; `{:?}` keeps `-0.0` and every digit).
fn vector(v: &[f64]) -> String {
    let mut s = String::from("[");
    for (k, x) in v.iter().enumerate() {
        let _ = write!(s, "{}{x:?}", if k > 0 { "," } else { "" });
    }
    s + "]"
}

/// `{quaternion=[w,x,y,z]}`.
fn rotation(q: &[f64; 4]) -> String {
    format!("{{quaternion={}}}", vector(q))
}

/// A `--set` override quoted for a POSIX shell.
#[must_use]
pub fn shell_quote(s: &str) -> String {
    if s.chars()
        .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+".contains(c))
    {
        s.to_owned()
    } else {
        format!("'{}'", s.replace('\'', r"'\''"))
    }
}
