//! The node loop shared by the agent and the leader processes.
//!
//! Protocol (ARCHITECTURE.md § step protocol, PROTOCOL.md):
//! 1. open every port; wait (bounded) until every receiver of our state, the
//!    orchestrator's telemetry subscriber and the sender of every input are
//!    connected; report `Ready`; wait (bounded) for `Start`;
//! 2. step, walking the run's [`Schedule`] (stages, exchanges, stage
//!    times), either in deterministic lockstep (`lockstep.rs`, the default)
//!    or free against the wall clock (`realtime.rs`);
//! 3. report the counters of the incoming links, then `Done`, and wait
//!    (bounded) for `Stop`.
//!
//! Every received state is checked ([`StateMsg::validated`]); an invalid
//! one is refused, counted and reported, and the node keeps the value it had.
//! In every phase the node checks its parent at least every 100 ms and
//! exits ([`NodeError::Orphaned`]) once the orchestrator is gone; the
//! parent it expects comes from [`msgs::parent::PARENT_PID_VAR`], so a node
//! orphaned before its first look notices too.
//!
//! # Layout
//! - `ports.rs`: every iceoryx2 port and the readiness barrier.
//! - `hooks.rs`: [`Hooks`], asked at every publish, receive, report and
//!   command ([`run_with`]; [`run`] uses [`NoHooks`]).
//! - `lockstep.rs`, `realtime.rs`: the two stepping loops.
//! - here: [`Stepper`], [`NodeError`], the phases around the loops.

mod ages;
mod hooks;
mod lockstep;
mod lookahead;
mod ports;
mod realtime;

pub use attitude::schedule::{Schedule, Slot};
pub use hooks::{Hooks, NoHooks, Override};

use attitude::guard::{self, Envelope, Violation};
use attitude::link::LinkStats;
use attitude::network::Exchanged;
use hooks::Hooked;
use iceoryx2::node::Node;
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::open::OpenError;
use msgs::telemetry::peak_rss_kb;
use msgs::{ControlCommand, Done, FailReason, PROTOCOL_VERSION, StateMsg, Telemetry, unix_ns_now};
use ports::Ports;
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use thiserror::Error;
use tracing::{debug, info, warn};

/// A node's model, seen by the loop: the leader, an agent, or a plug-in's
/// own model. The loop calls, for every step n and stage s = 0..3: at an
/// exchange, [`Stepper::stage_exchange`] (published stamped (n, s)) and
/// [`Stepper::receive`] once per input; then [`Stepper::advance`]. The
/// stepper keeps track of its own stage (four `advance` calls make a step).
pub trait Stepper {
    /// State published at the current stage.
    fn stage_exchange(&self) -> Exchanged;
    /// Stores the value received from input `k`: the order of
    /// `NodeConfig::inputs`, i.e. neighbours by ascending id, then the leader
    /// (0) if linked. Values arrive already validated (finite, a rotation).
    fn receive(&mut self, k: usize, x: Exchanged);
    /// Evaluates the current stage and moves on.
    fn advance(&mut self);
    /// Telemetry sample of the state at the start of the current step, which
    /// is step `step` ([`Telemetry::Sample`] for an agent,
    /// [`Telemetry::LeaderSample`] for the leader).
    fn sample(&self, step: u64) -> Telemetry;
    /// Largest torque norm applied so far, taken at stage 0 of each step
    /// (as the built-in agent does), N·m.
    fn peak_torque(&self) -> f64;
    /// Telemetry of the torque applied at stage 0 of the current step,
    /// which is step `step`, just after that stage was evaluated
    /// ([`Telemetry::Torque`]); the loop reports it at every sampled step
    /// but the last. `None` (the default: the leader, or a plug-in that
    /// does not say) reports nothing, and the run records NaN.
    fn torque(&self, step: u64) -> Option<Telemetry> {
        let _ = step;
        None
    }
    /// Counters of the impaired incoming links: (sender id, stats).
    fn link_stats(&self) -> Vec<(u32, LinkStats)> {
        Vec::new()
    }
    /// At the start of step `step`: [`Telemetry::Crashed`] if the node's
    /// timeline crashes it now (PROTOCOL.md § 10.10; the default: never).
    fn crash(&self, step: u64) -> Option<Telemetry> {
        let _ = step;
        None
    }
    /// Whether the node is down (crashed): it publishes a stand-in that
    /// nobody uses and takes nothing from its inputs.
    fn is_down(&self) -> bool {
        false
    }
    /// How many steps ahead of the node input `k` may be taken (its link's
    /// delay: PROTOCOL.md § 10.9): at exchange (n, s) the loop waits only
    /// for that input's messages up to (n − d, s), and hands every message
    /// up to (n, s) to [`Stepper::receive_stamped`]. 0 (the default): the
    /// input is taken in lockstep, through [`Stepper::receive`].
    fn lookahead(&self, k: usize) -> u64 {
        let _ = k;
        0
    }
    /// [`Stepper::receive`] of a message stamped `stamp` (step, stage),
    /// taken at or before the node's own slot (an input with a
    /// [`Stepper::lookahead`]).
    fn receive_stamped(&mut self, k: usize, x: Exchanged, stamp: (u64, u32)) {
        let _ = stamp;
        self.receive(k, x);
    }
}

