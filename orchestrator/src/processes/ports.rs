//! The orchestrator's side of a run's iceoryx2 services, in one place: the
//! run's [`Namespace`], an iceoryx2 node in it, the control publisher
//! (`Start`, `Stop`), the wake listener every node notifies, and one
//! telemetry subscriber per watched node. Both the process engine and
//! `conform` open theirs with [`Ports::open`].

use super::ProcessError;
use crate::launch::namespace::Namespace;
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use msgs::iox::{IoxError, create_node, iox};
use msgs::open::Opener;
use msgs::{ControlCommand, ControlMsg, Limits, TelemetryMsg};
use std::path::Path;
use std::time::Duration;

/// A telemetry subscriber of the orchestrator.
pub type TelemetrySub = Subscriber<ipc::Service, TelemetryMsg, ()>;

/// The orchestrator's ports of one run. Dropping it closes the ports, then
/// the node, then removes the namespace (fields drop in this order).
#[derive(Debug)]
pub struct Ports {
    telemetry: Vec<TelemetrySub>,
    control: Publisher<ipc::Service, ControlMsg, ()>,
    wake: Listener<ipc::Service>,
    node: Node<ipc::Service>,
    ns: Namespace,
}

impl Ports {
    /// Opens, in namespace `ns`, an iceoryx2 node `name`, the control
    /// publisher, the wake listener and a telemetry subscriber for each node
    /// id of `telemetry_of` (in that order), with `limits`; a service another
    /// process is still creating is waited for, within `start_timeout`.
    pub fn open(
        ns: Namespace,
        name: &str,
        limits: &Limits,
        telemetry_of: &[u32],
        start_timeout: Duration,
    ) -> Result<Self, ProcessError> {
        let run = ns.run().to_string();
        let node = create_node::<ipc::Service>(&run, ns.dir(), name)?;
        let open = Opener::new(&node, &run, limits).patience(start_timeout);
        let control = open
            .control()?
            .publisher_builder()
            .create()
            .map_err(iox("control publisher"))?;
        let wake = open
            .orchestrator_wake()?
            .listener_builder()
            .create()
            .map_err(iox("wake listener"))?;
        let telemetry = telemetry_of
            .iter()
            .map(|&id| {
                open.telemetry(id)?
                    .subscriber_builder()
                    .buffer_size(limits.telemetry_buffer)
                    .create()
                    .map_err(|e| iox("telemetry subscriber")(e).into())
            })
            .collect::<Result<_, ProcessError>>()?;
        Ok(Self {
            telemetry,
            control,
            wake,
            node,
            ns,
        })
    }

    /// The run id.
    #[must_use]
    pub fn run(&self) -> &str {
        self.ns.run()
    }

    /// The namespace's directory (iceoryx2 root; node configs go there).
    #[must_use]
    pub fn dir(&self) -> &Path {
        self.ns.dir()
    }

    /// The iceoryx2 node, to open more ports with.
    #[must_use]
    pub fn node(&self) -> &Node<ipc::Service> {
        &self.node
    }

    /// The telemetry subscribers, in the order of `telemetry_of`.
    #[must_use]
    pub fn telemetry(&self) -> &[TelemetrySub] {
        &self.telemetry
    }

    /// The next telemetry message of the `k`th watched node, if one is there.
    pub fn receive(&self, k: usize) -> Result<Option<TelemetryMsg>, IoxError> {
        let sample = self.telemetry[k]
            .receive()
            .map_err(iox("telemetry receive"))?;
        Ok(sample.map(|s| *s))
    }

    /// Publishes control message `msg`.
    pub fn send(&self, msg: ControlMsg) -> Result<(), IoxError> {
        self.control
            .send_copy(msg)
            .map(|_| ())
            .map_err(iox("control send"))
    }

    /// Publishes `Start` now (or at `at_unix_ns` in real-time mode).
    pub fn start(&self, at_unix_ns: Option<u64>) -> Result<(), IoxError> {
        self.send(match at_unix_ns {
            Some(t) => ControlMsg::start_at(t),
            None => ControlMsg::new(ControlCommand::Start),
        })
    }

    /// Publishes `Stop`.
    pub fn stop(&self) -> Result<(), IoxError> {
        self.send(ControlMsg::new(ControlCommand::Stop))
    }

    /// Waits up to `timeout` for a node to notify the wake event.
    pub fn wait(&self, timeout: Duration) {
        let _ = self.wake.timed_wait(|_| {}, timeout);
    }
}
