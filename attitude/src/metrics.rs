//! The quantities the paper reports (Section `simulation`).

use crate::network::AgentState;
use crate::reference::LeaderState;
use crate::so3::abs_i;

/// Synchronisation errors of one agent against the leader at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Errors {
    /// `|Rᵢ R₀ᵀ|_I ∈ [0, 1]`.
    pub att: f64,
    /// `‖ωᵢ − ω₀‖`, rad/s.
    pub angvel: f64,
    /// `|R̂ᵢ R₀ᵀ|_I` and `‖ω̂ᵢ − ω₀‖` when the agent runs an observer.
    pub observer: Option<(f64, f64)>,
}

/// Errors of agent state `x` against leader state `l`.
///
/// # NOTE
/// `‖ωᵢ − ω₀‖` compares body-frame vectors of two different frames, exactly
/// as the paper's figures do; it vanishes when `Rᵢ = R₀` and `ωᵢ = ω₀`.
#[must_use]
pub fn errors(x: &AgentState, l: &LeaderState, has_observer: bool) -> Errors {
    Errors {
        att: abs_i(&(x.r * l.r0.transpose())),
        angvel: (x.w - l.w0).norm(),
        observer: has_observer.then(|| {
            (
                abs_i(&(x.r_hat * l.r0.transpose())),
                (x.w_hat - l.w0).norm(),
            )
        }),
    }
}
