//! The process-per-agent engine: the leader and every agent run as their own
//! OS processes (`attsync-leader`, `attsync-agent`), exchanging states over
//! iceoryx2 in lockstep; the orchestrator supervises them, collects their
//! telemetry into the same snapshots the in-process engine produces, and
//! removes everything the run created.

pub mod namespace;
pub mod node_log;
pub mod reaper;
pub mod supervise;

use crate::scenario::plugin::Plugin;
use attitude::engine::Snapshot;
use attitude::link::LinkStats;
use attitude::network::{AgentState, Network};
use attitude::reference::LeaderState;
use iceoryx2::node::NodeBuilder;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use msgs::config::{NodeConfig, Role, WaitStrategy};
use msgs::{
    ControlCommand, ControlMsg, Done, FailReason, Limits, PROTOCOL_VERSION, Telemetry, TelemetryMsg,
};
use namespace::Namespace;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};
use supervise::{Supervisor, describe, find_binaries, tail};
use thiserror::Error;

/// Options of the process engine.
#[derive(Debug, Clone)]
pub struct ProcessOptions {
    /// How nodes wait for their inputs.
    pub wait: WaitStrategy,
    /// Longest wait of a node for one stage's inputs, s.
    pub stage_timeout: f64,
    /// Longest wait for connections and commands, s.
    pub start_timeout: f64,
    /// Real-time mode: simulated seconds per wall second (`None`: lockstep).
    pub realtime: Option<f64>,
    /// Agents run by the user's own programs.
    pub plugins: Vec<Plugin>,
}

impl Default for ProcessOptions {
    fn default() -> Self {
        Self {
            wait: WaitStrategy::Adaptive,
            stage_timeout: 10.0,
            start_timeout: 30.0,
            realtime: None,
            plugins: Vec::new(),
        }
    }
}

/// Time between the orchestrator's `Start` and simulated time 0 in
/// real-time mode, so that every node has read `Start` before it is due.
const REALTIME_LEAD: Duration = Duration::from_millis(50);

/// The engine could not start.
#[derive(Debug, Error)]
pub enum ProcessError {
    /// A node binary is missing.
    #[error("{0}")]
    MissingBinary(String),
    /// Setting up iceoryx2 failed.
    #[error("iceoryx2: {0}")]
    Iceoryx(String),
    /// A file could not be written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
}

/// How a process run ended.
#[derive(Debug)]
pub struct Outcome {
    /// Peak torque per agent (network order); 0 where never reported.
    pub peak_torques: Vec<f64>,
    /// Steps of the last complete snapshot.
    pub steps: u64,
    /// Why the run stopped early, if it did.
    pub failure: Option<String>,
    /// Counters of the impaired links: (from, to, stats).
    pub links: Vec<(u32, u32, LinkStats)>,
    /// Real-time pacing per agent (network order): (stages started more
    /// than a step late, largest lateness in wall s).
    pub pacing: Vec<(u64, f64)>,
    /// What each node that finished reported with `Done`: (name, id, report).
    pub nodes: Vec<(String, u32, Done)>,
}

fn iox<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> ProcessError {
    move |e| ProcessError::Iceoryx(format!("{what}: {e:?}"))
}

/// Node names: `leader`, `agent-<id>`.
fn node_name(net: &Network, index: usize) -> String {
    if index == 0 {
        "leader".into()
    } else {
        format!("agent-{}", net.agents[index - 1].model.id)
    }
}

/// Node names for messages: a plug-in's name says so, with its command.
fn node_label(net: &Network, plugins: &[Plugin], index: usize) -> String {
    let name = node_name(net, index);
    match plugin_of(net, plugins, index) {
        Some(p) => format!("{name} (plug-in `{}`)", p.display()),
        None => name,
    }
}

fn plugin_of<'a>(net: &Network, plugins: &'a [Plugin], index: usize) -> Option<&'a Plugin> {
    let id = (index > 0).then(|| net.agents[index - 1].model.id)?;
    plugins.iter().find(|p| p.agent == id)
}

