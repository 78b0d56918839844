//! Command line and start-up shared by `attsync-agent` and `attsync-leader`.

use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use std::path::PathBuf;

/// `attsync-agent --config FILE` / `attsync-leader --config FILE`.
#[derive(Debug, clap::Parser)]
#[command(version, about = "An attsync node process (started by `attsync run`).")]
pub struct NodeArgs {
    /// The node's JSON configuration, written by the orchestrator.
    #[arg(long)]
    pub config: PathBuf,
}

/// Sets up tracing to stderr (the orchestrator sends it to `<out>/logs/<name>.log`).
/// Level from `ATTSYNC_LOG` (default `info`).
pub fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_env("ATTSYNC_LOG")
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_ansi(false)
        .init();
}

/// Creates the node's iceoryx2 node in the run's namespace. Signals are left
/// to their defaults: the orchestrator owns the process's life.
pub fn create_node(cfg: &NodeConfig, name: &str) -> Result<Node<ipc::Service>, String> {
    set_log_level(LogLevel::Error);
    let iox = msgs::namespace::config(&cfg.run, std::path::Path::new(&cfg.iox_root))?;
    NodeBuilder::new()
        .name(
            &name
                .try_into()
                .map_err(|e| format!("node name {name:?}: {e:?}"))?,
        )
        .config(&iox)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| format!("cannot create iceoryx2 node: {e:?}"))
}
