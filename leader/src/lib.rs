//! `attsync-leader`: the virtual leader 0 (eq. `leader`) as a process. It has
//! no inputs; it publishes its stage states to the agents linked to it, held
//! back only by their buffers, and reports telemetry.

use attitude::network::Exchanged;
use attitude::reference::Leader;
use attsync_agent::{NodeError, RoleError, Stepper};
use iceoryx2::node::Node;
use iceoryx2::service::Service;
use msgs::Telemetry;
use msgs::config::{NodeConfig, Role};
use std::sync::atomic::AtomicBool;

/// The leader behind the node loop.
#[derive(Debug)]
pub struct LeaderNode(Leader);

impl LeaderNode {
    /// Builds the leader of `cfg` (which must have the leader role).
    ///
    /// # Errors
    /// [`RoleError::Agent`] if `cfg` is an agent's.
    pub fn from_config(cfg: &NodeConfig) -> Result<Self, RoleError> {
        match &cfg.role {
            Role::Leader {
                p,
                initial,
                repoint,
            } => Ok(Self(
                Leader::new(*p, *initial, cfg.dt).with_repoints(repoint.clone()),
            )),
            Role::Agent { .. } => Err(RoleError::Agent(cfg.id)),
        }
    }
}

impl Stepper for LeaderNode {
    fn stage_exchange(&self) -> Exchanged {
        self.0.stage_exchange()
    }

    fn receive(&mut self, _k: usize, _x: Exchanged) {}

    fn advance(&mut self) {
        self.0.advance();
    }

    fn sample(&self, step: u64) -> Telemetry {
        Telemetry::LeaderSample {
            step,
            state: *self.0.state(),
        }
    }

    fn peak_torque(&self) -> f64 {
        0.0
    }
}

/// Runs the leader of `cfg` on `node` until the end of the protocol.
pub fn run<S: Service>(
    node: &Node<S>,
    cfg: &NodeConfig,
    shutdown: &AtomicBool,
) -> Result<(), NodeError> {
    let mut l = LeaderNode::from_config(cfg).map_err(|e| NodeError::Protocol(e.to_string()))?;
    attsync_agent::runtime::run(node, cfg, &mut l, shutdown)
}
