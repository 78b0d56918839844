//! The lockstep node loop shared by the agent and the leader processes.
//!
//! Protocol (ARCHITECTURE.md § step protocol, PROTOCOL.md):
//! 1. open every port; wait (bounded) until every receiver of our state, the
//!    orchestrator's telemetry subscriber and the sender of every input are
//!    connected; report `Ready`; wait (bounded) for `Start`;
//! 2. report the sample at step 0; then for every step n and stage s:
//!    if the coupling exchanges at (n, s), publish our stage state stamped
//!    (n, s), wake our receivers, and wait until every input's message
//!    stamped (n, s) has arrived; then advance one stage;
//! 3. report a sample every `sample_every` steps and at the last step, then
//!    `Done`, and wait (bounded) for `Stop`.
//!
//! Every wait has a deadline; after every wake-up (or timeout) the
//! subscribers are polled again, because an iceoryx2 0.10 event can be lost.

use crate::wait::Waiter;
use attitude::network::Exchanged;
use iceoryx2::node::Node;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::open::{self, OpenError};
use msgs::{ControlCommand, ControlMsg, PROTOCOL_VERSION, StateMsg, TelemetryKind, TelemetryMsg};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use thiserror::Error;
use tracing::{debug, info};

/// A node's model, seen by the loop: the leader or an agent.
pub trait Stepper {
    /// State published at the current stage.
    fn stage_exchange(&self) -> Exchanged;
    /// Stores the value received from input `k` (order of `NodeConfig::inputs`).
    fn receive(&mut self, k: usize, x: Exchanged);
    /// Evaluates the current stage and moves on.
    fn advance(&mut self);
    /// Telemetry sample of the state at the start of the current step.
    fn sample(&self, step: u64) -> TelemetryMsg;
    /// Largest torque norm so far.
    fn peak_torque(&self) -> f64;
    /// Counters of the impaired incoming links: (sender id, stats).
    fn link_stats(&self) -> Vec<(u32, attitude::link::LinkStats)> {
        Vec::new()
    }
}

/// Why a node stopped before completing the protocol.
#[derive(Debug, Error)]
pub enum NodeError {
    /// A service could not be opened.
    #[error(transparent)]
    Open(#[from] OpenError),
    /// A port could not be created or used.
    #[error("iceoryx2 port: {0}")]
    Port(String),
    /// A bounded wait ran out.
    #[error("timed out after {waited:.1} s waiting for {what}")]
    Timeout {
        /// What was awaited.
        what: String,
        /// How long, s.
        waited: f64,
    },
    /// A peer broke the protocol.
    #[error("protocol violation: {0}")]
    Protocol(String),
    /// The process that started this node has exited.
    #[error("the orchestrator (pid {0}) has exited")]
    Orphaned(u32),
    /// The orchestrator said stop, or the shutdown signal was raised, before the end.
    #[error("stopped before the end (at step {0})")]
    Stopped(u64),
}

fn port<E: std::fmt::Debug>(what: &str) -> impl FnOnce(E) -> NodeError + '_ {
    move |e| NodeError::Port(format!("{what}: {e:?}"))
}

