//! How a run ended, whichever engine ran it: one [`Outcome`] from the
//! process engine ([`crate::processes::run`]) or the in-process engine
//! ([`Outcome::in_process`]).

use crate::failure::Failure;
use attitude::engine::InProcess;
use attitude::guard::Divergence;
use attitude::link::LinkStats;
use msgs::Done;

/// How a run ended.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Peak torque per agent (network order), N·m; 0 where never reported.
    pub peak_torques: Vec<f64>,
    /// Steps of the last complete snapshot.
    pub steps: u64,
    /// Why the run stopped early, if it did.
    pub failure: Option<Failure>,
    /// The state that left the envelope, if the run diverged (then
    /// `failure` is set too).
    pub diverged: Option<Divergence>,
    /// Counters of the impaired links: (from, to, stats), by (from, to).
    pub links: Vec<(u32, u32, LinkStats)>,
    /// Real-time pacing per agent (network order): (stages started more
    /// than a step late, largest lateness in wall s). Empty in-process.
    pub pacing: Vec<(u64, f64)>,
    /// What each node that finished reported with `Done`: (name, id,
    /// report). Empty in-process.
    pub nodes: Vec<(String, u32, Done)>,
    /// The agents' processes that crashed and the ones that took over, in
    /// order. Empty in-process.
    pub restarts: Vec<Restart>,
}

/// A crashed agent's process replaced by a new one (`summary.json`'s
/// `restarts`; PROTOCOL.md § 10.10).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Restart {
    /// The agent.
    pub agent: u32,
    /// The step it crashed at.
    pub step: u64,
    /// The process that crashed.
    pub pid_before: u32,
    /// The process that took over.
    pub pid_after: u32,
    /// Wall time from the crash's report to the new process's `Ready`, ms
    /// (`None` if it never became ready).
    pub handover_ms: Option<f64>,
}

impl Outcome {
    /// The outcome of in-process `engine` as it stands (`interrupted`: it was
    /// stopped by an interrupt; `diverged`: it stopped there).
    #[must_use]
    pub fn in_process(engine: &InProcess, interrupted: bool, diverged: Option<Divergence>) -> Self {
        let agents = engine.agents();
        let mut links: Vec<(u32, u32, LinkStats)> = agents
            .iter()
            .flat_map(|a| {
                let to = a.model().id;
                (a.link_stats().into_iter()).map(move |(from, st)| (from, to, st))
            })
            .collect();
        links.sort_by_key(|&(f, t, _)| (f, t));
        // A diverged or interrupted run reports what it recorded: the last
        // snapshot's step and peak torques (as the process engine's last
        // complete snapshot).
        let (sampled, peaks) = engine.last_sample();
        let (steps, peak_torques) = if diverged.is_some() || interrupted {
            (sampled, peaks.to_vec())
        } else {
            (
                engine.step_index(),
                agents.iter().map(|a| a.peak_torque()).collect(),
            )
        };
        Self {
            peak_torques,
            steps,
            failure: match (diverged, interrupted) {
                (Some(_), _) => Some(Failure::Diverged(None)),
                (None, true) => Some(Failure::Interrupted(None)),
                (None, false) => None,
            },
            diverged,
            links,
            pacing: Vec::new(),
            nodes: Vec::new(),
            restarts: Vec::new(),
        }
    }
}