/// Why a node stopped before completing the protocol.
#[derive(Debug, Error)]
pub enum NodeError {
    /// A service could not be opened.
    #[error(transparent)]
    Open(#[from] OpenError),
    /// A port could not be created or used.
    #[error(transparent)]
    Port(#[from] msgs::iox::IoxError),
    /// A bounded wait ran out.
    #[error("timed out after {waited:.1} s waiting for {what}")]
    Timeout {
        /// What was awaited.
        what: String,
        /// How long, s.
        waited: f64,
    },
    /// An input's state did not arrive in time.
    #[error(
        "timed out after {waited:.1} s waiting for node {from}'s state of step {step} stage {stage}"
    )]
    InputTimeout {
        /// The silent node.
        from: u32,
        /// Step awaited.
        step: u64,
        /// Stage awaited.
        stage: u32,
        /// How long, s.
        waited: f64,
    },
    /// An input broke the protocol.
    #[error("protocol violation by node {from}: {why}")]
    BadInput {
        /// The offending node.
        from: u32,
        /// What it did.
        why: String,
    },
    /// A peer broke the protocol.
    #[error("protocol violation: {0}")]
    Protocol(String),
    /// A hook failed the node ([`Override::Fail`]).
    #[error("failed by a hook: {0}")]
    Injected(String),
    /// The process that started this node has exited.
    #[error("the orchestrator (pid {0}) has exited")]
    Orphaned(u32),
    /// The orchestrator said stop, or the shutdown signal was raised, before the end.
    #[error("stopped before the end (at step {0})")]
    Stopped(u64),
    /// The node's own state left the envelope (`cfg.guard`) after a step.
    #[error("diverged at step {step}: {what}")]
    Diverged {
        /// The step whose state is out (t = step · dt).
        step: u64,
        /// What left the envelope.
        violation: Violation,
        /// The violation, described.
        what: String,
    },
}

pub(crate) fn port<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> NodeError {
    move |e| NodeError::Port(msgs::iox::iox(what)(e))
}

/// Runs node `cfg.id` to the end of the protocol.
pub fn run<S: Service, N: Stepper>(
    node: &Node<S>,
    cfg: &NodeConfig,
    stepper: &mut N,
    shutdown: &AtomicBool,
) -> Result<(), NodeError> {
    run_with(node, cfg, stepper, &mut NoHooks, shutdown)
}