/// Runs node `cfg.id` to the end of the protocol.
pub fn run<S: Service, N: Stepper>(
    node: &Node<S>,
    cfg: &NodeConfig,
    stepper: &mut N,
    shutdown: &AtomicBool,
) -> Result<(), NodeError> {
    let (run, l, id) = (cfg.run.as_str(), &cfg.limits, cfg.id);
    let orphan = Orphan::new();
    let stage_timeout = Duration::from_secs_f64(cfg.stage_timeout);
    let start_timeout = Duration::from_secs_f64(cfg.start_timeout);

    // Ports.
    let own = open::state(node, run, id, l)?;
    let publisher = own
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
        .set_backpressure_handler(retry_until(stage_timeout))
        .create()
        .map_err(port("state publisher"))?;
    let wake = open::wake(node, run, id, l)?;
    let listener = wake
        .listener_builder()
        .create()
        .map_err(port("wake listener"))?;
    let tele = open::telemetry(node, run, id, l)?;
    let tele_pub = tele
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
        .set_backpressure_handler(retry_until(stage_timeout))
        .create()
        .map_err(port("telemetry publisher"))?;
    let orch_notifier = open::orchestrator_wake(node, run, l)?
        .notifier_builder()
        .create()
        .map_err(port("orchestrator notifier"))?;
    let control = open::control(node, run, l)?
        .subscriber_builder()
        .create()
        .map_err(port("control subscriber"))?;
    let mut inputs = Vec::new();
    let mut input_services = Vec::new();
    for &j in &cfg.inputs {
        let svc = open::state(node, run, j, l)?;
        inputs.push(
            svc.subscriber_builder()
                .buffer_size(l.state_buffer)
                .create()
                .map_err(port("state subscriber"))?,
        );
        input_services.push(svc);
    }
    let notifiers = cfg
        .outputs
        .iter()
        .map(|&j| {
            open::wake(node, run, j, l)?
                .notifier_builder()
                .create()
                .map_err(port("wake notifier"))
        })
        .collect::<Result<Vec<_>, _>>()?;

    // Readiness barrier: every edge connected in both directions.
    let ready_by = Instant::now() + start_timeout;
    loop {
        let subs_ok = own.dynamic_config().number_of_subscribers() >= cfg.outputs.len()
            && tele.dynamic_config().number_of_subscribers() >= 1;
        let missing: Vec<u32> = cfg
            .inputs
            .iter()
            .zip(&input_services)
            .filter(|(_, s)| s.dynamic_config().number_of_publishers() < 1)
            .map(|(&j, _)| j)
            .collect();
        if missing.is_empty() {
            // iceoryx2 attaches a subscriber to a publisher lazily; attach
            // now, so that nothing a sender publishes before our first
            // receive() can be dropped.
            for sub in &inputs {
                sub.update_connections().map_err(port("connect input"))?;
            }
        }
        if subs_ok && missing.is_empty() {
            break;
        }
        if Instant::now() > ready_by {
            return Err(NodeError::Timeout {
                what: format!(
                    "connections (receivers {}/{}, orchestrator {}, inputs without a publisher {:?})",
                    own.dynamic_config().number_of_subscribers(),
                    cfg.outputs.len(),
                    tele.dynamic_config().number_of_subscribers(),
                    missing
                ),
                waited: cfg.start_timeout,
            });
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    let report = |m: TelemetryMsg| -> Result<(), NodeError> {
        tele_pub.send_copy(m).map_err(port("telemetry send"))?;
        let _ = orch_notifier.notify();
        Ok(())
    };
    report(TelemetryMsg::bare(id, 0, TelemetryKind::Ready, 0.0))?;
    info!(id, inputs = ?cfg.inputs, outputs = ?cfg.outputs, "ready");
    match wait_command(&control, start_timeout, shutdown, &orphan)? {
        Some(ControlCommand::Start) => {}
        _ => return Err(NodeError::Stopped(0)),
    }
    info!("started");

    // Lockstep.
    let mut waiter = Waiter::new(cfg.wait);
    let notify = waiter.receivers_may_block();
    report(stepper.sample(0))?;
    for n in 0..cfg.steps {
        if shutdown.load(Ordering::Relaxed) {
            return Err(NodeError::Stopped(n));
        }
        if n % 256 == 0 {
            orphan.check()?;
        }
        for s in 0..4u32 {
            if cfg.coupling.exchanges_at(n, s as usize) {
                publisher
                    .send_copy(StateMsg::new(id, n, s, &stepper.stage_exchange()))
                    .map_err(port("state send"))?;
                if notify {
                    for nt in &notifiers {
                        let _ = nt.notify();
                    }
                }
                let deadline = Instant::now() + stage_timeout;
                waiter.begin();
                for k in 0..inputs.len() {
                    let msg = loop {
                        // Take one message at a time: what stays in iceoryx2's
                        // buffer holds a fast sender back (flow control).
                        if let Some(sample) = inputs[k].receive().map_err(port("state receive"))? {
                            break *sample;
                        }
                        if waiter.polls() % 1024 == 1023 {
                            orphan.check()?;
                        }
                        if waiter.wait(&listener, deadline) {
                            return Err(NodeError::Timeout {
                                what: format!(
                                    "node {}'s state of step {n} stage {s}",
                                    cfg.inputs[k]
                                ),
                                waited: cfg.stage_timeout,
                            });
                        }
                    };
                    check(&msg, cfg.inputs[k], n, s)?;
                    stepper.receive(k, msg.exchanged());
                }
            }
            stepper.advance();
        }
        let done = n + 1;
        if done % cfg.sample_every == 0 || done == cfg.steps {
            report(stepper.sample(done))?;
        }
    }
    for (from, st) in stepper.link_stats() {
        report(TelemetryMsg::link_stats(id, from, &st))?;
    }
    report(TelemetryMsg::bare(
        id,
        cfg.steps,
        TelemetryKind::Done,
        stepper.peak_torque(),
    ))?;
    info!(steps = cfg.steps, peak_rss_kb = peak_rss_kb(), "done");
    // Other nodes may still be stepping: wait for Stop as long as the
    // orchestrator lives (bounded by STOP_TIMEOUT all the same).
    match wait_command(&control, STOP_TIMEOUT, shutdown, &orphan)? {
        Some(ControlCommand::Stop) | None => Ok(()),
        Some(ControlCommand::Start) => Err(NodeError::Protocol("second Start".into())),
    }
}

/// Longest wait for `Stop` after the last step.
const STOP_TIMEOUT: Duration = Duration::from_secs(600);

/// Peak resident set size of this process (VmHWM), kB; 0 if unknown.
#[must_use]
pub fn peak_rss_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse().ok())
        })
        .unwrap_or(0)
}

