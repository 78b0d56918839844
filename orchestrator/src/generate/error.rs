//! [`TreeError`]: why [`super::tree`] generates no scenario.

use thiserror::Error;

/// Why `attsync gen tree` generates no scenario (its arguments: exit 2).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TreeError {
    /// `--agents 0`.
    #[error("--agents must be ≥ 1")]
    NoAgents,
    /// `--leader-links` is 0 or more than the agents.
    #[error("--leader-links must be in 1..={agents}")]
    LeaderLinks {
        /// `--agents`.
        agents: u32,
    },
    /// `attsync check` would refuse `--duration` with the `dt` the tree needs.
    #[error(
        "--duration {duration}: {issue} (simulation.dt = {dt} s is what this tree needs: pass a whole multiple of it, at most 2^40 steps; without --duration the longest allowed is picked)"
    )]
    Duration {
        /// `--duration`, s.
        duration: f64,
        /// The first timing issue `check` finds.
        issue: String,
        /// The step the tree needs, s.
        dt: f64,
    },
    /// The `dt` the tree needs is too small for any whole 10 s horizon.
    #[error(
        "the tree needs simulation.dt = {dt} s, too small for a horizon of a whole 10 s within 2^40 steps: {issue}"
    )]
    TooFine {
        /// The first timing issue `check` finds.
        issue: String,
        /// The step the tree needs, s.
        dt: f64,
    },
}
