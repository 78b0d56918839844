//! [`Failure`]: why a run stopped early, whichever engine ran it. Carried
//! from the engine through [`crate::outcome::Outcome`] into the results
//! (`summary.json` `incomplete_reason`, its [`Display`](std::fmt::Display)
//! text) and to the exit code ([`Failure::exit_code`]).

pub use bridge::remote::RemoteError;
use std::fmt;

/// Why a run stopped early. Its text is `summary.json`'s `incomplete_reason`.
#[derive(Debug, Clone, PartialEq)]
pub enum Failure {
    /// An interrupt stopped the run: the signal, once the run has named it
    /// (the engines only see the flag: `interrupted`).
    Interrupted(Option<i32>),
    /// A node exited before it was done.
    NodeEnded {
        /// The node, as messages name it (a plug-in's or a host's says so).
        label: String,
        /// Its exit, described (`exit code 1`, `killed by signal 9 (SIGKILL)`).
        status: String,
        /// The name of its log (`logs/<log>.log` in the results directory).
        log: String,
        /// The last lines of its log.
        tail: String,
    },
    /// Some nodes did not become ready within the start timeout.
    StartupTimedOut {
        /// The start timeout, s.
        after: f64,
        /// Which nodes, and why (`not ready: …`, `never connected …`).
        nodes: String,
    },
    /// `Start` could not be sent.
    StartNotSent,
    /// No telemetry came for twice the stage timeout.
    Stalled {
        /// How long none came, s.
        seconds: f64,
    },
    /// A node's telemetry broke the protocol.
    BrokeProtocol {
        /// The node, as messages name it.
        node: String,
        /// What it did.
        how: String,
    },
    /// The telemetry could not be received (iceoryx2's error, its text).
    Telemetry(String),
    /// A node's telemetry message does not decode.
    Undecodable {
        /// The node id it claims.
        node: u32,
        /// Why it does not decode.
        why: String,
    },
    /// A node's sample is not at the leader's step.
    OutOfStep {
        /// The node's name.
        node: String,
        /// Its step.
        step: u64,
        /// The leader's.
        leader: u64,
    },
    /// The leader sent an agent's sample.
    LeaderSentAgentSample,
    /// An agent (its name) sent the leader's sample.
    AgentSentLeaderSample(String),
    /// A state left the envelope: where, once the run has said it
    /// ([`attitude::guard::Divergence::message`]; the engines say `diverged`).
    Diverged(Option<String>),
    /// The results writer asked to stop (a file could not be written).
    WriterStopped,
    /// A host of the run was lost or failed (a run across machines).
    Host(RemoteError),
    /// Nodes that did not exit cleanly after `Stop`: each one's label and exit.
    Shutdown(Vec<String>),
    /// `failure`, with the nodes others gave up waiting for named first.
    Blamed {
        /// One line per node blamed.
        culprits: String,
        /// The failure those nodes caused.
        failure: Box<Failure>,
    },
    /// A failure read back from a results file (its text).
    Recorded(String),
}

impl Failure {
    /// The failure at the root of this one (what [`Failure::Blamed`] wraps).
    #[must_use]
    pub fn root(&self) -> &Failure {
        match self {
            Failure::Blamed { failure, .. } => failure.root(),
            f => f,
        }
    }

    /// This failure, an interrupt in it naming `signal`.
    #[must_use]
    pub fn with_signal(self, signal: i32) -> Self {
        match self {
            Failure::Interrupted(_) => Failure::Interrupted(Some(signal)),
            Failure::Blamed { culprits, failure } => Failure::Blamed {
                culprits,
                failure: Box::new(failure.with_signal(signal)),
            },
            f => f,
        }
    }

    /// Whether the run diverged.
    #[must_use]
    pub fn is_divergence(&self) -> bool {
        matches!(self.root(), Failure::Diverged(_))
    }

