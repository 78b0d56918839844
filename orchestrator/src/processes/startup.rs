//! Start-up phases: open the ports, write each node's configuration and
//! start its process ([`Session::open`], [`Session::spawn_nodes`]), wait
//! until every node reports `Ready`, then send `Start`.

use super::collect::{Collector, NodeSlot};
use super::configs::{node_configs, node_id, node_label, node_name, plugin_of};
use super::site::{Setup, SetupNode};
use super::{ProcessError, ProcessOptions, Session, io_at};
use crate::failure::Failure;
use crate::launch::namespace::{self, Namespace};
use crate::launch::supervise::{Launch, Supervisor, find_binaries};
use attitude::network::Network;
use iceoryx2::service::port_factory::PortFactory;
use msgs::{ControlCommand, ControlMsg, Limits};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Time between the orchestrator's `Start` and simulated time 0 in
/// real-time mode, so that every node has read `Start` before it is due.
const REALTIME_LEAD: Duration = Duration::from_millis(50);

/// How long a phase waits for a node's wake-up before it looks around.
pub(super) const POLL: Duration = Duration::from_millis(10);

impl<'a> Session<'a> {
    /// Creates the run's namespace and opens the orchestrator's ports.
    pub(super) fn open(
        net: &'a Network,
        opts: &'a ProcessOptions,
        logs: &'a Path,
        interrupt: &'a AtomicBool,
    ) -> Result<Self, ProcessError> {
        let binaries = find_binaries()?;
        std::fs::create_dir_all(logs).map_err(io_at(logs))?;
        let ns = Namespace::create().map_err(io_at(&namespace::base_dir()))?;
        let n_nodes = net.agents.len() + 1;
        let ids: Vec<u32> = (0..n_nodes).map(|i| node_id(net, i)).collect();
        let start_timeout = Duration::from_secs_f64(opts.start_timeout);
        let ports = super::Ports::open(ns, "orchestrator", &Limits::of(net), &ids, start_timeout)?;
        let sup = Supervisor::new().map_err(io_at(Path::new("tokio runtime")))?;
        let sites: Vec<_> = (opts.hosts.iter())
            .map(|e| e.open(ports.run()))
            .collect::<Result<_, _>>()?;
        let slots = (0..n_nodes)
            .map(|i| {
                let mut label = node_label(net, &opts.plugins, i);
                if let Some(h) = sites.iter().find_map(|s| s.host_of(ids[i])) {
                    label = format!("{label} on host {h}");
                }
                NodeSlot::new(node_name(net, i), label, ids[i])
            })
            .collect();
        Ok(Self {
            net,
            opts,
            logs,
            interrupt,
            binaries,
            sites,
            ports,
            sup,
            nodes: Collector::new(slots),
        })
    }

    /// The log file of node index `i`.
    pub(super) fn log_of(&self, i: usize) -> PathBuf {
        (self.logs).join(crate::results::layout::node_log_file(
            &self.nodes.slots[i].name,
        ))
    }

    /// Writes every node's configuration and starts its process: a plug-in's
    /// command in the scenario's directory, else the built-in binary.
    pub(super) fn spawn_nodes(&mut self) -> Result<(), ProcessError> {
        let (agent_bin, leader_bin) = self.binaries.clone();
        let configs = node_configs(self.net, self.ports.run(), self.ports.dir(), self.opts);
        for (i, c) in configs.iter().enumerate() {
            if self.sites.iter().any(|s| s.places(c.id)) {
                continue;
            }
            let file = (self.ports.dir()).join(crate::results::layout::node_config_file(c.id));
            c.write(&file).map_err(|e| ProcessError::Io {
                path: file.clone(),
                source: std::io::Error::other(e),
            })?;
            let log = self.log_of(i);
            let launch = match plugin_of(self.net, &self.opts.plugins, i) {
                Some(p) => Launch::Plugin {
                    command: &p.command,
                    env: &p.env,
                    dir: &p.dir,
                },
                None => Launch::Builtin(if i == 0 { &leader_bin } else { &agent_bin }),
            };
            (self.sup)
                .spawn_node(i, &launch, &file, &log)
                .map_err(io_at(&log))?;
        }
        Ok(())
    }

