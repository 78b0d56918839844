//! One opener per service. iceoryx2 fixes a service's limits when it is
//! created and refuses an opener that asks for more, so every process, the
//! orchestrator included, opens every service through these functions
//! ([`Opener`], or the free functions with its default patience) with the
//! same [`Limits`]. A service another process is still creating is waited
//! for, within the start timeout ([`retry`]).

pub mod retry;

use crate::names;
use crate::payload::{ControlMsg, StateMsg};
use crate::telemetry::TelemetryMsg;
use attitude::network::Network;
use iceoryx2::node::Node;
use iceoryx2::prelude::ServiceName;
use iceoryx2::service::Service;
use iceoryx2::service::port_factory::{event, publish_subscribe};
use retry::{Failed, Transient};
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
        // A node's state has as many readers as agents hear it: its
        // neighbours on an undirected graph, more with one-way edges.
        let mut readers: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
        for n in net.agents.iter().flat_map(|a| &a.model.neighbours) {
            *readers.entry(n.id).or_default() += 1;
        }
        let max_degree = (net.agents.iter())
            .map(|a| a.model.neighbours.len())
            .chain(readers.into_values())
            .max()
            .unwrap_or(0);
        // A crashed agent's ports stay until its new process has opened
        // its own (PROTOCOL.md § 10.10): one more of each, then.
        let restarts = net
            .agents
            .iter()
            .any(|a| (a.model.timeline.as_deref()).is_some_and(|t| !t.crashes.is_empty()));
        Self {
            nodes: net.agents.len() + 1,
            max_fanout: leader_links.max(max_degree).max(1) + usize::from(restarts),
            state_buffer: 64,
            telemetry_buffer: 256,
        }
    }
}

/// A service could not be opened.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot open service {service}: {reason}")]
pub struct OpenError {
    /// The service name.
    pub service: String,
    /// Why: iceoryx2's error, and what was tried for how long.
    pub reason: String,
}

impl OpenError {
    /// The error of service `name` whose tries ended as `failed`, with
    /// `patience` to spend.
    fn of<E: Transient>(name: &ServiceName, failed: Failed<E>, patience: Duration) -> Self {
        let reason = match failed {
            Failed::Refused { error, tries } => format!(
                "{error:?} at try {tries} (not retried: the service exists with other \
                 settings, or cannot be used by this process)"
            ),
            Failed::NotReady {
                last,
                tries,
                waited,
            } => format!(
                "not ready after {:.1} s ({tries} tries of open-or-create, retried within \
                 the start timeout of {:.1} s); last error: {last:?}",
                waited.as_secs_f64(),
                patience.as_secs_f64()
            ),
        };
        Self {
            service: name.to_string(),
            reason,
        }
    }
}

/// How long the free functions below retry a service that another process
/// is still creating: the orchestrator's default start timeout (30 s), the
/// bound of every start-up wait. [`Opener::patience`] sets another.
pub const DEFAULT_PATIENCE: Duration = Duration::from_secs(30);

/// Opens (or creates) the services of run `run` for one iceoryx2 node,
/// retrying while another process is still creating one (iceoryx2's
/// transient failures, [`Transient`]) until its patience (a node's start
/// timeout), counted from its creation, runs out: every service it opens
/// shares that one bound. Tries back off ([`retry::FIRST_PAUSE`] doubling to
/// [`retry::MAX_PAUSE`]); any other failure is returned at once.
#[derive(Debug)]
pub struct Opener<'a, S: Service> {
    node: &'a Node<S>,
    run: &'a str,
    limits: &'a Limits,
    patience: Duration,
    until: Instant,
}

impl<'a, S: Service> Opener<'a, S> {
    /// An opener of run `run`'s services with `limits`, patient for
    /// [`DEFAULT_PATIENCE`].
    #[must_use]
    pub fn new(node: &'a Node<S>, run: &'a str, limits: &'a Limits) -> Self {
        Self {
            node,
            run,
            limits,
            patience: DEFAULT_PATIENCE,
            until: Instant::now() + DEFAULT_PATIENCE,
        }
    }

    /// Retries transient failures until `patience` (the start timeout) from
    /// now, for all the services it opens together.
    #[must_use]
    pub fn patience(mut self, patience: Duration) -> Self {
        self.patience = patience;
        self.until = Instant::now() + patience;
        self
    }