/// As [`run`], asking `hooks` at every publish, receive, report and command.
pub fn run_with<S: Service, N: Stepper, H: Hooks>(
    node: &Node<S>,
    cfg: &NodeConfig,
    stepper: &mut N,
    hooks: &mut H,
    shutdown: &AtomicBool,
) -> Result<(), NodeError> {
    let orphan = Orphan::new()?;
    let ports = Ports::open(node, cfg)?;
    ports.await_connections(cfg, &orphan)?;
    let mut io = Hooked::new(&ports, hooks, cfg.id);
    io.report(Telemetry::Ready)?;
    info!(id = cfg.id, inputs = ?cfg.inputs, outputs = ?cfg.outputs, "ready");
    let start = await_start(&mut io, cfg, shutdown, &orphan)?;
    info!(realtime = ?cfg.realtime, "started");
    let started_unix_ns = unix_ns_now();

    let mut inputs = Inputs::new(cfg);
    let stepped = match cfg.realtime {
        None => lockstep::run(&mut io, cfg, stepper, &mut inputs, shutdown, &orphan),
        Some(factor) => realtime::run(
            &mut io,
            cfg,
            stepper,
            &mut inputs,
            realtime::Clock::new(start, factor, cfg.dt),
            shutdown,
            &orphan,
        ),
    };
    let pacing = match stepped {
        Ok(pacing) => pacing,
        Err(e) => {
            // Tell the orchestrator whom we waited for (or that it was
            // something else), so that it can name the node that hangs
            // (best effort: we are failing anyway).
            let _ = io.report(Telemetry::Failed(failure(&e)));
            if matches!(e, NodeError::Diverged { .. }) {
                // Keep our ports until Stop: the others finish the step
                // with what we published, and report their own divergence.
                tracing::error!("{e}");
                let _ = wait_command(&mut io, STOP_TIMEOUT, shutdown, &orphan);
            }
            return Err(e);
        }
    };
    let done_unix_ns = unix_ns_now();
    for (from, stats) in inputs.stats(cfg, stepper.link_stats()) {
        io.report(Telemetry::LinkStats { from, stats })?;
    }
    let done = Done {
        steps: cfg.steps,
        peak_torque: stepper.peak_torque(),
        peak_rss_kb: peak_rss_kb(),
        started_unix_ns,
        done_unix_ns,
        pacing,
    };
    io.report(Telemetry::Done(done))?;
    info!(steps = cfg.steps, peak_rss_kb = done.peak_rss_kb, "done");
    await_stop(&mut io, cfg, shutdown, &orphan)
}

/// Waits (bounded by the start timeout) for `Start`: its `start_unix_ns`.
/// A new process of a crashed agent joins a run under way: it starts at once.
fn await_start<S: Service, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<u64, NodeError> {
    if cfg.resume.is_some() {
        return Ok(unix_ns_now());
    }
    let start_timeout = Duration::from_secs_f64(cfg.start_timeout);
    match wait_command(io, start_timeout, shutdown, orphan)? {
        Some((ControlCommand::Start, start)) => Ok(start),
        _ => Err(NodeError::Stopped(0)),
    }
}

/// After `Done`: other nodes may still be stepping, so waits for `Stop` as
/// long as the orchestrator lives (bounded by [`STOP_TIMEOUT`] all the same).
fn await_stop<S: Service, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<(), NodeError> {
    loop {
        match wait_command(io, STOP_TIMEOUT, shutdown, orphan)? {
            Some((ControlCommand::Stop, _)) | None => return Ok(()),
            // A process that joined the run late reads the run's Start now.
            Some((ControlCommand::Start, _)) if cfg.resume.is_some() => {}
            Some((ControlCommand::Start, _)) => {
                return Err(NodeError::Protocol("second Start".into()));
            }
        }
    }
}

/// What the node knows of its incoming links beyond the model: messages
/// refused as invalid and, in real-time mode, the measured counters.
#[derive(Debug)]
pub(crate) struct Inputs {
    /// Per input: messages refused.
    rejected: Vec<u64>,
    /// Per input: counters measured by the runtime (real-time mode).
    measured: Vec<LinkStats>,
    /// Per input: the ages of information measured (real-time mode).
    ages: Vec<ages::Ages>,
    /// Whether `measured` is reported.
    report_measured: bool,
}

