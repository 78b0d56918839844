//! `attsync-agent`: one rigid body as its own OS process. It talks only to
//! its graph neighbours (and the leader, if linked) over iceoryx2 shared
//! memory, in lockstep, and reports telemetry to the orchestrator.
//!
//! # Layout
//! - [`runtime`]: the lockstep node loop shared with the leader process.
//! - [`wait`]: waiting strategies.
//! - [`backpressure`]: how a publisher paces itself while a receiver is full.
//! - [`args`]: the command line shared by the agent and leader binaries.
//! - [`role`]: a configuration for the other role ([`RoleError`]).
//! - [`AgentNode`]: the model ([`attitude::agent::Agent`]) behind the loop.

pub mod args;
pub mod backpressure;
pub mod role;
pub mod runtime;
pub mod wait;

use attitude::agent::Agent;
use attitude::network::Exchanged;
use iceoryx2::node::Node;
use iceoryx2::service::Service;
use msgs::Telemetry;
use msgs::config::{NodeConfig, Role};
pub use role::RoleError;
/// Runs any [`Stepper`] (your own agent model) behind the node loop: the
/// way to write a plug-in agent in Rust (see `examples/saturated_agent/`).
pub use runtime::run as run_stepper;
pub use runtime::{Hooks, NoHooks, NodeError, Override, Stepper, run_with};
use std::sync::atomic::AtomicBool;

/// An agent behind the node loop. Inputs are its neighbours in id order,
/// then the leader if linked (as in [`NodeConfig::inputs`]).
#[derive(Debug)]
pub struct AgentNode {
    agent: Agent,
}

impl AgentNode {
    /// Builds the agent of `cfg` (which must have an agent role).
    ///
    /// # Errors
    /// [`RoleError::Leader`] if `cfg` is the leader's.
    pub fn from_config(cfg: &NodeConfig) -> Result<Self, RoleError> {
        match &cfg.role {
            Role::Agent { model, initial } => Ok(Self {
                agent: match &cfg.resume {
                    Some(from) => Agent::resumed((**model).clone(), *initial, cfg.dt, from),
                    None => Agent::new((**model).clone(), *initial, cfg.dt),
                },
            }),
            Role::Leader { .. } => Err(RoleError::Leader(cfg.id)),
        }
    }
}

impl Stepper for AgentNode {
    fn stage_exchange(&self) -> Exchanged {
        self.agent.stage_exchange()
    }

    /// `x` was validated by the runtime ([`msgs::StateMsg::validated`],
    /// the same [`Exchanged::trust`] the agent would apply), so the agent
    /// takes it as judged trusted instead of checking it a second time.
    fn receive(&mut self, k: usize, x: Exchanged) {
        if k < self.agent.model().neighbours.len() {
            self.agent.receive_neighbour_judged(k, x, true);
        } else {
            self.agent.receive_leader_judged(x, true);
        }
    }

    fn lookahead(&self, k: usize) -> u64 {
        self.agent.lookahead(k)
    }

    fn receive_stamped(&mut self, k: usize, x: Exchanged, stamp: (u64, u32)) {
        if k < self.agent.model().neighbours.len() {
            self.agent.receive_neighbour_stamped(k, x, true, stamp);
        } else {
            self.agent.receive_leader_stamped(x, true, stamp);
        }
    }

    fn advance(&mut self) {
        self.agent.advance();
    }

    fn sample(&self, step: u64) -> Telemetry {
        Telemetry::Sample {
            step,
            state: *self.agent.state(),
            peak_torque: self.agent.peak_torque(),
        }
    }

    fn peak_torque(&self) -> f64 {
        self.agent.peak_torque()
    }

    fn torque(&self, step: u64) -> Option<Telemetry> {
        // A down agent applies none: the run records NaN.
        (!self.agent.is_down()).then_some(())?;
        Some(Telemetry::Torque {
            step,
            tau: self.agent.torque(),
        })
    }

    fn link_stats(&self) -> Vec<(u32, attitude::link::LinkStats)> {
        self.agent.link_stats()
    }

    fn crash(&self, step: u64) -> Option<Telemetry> {
        let timeline = self.agent.model().timeline.as_deref()?;
        timeline.crash_at(step).map(|_| Telemetry::Crashed {
            step,
            state: *self.agent.state(),
            peak_torque: self.agent.peak_torque(),
        })
    }

    fn is_down(&self) -> bool {
        self.agent.is_down()
    }
}

/// Runs the agent of `cfg` on `node` until the end of the protocol.
pub fn run<S: Service>(
    node: &Node<S>,
    cfg: &NodeConfig,
    shutdown: &AtomicBool,
) -> Result<(), NodeError> {
    let mut a = AgentNode::from_config(cfg).map_err(|e| NodeError::Protocol(e.to_string()))?;
    runtime::run(node, cfg, &mut a, shutdown)
}
