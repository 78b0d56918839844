//! `saturated-agent --config FILE`: one torque-limited rigid body as an
//! attsync plug-in process (`τ_max` from `SATURATED_TAU_MAX`, N·m).

use attsync_agent::args::{NodeArgs, create_node, init_tracing};
use clap::Parser;
use msgs::config::NodeConfig;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

fn main() -> ExitCode {
    let args = NodeArgs::parse();
    init_tracing();
    let result = NodeConfig::read(&args.config).and_then(|cfg| {
        let tau_max = saturated_agent::tau_max_from_env()?;
        let node = create_node(&cfg, &format!("agent_{}", cfg.id))?;
        saturated_agent::run(&node, &cfg, tau_max, &AtomicBool::new(false))
            .map_err(|e| e.to_string())
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("saturated-agent: {e}");
            ExitCode::FAILURE
        }
    }
}
