//! The scripted neighbourhood: attsync as orchestrator, leader and
//! neighbours of one candidate process, in lockstep.

use super::ConformOptions;
use super::law::{ExchangeRecord, LawRecord};
use super::rules::{Report, RuleId};
use crate::processes::namespace::Namespace;
use crate::processes::{ProcessOptions, node_configs, supervise::tail};
use attitude::agent::Agent;
use attitude::network::{Exchanged, Network};
use attitude::reference::Leader;
use iceoryx2::node::{Node, NodeBuilder, NodeState, NodeView};
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::{
    ControlCommand, ControlMsg, Limits, PROTOCOL_VERSION, StateMsg, Telemetry, TelemetryMsg,
};
use std::os::unix::process::CommandExt;
use std::path::Path;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// From this step on, the neighbourhood holds its inputs back at the next
/// exchange that has a successor, to see whether the candidate advances
/// without them.
const WITHHOLD_FROM: u64 = 5;
/// How long the inputs are held back.
const WITHHOLD_FOR: Duration = Duration::from_millis(300);
/// From this step on, the first input carries a NaN at the next exchange.
const NAN_FROM: u64 = 8;

/// The exchanges (n, s) of `cfg`, in order.
fn exchanges(cfg: &NodeConfig) -> impl Iterator<Item = (u64, u32)> + '_ {
    (0..cfg.steps).flat_map(move |n| {
        (0..4u32).filter_map(move |s| cfg.coupling.exchanges_at(n, s as usize).then_some((n, s)))
    })
}

/// The first exchange at or after step `from` that is followed by another
/// exchange.
fn exchange_from(cfg: &NodeConfig, from: u64) -> Option<(u64, u32)> {
    let mut it = exchanges(cfg).skip_while(|&(n, _)| n < from);
    let first = it.next()?;
    it.next().map(|_| first)
}
/// Longest wait for the candidate to exit (after Stop, or with a bad config).
const EXIT_TIMEOUT: Duration = Duration::from_secs(10);

/// Starts the candidate with `config`, output to `log`.
fn spawn(opts: &ConformOptions, config: &Path, log: &Path) -> anyhow::Result<Child> {
    let out = std::fs::File::create(log)?;
    let err = out.try_clone()?;
    let child = Command::new(&opts.command[0])
        .args(&opts.command[1..])
        .arg("--config")
        .arg(config)
        .env("ATTSYNC_CONFIG", config)
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .process_group(0)
        .spawn()
        .map_err(|e| anyhow::anyhow!("cannot start `{}`: {e}", opts.command.join(" ")))?;
    Ok(child)
}