/// The per-node configurations of `net`.
#[must_use]
pub fn node_configs(
    net: &Network,
    run: &str,
    root: &Path,
    opts: &ProcessOptions,
) -> Vec<NodeConfig> {
    let limits = Limits::of(net);
    let linked: Vec<u32> = net
        .agents
        .iter()
        .filter(|a| a.model.leader_gain.is_some())
        .map(|a| a.model.id)
        .collect();
    let base = |id: u32, inputs: Vec<u32>, outputs: Vec<u32>, role: Role| NodeConfig {
        protocol_version: PROTOCOL_VERSION,
        run: run.to_string(),
        iox_root: root.to_string_lossy().into_owned(),
        id,
        dt: net.dt,
        steps: net.steps,
        coupling: net.coupling,
        sample_every: net.sample_every,
        inputs,
        outputs,
        limits,
        wait: opts.wait,
        stage_timeout: opts.stage_timeout,
        start_timeout: opts.start_timeout,
        realtime: opts.realtime,
        role,
    };
    let mut out = vec![base(
        0,
        Vec::new(),
        linked,
        Role::Leader {
            p: net.p,
            initial: net.leader,
        },
    )];
    for a in &net.agents {
        let nbrs: Vec<u32> = a.model.neighbours.iter().map(|n| n.id).collect();
        let mut inputs = nbrs.clone();
        if a.model.leader_gain.is_some() {
            inputs.push(0);
        }
        out.push(base(
            a.model.id,
            inputs,
            nbrs,
            Role::Agent {
                model: Box::new(a.model.clone()),
                initial: a.initial,
            },
        ));
    }
    out
}

