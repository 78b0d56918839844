//! `broken_agent --config FILE`: a deliberately faulty attsync agent, a
//! fixture for the conformance tests (`attsync conform -- broken_agent`) and
//! for runs with a misbehaving plug-in. Without `ATTSYNC_FAULT` (or with it
//! empty) it is a correct agent. Otherwise it runs the built-in model
//! ([`AgentNode`]) through the real node runtime and injects one fault with
//! its hooks ([`attsync_agent::Hooks`]):
//!
//! | `ATTSYNC_FAULT` | what it does | what should catch it |
//! |---|---|---|
//! | `wrong-type` | opens its own state service `attsync/<run>/node/<id>/state` with payload type `attsync::StateMsgV1` (another type name and size), so iceoryx2 refuses with `IncompatibleTypes`; it exits 1 naming the type (or, if it created the service first, its peers are refused) | rule `connects` |
//! | `skip-step` | at the first exchange from step 3 on, stamps its state (n + 1, s) where (n, s) was due (once) | rule `in-order`; in a run, its receivers' protocol check |
//! | `never-stops` | does everything right, then ignores `Stop` and waits until killed (or until its parent is gone) | rule `stops` |
//! | `nan` | at the first exchange from step 5 on, publishes ω with a NaN | rule `valid-states`; in a run, its receivers refuse it and count it |
//! | `nan-telemetry` | from step 10 on, reports samples whose ω is NaN (its state, what it publishes, stays correct) | rule `telemetry`; in a run, the orchestrator: the node diverged (exit 3) |
//! | `bad-telemetry` | from step 10 on, reports samples whose attitude is 2·R (not a rotation) | rule `telemetry`; in a run, the orchestrator: the node broke the protocol |
//!
//! Any other value exits 2. Faults need lockstep (`realtime` = null).

use attsync_agent::args::{MainError, node_main};
use attsync_agent::runtime::{Schedule, Slot};
use attsync_agent::{AgentNode, Hooks, NodeError, Override};
use iceoryx2::prelude::*;
use iceoryx2::service::builder::publish_subscribe::{
    PublishSubscribeOpenError as Open, PublishSubscribeOpenOrCreateError as OpenOrCreate,
};
use msgs::{ControlCommand, StateMsg, Telemetry, config::NodeConfig, names};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};
use tracing::warn;

/// The fault as hooks on the runtime: alter the state of exchange `at`, or
/// ignore `Stop`. With `kind` empty they do nothing: a correct agent.
struct Fault {
    kind: String,
    at: Option<Slot>,
}

/// Samples from this step on are garbled (`nan-telemetry`, `bad-telemetry`).
const GARBLED_FROM: u64 = 10;

impl Hooks for Fault {
    fn before_publish(&mut self, slot: Slot, msg: &mut StateMsg) -> Override {
        if self.at == Some(slot) {
            warn!(slot.step, slot.stage, fault = self.kind, "fault strikes");
            match self.kind.as_str() {
                "skip-step" => msg.step += 1,
                _ => msg.w[0] = f64::NAN,
            }
        }
        Override::Run
    }

    fn before_report(&mut self, t: &mut Telemetry) -> Override {
        if let Telemetry::Sample { step, state, .. } = t {
            match self.kind.as_str() {
                "nan-telemetry" if *step >= GARBLED_FROM => state.w[1] = f64::NAN,
                "bad-telemetry" if *step >= GARBLED_FROM => state.r *= 2.0,
                _ => {}
            }
        }
        Override::Run
    }

    fn on_command(&mut self, command: ControlCommand) -> Override {
        match (self.kind.as_str(), command) {
            ("never-stops", ControlCommand::Stop) => Override::Skip,
            _ => Override::Run,
        }
    }
}

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
    r_w: [f64; 12],
}

/// `wrong-type`: open our state service with [`StateMsgV1`] (the settings
/// of `msgs::open::state`); if we created it, hold it until start-up times out.
fn wrong_type<S: Service>(node: &Node<S>, cfg: &NodeConfig) -> Result<(), MainError> {
    let (name, l) = (names::state(&cfg.run, cfg.id), &cfg.limits);
    let (t, size) = ("attsync::StateMsgV1", std::mem::size_of::<StateMsgV1>());
    // Retry (as msgs::open does): two creators at once make one fail transiently.
    let give_up = Instant::now() + Duration::from_secs(2);
    let incompatible = OpenOrCreate::PublishSubscribeOpenError(Open::IncompatibleTypes);
    while let Err(e) = node
        .service_builder(&name)
        .publish_subscribe::<StateMsgV1>()
        .max_publishers(1)
        .max_subscribers(l.max_fanout)
        .max_nodes(l.max_fanout + 2)
        .history_size(0)
        .subscriber_max_buffer_size(l.state_buffer)
        .subscriber_max_borrowed_samples(2)
        .enable_safe_overflow(false)
        .open_or_create()
    {
        if e == incompatible || Instant::now() > give_up {
            return Err(MainError::Setup(format!(
                "cannot open service {name} with payload type {t} ({size} B): {e:?}"
            )));
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    // We created it: every peer that opens it with attsync's type is refused.
    warn!(%name, size, "created the state service with payload type {t}");
    std::thread::sleep(Duration::from_secs_f64(cfg.start_timeout));
    Err(MainError::Setup(format!(
        "created {name} with the wrong payload type; nobody could connect"
    )))
}

fn main() -> ExitCode {
    let kind = std::env::var("ATTSYNC_FAULT").unwrap_or_default();
    let kinds = ["", "wrong-type", "skip-step", "never-stops", "nan"];
    let telemetry = ["nan-telemetry", "bad-telemetry"];
    if !kinds.iter().chain(&telemetry).any(|k| *k == kind) {
        let expected =
            "expected wrong-type, skip-step, never-stops, nan, nan-telemetry or bad-telemetry";
        eprintln!("broken_agent: ATTSYNC_FAULT={kind:?}: {expected}");
        return ExitCode::from(2);
    }
    node_main(
        "broken_agent",
        |c| format!("agent_{}", c.id),
        |node, cfg| {
            if !kind.is_empty() && cfg.realtime.is_some() {
                return Err(MainError::Setup("faults need lockstep".into()));
            }
            // The first exchange from step 3 (skip-step) or 5 (nan) on.
            let from = match kind.as_str() {
                "wrong-type" => return wrong_type(node, cfg),
                "skip-step" => 3,
                "nan" => 5,
                _ => u64::MAX,
            };
            let at = Schedule::new(cfg.coupling, cfg.steps).first_exchange_from(from);
            let mut agent =
                AgentNode::from_config(cfg).map_err(|e| NodeError::Protocol(e.to_string()))?;
            let (mut fault, shutdown) = (Fault { kind, at }, AtomicBool::new(false));
            Ok(attsync_agent::run_with(
                node, cfg, &mut agent, &mut fault, &shutdown,
            )?)
        },
    )
}
