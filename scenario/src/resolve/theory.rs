//! [`Departure`]: a way a scenario leaves the paper's Assumption 1 (the
//! follower graph a forest, every agent reached from the leader), allowed
//! only with `[graph] assumptions = "off"`, and what the paper then no
//! longer guarantees.

use super::Issue;
use serde::Serialize;
use std::fmt;

/// The field of the warning of a scenario outside the theory.
pub const FIELD: &str = "graph.assumptions";

/// The one warning of a scenario with `departures` (none without).
#[must_use]
pub fn warning(departures: &[Departure]) -> Option<Issue> {
    if departures.is_empty() {
        return None;
    }
    let said: Vec<String> = departures.iter().map(ToString::to_string).collect();
    Some(Issue {
        field: FIELD.into(),
        reason: format!(
            "outside the paper's theory ({}): its guarantees do not cover this run \
             (`attsync check` says what is lost)",
            said.join("; ")
        ),
    })
}

/// A way the scenario leaves Assumption 1.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Departure {
    /// A one-way `[[edge]]` (`from`, `to`): only `to` hears `from`.
    OneWay {
        /// Sender and receiver.
        edge: [u32; 2],
    },
    /// `[[edge]]` closes a cycle of followers.
    Cycle {
        /// The edge's agents (smaller id first).
        edge: [u32; 2],
    },
    /// Agents no path of edges from a leader-linked agent reaches.
    Unreachable {
        /// Their ids, ascending.
        agents: Vec<u32>,
    },
    /// No `[[leader_link]]`: no agent hears the leader.
    NoLeaderLink,
}

impl Departure {
    /// What the paper no longer guarantees.
    #[must_use]
    pub fn lost(&self) -> &'static str {
        match self {
            Self::OneWay { .. } => {
                "the paper's graph is undirected (A_ij = A_ji, a symmetric Laplacian): its \
                 Lyapunov functions, and every guarantee built on them, assume each \
                 neighbour hears the other"
            }
            Self::Cycle { .. } => {
                "the stability proofs use a forest (a full-rank incidence matrix); on a cycle \
                 other equilibria (\"twisted\" states) can be stable, so almost-global \
                 synchronisation is no longer guaranteed"
            }
            Self::Unreachable { .. } => {
                "no information about the reference reaches them: nothing drives them to \
                 the leader's attitude (they may still synchronise among themselves)"
            }
            Self::NoLeaderLink => {
                "no agent tracks the reference: at most the agents synchronise among \
                 themselves, to no particular attitude"
            }
        }
    }
}

impl fmt::Display for Departure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::OneWay { edge: [a, b] } => write!(f, "edge {a}→{b} is one-way"),
            Self::Cycle { edge: [a, b] } => write!(f, "edge {a}–{b} closes a cycle"),
            Self::Unreachable { agents } => {
                let ids: Vec<String> = agents.iter().map(u32::to_string).collect();
                let s = if agents.len() == 1 { "" } else { "s" };
                write!(f, "agent{s} {} unreachable from the leader", ids.join(", "))
            }
            Self::NoLeaderLink => f.write_str("no [[leader_link]]: no agent hears the leader"),
        }
    }
}