    /// Calls `f` until it succeeds, fails for good, or the patience runs out.
    fn retry<T, E: Transient>(
        &self,
        name: &ServiceName,
        f: impl FnMut() -> Result<T, E>,
    ) -> Result<T, OpenError> {
        let left = self.until.saturating_duration_since(Instant::now());
        retry::retry(left, f).map_err(|e| OpenError::of(name, e, self.patience))
    }

    /// Node `id`'s state service (one publisher: the node; subscribers: its receivers).
    pub fn state(
        &self,
        id: u32,
    ) -> Result<publish_subscribe::PortFactory<S, StateMsg, ()>, OpenError> {
        let (l, name) = (self.limits, names::state(self.run, id));
        self.retry(&name, || {
            self.node
                .service_builder(&name)
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
    pub fn wake(&self, id: u32) -> Result<event::PortFactory<S>, OpenError> {
        let (l, name) = (self.limits, names::wake(self.run, id));
        self.retry(&name, || {
            self.node
                .service_builder(&name)
                .event()
                .max_listeners(1)
                .max_notifiers(l.max_fanout + 1)
                .max_nodes(l.max_fanout + 3)
                .open_or_create()
        })
    }

    /// Node `id`'s telemetry (one publisher: the node; subscribers: the
    /// orchestrator and one tool).
    pub fn telemetry(
        &self,
        id: u32,
    ) -> Result<publish_subscribe::PortFactory<S, TelemetryMsg, ()>, OpenError> {
        let (l, name) = (self.limits, names::telemetry(self.run, id));
        self.retry(&name, || {
            self.node
                .service_builder(&name)
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

    /// The orchestrator's wake event (one listener: the orchestrator;
    /// notifiers: every node).
    pub fn orchestrator_wake(&self) -> Result<event::PortFactory<S>, OpenError> {
        let (l, name) = (self.limits, names::orchestrator_wake(self.run));
        self.retry(&name, || {
            self.node
                .service_builder(&name)
                .event()
                .max_listeners(1)
                .max_notifiers(l.nodes + 1)
                .max_nodes(l.nodes + 2)
                .open_or_create()
        })
    }

    /// The control service (one publisher: the orchestrator; subscribers: every node).
    pub fn control(&self) -> Result<publish_subscribe::PortFactory<S, ControlMsg, ()>, OpenError> {
        let (l, name) = (self.limits, names::control(self.run));
        self.retry(&name, || {
            self.node
                .service_builder(&name)
                .publish_subscribe::<ControlMsg>()
                .max_publishers(1)
                .max_subscribers(l.nodes + 1)
                .max_nodes(l.nodes + 2)
                .history_size(2)
                .subscriber_max_buffer_size(4)
                .open_or_create()
        })
    }
}

/// Node `id`'s state service ([`Opener::state`], [`DEFAULT_PATIENCE`]).
pub fn state<S: Service>(
    node: &Node<S>,
    run: &str,
    id: u32,
    l: &Limits,
) -> Result<publish_subscribe::PortFactory<S, StateMsg, ()>, OpenError> {
    Opener::new(node, run, l).state(id)
}

/// Node `id`'s wake event ([`Opener::wake`], [`DEFAULT_PATIENCE`]).
pub fn wake<S: Service>(
    node: &Node<S>,
    run: &str,
    id: u32,
    l: &Limits,
) -> Result<event::PortFactory<S>, OpenError> {
    Opener::new(node, run, l).wake(id)
}

/// Node `id`'s telemetry ([`Opener::telemetry`], [`DEFAULT_PATIENCE`]).
pub fn telemetry<S: Service>(
    node: &Node<S>,
    run: &str,
    id: u32,
    l: &Limits,
) -> Result<publish_subscribe::PortFactory<S, TelemetryMsg, ()>, OpenError> {
    Opener::new(node, run, l).telemetry(id)
}

/// The orchestrator's wake event ([`Opener::orchestrator_wake`], [`DEFAULT_PATIENCE`]).
pub fn orchestrator_wake<S: Service>(
    node: &Node<S>,
    run: &str,
    l: &Limits,
) -> Result<event::PortFactory<S>, OpenError> {
    Opener::new(node, run, l).orchestrator_wake()
}

/// The control service ([`Opener::control`], [`DEFAULT_PATIENCE`]).
pub fn control<S: Service>(
    node: &Node<S>,
    run: &str,
    l: &Limits,
) -> Result<publish_subscribe::PortFactory<S, ControlMsg, ()>, OpenError> {
    Opener::new(node, run, l).control()
}
