//! [`RoleError`]: a node configuration whose role is not the one its
//! program runs ([`crate::AgentNode::from_config`], the leader's alike).

use thiserror::Error;

/// A node configured for the other role (the node's id).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum RoleError {
    /// An agent was asked for; the node is the leader.
    #[error("node {0} is configured as the leader")]
    Leader(u32),
    /// The leader was asked for; the node is an agent.
    #[error("node {0} is configured as an agent")]
    Agent(u32),
}
