//! `attsync-agent --config FILE`: one rigid body as a process.

use attsync_agent::args::node_main;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

fn main() -> ExitCode {
    node_main(
        "attsync-agent",
        |cfg| format!("agent_{}", cfg.id),
        |node, cfg| Ok(attsync_agent::run(node, cfg, &AtomicBool::new(false))?),
    )
}
