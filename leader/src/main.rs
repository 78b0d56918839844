//! `attsync-leader --config FILE`: the reference trajectory as a process.

use attsync_agent::args::{NodeArgs, create_node, init_tracing};
use clap::Parser;
use msgs::config::NodeConfig;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

fn main() -> ExitCode {
    let args = NodeArgs::parse();
    init_tracing();
    let result = NodeConfig::read(&args.config).and_then(|cfg| {
        let node = create_node(&cfg, "leader")?;
        attsync_leader::run(&node, &cfg, &AtomicBool::new(false)).map_err(|e| e.to_string())
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("attsync-leader: {e}");
            ExitCode::FAILURE
        }
    }
}
