//! `broken_agent --config FILE`: a deliberately faulty attsync agent, a
//! fixture for the conformance tests (`attsync conform -- broken_agent`) and
//! for runs with a misbehaving plug-in. Without `ATTSYNC_FAULT` (or with it
//! empty) it is a correct agent: it calls `attsync_agent::run`. Otherwise it
//! runs the built-in model ([`AgentNode`]) in its own lockstep loop and
//! injects one fault:
//!
//! | `ATTSYNC_FAULT` | what it does | what should catch it |
//! |---|---|---|
//! | `wrong-type` | opens its own state service `attsync/<run>/node/<id>/state` with payload type `attsync::StateMsgV1` (another type name and size), so iceoryx2 refuses with `IncompatibleTypes`; it exits 1 naming the type (or, if it created the service first, its peers are refused) | rule `connects` |
//! | `skip-step` | at the first exchange from step 3 on, stamps its state (n + 1, s) where (n, s) was due (once) | rule `in-order`; in a run, its receivers' protocol check |
//! | `never-stops` | does everything right, then ignores `Stop` and sleeps until killed (or until its parent is gone) | rule `stops` |
//! | `nan` | at the first exchange from step 5 on, publishes ω with a NaN | rule `valid-states`; in a run, its receivers refuse it and count it |
//!
//! Any other value exits 2. Faults need lockstep (`realtime` = null).
//!
//! NOTE: the loop below duplicates, in small, `agent/src/runtime/{mod,
//! ports,lockstep}.rs` (ports, readiness barrier, `Ready`/`Start`, lockstep
//! exchange, telemetry, `Done`/`Stop`): the runtime has no hooks to
//! misbehave, and its ports are private. The duplication is acceptable for
//! a test fixture; it omits what no fault needs (wait strategies other than
//! yield-then-block, link counters, real-time mode).

use attsync_agent::args::{create_node, init_tracing};
use attsync_agent::{AgentNode, Stepper};
use iceoryx2::node::Node;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::port::{BackpressureAction, BackpressureInfo};
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError, PublishSubscribeOpenOrCreateError,
};
use msgs::config::NodeConfig;
use msgs::{
    ControlCommand, Done, PROTOCOL_VERSION, StateMsg, Telemetry, TelemetryMsg, names, open,
};
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};
use tracing::{info, warn};

/// The fault to inject.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fault {
    WrongType,
    SkipStep,
    NeverStops,
    Nan,
}

impl Fault {
    fn from_env() -> Result<Option<Self>, String> {
        let v = std::env::var("ATTSYNC_FAULT").unwrap_or_default();
        match v.as_str() {
            "" => Ok(None),
            "wrong-type" => Ok(Some(Self::WrongType)),
            "skip-step" => Ok(Some(Self::SkipStep)),
            "never-stops" => Ok(Some(Self::NeverStops)),
            "nan" => Ok(Some(Self::Nan)),
            _ => Err(format!(
                "ATTSYNC_FAULT={v:?}: expected wrong-type, skip-step, never-stops or nan"
            )),
        }
    }
}

/// Step from which `skip-step` strikes (at the first exchange).
const SKIP_FROM: u64 = 3;
/// Step from which `nan` strikes (at the first exchange).
const NAN_FROM: u64 = 5;

/// The state payload of a pretend protocol version 1: another type name and
/// layout than [`StateMsg`] (no wall-clock stamp, no σ; 120 B, not 152 B).
#[derive(Debug, Clone, Copy, ZeroCopySend)]
#[repr(C)]
#[type_name("attsync::StateMsgV1")]
struct StateMsgV1 {
    version: u32,
    sender: u32,
    step: u64,
    stage: u32,
    reserved: u32,
    r: [f64; 9],
    w: [f64; 3],
}

fn main() -> ExitCode {
    init_tracing();
    let fault = match Fault::from_env() {
        Ok(f) => f,
        Err(e) => {
            eprintln!("broken_agent: {e}");
            return ExitCode::from(2);
        }
    };
    let result = config_path().and_then(|path| {
        let cfg = NodeConfig::read(&path).map_err(|e| e.to_string())?;
        let node = create_node(&cfg, &format!("agent_{}", cfg.id)).map_err(|e| e.to_string())?;
        info!(id = cfg.id, ?fault, "broken agent");
        match fault {
            None => {
                attsync_agent::run(&node, &cfg, &AtomicBool::new(false)).map_err(|e| e.to_string())
            }
            Some(Fault::WrongType) => wrong_type(&node, &cfg),
            Some(f) => lockstep(&node, &cfg, f),
        }
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("broken_agent: {e}");
            ExitCode::FAILURE
        }
    }
}

/// `--config FILE` (or `--config=FILE`), else `ATTSYNC_CONFIG`.
fn config_path() -> Result<PathBuf, String> {
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        if a == "--config" {
            return args
                .next()
                .map(PathBuf::from)
                .ok_or("--config needs a file".into());
        }
        if let Some(p) = a.strip_prefix("--config=") {
            return Ok(p.into());
        }
    }
    std::env::var_os("ATTSYNC_CONFIG")
        .map(PathBuf::from)
        .ok_or_else(|| "usage: broken_agent --config FILE (or env ATTSYNC_CONFIG)".into())
}

