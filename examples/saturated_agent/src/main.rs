//! `saturated-agent --config FILE`: one torque-limited rigid body as an
//! attsync plug-in process (`τ_max` from `SATURATED_TAU_MAX`, N·m).

use attsync_agent::args::{MainError, node_main};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

fn main() -> ExitCode {
    node_main(
        "saturated-agent",
        |cfg| format!("agent_{}", cfg.id),
        |node, cfg| {
            let tau_max = saturated_agent::tau_max_from_env().map_err(MainError::Setup)?;
            Ok(saturated_agent::run(
                node,
                cfg,
                tau_max,
                &AtomicBool::new(false),
            )?)
        },
    )
}
