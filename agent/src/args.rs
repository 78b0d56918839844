//! Command line and start-up shared by `attsync-agent`, `attsync-leader` and
//! Rust plug-ins (`examples/saturated_agent`).

use crate::runtime::NodeError;
use iceoryx2::node::Node;
use iceoryx2::prelude::*;
use msgs::config::{ConfigError, NodeConfig};
use msgs::iox::IoxError;
use std::path::PathBuf;
use std::process::ExitCode;
use thiserror::Error;

/// `attsync-agent --config FILE` / `attsync-leader --config FILE`.
#[derive(Debug, clap::Parser)]
#[command(version, about = "An attsync node process (started by `attsync run`).")]
pub struct NodeArgs {
    /// The node's JSON configuration, written by the orchestrator.
    #[arg(long)]
    pub config: PathBuf,
}

/// Why a node process ends with a non-zero status.
#[derive(Debug, Error)]
pub enum MainError {
    /// Its configuration file.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// Its iceoryx2 node.
    #[error(transparent)]
    Iox(#[from] IoxError),
    /// The node loop.
    #[error(transparent)]
    Node(#[from] NodeError),
    /// A plug-in's own set-up (e.g. a bad environment variable).
    #[error("{0}")]
    Setup(String),
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
pub fn create_node(cfg: &NodeConfig, name: &str) -> Result<Node<ipc::Service>, IoxError> {
    msgs::iox::create_node(&cfg.run, std::path::Path::new(&cfg.iox_root), name)
}

/// The `main` of a node program `program`: exits at once if its expected
/// parent is already gone ([`msgs::parent::watched`]), parses `--config`,
/// sets up tracing, reads the configuration, creates the iceoryx2 node
/// named by `name`, runs `body`, and turns an error into a message and exit
/// status 1.
pub fn node_main(
    program: &str,
    name: impl FnOnce(&NodeConfig) -> String,
    body: impl FnOnce(&Node<ipc::Service>, &NodeConfig) -> Result<(), MainError>,
) -> ExitCode {
    if let Err(orphaned) = msgs::parent::watched() {
        eprintln!("{program}: {orphaned}");
        return ExitCode::FAILURE;
    }
    let args = <NodeArgs as clap::Parser>::parse();
    init_tracing();
    let result = NodeConfig::read(&args.config)
        .map_err(MainError::from)
        .and_then(|cfg| {
            let node = create_node(&cfg, &name(&cfg))?;
            body(&node, &cfg)
        });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            eprintln!("{program}: {e}");
            ExitCode::FAILURE
        }
    }
}