fn iox<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> String {
    move |e| format!("iceoryx2: {what}: {e:?}")
}

/// `wrong-type`: open our state service with [`StateMsgV1`] and the
/// settings of `msgs::open::state`.
fn wrong_type<S: Service>(node: &Node<S>, cfg: &NodeConfig) -> Result<(), String> {
    let (name, l) = (names::state(&cfg.run, cfg.id), &cfg.limits);
    let size = std::mem::size_of::<StateMsgV1>();
    let give_up = Instant::now() + Duration::from_secs(2);
    let _service = loop {
        let r = node
            .service_builder(&name)
            .publish_subscribe::<StateMsgV1>()
            .max_publishers(1)
            .max_subscribers(l.max_fanout)
            .max_nodes(l.max_fanout + 2)
            .history_size(0)
            .subscriber_max_buffer_size(l.state_buffer)
            .subscriber_max_borrowed_samples(2)
            .enable_safe_overflow(false)
            .open_or_create();
        match r {
            Ok(s) => break s,
            Err(
                e @ PublishSubscribeOpenOrCreateError::PublishSubscribeOpenError(
                    PublishSubscribeOpenError::IncompatibleTypes,
                ),
            ) => {
                return Err(format!(
                    "cannot open service {name} with payload type attsync::StateMsgV1 ({size} B): {e:?}"
                ));
            }
            Err(e) if Instant::now() > give_up => {
                return Err(format!("cannot open service {name}: {e:?}"));
            }
            Err(_) => std::thread::sleep(Duration::from_millis(5)),
        }
    };
    // We created it: every peer that opens it with attsync's type is refused.
    warn!(%name, size, "created the state service with payload type attsync::StateMsgV1");
    std::thread::sleep(Duration::from_secs_f64(cfg.start_timeout));
    Err(format!(
        "created {name} with the wrong payload type; nobody could connect"
    ))
}

/// Backpressure: retry until `timeout`, then fail the send (as the runtime does).
fn retry_until(
    timeout: Duration,
) -> impl Fn(&BackpressureInfo) -> BackpressureAction + Send + 'static {
    move |info| {
        if info.elapsed_time > timeout {
            BackpressureAction::DiscardDataAndFail
        } else {
            std::thread::yield_now();
            BackpressureAction::Retry
        }
    }
}

/// The first exchange (n, s) with n ≥ `from`.
fn exchange_from(cfg: &NodeConfig, from: u64) -> Option<(u64, u32)> {
    (from..cfg.steps)
        .flat_map(|n| (0..4u32).map(move |s| (n, s)))
        .find(|&(n, s)| cfg.coupling.exchanges_at(n, s as usize))
}

