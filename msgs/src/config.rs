//! The configuration a node process receives: one JSON file per node
//! (`--config FILE`), written by the orchestrator. f64 values round-trip
//! exactly (shortest representation, parsed with correct rounding), so a
//! node computes bit-identical results to the in-process engine.
//!
//! An agent's law travels in its model: `role.model.law` (`"as-printed"`
//! for the negative control of erratum 1; absent: `"corrected"`).

use crate::open::Limits;
use attitude::guard::Envelope;
use attitude::network::{AgentModel, AgentState, Coupling};
use attitude::reference::LeaderState;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// How a node waits for the messages a stage needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WaitStrategy {
    /// Busy-poll the subscribers.
    Spin,
    /// Poll, calling `sched_yield` between polls.
    Yield,
    /// Sleep on the node's wake event (1 ms slices; re-poll after every wake).
    Block,
    /// Yield for a short while (≤ 200 polls, 2 ms), then block; unless the
    /// orchestrator places the run ([`Contention::Placement`]), block at once
    /// while yields show that another program takes the core.
    Adaptive,
}

/// Who answers programs that compete with the run for its cores.
///
/// An adaptive waiter can see a competitor only by its yields coming back
/// late; but when the run's own processes outnumber the cores (100 nodes on
/// 2 cores) yields come back late on an idle machine too, and blocking then
/// slows the whole lockstep several-fold. Where the orchestrator places the
/// run (`--placement auto|pack`), it measures the foreign load itself and
/// moves the run off busy cores, so the waiter need not guess.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Contention {
    /// Nobody places the node: an adaptive waiter whose yield is stolen
    /// blocks for a while (`agent::wait`).
    #[default]
    Waiter,
    /// The orchestrator's placement copes: an adaptive waiter keeps
    /// yielding (within its window) whatever its yields take.
    Placement,
}

/// What the node is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Role {
    /// The virtual leader 0.
    Leader {
        /// Generator `P`.
        p: Matrix3<f64>,
        /// State at t = 0.
        initial: LeaderState,
        /// Jumps of a constant reference (`set = { "leader.attitude" = … }`
        /// events), by ascending step; empty (and then not written) without.
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        repoint: Vec<attitude::timeline::Repoint>,
    },
    /// A follower.
    Agent {
        /// What the agent knows.
        model: Box<AgentModel>,
        /// State at t = 0.
        initial: AgentState,
    },
}

/// Everything one node process needs to know.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NodeConfig {
    /// [`crate::PROTOCOL_VERSION`] the orchestrator speaks.
    pub protocol_version: u32,
    /// Run id: the service namespace `attsync/<run>/` and the iceoryx2 prefix.
    pub run: String,
    /// iceoryx2 root path of the run.
    pub iox_root: String,
    /// Node id (0 = leader).
    pub id: u32,
    /// Integrator step, s.
    pub dt: f64,
    /// Steps to do.
    pub steps: u64,
    /// Exchange schedule.
    pub coupling: Coupling,
    /// Telemetry every this many steps (and at the last step).
    pub sample_every: u64,
    /// Ids whose state this node reads, in the order the model expects
    /// (neighbours by id, then the leader 0 if linked).
    pub inputs: Vec<u32>,
    /// Ids that read this node's state (to wake them).
    pub outputs: Vec<u32>,
    /// Service limits of the run.
    pub limits: Limits,
    /// Waiting strategy.
    pub wait: WaitStrategy,
    /// Longest wait for one stage's inputs before giving up, s.
    pub stage_timeout: f64,
    /// Longest wait for connections and the start command, s.
    pub start_timeout: f64,
    /// Real-time mode: `Some(factor)` runs free against the wall clock at
    /// `factor` simulated seconds per wall second, never waiting for
    /// inputs; `None` (the default) is deterministic lockstep.
    #[serde(default)]
    pub realtime: Option<f64>,
    /// The envelope the node's own state must stay in (PROTOCOL.md § 9);
    /// absent: [`Envelope::default`].
    #[serde(default, skip_serializing_if = "Envelope::is_default")]
    pub guard: Envelope,
    /// Who copes with competing programs ([`Contention`]); absent:
    /// [`Contention::Waiter`].
    #[serde(default)]
    pub contention: Contention,
    /// The node's role and model.
    pub role: Role,
    /// For a new process of an agent that crashed: where the crashed one
    /// stopped and what carries on ([`attitude::agent::Carried`]); it
    /// begins at that step, down, without waiting for `Start`
    /// (PROTOCOL.md § 10.10). Absent for every other node.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resume: Option<attitude::agent::Carried>,
}

impl NodeConfig {
    /// Reads a config file.
    pub fn read(path: &Path) -> Result<Self, ConfigError> {
        let file = path.to_path_buf();
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Read {
            file: file.clone(),
            cause: e.to_string(),
        })?;
        let cfg: Self = serde_json::from_str(&text).map_err(|e| ConfigError::Invalid {
            file: file.clone(),
            cause: e.to_string(),
        })?;
        if cfg.protocol_version != crate::PROTOCOL_VERSION {
            return Err(ConfigError::Version {
                file,
                theirs: cfg.protocol_version,
            });
        }
        Ok(cfg)
    }

    /// Writes a config file.
    pub fn write(&self, path: &Path) -> Result<(), ConfigError> {
        let text = serde_json::to_string_pretty(self).expect("a config serialises");
        std::fs::write(path, text).map_err(|e| ConfigError::Write {
            file: path.to_path_buf(),
            cause: e.to_string(),
        })
    }
}

