//! `saturated-agent`: an attsync agent written outside attsync, as a plug-in
//! (`[[agent]] command = ["…/saturated-agent"]` in a scenario). It runs the
//! paper's observerless law `districontrol` (scheme 3) on a rigid body whose
//! actuators deliver at most `τ_max` N·m: `τᵢ = sat(τ_districontrol)`, the
//! torque's norm scaled down to `τ_max` ([`saturate`]).
//!
//! It uses attsync's public crates only: the model's building blocks from
//! `attitude` (the law, the rigid body, RKMK4), the wire contract from
//! `msgs`, and the node loop of `attsync-agent`, which it drives through
//! the [`attsync_agent::Stepper`] trait. So it speaks the protocol (lockstep
//! and real-time, continuous and sampled coupling) without reimplementing it.
//!
//! `τ_max` comes from the environment variable [`TAU_MAX_VAR`] (default
//! [`DEFAULT_TAU_MAX`]); set it per agent with the scenario's `env = { … }`.
//!
//! # Layout
//! - [`saturate`]: the actuator limit.
//! - [`SaturatedAgent`]: the agent as a [`attsync_agent::Stepper`].
//! - [`run`]: one node process, start to end of the protocol.

mod saturate;
mod stepper;

pub use saturate::saturate;
pub use stepper::SaturatedAgent;

use attsync_agent::NodeError;
use iceoryx2::node::Node;
use iceoryx2::service::Service;
use msgs::config::NodeConfig;
use std::sync::atomic::AtomicBool;
use tracing::info;

/// Environment variable holding `τ_max`, N·m (a positive number; `inf` turns
/// the limit off).
pub const TAU_MAX_VAR: &str = "SATURATED_TAU_MAX";

/// `τ_max` when [`TAU_MAX_VAR`] is not set, N·m.
pub const DEFAULT_TAU_MAX: f64 = 5.0;

/// `τ_max` from [`TAU_MAX_VAR`], or [`DEFAULT_TAU_MAX`] if it is not set.
pub fn tau_max_from_env() -> Result<f64, String> {
    match std::env::var(TAU_MAX_VAR) {
        Err(std::env::VarError::NotPresent) => Ok(DEFAULT_TAU_MAX),
        Err(e) => Err(format!("{TAU_MAX_VAR}: {e}")),
        Ok(v) => match v.trim().parse::<f64>() {
            Ok(t) if t > 0.0 => Ok(t),
            _ => Err(format!(
                "{TAU_MAX_VAR}={v:?}: expected a positive number of N·m (or inf)"
            )),
        },
    }
}

/// Runs the agent of `cfg`, with torque limit `tau_max` (N·m), on `node`
/// until the end of the protocol.
pub fn run<S: Service>(
    node: &Node<S>,
    cfg: &NodeConfig,
    tau_max: f64,
    shutdown: &AtomicBool,
) -> Result<(), NodeError> {
    let mut agent = SaturatedAgent::from_config(cfg, tau_max).map_err(NodeError::Protocol)?;
    info!(id = cfg.id, tau_max, "saturated districontrol agent");
    let result = attsync_agent::runtime::run(node, cfg, &mut agent, shutdown);
    let (steps, saturated) = agent.saturated_steps();
    let span = agent.saturated_span();
    info!(
        steps,
        saturated_steps = saturated,
        first_saturated_step = span.map(|s| s.0),
        last_saturated_step = span.map(|s| s.1),
        peak_demanded = agent.peak_demanded(),
        peak_applied = attsync_agent::Stepper::peak_torque(&agent),
        "torque limit"
    );
    result
}
