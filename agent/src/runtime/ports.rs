//! Every iceoryx2 port a node uses, and the readiness barrier.

use super::{NodeError, Orphan, port};
use crate::backpressure::{Pacer, retry_until};
use iceoryx2::node::Node;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PubSub;
use msgs::config::NodeConfig;
use msgs::open::Opener;
use msgs::{ControlMsg, StateMsg, Telemetry, TelemetryMsg};
use std::time::{Duration, Instant};

/// A node's ports.
pub(crate) struct Ports<S: Service> {
    own: PubSub<S, StateMsg, ()>,
    /// Publishes our state.
    pub publisher: Publisher<S, StateMsg, ()>,
    /// Paces `publisher` while a receiver's buffer is full (lockstep).
    pacer: Pacer,
    /// Our wake event (inputs have news).
    pub listener: Listener<S>,
    tele: PubSub<S, TelemetryMsg, ()>,
    tele_pub: Publisher<S, TelemetryMsg, ()>,
    tele_pacer: Pacer,
    orch_notifier: Notifier<S>,
    /// Orchestrator commands.
    pub control: Subscriber<S, ControlMsg, ()>,
    /// One subscriber per input, in `NodeConfig::inputs` order.
    pub inputs: Vec<Subscriber<S, StateMsg, ()>>,
    input_services: Vec<PubSub<S, StateMsg, ()>>,
    /// The wake events of our receivers.
    pub notifiers: Vec<Notifier<S>>,
}

impl<S: Service> Ports<S> {
    /// Opens every port of node `cfg.id`. In lockstep a full receiver holds
    /// our state back (flow control, bounded by the stage timeout); in
    /// real-time mode nothing waits, so a full receiver misses the message.
    pub fn open(node: &Node<S>, cfg: &NodeConfig) -> Result<Self, NodeError> {
        let (run, l, id) = (cfg.run.as_str(), &cfg.limits, cfg.id);
        let stage_timeout = Duration::from_secs_f64(cfg.stage_timeout);
        let start_timeout = Duration::from_secs_f64(cfg.start_timeout);
        // Services other nodes are still creating are waited for, within
        // the start timeout (PROTOCOL.md § 6.2).
        let open = Opener::new(node, run, l).patience(start_timeout);
        let (inputs, input_services) = Self::subscribe(&open, cfg)?;
        if cfg.resume.is_some() {
            // The process this one replaces is dead, its ports not yet
            // removed: ours were opened first, so that no message sent
            // meanwhile is lost (PROTOCOL.md § 10.10); now free its place.
            let cleaned = node.try_cleanup_dead_nodes();
            tracing::info!(?cleaned, "took over from a crashed process");
        }
        let own = open.state(id)?;
        let pacer = Pacer::new(l.state_buffer);
        let publisher = match cfg.realtime {
            None => own
                .publisher_builder()
                .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
                .set_backpressure_handler(retry_until(stage_timeout, pacer.clone())),
            Some(_) => own
                .publisher_builder()
                .backpressure_strategy(BackpressureStrategy::DiscardData),
        }
        .create()
        .map_err(port("state publisher"))?;
        let listener = open
            .wake(id)?
            .listener_builder()
            .create()
            .map_err(port("wake listener"))?;
        let tele = open.telemetry(id)?;
        let tele_pacer = Pacer::new(l.telemetry_buffer);
        let tele_pub = tele
            .publisher_builder()
            .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
            .set_backpressure_handler(retry_until(stage_timeout, tele_pacer.clone()))
            .create()
            .map_err(port("telemetry publisher"))?;
        let orch_notifier = open
            .orchestrator_wake()?
            .notifier_builder()
            .create()
            .map_err(port("orchestrator notifier"))?;
        let control = open
            .control()?
            .subscriber_builder()
            .create()
            .map_err(port("control subscriber"))?;
        let notifiers = cfg
            .outputs
            .iter()
            .map(|&j| {
                open.wake(j)?
                    .notifier_builder()
                    .create()
                    .map_err(port("wake notifier"))
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            own,
            publisher,
            pacer,
            listener,
            tele,
            tele_pub,
            tele_pacer,
            orch_notifier,
            control,
            inputs,
            input_services,
            notifiers,
        })
    }

