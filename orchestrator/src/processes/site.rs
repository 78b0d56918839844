//! Where nodes run other than on this machine, behind one interface: the
//! phases start, command, watch and end every [`Site`] alike and never
//! know what one is. A run across machines (`crate::remote`) is one site
//! per run that reaches every host of its plan; this machine's nodes are
//! the session's own supervisor.

use super::ProcessError;
use crate::failure::Failure;
use crate::scenario::plugin::Plugin;
pub use launch::site_exit::SiteExit;
use msgs::config::NodeConfig;
use msgs::{ControlMsg, Limits};
use std::fmt::Debug;
use std::path::Path;
use std::time::Duration;

/// What opens the sites of a run (e.g. the hosts of a plan), given the
/// run's name: held by [`super::ProcessOptions`].
pub trait Elsewhere: Debug + Send + Sync {
    /// Connects the sites of run `run` (before any node starts).
    ///
    /// # Errors
    /// A site cannot be reached or used.
    fn open(&self, run: &str) -> Result<Box<dyn Site>, ProcessError>;
}

/// Nodes of the run placed on other machines.
pub trait Site {
    /// Whether node `id` runs there.
    fn places(&self, id: u32) -> bool;
    /// The machine node `id` runs on, if it runs there (for its label).
    fn host_of(&self, id: u32) -> Option<String>;
    /// Starts its nodes and what carries their messages to this machine.
    ///
    /// # Errors
    /// A machine refused or could not start its nodes.
    fn start(&mut self, setup: &Setup<'_>) -> Result<(), Failure>;
    /// Sends `msg` (`Start`, `Stop`) to its nodes.
    ///
    /// # Errors
    /// It could not be sent.
    fn control(&self, msg: ControlMsg) -> Result<(), Failure>;
    /// Its nodes that ended since the last call.
    ///
    /// # Errors
    /// The site itself failed (a machine lost, a bridge broken).
    fn ended(&mut self) -> Result<Vec<SiteExit>, Failure>;
    /// Ends its nodes (killed if `kill`, else awaited after `Stop`), their
    /// logs copied into `logs`; returns those that did not end cleanly.
    fn finish(&mut self, kill: bool, logs: &Path) -> Vec<SiteExit>;
}

/// A run as the sites need it to start their nodes.
pub struct Setup<'a> {
    /// The run's name (its iceoryx2 services' prefix).
    pub run: &'a str,
    /// The run's directory on this machine (node configurations).
    pub dir: &'a Path,
    /// The services' sizes.
    pub limits: Limits,
    /// `--stage-timeout`.
    pub stage_timeout: Duration,
    /// Real-time mode.
    pub realtime: bool,
    /// Every node's configuration.
    pub configs: &'a [NodeConfig],
    /// Every node, in the order of `configs`.
    pub nodes: Vec<SetupNode<'a>>,
}

/// A node as a site starts it, beside its configuration.
pub struct SetupNode<'a> {
    /// Its name in messages and logs (`leader`, `agent-3`).
    pub name: String,
    /// Its plug-in command, if a plug-in runs it.
    pub plugin: Option<&'a Plugin>,
}