    /// Waits until every node has reported `Ready`, at most the start timeout.
    pub(super) fn await_ready(&mut self) -> Result<(), Failure> {
        let deadline = Instant::now() + Duration::from_secs_f64(self.opts.start_timeout);
        while !self.nodes.slots.iter().all(|s| s.ready) {
            self.ports.wait(POLL);
            self.nodes.drain(&self.ports)?;
            self.still_running()?;
            if Instant::now() > deadline {
                return Err(self.not_ready());
            }
        }
        Ok(())
    }

    /// Why start-up timed out: the nodes that never opened their ports
    /// first (a silent plug-in), then the nodes left waiting for them; or,
    /// if every node opened its ports, the nodes not ready.
    fn not_ready(&self) -> Failure {
        let limits = Limits::of(self.net);
        // A node that opened its ports has its telemetry publisher.
        let connected = |id: u32| {
            // (A look, not a wait: the orchestrator created the service.)
            msgs::open::Opener::new(self.ports.node(), self.ports.run(), &limits)
                .patience(Duration::ZERO)
                .telemetry(id)
                .is_ok_and(|t| t.dynamic_config().number_of_publishers() > 0)
        };
        let (silent, waiting): (Vec<_>, Vec<_>) = (self.nodes.slots.iter())
            .filter(|s| !s.ready)
            .partition(|s| !connected(s.id));
        let labels = |v: &[&super::collect::NodeSlot]| {
            v.iter()
                .map(|s| s.label.as_str())
                .collect::<Vec<_>>()
                .join(", ")
        };
        let nodes = match (silent.is_empty(), waiting.is_empty()) {
            (true, _) => format!("not ready: {}", labels(&waiting)),
            (false, true) => format!("never connected (opened no ports): {}", labels(&silent)),
            (false, false) => format!(
                "never connected (opened no ports): {}\n\
                 (connected, but left waiting for them: {})",
                labels(&silent),
                (waiting.iter())
                    .map(|s| s.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        };
        Failure::StartupTimedOut {
            after: self.opts.start_timeout,
            nodes,
        }
    }

    /// Sends `Start` (in real-time mode: for a moment just ahead), here
    /// and to every host.
    pub(super) fn start(&mut self) -> Result<(), Failure> {
        let msg = match self.opts.realtime {
            Some(_) => ControlMsg::start_at(msgs::unix_ns_now() + REALTIME_LEAD.as_nanos() as u64),
            None => ControlMsg::new(ControlCommand::Start),
        };
        for site in &self.sites {
            site.control(msg)?;
        }
        (self.ports).send(msg).map_err(|_| Failure::StartNotSent)
    }

    /// Starts the nodes placed elsewhere, on every site (none for a run on
    /// this machine).
    pub(super) fn start_sites(&mut self) -> Result<(), Failure> {
        if self.sites.is_empty() {
            return Ok(());
        }
        let configs = node_configs(self.net, self.ports.run(), self.ports.dir(), self.opts);
        let setup = Setup {
            run: self.ports.run(),
            dir: self.ports.dir(),
            limits: Limits::of(self.net),
            stage_timeout: Duration::from_secs_f64(self.opts.stage_timeout),
            realtime: self.opts.realtime.is_some(),
            configs: &configs,
            nodes: (0..configs.len())
                .map(|i| SetupNode {
                    name: node_name(self.net, i),
                    plugin: plugin_of(self.net, &self.opts.plugins, i),
                })
                .collect(),
        };
        self.sites.iter_mut().try_for_each(|s| s.start(&setup))
    }

    /// Fails if a node has ended before it was done, or on an interrupt.
    pub(super) fn still_running(&mut self) -> Result<(), Failure> {
        if let Some(f) = self.ended_early() {
            return Err(f);
        }
        if let Some(f) = self.ended_elsewhere()? {
            return Err(f);
        }
        if self.interrupt.load(Ordering::Relaxed) {
            return Err(Failure::Interrupted(None));
        }
        Ok(())
    }
}