/// Detects that the process that started us (the orchestrator) is gone, so
/// that a node never outlives its run.
#[derive(Debug)]
struct Orphan {
    parent: u32,
}

impl Orphan {
    fn new() -> Self {
        Self {
            parent: std::os::unix::process::parent_id(),
        }
    }

    fn check(&self) -> Result<(), NodeError> {
        if std::os::unix::process::parent_id() != self.parent {
            return Err(NodeError::Orphaned(self.parent));
        }
        Ok(())
    }
}

/// A backpressure handler: yield and retry until `timeout`, then give up on
/// that receiver and fail the send (so nothing hangs).
fn retry_until(
    timeout: Duration,
) -> impl Fn(&iceoryx2::port::BackpressureInfo) -> iceoryx2::port::BackpressureAction + Send + 'static
{
    move |info| {
        if info.elapsed_time > timeout {
            iceoryx2::port::BackpressureAction::DiscardDataAndFail
        } else {
            std::thread::yield_now();
            iceoryx2::port::BackpressureAction::Retry
        }
    }
}

/// The message must be from `sender`, speak our version, and carry exactly the stamp (n, s).
fn check(m: &StateMsg, sender: u32, n: u64, s: u32) -> Result<(), NodeError> {
    if m.version != PROTOCOL_VERSION {
        return Err(NodeError::Protocol(format!(
            "node {sender} speaks protocol version {}, this node {PROTOCOL_VERSION}",
            m.version
        )));
    }
    if m.sender != sender {
        return Err(NodeError::Protocol(format!(
            "message on node {sender}'s state service claims sender {}",
            m.sender
        )));
    }
    if (m.step, m.stage) != (n, s) {
        return Err(NodeError::Protocol(format!(
            "node {sender} sent step {} stage {} where step {n} stage {s} was due",
            m.step, m.stage
        )));
    }
    Ok(())
}

/// Waits (polling every millisecond, bounded) for a control command.
fn wait_command<S: Service>(
    control: &Subscriber<S, ControlMsg, ()>,
    timeout: Duration,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<Option<ControlCommand>, NodeError> {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(sample) = control.receive().map_err(port("control receive"))? {
            if sample.version != PROTOCOL_VERSION {
                return Err(NodeError::Protocol(format!(
                    "orchestrator speaks protocol version {}, this node {PROTOCOL_VERSION}",
                    sample.version
                )));
            }
            debug!(command = sample.command, "control");
            return Ok(sample.command());
        }
        if shutdown.load(Ordering::Relaxed) {
            return Ok(None);
        }
        orphan.check()?;
        if Instant::now() > deadline {
            return Err(NodeError::Timeout {
                what: "a command from the orchestrator".into(),
                waited: timeout.as_secs_f64(),
            });
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}
