//! `summary.json` `until`: the record of an `--until settled` run (the
//! rule that extends it is `crate::until`).

use serde::{Deserialize, Serialize};

/// Why an extended run stopped (`summary.json` `until.stopped`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stopped {
    /// The verdict became final.
    VerdictFinal,
    /// The horizon reached `--max-duration` first.
    MaxDuration,
    /// The run ended otherwise (diverged, failed or interrupted).
    RunEnded,
}

/// `summary.json` `until`: how long an `--until settled` run went and why
/// it stopped.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct UntilSummary {
    /// `settled`.
    pub rule: String,
    /// The scenario's `simulation.duration`, s.
    pub scenario_duration: f64,
    /// `--max-duration`, s.
    pub max_duration: f64,
    /// The horizon it ended with, s (the run's `duration`).
    pub duration: f64,
    /// Chunks run (1: the scenario's horizon sufficed).
    pub chunks: u32,
    /// Why it stopped.
    pub stopped: Stopped,
}