    /// The process exit code of a run that ended so ([`crate::error`]'s
    /// table): 3 diverged, 128 + N interrupted by signal N, else 1.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self.root() {
            Failure::Diverged(_) => crate::exit::DIVERGED,
            Failure::Interrupted(Some(signal)) => crate::interrupt::exit_code(*signal),
            _ => crate::exit::FAILED,
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Interrupted(None) => f.write_str("interrupted"),
            Failure::Interrupted(Some(signal)) => f.write_str(&crate::interrupt::reason(*signal)),
            Failure::NodeEnded {
                label,
                status,
                log,
                tail,
            } => write!(
                f,
                "{label} ended during the run ({status}); last lines of its log \
                 (logs/{log}.log in the results directory):\n{tail}"
            ),
            Failure::StartupTimedOut { after, nodes } => {
                write!(f, "start-up timed out after {after} s: {nodes}")
            }
            Failure::StartNotSent => f.write_str("cannot send Start"),
            Failure::Stalled { seconds } => {
                write!(f, "no telemetry for {seconds:.0} s: the run is stalled")
            }
            Failure::BrokeProtocol { node, how } => write!(f, "{node} broke the protocol: {how}"),
            Failure::Telemetry(what) | Failure::Recorded(what) => f.write_str(what),
            Failure::Undecodable { node, why } => write!(f, "node {node}'s telemetry: {why}"),
            Failure::OutOfStep { node, step, leader } => write!(
                f,
                "telemetry out of step: {node} at step {step}, leader at {leader}"
            ),
            Failure::LeaderSentAgentSample => f.write_str("the leader sent an agent's sample"),
            Failure::AgentSentLeaderSample(node) => write!(f, "{node} sent the leader's sample"),
            Failure::Diverged(None) => f.write_str("diverged"),
            Failure::Diverged(Some(message)) => f.write_str(message),
            Failure::WriterStopped => f.write_str("stopped by the results writer"),
            Failure::Host(e) => write!(f, "{e}"),
            Failure::Shutdown(nodes) => {
                write!(f, "nodes failed at shutdown: {}", nodes.join("; "))
            }
            Failure::Blamed { culprits, failure } => write!(f, "{culprits}\n{failure}"),
        }
    }
}

impl From<RemoteError> for Failure {
    fn from(e: RemoteError) -> Self {
        Failure::Host(e)
    }
}

/// `summary.json` holds the text.
impl serde::Serialize for Failure {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

/// Read back as [`Failure::Recorded`].
impl<'de> serde::Deserialize<'de> for Failure {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        String::deserialize(d).map(Failure::Recorded)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_interrupt_under_blame_names_its_signal() {
        let f = Failure::Blamed {
            culprits: "agent-1 stopped answering: leader timed out waiting for its state".into(),
            failure: Box::new(Failure::Interrupted(None)),
        };
        assert!(f.to_string().ends_with("\ninterrupted"));
        let f = f.with_signal(signal_hook::consts::SIGTERM);
        assert!(f.to_string().ends_with("\ninterrupted by SIGTERM"), "{f}");
        assert_eq!(f.exit_code(), 143);
    }

    #[test]
    fn texts() {
        assert_eq!(Failure::Diverged(None).to_string(), "diverged");
        assert_eq!(Failure::Diverged(None).exit_code(), 3);
        assert_eq!(
            Failure::Stalled { seconds: 20.0 }.to_string(),
            "no telemetry for 20 s: the run is stalled"
        );
        let shut = Failure::Shutdown(vec!["leader: exit code 1".into(), "agent-2: x".into()]);
        assert_eq!(
            shut.to_string(),
            "nodes failed at shutdown: leader: exit code 1; agent-2: x"
        );
        assert_eq!(shut.exit_code(), 1);
        let late = Failure::OutOfStep {
            node: "agent-2".into(),
            step: 30,
            leader: 20,
        };
        assert_eq!(
            late.to_string(),
            "telemetry out of step: agent-2 at step 30, leader at 20"
        );
    }
}
