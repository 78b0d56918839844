//! `attsync-leader --config FILE`: the reference trajectory as a process.

use attsync_agent::args::node_main;
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

fn main() -> ExitCode {
    node_main(
        "attsync-leader",
        |_| "leader".to_owned(),
        |node, cfg| Ok(attsync_leader::run(node, cfg, &AtomicBool::new(false))?),
    )
}