    /// A subscriber to every input, attached at once.
    #[allow(clippy::type_complexity)]
    fn subscribe(
        open: &Opener<'_, S>,
        cfg: &NodeConfig,
    ) -> Result<
        (
            Vec<Subscriber<S, StateMsg, ()>>,
            Vec<PubSub<S, StateMsg, ()>>,
        ),
        NodeError,
    > {
        let mut inputs = Vec::new();
        let mut input_services = Vec::new();
        for &j in &cfg.inputs {
            let svc = open.state(j)?;
            let sub = (svc.subscriber_builder())
                .buffer_size(cfg.limits.state_buffer)
                .create()
                .map_err(port("state subscriber"))?;
            if cfg.resume.is_some() {
                sub.update_connections().map_err(port("connect input"))?;
            }
            inputs.push(sub);
            input_services.push(svc);
        }
        Ok((inputs, input_services))
    }

    /// Readiness barrier: waits (bounded by the start timeout, and by the
    /// orchestrator's life) until every edge is connected in both directions,
    /// polling with a [`Backoff`].
    pub fn await_connections(&self, cfg: &NodeConfig, orphan: &Orphan) -> Result<(), NodeError> {
        let ready_by = Instant::now() + Duration::from_secs_f64(cfg.start_timeout);
        let mut backoff = Backoff::new();
        loop {
            let subs_ok = self.own.dynamic_config().number_of_subscribers() >= cfg.outputs.len()
                && self.tele.dynamic_config().number_of_subscribers() >= 1;
            let missing: Vec<u32> = cfg
                .inputs
                .iter()
                .zip(&self.input_services)
                .filter(|(_, s)| s.dynamic_config().number_of_publishers() < 1)
                .map(|(&j, _)| j)
                .collect();
            if missing.is_empty() {
                // iceoryx2 attaches a subscriber to a publisher lazily; attach
                // now, so that nothing a sender publishes before our first
                // receive() can be dropped.
                for sub in &self.inputs {
                    sub.update_connections().map_err(port("connect input"))?;
                }
            }
            if subs_ok && missing.is_empty() {
                return Ok(());
            }
            orphan.poll()?;
            if Instant::now() > ready_by {
                return Err(NodeError::Timeout {
                    what: format!(
                        "connections (receivers {}/{}, orchestrator {}, inputs without a publisher {:?})",
                        self.own.dynamic_config().number_of_subscribers(),
                        cfg.outputs.len(),
                        self.tele.dynamic_config().number_of_subscribers(),
                        missing
                    ),
                    waited: cfg.start_timeout,
                });
            }
            backoff.sleep();
        }
    }

    /// Sends a telemetry report of node `id`; an event (anything but a
    /// sample or a torque: [`Telemetry::is_sample`]) also wakes the
    /// orchestrator.
    ///
    /// NOTE: samples are not notified. The orchestrator drains its telemetry
    /// at least every 10 ms anyway (its wait's timeout) and its buffer holds
    /// 256 reports per node; a wake-up per sample and node (32 000 in the
    /// paper run) put the orchestrator on a core the nodes needed — the
    /// benchmark measured 20.1 µs per exchange with samples against 14.5 µs
    /// without.
    pub fn report(&self, id: u32, t: &Telemetry) -> Result<(), NodeError> {
        self.tele_pub
            .send_copy(TelemetryMsg::encode(id, t))
            .map_err(port("telemetry send"))?;
        self.tele_pacer.sent();
        if !t.is_sample() {
            let _ = self.orch_notifier.notify();
        }
        Ok(())
    }

    /// Publishes our state and, if `notify`, wakes every receiver.
    pub fn publish(&self, m: StateMsg, notify: bool) -> Result<(), NodeError> {
        self.publisher.send_copy(m).map_err(port("state send"))?;
        self.pacer.sent();
        if notify {
            for nt in &self.notifiers {
                let _ = nt.notify();
            }
        }
        Ok(())
    }
}

/// The pause between two polls of a start-up or shutdown wait (the
/// readiness barrier, `Start`, `Stop`): 1 ms at first, doubling up to
/// [`Backoff::MAX`].
///
/// NOTE: a fixed 1 ms poll made every waiting node wake 1 000 times a
/// second; with many nodes on few cores those wake-ups took the CPU from
/// the nodes still starting (start-up grew as n²). A node that waits long
/// polls 8 ms apart; one that waits briefly still sees its event within ~1 ms.
#[derive(Debug)]
pub(crate) struct Backoff(Duration);

impl Backoff {
    /// Longest pause.
    pub(crate) const MAX: Duration = Duration::from_millis(8);

    pub(crate) fn new() -> Self {
        Self(Duration::from_millis(1))
    }

    /// Sleeps for the current pause, then doubles it (up to [`Self::MAX`]).
    pub(crate) fn sleep(&mut self) {
        std::thread::sleep(self.0);
        self.0 = (self.0 * 2).min(Self::MAX);
    }
}