impl Inputs {
    fn new(cfg: &NodeConfig) -> Self {
        Self {
            rejected: vec![0; cfg.inputs.len()],
            measured: vec![LinkStats::default(); cfg.inputs.len()],
            ages: vec![ages::Ages::default(); cfg.inputs.len()],
            report_measured: cfg.realtime.is_some(),
        }
    }

    /// Checks message `msg` of input `k`: `Some(value)` if it can be used.
    pub(crate) fn accept(
        &mut self,
        cfg: &NodeConfig,
        k: usize,
        msg: &StateMsg,
    ) -> Option<Exchanged> {
        match msg.validated() {
            Ok(x) => Some(x),
            Err(why) => {
                if self.rejected[k] == 0 {
                    warn!(
                        from = cfg.inputs[k],
                        step = msg.step,
                        stage = msg.stage,
                        "refused a state: {why} (further refusals are only counted)"
                    );
                }
                self.rejected[k] += 1;
                None
            }
        }
    }

    /// The counters to report: (sender id, stats) for every input that is
    /// impaired, measured or has refused messages.
    fn stats(&self, cfg: &NodeConfig, model: Vec<(u32, LinkStats)>) -> Vec<(u32, LinkStats)> {
        cfg.inputs
            .iter()
            .enumerate()
            .filter_map(|(k, &from)| {
                let modelled = model.iter().find(|(id, _)| *id == from).map(|(_, s)| *s);
                let base = match (modelled, self.report_measured) {
                    (Some(s), _) => Some(s),
                    (None, true) => Some(self.measured[k]),
                    (None, false) if self.rejected[k] > 0 => Some(LinkStats::default()),
                    (None, false) => None,
                };
                base.map(|s| {
                    (
                        from,
                        LinkStats {
                            rejected: s.rejected + self.rejected[k],
                            ..s
                        },
                    )
                })
            })
            .collect()
    }
}

/// The `Failed` report of a node that gives up with `e` while stepping.
fn failure(e: &NodeError) -> FailReason {
    match *e {
        NodeError::InputTimeout { from, .. } => FailReason::InputTimeout { from },
        NodeError::BadInput { from, .. } => FailReason::BadInput { from },
        NodeError::Diverged {
            step, violation, ..
        } => FailReason::Diverged {
            step,
            quantity: violation.quantity,
            value: violation.value,
        },
        _ => FailReason::Other,
    }
}

/// Longest wait for `Stop` after the last step.
const STOP_TIMEOUT: Duration = Duration::from_secs(600);

/// Longest time between two checks of the parent while a node runs, so
/// that it exits well within a second of the orchestrator's death.
const ORPHAN_CHECK: Duration = Duration::from_millis(100);

/// Detects that the process that started us (the orchestrator) is gone, so
/// that a node never outlives its run.
#[derive(Debug)]
pub(crate) struct Orphan {
    parent: u32,
    last_check: Cell<Instant>,
}

impl Orphan {
    /// Watches the parent [`msgs::parent::watched`] names; fails at once if
    /// the expected parent is already gone (died before we could look).
    fn new() -> Result<Self, NodeError> {
        let parent = msgs::parent::watched().map_err(|o| NodeError::Orphaned(o.parent))?;
        Ok(Self {
            parent,
            last_check: Cell::new(Instant::now()),
        })
    }

    /// Fails if the parent is gone (checks now).
    pub(crate) fn check(&self) -> Result<(), NodeError> {
        self.last_check.set(Instant::now());
        if std::os::unix::process::parent_id() != self.parent {
            return Err(NodeError::Orphaned(self.parent));
        }
        Ok(())
    }

    /// As [`Orphan::check`], if the last check is [`ORPHAN_CHECK`] old
    /// (cheap enough for every step or poll).
    pub(crate) fn poll(&self) -> Result<(), NodeError> {
        if self.last_check.get().elapsed() >= ORPHAN_CHECK {
            self.check()?;
        }
        Ok(())
    }
}

