//! One opener per service. iceoryx2 fixes a service's limits when it is
//! created and refuses an opener that asks for more, so every process, the
//! orchestrator included, opens every service through these functions with
//! the same [`Limits`].

use crate::names;
use crate::payload::{ControlMsg, StateMsg};
use crate::telemetry::TelemetryMsg;
use attitude::network::Network;
use iceoryx2::node::Node;
use iceoryx2::prelude::ServiceName;
use iceoryx2::service::Service;
use iceoryx2::service::port_factory::{event, publish_subscribe};
use std::fmt;
use std::time::{Duration, Instant};

/// Limits of every service of a run, derived from its topology.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Limits {
    /// Nodes in the run: agents + the leader.
    pub nodes: usize,
    /// Largest number of receivers of any node's state (an agent's degree,
    /// or the leader's number of links).
    pub max_fanout: usize,
    /// Subscriber buffer of a state service: how many exchanges a sender may
    /// be ahead of a receiver before it is held back.
    pub state_buffer: usize,
    /// Subscriber buffer of a telemetry service.
    pub telemetry_buffer: usize,
}

impl Limits {
    /// The limits of `net`'s run.
    #[must_use]
    pub fn of(net: &Network) -> Self {
        let leader_links = net
            .agents
            .iter()
            .filter(|a| a.model.leader_gain.is_some())
            .count();
        let max_degree = net
            .agents
            .iter()
            .map(|a| a.model.neighbours.len())
            .max()
            .unwrap_or(0);
        Self {
            nodes: net.agents.len() + 1,
            max_fanout: leader_links.max(max_degree).max(1),
            state_buffer: 64,
            telemetry_buffer: 256,
        }
    }
}

/// A service could not be opened.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OpenError {
    /// The service name.
    pub service: String,
    /// iceoryx2's reason.
    pub reason: String,
}

impl fmt::Display for OpenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "cannot open service {}: {}", self.service, self.reason)
    }
}

impl std::error::Error for OpenError {}

/// Retries `f` for up to 2 s: two processes creating the same service at
/// once make one of them fail transiently.
fn retry<T, E: fmt::Debug>(
    name: &ServiceName,
    mut f: impl FnMut() -> Result<T, E>,
) -> Result<T, OpenError> {
    let start = Instant::now();
    loop {
        match f() {
            Ok(x) => return Ok(x),
            Err(e) if start.elapsed() > Duration::from_secs(2) => {
                return Err(OpenError {
                    service: name.to_string(),
                    reason: format!("{e:?}"),
                });
            }
            Err(_) => std::thread::sleep(Duration::from_millis(5)),
        }
    }
}

/// Node `id`'s state service (one publisher: the node; subscribers: its receivers).
pub fn state<S: Service>(
    node: &Node<S>,
    run: &str,
    id: u32,
    l: &Limits,
) -> Result<publish_subscribe::PortFactory<S, StateMsg, ()>, OpenError> {
    let name = names::state(run, id);
    retry(&name, || {
        node.service_builder(&name)
            .publish_subscribe::<StateMsg>()
            .max_publishers(1)
            .max_subscribers(l.max_fanout)
            .max_nodes(l.max_fanout + 2)
            .history_size(0)
            .subscriber_max_buffer_size(l.state_buffer)
            .subscriber_max_borrowed_samples(2)
            .enable_safe_overflow(false)
            .open_or_create()
    })
}

/// Node `id`'s wake event (one listener: the node; notifiers: its senders).
pub fn wake<S: Service>(
    node: &Node<S>,
    run: &str,
    id: u32,
    l: &Limits,
) -> Result<event::PortFactory<S>, OpenError> {
    let name = names::wake(run, id);
    retry(&name, || {
        node.service_builder(&name)
            .event()
            .max_listeners(1)
            .max_notifiers(l.max_fanout + 1)
            .max_nodes(l.max_fanout + 3)
            .open_or_create()
    })
}

/// Node `id`'s telemetry (one publisher: the node; subscribers: the orchestrator and one tool).
pub fn telemetry<S: Service>(
    node: &Node<S>,
    run: &str,
    id: u32,
    l: &Limits,
) -> Result<publish_subscribe::PortFactory<S, TelemetryMsg, ()>, OpenError> {
    let name = names::telemetry(run, id);
    retry(&name, || {
        node.service_builder(&name)
            .publish_subscribe::<TelemetryMsg>()
            .max_publishers(1)
            .max_subscribers(2)
            .max_nodes(4)
            .history_size(0)
            .subscriber_max_buffer_size(l.telemetry_buffer)
            .subscriber_max_borrowed_samples(2)
            .enable_safe_overflow(false)
            .open_or_create()
    })
}

/// The orchestrator's wake event (one listener: the orchestrator; notifiers: every node).
pub fn orchestrator_wake<S: Service>(
    node: &Node<S>,
    run: &str,
    l: &Limits,
) -> Result<event::PortFactory<S>, OpenError> {
    let name = names::orchestrator_wake(run);
    retry(&name, || {
        node.service_builder(&name)
            .event()
            .max_listeners(1)
            .max_notifiers(l.nodes + 1)
            .max_nodes(l.nodes + 2)
            .open_or_create()
    })
}

/// The control service (one publisher: the orchestrator; subscribers: every node).
pub fn control<S: Service>(
    node: &Node<S>,
    run: &str,
    l: &Limits,
) -> Result<publish_subscribe::PortFactory<S, ControlMsg, ()>, OpenError> {
    let name = names::control(run);
    retry(&name, || {
        node.service_builder(&name)
            .publish_subscribe::<ControlMsg>()
            .max_publishers(1)
            .max_subscribers(l.nodes + 1)
            .max_nodes(l.nodes + 2)
            .history_size(2)
            .subscriber_max_buffer_size(4)
            .open_or_create()
    })
}