/// The lockstep protocol with fault `fault` (not `wrong-type`).
fn lockstep<S: Service>(node: &Node<S>, cfg: &NodeConfig, fault: Fault) -> Result<(), String> {
    if cfg.realtime.is_some() {
        return Err("faults are injected in lockstep only (realtime is set)".into());
    }
    let mut model = AgentNode::from_config(cfg)?;
    let (run, l, id) = (cfg.run.as_str(), &cfg.limits, cfg.id);
    let stage_timeout = Duration::from_secs_f64(cfg.stage_timeout);
    let start_timeout = Duration::from_secs_f64(cfg.start_timeout);
    let parent = std::os::unix::process::parent_id();
    let orphaned = || std::os::unix::process::parent_id() != parent;
    let open_err = |e: open::OpenError| e.to_string();

    // Ports (runtime/ports.rs).
    let own = open::state(node, run, id, l).map_err(open_err)?;
    let publisher = own
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
        .set_backpressure_handler(retry_until(stage_timeout))
        .create()
        .map_err(iox("state publisher"))?;
    let listener = open::wake(node, run, id, l)
        .map_err(open_err)?
        .listener_builder()
        .create()
        .map_err(iox("wake listener"))?;
    let tele = open::telemetry(node, run, id, l).map_err(open_err)?;
    let tele_pub = tele
        .publisher_builder()
        .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
        .set_backpressure_handler(retry_until(stage_timeout))
        .create()
        .map_err(iox("telemetry publisher"))?;
    let orch = open::orchestrator_wake(node, run, l)
        .map_err(open_err)?
        .notifier_builder()
        .create()
        .map_err(iox("orchestrator notifier"))?;
    let control = open::control(node, run, l)
        .map_err(open_err)?
        .subscriber_builder()
        .create()
        .map_err(iox("control subscriber"))?;
    let mut input_services = Vec::new();
    let mut inputs = Vec::new();
    for &j in &cfg.inputs {
        let svc = open::state(node, run, j, l).map_err(open_err)?;
        inputs.push(
            svc.subscriber_builder()
                .buffer_size(l.state_buffer)
                .create()
                .map_err(iox("state subscriber"))?,
        );
        input_services.push(svc);
    }
    let notifiers = cfg
        .outputs
        .iter()
        .map(|&j| {
            open::wake(node, run, j, l)
                .map_err(open_err)?
                .notifier_builder()
                .create()
                .map_err(iox("wake notifier"))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let report = |t: Telemetry| -> Result<(), String> {
        tele_pub
            .send_copy(TelemetryMsg::encode(id, &t))
            .map_err(iox("telemetry send"))?;
        let _ = orch.notify();
        Ok(())
    };

    // Readiness barrier, Ready, Start (runtime/mod.rs).
    let deadline = Instant::now() + start_timeout;
    loop {
        let connected = own.dynamic_config().number_of_subscribers() >= cfg.outputs.len()
            && tele.dynamic_config().number_of_subscribers() >= 1
            && input_services
                .iter()
                .all(|s| s.dynamic_config().number_of_publishers() >= 1);
        if connected {
            for sub in &inputs {
                sub.update_connections().map_err(iox("connect input"))?;
            }
            break;
        }
        if Instant::now() > deadline {
            return Err("timed out waiting for connections".into());
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    report(Telemetry::Ready)?;
    let command = |timeout: Duration| -> Result<Option<ControlCommand>, String> {
        let deadline = Instant::now() + timeout;
        loop {
            if let Some(m) = control.receive().map_err(iox("control receive"))? {
                if m.version != PROTOCOL_VERSION {
                    return Err(format!("control message of version {}", m.version));
                }
                return Ok(m.command());
            }
            if orphaned() || Instant::now() > deadline {
                return Err("no command from the orchestrator".into());
            }
            std::thread::sleep(Duration::from_millis(1));
        }
    };
    if command(start_timeout)? != Some(ControlCommand::Start) {
        return Err("expected Start".into());
    }

    // Lockstep (runtime/lockstep.rs), with the fault.
    let skip_at = (fault == Fault::SkipStep)
        .then(|| exchange_from(cfg, SKIP_FROM))
        .flatten();
    let nan_at = (fault == Fault::Nan)
        .then(|| exchange_from(cfg, NAN_FROM))
        .flatten();
    report(model.sample(0))?;
    for n in 0..cfg.steps {
        for s in 0..4u32 {
            if cfg.coupling.exchanges_at(n, s as usize) {
                let mut m = StateMsg::new(id, n, s, &model.stage_exchange());
                if Some((n, s)) == skip_at {
                    warn!(n, s, "fault: stamping step {} instead", n + 1);
                    m.step = n + 1;
                }
                if Some((n, s)) == nan_at {
                    warn!(n, s, "fault: publishing a NaN in ω");
                    m.w[0] = f64::NAN;
                }
                publisher.send_copy(m).map_err(iox("state send"))?;
                for nt in &notifiers {
                    let _ = nt.notify();
                }
                let deadline = Instant::now() + stage_timeout;
                for (k, sub) in inputs.iter().enumerate() {
                    let mut polls = 0u32;
                    let msg = loop {
                        if let Some(sample) = sub.receive().map_err(iox("state receive"))? {
                            break *sample;
                        }
                        polls += 1;
                        if polls < 200 {
                            std::thread::yield_now();
                        } else {
                            let _ = listener.timed_wait(|_| {}, Duration::from_millis(1));
                        }
                        if Instant::now() > deadline || orphaned() {
                            return Err(format!(
                                "no state of node {} for step {n} stage {s}",
                                cfg.inputs[k]
                            ));
                        }
                    };
                    if (msg.version, msg.sender, msg.step, msg.stage)
                        != (PROTOCOL_VERSION, cfg.inputs[k], n, s)
                    {
                        return Err(format!(
                            "node {} sent version {} sender {} step {} stage {} where step {n} stage {s} was due",
                            cfg.inputs[k], msg.version, msg.sender, msg.step, msg.stage
                        ));
                    }
                    // A refused value is like a lost message: keep what we had.
                    if let Ok(x) = msg.validated() {
                        model.receive(k, x);
                    }
                }
            }
            model.advance();
        }
        let done = n + 1;
        if done % cfg.sample_every == 0 || done == cfg.steps {
            report(model.sample(done))?;
        }
    }
    report(Telemetry::Done(Done {
        steps: cfg.steps,
        peak_torque: model.peak_torque(),
        ..Done::default()
    }))?;
    if fault == Fault::NeverStops {
        warn!("fault: ignoring Stop; sleeping until killed");
        // Bounded only by the parent's life, so that a test that forgets
        // this process does not leak it forever.
        while !orphaned() {
            std::thread::sleep(Duration::from_millis(100));
        }
        return Err("the parent has exited".into());
    }
    match command(Duration::from_secs(600))? {
        Some(ControlCommand::Stop) => Ok(()),
        other => Err(format!("expected Stop, got {other:?}")),
    }
}