/// At the start of step `n`: if the node's timeline crashes it now, reports
/// its links' counters and [`Telemetry::Crashed`], then waits to be killed
/// (it never returns `Ok(true)`: it ends when the orchestrator kills it,
/// or with an error when told to stop or orphaned). `Ok(false)`: no crash.
pub(crate) fn crash_point<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    (cfg, inputs): (&NodeConfig, &Inputs),
    stepper: &N,
    n: u64,
    (shutdown, orphan): (&AtomicBool, &Orphan),
) -> Result<bool, NodeError> {
    let Some(crashed) = stepper.crash(n) else {
        return Ok(false);
    };
    for (from, stats) in inputs.stats(cfg, stepper.link_stats()) {
        io.report(Telemetry::LinkStats { from, stats })?;
    }
    io.report(crashed)?;
    info!(step = n, "crash point: waiting to be killed");
    loop {
        std::thread::sleep(ORPHAN_CHECK);
        before_step(n, shutdown, orphan)?;
    }
}

/// Before step `n`: stop if told to, or if orphaned.
pub(crate) fn before_step(n: u64, shutdown: &AtomicBool, orphan: &Orphan) -> Result<(), NodeError> {
    if shutdown.load(Ordering::Relaxed) {
        return Err(NodeError::Stopped(n));
    }
    orphan.poll()
}

/// After stage 0 of step `n`: report the torque it applied if the step is
/// sampled (PROTOCOL.md § 6; never at the last step: none follows it).
pub(crate) fn after_stage_0<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &N,
    n: u64,
) -> Result<(), NodeError> {
    if n % cfg.sample_every == 0
        && let Some(torque) = stepper.torque(n)
    {
        io.report(torque)?;
    }
    Ok(())
}

/// After a step: check the state against the envelope (PROTOCOL.md § 9),
/// then report a sample if `done` steps make one due.
pub(crate) fn after_step<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &N,
    done: u64,
) -> Result<(), NodeError> {
    let sample = stepper.sample(done);
    if let Some(violation) = out_of_envelope(&sample, &cfg.guard) {
        return Err(NodeError::Diverged {
            step: done,
            violation,
            what: violation.describe(&cfg.guard),
        });
    }
    if done % cfg.sample_every == 0 || done == cfg.steps {
        io.report(sample)?;
    }
    Ok(())
}

/// The first violation of the envelope in a sample of the node's state.
fn out_of_envelope(sample: &Telemetry, env: &Envelope) -> Option<Violation> {
    match sample {
        Telemetry::Sample { state, .. } => guard::check_agent(state, env),
        Telemetry::LeaderSample { state, .. } => guard::check_leader(state, env),
        _ => None,
    }
}

/// The message must be from `sender` and speak our version.
pub(crate) fn check_origin(m: &StateMsg, sender: u32) -> Result<(), NodeError> {
    if m.version != PROTOCOL_VERSION {
        return Err(NodeError::BadInput {
            from: sender,
            why: format!(
                "it speaks protocol version {}, this node {PROTOCOL_VERSION}",
                m.version
            ),
        });
    }
    if m.sender != sender {
        return Err(NodeError::BadInput {
            from: sender,
            why: format!("a message on its state service claims sender {}", m.sender),
        });
    }
    Ok(())
}

/// Waits (polling with a [`ports::Backoff`], bounded) for a control command the
/// hooks let through; returns it with its `start_unix_ns`.
fn wait_command<S: Service, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    timeout: Duration,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<Option<(ControlCommand, u64)>, NodeError> {
    let deadline = Instant::now() + timeout;
    let mut backoff = ports::Backoff::new();
    loop {
        if let Some(sample) = io
            .ports
            .control
            .receive()
            .map_err(port("control receive"))?
        {
            if sample.version != PROTOCOL_VERSION {
                return Err(NodeError::Protocol(format!(
                    "orchestrator speaks protocol version {}, this node {PROTOCOL_VERSION}",
                    sample.version
                )));
            }
            debug!(command = sample.command, "control");
            match sample.command() {
                Some(c) if !io.obey(c)? => warn!(?c, "a hook ignores the command"),
                c => return Ok(c.map(|c| (c, sample.start_unix_ns))),
            }
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
        backoff.sleep();
    }
}
