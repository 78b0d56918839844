//! Why a network has no linear delay system to analyse.

use std::fmt;

/// A link impairment that is not a constant delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Impairment {
    /// A random extra delay of up to `steps` steps.
    Jitter {
        /// The jitter bound, steps of `dt`.
        steps: u64,
    },
    /// Messages are lost.
    Loss,
    /// The link carries only every `steps`-th step's first stage (a hold).
    Period {
        /// The link's exchange period, steps of `dt`.
        steps: u64,
    },
}

impl Impairment {
    /// The scenario field that sets it (`[network]` or a
    /// `[[network.link]]` override).
    #[must_use]
    pub fn field(&self) -> &'static str {
        match self {
            Self::Jitter { .. } => "network.jitter",
            Self::Loss => "network.loss",
            Self::Period { .. } => "network.period",
        }
    }
}

impl fmt::Display for Impairment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Jitter { steps } => write!(f, "a jitter of up to {steps} steps"),
            Self::Loss => write!(f, "message loss"),
            Self::Period { steps } => write!(f, "an exchange period of {steps} steps"),
        }
    }
}

/// Why [`super::Linearisation::of`] refuses a network.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinearError {
    /// Scheme 1 (`7a`–`7c` with eq. `control`): about a rotating reference
    /// the error dynamics are time-varying, so there are no characteristic
    /// roots; with a delay the `σ̂` observer (`7c`) is moreover forced by
    /// `σ₀(t) − σ₀(t − d)`, so its errors do not vanish.
    TimeVarying,
    /// `Coupling::Sampled`: received values are held between exchanges (a
    /// zero-order hold, not a delay).
    Sampled {
        /// The exchange period, steps.
        every: u64,
    },
    /// A follower link that is not a constant delay.
    Impaired {
        /// The sender's id.
        from: u32,
        /// The receiver's id.
        to: u32,
        /// What it does besides delaying.
        what: Impairment,
    },
    /// The network has no agent.
    NoAgents,
    /// An agent lists a neighbour that is not in the network.
    UnknownNeighbour {
        /// The agent's id.
        agent: u32,
        /// The unknown neighbour's id.
        neighbour: u32,
    },
    /// A decoupled system too large for the dense pseudospectral method.
    TooLarge {
        /// States of its discretisation at the second Chebyshev order
        /// (`n + pM`, [`super::roots::size`]: `n = 2N` per axis or `6N`, `p`
        /// of them delayed).
        states: usize,
        /// The most states a dense discretisation may have
        /// ([`super::model::DENSE_LIMIT`]).
        limit: usize,
    },
}

impl LinearError {
    /// The scenario field to change, where one is to blame.
    #[must_use]
    pub fn field(&self) -> Option<&'static str> {
        match self {
            Self::TimeVarying => Some("scheme.kind"),
            Self::Sampled { .. } => Some("simulation.coupling"),
            Self::Impaired { what, .. } => Some(what.field()),
            Self::NoAgents | Self::UnknownNeighbour { .. } | Self::TooLarge { .. } => None,
        }
    }
}

impl fmt::Display for LinearError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TimeVarying => write!(
                f,
                "scheme 1 (observer, time-varying reference) has time-varying error dynamics \
                 about a rotating reference: no characteristic roots (and with a delay the \
                 σ̂ observer is forced by σ₀(t) − σ₀(t − d)); only schemes 2 and 3 are linearised"
            ),
            Self::Sampled { every } => write!(
                f,
                "sampled coupling (every {every} steps) holds received values between exchanges: \
                 a zero-order hold, not a delay; the linearisation needs continuous coupling"
            ),
            Self::Impaired { from, to, what } => write!(
                f,
                "the link {from} → {to} has {what} ({}): not a constant delay",
                what.field()
            ),
            Self::NoAgents => write!(f, "the network has no agent"),
            Self::UnknownNeighbour { agent, neighbour } => {
                write!(
                    f,
                    "agent {agent} lists neighbour {neighbour}, which is not in the network"
                )
            }
            Self::TooLarge { states, limit } => write!(
                f,
                "the network's delay system discretises into {states} states, over the limit of \
                 {limit} for dense eigenvalues (the linear analysis is for small networks)"
            ),
        }
    }
}

impl std::error::Error for LinearError {}
