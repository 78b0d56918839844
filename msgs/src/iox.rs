//! iceoryx2 at the edge: one error type for a failed iceoryx2 call and one
//! way to create a node in a run's namespace, for every process of a run.

use iceoryx2::node::{Node, NodeBuilder};
use iceoryx2::prelude::*;
use thiserror::Error;

/// An iceoryx2 call failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
#[error("iceoryx2: {what}: {detail}")]
pub struct IoxError {
    /// What was being done (e.g. "telemetry receive").
    pub what: &'static str,
    /// iceoryx2's reason (its error value, printed).
    pub detail: String,
}

/// Maps an iceoryx2 error to an [`IoxError`] saying what was being done:
/// `port.receive().map_err(iox("telemetry receive"))`.
pub fn iox<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> IoxError {
    move |e| IoxError {
        what,
        detail: format!("{e:?}"),
    }
}

/// Creates the iceoryx2 node `name` in run `run`'s namespace (prefix and
/// root path: [`crate::namespace::config`]). Signals are left to their
/// defaults: whoever started the process owns its life.
pub fn create_node<S: Service>(
    run: &str,
    iox_root: &std::path::Path,
    name: &str,
) -> Result<Node<S>, IoxError> {
    set_log_level(LogLevel::Error);
    let config = crate::namespace::config(run, iox_root)?;
    let node_name = NodeName::new(name).map_err(iox("node name"))?;
    NodeBuilder::new()
        .name(&node_name)
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<S>()
        .map_err(iox("create node"))
}