/// A node configuration file that cannot be read or written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ConfigError {
    /// The file cannot be read.
    #[error("{}: cannot read: {cause}", file.display())]
    Read {
        /// The file.
        file: std::path::PathBuf,
        /// The operating system's reason.
        cause: String,
    },
    /// The file is not a valid configuration.
    #[error("{}: invalid node config: {cause}", file.display())]
    Invalid {
        /// The file.
        file: std::path::PathBuf,
        /// What is wrong.
        cause: String,
    },
    /// The configuration is for another protocol version.
    #[error("{}: protocol version {theirs} but this program speaks {}", file.display(), crate::PROTOCOL_VERSION)]
    Version {
        /// The file.
        file: std::path::PathBuf,
        /// Its `protocol_version`.
        theirs: u32,
    },
    /// The file cannot be written.
    #[error("{}: cannot write: {cause}", file.display())]
    Write {
        /// The file.
        file: std::path::PathBuf,
        /// The operating system's reason.
        cause: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;
    use attitude::body::Inertia;
    use attitude::control::{ControlGains, ControlLaw};
    use attitude::network::{Neighbour, Scheme};
    use attitude::observer::ObserverGains;
    use nalgebra::Vector3;

    /// An agent's configuration under `law`, with values that need all 17
    /// digits (0.1, π/7, 1/3).
    fn config(law: ControlLaw) -> NodeConfig {
        let third = 1.0 / 3.0;
        let model = AgentModel {
            id: 2,
            inertia: Inertia::new(Matrix3::from_diagonal(&Vector3::new(0.1, 0.3, third))),
            a_bar: Matrix3::from_diagonal(&Vector3::new(11.0, 12.0, 13.0)),
            neighbours: vec![Neighbour {
                id: 1,
                a: Matrix3::from_diagonal(&Vector3::new(12.0, 13.0, 14.0)),
                link: None,
            }],
            leader_gain: Some(Matrix3::from_diagonal(&Vector3::new(16.0, 17.0, 18.0))),
            leader_link: None,
            scheme: Scheme::ObserverTimeVarying {
                observer: ObserverGains {
                    k_r: 9.0,
                    k_w: 14.0,
                    k_sigma: 12.0,
                },
                control: ControlGains {
                    k_r: 8.0,
                    k_w: 13.0,
                },
            },
            p: Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, -0.7, 0.0, 0.7, 0.0),
            law,
            timeline: Default::default(),
            effects: None,
        };
        let r = attitude::so3::rot(std::f64::consts::PI / 7.0, &Vector3::new(0.6, 0.8, 0.0));
        NodeConfig {
            protocol_version: crate::PROTOCOL_VERSION,
            run: "RUN".into(),
            iox_root: "/tmp/attsync-iox2/RUN".into(),
            id: 2,
            dt: 0.001,
            steps: 40_000,
            coupling: Coupling::Continuous,
            sample_every: 10,
            inputs: vec![1, 0],
            outputs: vec![1],
            limits: Limits {
                nodes: 3,
                max_fanout: 1,
                state_buffer: 64,
                telemetry_buffer: 64,
            },
            wait: WaitStrategy::Adaptive,
            stage_timeout: 5.0,
            start_timeout: 30.0,
            realtime: None,
            guard: Envelope::default(),
            contention: Contention::Waiter,
            role: Role::Agent {
                model: Box::new(model),
                initial: AgentState {
                    r,
                    w: Vector3::new(2.5, 2.0, third),
                    r_hat: r.transpose(),
                    w_hat: Vector3::new(0.1, 0.2, 0.3),
                    s_hat: Vector3::new(3.0, 2.5, 2.0),
                },
            },
            resume: None,
        }
    }

    #[test]
    fn the_printed_law_round_trips_exactly() {
        let cfg = config(ControlLaw::AsPrinted);
        let text = serde_json::to_string_pretty(&cfg).unwrap();
        assert!(text.contains("\"law\": \"as-printed\""), "{text}");
        let back: NodeConfig = serde_json::from_str(&text).unwrap();
        assert_eq!(back, cfg);
    }

    #[test]
    fn the_corrected_law_is_not_written_and_is_the_default() {
        let cfg = config(ControlLaw::Corrected);
        let text = serde_json::to_string_pretty(&cfg).unwrap();
        assert!(!text.contains("\"law\""), "{text}");
        let back: NodeConfig = serde_json::from_str(&text).unwrap();
        assert_eq!(back, cfg);
    }

    #[test]
    fn an_unknown_law_is_refused() {
        let text = serde_json::to_string(&config(ControlLaw::AsPrinted)).unwrap();
        let bad = text.replace("\"as-printed\"", "\"as-typed\"");
        let e = serde_json::from_str::<NodeConfig>(&bad).unwrap_err();
        assert!(e.to_string().contains("as-typed"), "{e}");
    }
}