/// Waits up to `timeout` for the child to exit.
fn wait_exit(child: &mut Child, timeout: Duration) -> Option<ExitStatus> {
    let deadline = Instant::now() + timeout;
    loop {
        if let Ok(Some(st)) = child.try_wait() {
            return Some(st);
        }
        if Instant::now() > deadline {
            return None;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Processes of process group `pgid` still alive (read from /proc).
fn group_members(pgid: u32) -> Vec<u32> {
    let Ok(dir) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    dir.filter_map(|e| e.ok()?.file_name().to_str()?.parse::<u32>().ok())
        .filter(|pid| {
            std::fs::read_to_string(format!("/proc/{pid}/stat"))
                .ok()
                .and_then(|s| {
                    // Fields after the command name (which may hold spaces): state ppid pgrp …
                    let rest = &s[s.rfind(')')? + 2..];
                    let mut f = rest.split_whitespace();
                    let state = f.next()?;
                    let pgrp = f.nth(1)?.parse::<u32>().ok()?;
                    Some(pgrp == pgid && state != "Z")
                })
                .unwrap_or(false)
        })
        .collect()
}

fn kill_group(pgid: u32) {
    if let Ok(pid) = i32::try_from(pgid) {
        let _ = nix::sys::signal::killpg(
            nix::unistd::Pid::from_raw(pid),
            nix::sys::signal::Signal::SIGKILL,
        );
    }
}

fn describe(st: &ExitStatus) -> String {
    crate::processes::supervise::describe(&Ok(*st))
}

fn log_tail(opts: &ConformOptions) -> String {
    tail(&opts.log, 6)
}

/// Rule `version`: the candidate must refuse a config of another version.
pub(super) fn version_probe(
    net: &Network,
    index: usize,
    opts: &ConformOptions,
    report: &mut Report,
) -> anyhow::Result<()> {
    let ns = Namespace::create()?;
    let mut cfg = candidate_config(net, index, &ns, opts);
    cfg.protocol_version = PROTOCOL_VERSION + 100;
    let file = ns.dir().join("candidate-bad-version.json");
    cfg.write(&file).map_err(anyhow::Error::msg)?;
    let mut child = spawn(opts, &file, &opts.log)?;
    let pgid = child.id();
    match wait_exit(&mut child, EXIT_TIMEOUT) {
        Some(st) if !st.success() => report.pass(RuleId::Version),
        Some(st) => report.fail(
            RuleId::Version,
            format!(
                "given protocol_version {} it ended with {} instead of refusing",
                cfg.protocol_version,
                describe(&st)
            ),
        ),
        None => {
            let _ = child.kill();
            let _ = child.wait();
            report.fail(
                RuleId::Version,
                format!(
                    "given protocol_version {} it was still running after {} s",
                    cfg.protocol_version,
                    EXIT_TIMEOUT.as_secs()
                ),
            );
        }
    }
    kill_group(pgid);
    Ok(())
}

fn candidate_config(
    net: &Network,
    index: usize,
    ns: &Namespace,
    opts: &ConformOptions,
) -> NodeConfig {
    let popts = ProcessOptions {
        stage_timeout: opts.stage_timeout,
        start_timeout: opts.start_timeout,
        ..ProcessOptions::default()
    };
    node_configs(net, ns.run(), ns.dir(), &popts).swap_remove(index + 1)
}

/// The other nodes, run by attsync.
struct Neighbourhood {
    leader: Leader,
    /// Every agent but the candidate (`None` at its place).
    agents: Vec<Option<Agent>>,
    /// Per agent, the network index of each neighbour.
    nbr_index: Vec<Vec<usize>>,
    candidate: usize,
}

impl Neighbourhood {
    fn new(net: &Network, candidate: usize) -> Self {
        let agents = net
            .agents
            .iter()
            .enumerate()
            .map(|(i, a)| (i != candidate).then(|| Agent::new(a.model.clone(), a.initial, net.dt)))
            .collect();
        let nbr_index = net.neighbour_indices();
        Self {
            leader: Leader::new(net.p, net.leader, net.dt),
            agents,
            nbr_index,
            candidate,
        }
    }

    /// What node `id` publishes now (not the candidate).
    fn exchange_of(&self, net: &Network, id: u32) -> Exchanged {
        if id == 0 {
            return self.leader.stage_exchange();
        }
        let i = net.index_of(id).expect("an input of the candidate");
        self.agents[i]
            .as_ref()
            .expect("not the candidate")
            .stage_exchange()
    }

    /// One exchange: every node but the candidate receives, with `cand` the candidate's value.
    fn exchange(&mut self, cand: Option<Exchanged>) {
        let published: Vec<Option<Exchanged>> = self
            .agents
            .iter()
            .map(|a| a.as_ref().map(Agent::stage_exchange))
            .collect();
        let from_leader = self.leader.stage_exchange();
        for (i, agent) in self.agents.iter_mut().enumerate() {
            let Some(agent) = agent else { continue };
            for (k, &j) in self.nbr_index[i].iter().enumerate() {
                let x = if j == self.candidate {
                    cand
                } else {
                    published[j]
                };
                if let Some(x) = x {
                    agent.receive_neighbour(k, x);
                }
            }
            agent.receive_leader(from_leader);
        }
    }

    fn advance(&mut self) {
        self.leader.advance();
        for a in self.agents.iter_mut().flatten() {
            a.advance();
        }
    }
}

/// Checks of the candidate's telemetry.
struct TelemetryCheck {
    expected: Vec<u64>,
    seen: Vec<u64>,
    ready: bool,
    done: bool,
    problem: Option<String>,
    /// Every sample received (rule `law`).
    samples: Vec<(u64, attitude::network::AgentState)>,
}

impl TelemetryCheck {
    fn new(cfg: &NodeConfig) -> Self {
        let mut expected: Vec<u64> = (0..=cfg.steps).step_by(cfg.sample_every as usize).collect();
        if expected.last() != Some(&cfg.steps) {
            expected.push(cfg.steps);
        }
        Self {
            expected,
            seen: Vec::new(),
            ready: false,
            done: false,
            problem: None,
            samples: Vec::new(),
        }
    }

    fn drain(&mut self, sub: &Subscriber<ipc::Service, TelemetryMsg, ()>, id: u32, steps: u64) {
        while let Ok(Some(s)) = sub.receive() {
            let m = *s;
            let mut bad = |why: String| {
                if self.problem.is_none() {
                    self.problem = Some(why);
                }
            };
            if m.sender != id {
                bad(format!(
                    "telemetry claims sender {}, expected {id}",
                    m.sender
                ));
            }
            match m.decode() {
                Err(e) => bad(format!("telemetry: {e}")),
                Ok(Telemetry::Ready) => self.ready = true,
                Ok(Telemetry::Sample { step, state, .. }) => {
                    let finite = state.r.iter().chain(state.w.iter()).all(|v| v.is_finite());
                    if !finite
                        || attitude::so3::orthogonality_defect(&state.r) > msgs::ROTATION_TOLERANCE
                    {
                        bad(format!(
                            "sample at step {step} is not finite or R is not a rotation"
                        ));
                    }
                    if self.done {
                        bad(format!("sample at step {step} after Done"));
                    }
                    self.seen.push(step);
                    self.samples.push((step, state));
                }
                Ok(Telemetry::LeaderSample { step, .. }) => {
                    bad(format!("sends the leader's sample (step {step})"));
                }
                Ok(Telemetry::Done(d)) => {
                    if d.steps != steps {
                        bad(format!("Done carries step {}, expected {steps}", d.steps));
                    }
                    self.done = true;
                }
                Ok(Telemetry::LinkStats { .. } | Telemetry::Failed(_)) => {}
            }
        }
    }

    fn verdict(&self) -> Result<(), String> {
        if let Some(p) = &self.problem {
            return Err(p.clone());
        }
        if self.seen != self.expected {
            let first = self
                .seen
                .iter()
                .zip(&self.expected)
                .position(|(a, b)| a != b)
                .unwrap_or(self.seen.len().min(self.expected.len()));
            return Err(format!(
                "samples at steps {:?}… (from the {}th) where {:?}… were due ({} of {} received)",
                &self.seen[first.min(self.seen.len())..self.seen.len().min(first + 3)],
                first + 1,
                &self.expected[first.min(self.expected.len())..self.expected.len().min(first + 3)],
                self.seen.len(),
                self.expected.len()
            ));
        }
        if !self.done {
            return Err("no Done after the last step".into());
        }
        Ok(())
    }
}

fn iox<E: std::fmt::Debug>(what: &'static str) -> impl FnOnce(E) -> anyhow::Error {
    move |e| anyhow::anyhow!("iceoryx2: {what}: {e:?}")
}

/// The lockstep session: every rule but `version`.
pub(super) fn session(
    net: &Network,
    index: usize,
    opts: &ConformOptions,
    report: &mut Report,
) -> anyhow::Result<()> {
    let ns = Namespace::create()?;
    let cfg = candidate_config(net, index, &ns, opts);
    let (run, id) = (ns.run().to_string(), cfg.id);
    let limits = Limits::of(net);
    set_log_level(LogLevel::Error);
    let iox_cfg = msgs::namespace::config(&run, ns.dir()).map_err(anyhow::Error::msg)?;
    let node = NodeBuilder::new()
        .name(&"conform".try_into().map_err(iox("node name"))?)
        .config(&iox_cfg)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(iox("node"))?;
    let open_err = |e: msgs::open::OpenError| anyhow::anyhow!("{e}");
    let control = msgs::open::control(&node, &run, &limits)
        .map_err(open_err)?
        .publisher_builder()
        .create()
        .map_err(iox("control publisher"))?;
    let _orch_wake = msgs::open::orchestrator_wake(&node, &run, &limits)
        .map_err(open_err)?
        .listener_builder()
        .create()
        .map_err(iox("wake listener"))?;
    let tele = msgs::open::telemetry(&node, &run, id, &limits)
        .map_err(open_err)?
        .subscriber_builder()
        .buffer_size(limits.telemetry_buffer)
        .create()
        .map_err(iox("telemetry subscriber"))?;
    let mut input_pubs = Vec::new();
    for &j in &cfg.inputs {
        input_pubs.push(
            msgs::open::state(&node, &run, j, &limits)
                .map_err(open_err)?
                .publisher_builder()
                .create()
                .map_err(iox("input publisher"))?,
        );
    }
    let cand_state = msgs::open::state(&node, &run, id, &limits).map_err(open_err)?;
    let subs = (0..cfg.outputs.len().max(1))
        .map(|_| {
            cand_state
                .subscriber_builder()
                .buffer_size(limits.state_buffer)
                .create()
                .map_err(iox("candidate subscriber"))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let cand_wake = msgs::open::wake(&node, &run, id, &limits)
        .map_err(open_err)?
        .notifier_builder()
        .create()
        .map_err(iox("candidate wake notifier"))?;

    let file = ns.dir().join(format!("node-{id}.json"));
    cfg.write(&file).map_err(anyhow::Error::msg)?;
    let mut child = spawn(opts, &file, &opts.log)?;
    let pgid = child.id();
    let mut tcheck = TelemetryCheck::new(&cfg);

    let outcome = drive(
        net,
        index,
        &cfg,
        opts,
        report,
        &mut child,
        &control,
        &tele,
        &input_pubs,
        &subs,
        &cand_wake,
        &mut tcheck,
    );
    if outcome.is_err() {
        kill_group(pgid);
        let _ = child.kill();
        let _ = child.wait();
    }
    // Rule `clean`: after the candidate's exit, only our own node remains,
    // and nothing is left in its process group.
    let leftovers = group_members(pgid);
    if !leftovers.is_empty() {
        report.fail(
            RuleId::Clean,
            format!(
                "processes {leftovers:?} of its process group were still running after it exited"
            ),
        );
        kill_group(pgid);
    }
    let killed = outcome.is_err();
    let mut others = Vec::new();
    let _ = Node::<ipc::Service>::list(&iox_cfg, |state| {
        match &state {
            NodeState::Alive(v) if v.id() == node.id() => {}
            NodeState::Alive(_) => others.push("an iceoryx2 node still alive".to_string()),
            // A candidate we had to kill cannot release its node.
            NodeState::Dead(_) if killed => {}
            NodeState::Dead(_) => {
                others.push("an iceoryx2 node whose process died without releasing it".to_string())
            }
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => {
                others.push("an inaccessible or broken iceoryx2 node".to_string());
            }
        }
        CallbackProgression::Continue
    });
    match (killed, others.is_empty()) {
        (_, false) => report.fail(RuleId::Clean, format!("left behind: {}", others.join(", "))),
        (false, true) => report.pass(RuleId::Clean),
        (true, true) => report.not_checked(
            RuleId::Clean,
            "the candidate had to be killed, so it could not release its iceoryx2 node",
        ),
    }
    Ok(())
}

/// Everything from start-up to exit; `Err(())` when the candidate had to
/// be killed (the failing rule is recorded).
#[allow(clippy::too_many_arguments)]
fn drive(
    net: &Network,
    index: usize,
    cfg: &NodeConfig,
    opts: &ConformOptions,
    report: &mut Report,
    child: &mut Child,
    control: &iceoryx2::port::publisher::Publisher<ipc::Service, ControlMsg, ()>,
    tele: &Subscriber<ipc::Service, TelemetryMsg, ()>,
    input_pubs: &[iceoryx2::port::publisher::Publisher<ipc::Service, StateMsg, ()>],
    subs: &[Subscriber<ipc::Service, StateMsg, ()>],
    cand_wake: &iceoryx2::port::notifier::Notifier<ipc::Service>,
    tcheck: &mut TelemetryCheck,
) -> Result<(), ()> {
    let id = cfg.id;
    let later = [
        RuleId::InOrder,
        RuleId::WaitsForInputs,
        RuleId::ValidStates,
        RuleId::RefusesInvalid,
        RuleId::Telemetry,
        RuleId::Stops,
        RuleId::Law,
    ];
    let skip_rest = |report: &mut Report, why: &str| {
        for r in later {
            report.not_checked(r, why);
        }
    };

    // Start-up.
    let deadline = Instant::now() + Duration::from_secs_f64(opts.start_timeout);
    while !tcheck.ready {
        tcheck.drain(tele, id, cfg.steps);
        if let Ok(Some(st)) = child.try_wait() {
            let tail = log_tail(opts);
            let hint = if tail.contains("IncompatibleTypes") || tail.contains("ncompatible") {
                " — iceoryx2 refused its payload type or service settings (IncompatibleTypes): \
                 check type names, sizes and limits against PROTOCOL.md"
            } else {
                ""
            };
            report.fail(
                RuleId::Connects,
                format!(
                    "it ended ({}) before reporting Ready{hint}; its last output:\n{tail}",
                    describe(&st)
                ),
            );
            skip_rest(report, "it never connected");
            return Ok(());
        }
        if Instant::now() > deadline {
            report.fail(
                RuleId::Connects,
                format!("no Ready within {} s", opts.start_timeout),
            );
            skip_rest(report, "it never connected");
            return Err(());
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    report.pass(RuleId::Connects);
    if control
        .send_copy(ControlMsg::new(ControlCommand::Start))
        .is_err()
    {
        report.fail(RuleId::Connects, "attsync could not send Start");
        return Err(());
    }

    // Lockstep.
    let mut hood = Neighbourhood::new(net, index);
    let withhold_at = exchange_from(cfg, WITHHOLD_FROM);
    let nan_at = exchange_from(cfg, NAN_FROM.max(withhold_at.map_or(0, |w| w.0 + 1)));
    let stage_timeout = Duration::from_secs_f64(opts.stage_timeout);
    let mut early: Option<StateMsg> = None;
    let mut after_nan = false;
    let mut last_cand: Option<Exchanged> = None;
    let mut record = LawRecord::default();
    for n in 0..cfg.steps {
        for s in 0..4u32 {
            if !cfg.coupling.exchanges_at(n, s as usize) {
                hood.advance();
                continue;
            }
            let withhold = Some((n, s)) == withhold_at;
            let publish = |hood: &Neighbourhood| {
                let mut sent = Vec::with_capacity(cfg.inputs.len());
                for (k, (&j, p)) in cfg.inputs.iter().zip(input_pubs).enumerate() {
                    let mut m = StateMsg::new(j, n, s, &hood.exchange_of(net, j));
                    if Some((n, s)) == nan_at && k == 0 {
                        m.w[0] = f64::NAN;
                    }
                    sent.push(m.exchanged());
                    let _ = p.send_copy(m);
                }
                let _ = cand_wake.notify();
                sent
            };
            let mut delivered = Vec::new();
            if !withhold {
                delivered = publish(&hood);
            }
            // The candidate's state of (n, s).
            let deadline = Instant::now() + stage_timeout;
            let msg = loop {
                if let Some(m) = early.take() {
                    break m;
                }
                if let Ok(Some(m)) = subs[0].receive() {
                    break *m;
                }
                tcheck.drain(tele, id, cfg.steps);
                if let Ok(Some(st)) = child.try_wait() {
                    let why = format!(
                        "it ended ({}) at step {n} stage {s}; its last output:\n{}",
                        describe(&st),
                        log_tail(opts)
                    );
                    if after_nan {
                        report.fail(RuleId::RefusesInvalid, format!("after a NaN input {why}"));
                    }
                    report.fail(RuleId::InOrder, why);
                    skip_rest(report, "it exited during the run");
                    return Ok(());
                }
                if Instant::now() > deadline {
                    report.fail(
                        RuleId::InOrder,
                        format!(
                            "no state for step {n} stage {s} within {} s",
                            opts.stage_timeout
                        ),
                    );
                    skip_rest(report, "it stopped publishing");
                    return Err(());
                }
                std::hint::spin_loop();
                std::thread::yield_now();
            };
            for sub in &subs[1..] {
                while let Ok(Some(_)) = sub.receive() {}
            }
            if msg.version != PROTOCOL_VERSION || msg.sender != id {
                report.fail(
                    RuleId::InOrder,
                    format!(
                        "message of version {} from sender {} (expected version {PROTOCOL_VERSION}, sender {id})",
                        msg.version, msg.sender
                    ),
                );
            }
            if (msg.step, msg.stage) != (n, s) {
                report.fail(
                    RuleId::InOrder,
                    format!(
                        "sent step {} stage {} where step {n} stage {s} was due",
                        msg.step, msg.stage
                    ),
                );
                skip_rest(report, "it lost lockstep");
                return Err(());
            }
            let cand = match msg.validated() {
                Ok(x) => Some(x),
                Err(why) => {
                    report.fail(RuleId::ValidStates, format!("step {n} stage {s}: {why}"));
                    if after_nan {
                        report.fail(
                            RuleId::RefusesInvalid,
                            format!("after a NaN input, its state at step {n} stage {s}: {why}"),
                        );
                    }
                    None
                }
            };
            if withhold {
                // It has published (n, s); without our inputs it must not go on.
                std::thread::sleep(WITHHOLD_FOR);
                if let Ok(Some(m)) = subs[0].receive() {
                    let m = *m;
                    report.fail(
                        RuleId::WaitsForInputs,
                        format!(
                            "published step {} stage {} while its inputs of step {n} stage {s} were held back",
                            m.step, m.stage
                        ),
                    );
                    early = Some(m);
                } else {
                    report.pass(RuleId::WaitsForInputs);
                }
                delivered = publish(&hood);
            }
            if Some((n, s)) == nan_at {
                after_nan = true;
            }
            record.exchanges.push(ExchangeRecord {
                step: n,
                stage: s,
                inputs: delivered,
                published: msg.exchanged(),
            });
            last_cand = cand.or(last_cand);
            hood.exchange(last_cand);
            hood.advance();
        }
        tcheck.drain(tele, id, cfg.steps);
    }
    report.pass(RuleId::InOrder);
    report.pass(RuleId::ValidStates);
    if after_nan {
        report.pass(RuleId::RefusesInvalid);
    } else {
        report.not_checked(
            RuleId::RefusesInvalid,
            "the run is too short to inject a NaN",
        );
    }
    if withhold_at.is_none() {
        report.not_checked(
            RuleId::WaitsForInputs,
            "the run is too short to hold inputs back",
        );
    }

    // Done, then Stop.
    let deadline = Instant::now() + stage_timeout;
    while !tcheck.done && Instant::now() < deadline {
        tcheck.drain(tele, id, cfg.steps);
        std::thread::sleep(Duration::from_millis(1));
    }
    match tcheck.verdict() {
        Ok(()) => report.pass(RuleId::Telemetry),
        Err(why) => report.fail(RuleId::Telemetry, why),
    }
    record.samples = std::mem::take(&mut tcheck.samples);
    super::law::judge(cfg, &record, opts.law, report);
    if control
        .send_copy(ControlMsg::new(ControlCommand::Stop))
        .is_err()
    {
        report.not_checked(RuleId::Stops, "attsync could not send Stop");
        return Err(());
    }
    match wait_exit(child, EXIT_TIMEOUT) {
        Some(st) if st.success() => report.pass(RuleId::Stops),
        Some(st) => report.fail(
            RuleId::Stops,
            format!("told to stop, it ended with {}", describe(&st)),
        ),
        None => {
            report.fail(
                RuleId::Stops,
                format!("still running {} s after Stop", EXIT_TIMEOUT.as_secs()),
            );
            return Err(());
        }
    }
    Ok(())
}