/// Runs `net` as processes. `logs` receives one log file per node.
/// `on_sample` gets every snapshot in step order (return `false` to stop).
/// Failures after start-up (a node dies, a timeout, `interrupt`) end the run
/// early with [`Outcome::failure`] set; everything is cleaned up in all cases.
pub fn run(
    net: &Network,
    opts: &ProcessOptions,
    logs: &Path,
    interrupt: &AtomicBool,
    mut on_sample: impl FnMut(&Snapshot<'_>) -> bool,
) -> Result<Outcome, ProcessError> {
    let (agent_bin, leader_bin) = find_binaries().map_err(ProcessError::MissingBinary)?;
    let io = |path: &Path| {
        let path = path.to_owned();
        move |source| ProcessError::Io { path, source }
    };
    std::fs::create_dir_all(logs).map_err(io(logs))?;
    let ns = Namespace::create().map_err(io(&namespace::base_dir()))?;
    let run = ns.run().to_string();
    let limits = Limits::of(net);
    let n_nodes = net.agents.len() + 1;

    set_log_level(LogLevel::Error);
    let cfg = msgs::namespace::config(&run, ns.dir())
        .map_err(|e| ProcessError::Iceoryx(e.to_string()))?;
    let node = NodeBuilder::new()
        .name(&"orchestrator".try_into().map_err(iox("node name"))?)
        .config(&cfg)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(iox("node"))?;
    let control = msgs::open::control(&node, &run, &limits)
        .map_err(|e| ProcessError::Iceoryx(e.to_string()))?
        .publisher_builder()
        .create()
        .map_err(iox("control publisher"))?;
    let listener = msgs::open::orchestrator_wake(&node, &run, &limits)
        .map_err(|e| ProcessError::Iceoryx(e.to_string()))?
        .listener_builder()
        .create()
        .map_err(iox("wake listener"))?;
    let configs = node_configs(net, &run, ns.dir(), opts);
    let mut telemetry: Vec<Subscriber<ipc::Service, TelemetryMsg, ()>> = Vec::new();
    for c in &configs {
        telemetry.push(
            msgs::open::telemetry(&node, &run, c.id, &limits)
                .map_err(|e| ProcessError::Iceoryx(e.to_string()))?
                .subscriber_builder()
                .buffer_size(limits.telemetry_buffer)
                .create()
                .map_err(iox("telemetry subscriber"))?,
        );
    }

    let _reaper = reaper::Reaper::start(); // dropped after `sup`: kills the orphans
    let mut sup = Supervisor::new().map_err(io(Path::new("tokio runtime")))?;
    let log_of = |i: usize| logs.join(format!("{}.log", node_name(net, i)));
    for (i, c) in configs.iter().enumerate() {
        let file = ns.dir().join(format!("node-{}.json", c.id));
        c.write(&file).map_err(|e| ProcessError::Io {
            path: file.clone(),
            source: std::io::Error::other(e),
        })?;
        let file = file.to_string_lossy().into_owned();
        let mut env = vec![("ATTSYNC_CONFIG".to_string(), file.clone())];
        let config_arg = ["--config".to_string(), file];
        let spawned = match plugin_of(net, &opts.plugins, i) {
            Some(p) => {
                env.extend(p.env.iter().map(|(k, v)| (k.clone(), v.clone())));
                let args: Vec<String> = p.command[1..].iter().cloned().chain(config_arg).collect();
                sup.spawn(
                    i,
                    Path::new(&p.command[0]),
                    &args,
                    &env,
                    Some(&p.dir),
                    &log_of(i),
                )
            }
            None => {
                let bin = if i == 0 { &leader_bin } else { &agent_bin };
                sup.spawn(i, bin, &config_arg, &env, None, &log_of(i))
            }
        };
        spawned.map_err(io(&log_of(i)))?;
    }

    let mut c = Collector {
        pending: vec![VecDeque::new(); n_nodes],
        ready: vec![false; n_nodes],
        done: vec![false; n_nodes],
        peaks: vec![0.0; n_nodes],
        steps: 0,
        links: Vec::new(),
        reports: vec![None; n_nodes],
        blamed: Vec::new(),
        gave_up: Vec::new(),
        broke_protocol: Vec::new(),
    };
    let failure = (|| -> Option<String> {
        // Phase 1: every node ready.
        let deadline = Instant::now() + Duration::from_secs_f64(opts.start_timeout);
        while !c.ready.iter().all(|&r| r) {
            let _ = listener.timed_wait(|_| {}, Duration::from_millis(10));
            if let Err(e) = c.drain(&telemetry) {
                return Some(e);
            }
            if let Some(f) = check_exits(&mut sup, &c.done, net, &opts.plugins, &log_of) {
                return Some(f);
            }
            if interrupt.load(Ordering::Relaxed) {
                return Some("interrupted".into());
            }
            if Instant::now() > deadline {
                let missing: Vec<String> = (0..n_nodes)
                    .filter(|&i| !c.ready[i])
                    .map(|i| node_label(net, &opts.plugins, i))
                    .collect();
                return Some(format!(
                    "start-up timed out after {} s: not ready: {}",
                    opts.start_timeout,
                    missing.join(", ")
                ));
            }
        }
        let start = match opts.realtime {
            Some(_) => ControlMsg::start_at(msgs::unix_ns_now() + REALTIME_LEAD.as_nanos() as u64),
            None => ControlMsg::new(ControlCommand::Start),
        };
        if control.send_copy(start).is_err() {
            return Some("cannot send Start".into());
        }
        // Phase 2: collect until every node is done.
        let stall = Duration::from_secs_f64(opts.stage_timeout * 2.0);
        let mut last_progress = Instant::now();
        loop {
            let _ = listener.timed_wait(|_| {}, Duration::from_millis(10));
            match c.drain(&telemetry) {
                Ok(true) => last_progress = Instant::now(),
                Ok(false) => {}
                Err(e) => return Some(e),
            }
            loop {
                match c.next_snapshot(net) {
                    Ok(Some((step, leader, agents))) => {
                        c.steps = step;
                        let snap = Snapshot {
                            step,
                            leader: &leader,
                            agents: &agents,
                        };
                        if !on_sample(&snap) {
                            return Some("stopped by the results writer".into());
                        }
                    }
                    Ok(None) => break,
                    Err(e) => return Some(e),
                }
            }
            if c.done.iter().all(|&d| d) && c.pending.iter().all(VecDeque::is_empty) {
                return None;
            }
            if let Some(f) = check_exits(&mut sup, &c.done, net, &opts.plugins, &log_of) {
                return Some(f);
            }
            if interrupt.load(Ordering::Relaxed) {
                return Some("interrupted".into());
            }
            if last_progress.elapsed() > stall {
                return Some(format!(
                    "no telemetry for {:.0} s: the run is stalled",
                    stall.as_secs_f64()
                ));
            }
        }
    })();
    // A node that gave up waiting says for whom: put that first.
    let failure = failure.map(|f| {
        std::thread::sleep(Duration::from_millis(20));
        let _ = c.drain(&telemetry);
        match c.blame(net, &opts.plugins) {
            Some(b) => format!("{b}\n{f}"),
            None => f,
        }
    });

    match &failure {
        None => {
            let _ = control.send_copy(ControlMsg::new(ControlCommand::Stop));
            let exits = sup.wait_all(Duration::from_secs(10));
            let bad: Vec<String> = exits
                .iter()
                .filter(|e| !matches!(&e.status, Ok(s) if s.success()))
                .map(|e| {
                    format!(
                        "{}: {}",
                        node_label(net, &opts.plugins, e.index),
                        describe(&e.status)
                    )
                })
                .collect();
            if !bad.is_empty() {
                return Ok(Outcome {
                    peak_torques: c.peaks[1..].to_vec(),
                    links: std::mem::take(&mut c.links),
                    pacing: c.pacing(),
                    nodes: c.nodes(net),
                    steps: c.steps,
                    failure: Some(format!("nodes failed at shutdown: {}", bad.join("; "))),
                });
            }
        }
        Some(_) => {
            sup.kill_all();
            let _ = sup.wait_all(Duration::from_secs(5));
        }
    }
    drop(telemetry);
    drop(control);
    drop(listener);
    drop(node);
    drop(ns);
    c.links.sort_by_key(|&(f, t, _)| (f, t));
    Ok(Outcome {
        peak_torques: c.peaks[1..].to_vec(),
        pacing: c.pacing(),
        nodes: c.nodes(net),
        links: c.links,
        steps: c.steps,
        failure,
    })
}

/// A node that exited before it was done is a failure: name it, its status
/// and the end of its log.
fn check_exits(
    sup: &mut Supervisor,
    done: &[bool],
    net: &Network,
    plugins: &[Plugin],
    log_of: &dyn Fn(usize) -> PathBuf,
) -> Option<String> {
    while let Some(e) = sup.try_exit() {
        let clean = matches!(&e.status, Ok(s) if s.success());
        if !(done[e.index] && clean) {
            return Some(format!(
                "{} ended during the run ({}); last lines of its log (logs/{}.log in the results directory):\n{}",
                node_label(net, plugins, e.index),
                describe(&e.status),
                node_name(net, e.index),
                tail(&log_of(e.index), 10)
            ));
        }
    }
    None
}

/// Telemetry bookkeeping.
struct Collector {
    pending: Vec<VecDeque<(u64, Sampled)>>,
    ready: Vec<bool>,
    done: Vec<bool>,
    peaks: Vec<f64>,
    steps: u64,
    links: Vec<(u32, u32, LinkStats)>,
    /// Each node's `Done` report, once it came.
    reports: Vec<Option<Done>>,
    /// (node index, id of the input it timed out waiting for).
    blamed: Vec<(usize, u32)>,
    /// Nodes that reported giving up.
    gave_up: Vec<usize>,
    /// Ids of nodes a receiver caught breaking the protocol.
    broke_protocol: Vec<u32>,
}

/// A decoded sample waiting for the rest of its snapshot.
#[derive(Debug, Clone, Copy)]
enum Sampled {
    Leader(LeaderState),
    Agent(AgentState),
}

impl Collector {
    /// Real-time pacing per agent (network order).
    fn pacing(&self) -> Vec<(u64, f64)> {
        self.reports[1..]
            .iter()
            .map(|r| r.map_or((0, 0.0), |d| (d.pacing.late_stages, d.pacing.max_lateness)))
            .collect()
    }

    /// The `Done` reports: (name, id, report) per node that sent one.
    fn nodes(&self, net: &Network) -> Vec<(String, u32, Done)> {
        let id = |i: usize| {
            if i == 0 {
                0
            } else {
                net.agents[i - 1].model.id
            }
        };
        (self.reports.iter().enumerate())
            .filter_map(|(i, r)| r.map(|d| (node_name(net, i), id(i), d)))
            .collect()
    }

    /// Names the nodes others gave up waiting for, if any did.
    fn blame(&self, net: &Network, plugins: &[Plugin]) -> Option<String> {
        // Node index: 0 the leader, 1 + the agent's index.
        let index_of = |id: u32| net.index_of(id).map_or(0, |i| i + 1);
        let mut blamed: Vec<u32> = self.blamed.iter().map(|&(_, id)| id).collect();
        blamed.sort_unstable();
        blamed.dedup();
        // Lockstep propagates a hang: the nodes waiting for the silent one
        // stop publishing too. The cause is a blamed node that did not give
        // up waiting itself (if every blamed node did, list them all).
        let roots: Vec<u32> = blamed
            .iter()
            .copied()
            .filter(|&id| !self.gave_up.contains(&index_of(id)))
            .collect();
        let silent = if roots.is_empty() { blamed } else { roots };
        let lines: Vec<String> = silent
            .iter()
            .map(|&id| {
                let index = index_of(id);
                let waiters: Vec<String> = self
                    .blamed
                    .iter()
                    .filter(|&&(_, j)| j == id)
                    .map(|&(i, _)| node_name(net, i))
                    .collect();
                if self.broke_protocol.contains(&id) {
                    format!(
                        "{} broke the protocol: {} refused its messages (see their logs)",
                        node_label(net, plugins, index),
                        waiters.join(", ")
                    )
                } else {
                    format!(
                        "{} stopped answering: {} timed out waiting for its state",
                        node_label(net, plugins, index),
                        waiters.join(", ")
                    )
                }
            })
            .collect();
        (!lines.is_empty()).then(|| lines.join("\n"))
    }

    /// Reads every telemetry message available; `Ok(true)` if any arrived.
    fn drain(
        &mut self,
        subs: &[Subscriber<ipc::Service, TelemetryMsg, ()>],
    ) -> Result<bool, String> {
        let mut any = false;
        for (i, sub) in subs.iter().enumerate() {
            loop {
                let m = match sub.receive() {
                    Ok(Some(s)) => *s,
                    Ok(None) => break,
                    Err(e) => return Err(format!("telemetry receive: {e:?}")),
                };
                any = true;
                let t = m
                    .decode()
                    .map_err(|e| format!("node {}'s telemetry: {e}", m.sender))?;
                self.take(i, m.sender, t);
            }
        }
        Ok(any)
    }

    /// Books report `t` of node index `i` (id `sender`).
    fn take(&mut self, i: usize, sender: u32, t: Telemetry) {
        match t {
            Telemetry::Ready => self.ready[i] = true,
            Telemetry::Sample {
                step,
                state,
                peak_torque,
            } => {
                self.peaks[i] = self.peaks[i].max(peak_torque);
                self.pending[i].push_back((step, Sampled::Agent(state)));
            }
            Telemetry::LeaderSample { step, state } => {
                self.pending[i].push_back((step, Sampled::Leader(state)));
            }
            Telemetry::LinkStats { from, stats } => self.links.push((from, sender, stats)),
            Telemetry::Done(d) => {
                self.done[i] = true;
                self.peaks[i] = d.peak_torque;
                self.reports[i] = Some(d);
            }
            Telemetry::Failed(reason) => {
                self.gave_up.push(i);
                match reason {
                    FailReason::InputTimeout { from } => self.blamed.push((i, from)),
                    FailReason::BadInput { from } => {
                        self.blamed.push((i, from));
                        self.broke_protocol.push(from);
                    }
                    FailReason::Other => {}
                }
            }
        }
    }

    /// The next complete snapshot, if every node has sent it.
    #[allow(clippy::type_complexity)]
    fn next_snapshot(
        &mut self,
        net: &Network,
    ) -> Result<Option<(u64, LeaderState, Vec<AgentState>)>, String> {
        if self.pending.iter().any(VecDeque::is_empty) {
            return Ok(None);
        }
        let step = self.pending[0][0].0;
        if let Some((i, q)) = (self.pending.iter().enumerate()).find(|(_, q)| q[0].0 != step) {
            return Err(format!(
                "telemetry out of step: {} at step {}, leader at {step}",
                node_name(net, i),
                q[0].0
            ));
        }
        let mut samples = self
            .pending
            .iter_mut()
            .map(|q| q.pop_front().expect("non-empty").1);
        let Some(Sampled::Leader(leader)) = samples.next() else {
            return Err("the leader sent an agent's sample".into());
        };
        let agents = samples
            .enumerate()
            .map(|(k, s)| match s {
                Sampled::Agent(a) => Ok(a),
                Sampled::Leader(_) => Err(format!(
                    "{} sent the leader's sample",
                    node_name(net, k + 1)
                )),
            })
            .collect::<Result<_, _>>()?;
        Ok(Some((step, leader, agents)))
    }
}
