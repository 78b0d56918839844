//! Rule `telemetry`: the candidate's reports, checked as they come — its own
//! sender id, decodable, samples finite and at the due steps, then `Done`;
//! a torque (optional) only right after the sample of its step, never at
//! the last step.

use crate::processes::Ports;
use msgs::Telemetry;
use msgs::config::NodeConfig;

/// Checks of the candidate's telemetry.
pub(super) struct TelemetryCheck {
    /// Steps of the samples due.
    expected: Vec<u64>,
    /// Steps of the samples received.
    seen: Vec<u64>,
    /// It reported `Ready`.
    pub(super) ready: bool,
    /// It reported `Done`.
    pub(super) done: bool,
    /// The first thing wrong with its telemetry.
    problem: Option<String>,
    /// Every sample received (rule `law`).
    pub(super) samples: Vec<(u64, attitude::network::AgentState)>,
}

impl TelemetryCheck {
    /// Expects what `cfg` asks for.
    pub(super) fn new(cfg: &NodeConfig) -> Self {
        let mut expected: Vec<u64> = (0..=cfg.steps).step_by(cfg.sample_every as usize).collect();
        if expected.last() != Some(&cfg.steps) {
            expected.push(cfg.steps);
        }
        Self {
            expected,
            seen: Vec::new(),
            ready: false,
            done: false,
            problem: None,
            samples: Vec::new(),
        }
    }

    /// Reads and checks every message of the candidate's telemetry
    /// (`ports`' only subscriber) available; `id`: its node id, `steps`: the run's.
    pub(super) fn drain(&mut self, ports: &Ports, id: u32, steps: u64) {
        while let Ok(Some(m)) = ports.receive(0) {
            let mut bad = |why: String| {
                if self.problem.is_none() {
                    self.problem = Some(why);
                }
            };
            if m.sender != id {
                bad(format!(
                    "telemetry claims sender {}, expected {id}",
                    m.sender
                ));
            }
            match m.decode() {
                Err(e) => bad(format!("telemetry: {e}")),
                Ok(Telemetry::Ready) => self.ready = true,
                Ok(Telemetry::Sample { step, state, .. }) => {
                    let finite = state.r.iter().chain(state.w.iter()).all(|v| v.is_finite());
                    if !finite
                        || attitude::so3::orthogonality_defect(&state.r) > msgs::ROTATION_TOLERANCE
                    {
                        bad(format!(
                            "sample at step {step} is not finite or R is not a rotation"
                        ));
                    }
                    if self.done {
                        bad(format!("sample at step {step} after Done"));
                    }
                    self.seen.push(step);
                    self.samples.push((step, state));
                }
                Ok(Telemetry::LeaderSample { step, .. }) => {
                    bad(format!("sends the leader's sample (step {step})"));
                }
                Ok(Telemetry::Torque { step, .. }) => {
                    if self.seen.last() != Some(&step) || step >= steps || self.done {
                        bad(format!(
                            "a torque at step {step} that follows no sample of that step \
                             (or of the last step)"
                        ));
                    }
                }
                Ok(Telemetry::Done(d)) => {
                    if d.steps != steps {
                        bad(format!("Done carries step {}, expected {steps}", d.steps));
                    }
                    self.done = true;
                }
                Ok(Telemetry::Crashed { step, .. }) => {
                    bad(format!(
                        "reports a crash at step {step}: a plug-in never crashes (only a built-in agent's timeline does)"
                    ));
                }
                Ok(Telemetry::LinkStats { .. } | Telemetry::Failed(_)) => {}
            }
        }
    }

    /// Rule `telemetry`'s verdict: the first problem seen, else missing samples or `Done`.
    pub(super) fn verdict(&self) -> Result<(), TelemetryFault> {
        if let Some(p) = &self.problem {
            return Err(TelemetryFault::Seen(p.clone()));
        }
        if self.seen != self.expected {
            let first = self
                .seen
                .iter()
                .zip(&self.expected)
                .position(|(a, b)| a != b)
                .unwrap_or(self.seen.len().min(self.expected.len()));
            return Err(TelemetryFault::Steps {
                seen: self.seen[first.min(self.seen.len())..self.seen.len().min(first + 3)]
                    .to_vec(),
                from: first + 1,
                due: (self.expected
                    [first.min(self.expected.len())..self.expected.len().min(first + 3)])
                    .to_vec(),
                received: self.seen.len(),
                expected: self.expected.len(),
            });
        }
        if !self.done {
            return Err(TelemetryFault::NoDone);
        }
        Ok(())
    }
}

/// Why a candidate fails rule `telemetry` ([`TelemetryCheck::verdict`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub(super) enum TelemetryFault {
    /// The first problem seen in its reports.
    #[error("{0}")]
    Seen(String),
    /// Its samples are not at the steps due.
    #[error(
        "samples at steps {seen:?}… (from the {from}th) where {due:?}… were due ({received} of {expected} received)"
    )]
    Steps {
        /// Up to three steps received, from the first that differs.
        seen: Vec<u64>,
        /// The position of the first that differs, from 1.
        from: usize,
        /// The steps due there.
        due: Vec<u64>,
        /// Samples received.
        received: usize,
        /// Samples due.
        expected: usize,
    },
    /// No `Done` came after the last step.
    #[error("no Done after the last step")]
    NoDone,
}
