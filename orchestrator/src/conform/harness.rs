//! The lockstep session with the candidate: attsync as orchestrator, leader
//! and neighbours of one candidate process. [`session`] sets it up and checks
//! rule `clean` at the end; [`Drive`] runs the phases between: connect
//! (rule `connects`), the exchanges ([`super::lockstep`]), then `Done` and
//! `Stop` (rules `telemetry`, `stops`).

use super::candidate::{Candidate, EXIT_TIMEOUT, candidate_config, log_tail, success};
use super::law::LawRecord;
use super::rules::{Report, RuleId};
use super::telemetry_check::TelemetryCheck;
use super::wires::Wires;
use super::{ConformError, ConformOptions};
use crate::launch::namespace::{self, Namespace};
use crate::launch::supervise::describe;
use crate::processes::Ports;
use attitude::network::Network;
use iceoryx2::node::{Node, NodeState, NodeView};
use iceoryx2::prelude::*;
use msgs::Limits;
use msgs::config::NodeConfig;
use std::time::{Duration, Instant};

/// Why a phase did not go on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Halt {
    /// The candidate exited by itself (the failing rule is recorded).
    Exited,
    /// The candidate must be killed (the failing rule is recorded).
    Kill,
}

/// The rules checked after `connects`.
const LATER: [RuleId; 7] = [
    RuleId::InOrder,
    RuleId::WaitsForInputs,
    RuleId::ValidStates,
    RuleId::RefusesInvalid,
    RuleId::Telemetry,
    RuleId::Stops,
    RuleId::Law,
];

/// Everything the phases of a session work on.
pub(super) struct Drive<'a> {
    /// The neighbourhood.
    pub net: &'a Network,
    /// The candidate's index in `net.agents`.
    pub index: usize,
    /// The candidate's configuration.
    pub cfg: &'a NodeConfig,
    /// The options of the check.
    pub opts: &'a ConformOptions,
    /// Where verdicts go.
    pub report: &'a mut Report,
    /// The candidate process.
    pub cand: &'a mut Candidate,
    /// The harness's orchestrator ports (the candidate's telemetry is subscriber 0).
    pub ports: &'a Ports,
    /// The harness's state ports towards the candidate.
    pub wires: &'a Wires,
    /// Checks of the candidate's telemetry.
    pub tcheck: TelemetryCheck,
    /// What it received and published, for rule `law`.
    pub record: LawRecord,
}

/// The lockstep session: every rule but `version`.
pub(super) fn session(
    net: &Network,
    index: usize,
    opts: &ConformOptions,
    report: &mut Report,
) -> Result<(), ConformError> {
    let ns = Namespace::create().map_err(|source| ConformError::Io {
        path: namespace::base_dir(),
        source,
    })?;
    let cfg = candidate_config(net, index, ns.run(), ns.dir(), opts);
    let limits = Limits::of(net);
    let start_timeout = Duration::from_secs_f64(opts.start_timeout);
    let ports = Ports::open(ns, "conform", &limits, &[cfg.id], start_timeout)?;
    let wires = Wires::open(&ports, &cfg, &limits)?;
    let file = (ports.dir()).join(crate::results::layout::node_config_file(cfg.id));
    cfg.write(&file)?;
    let mut cand = Candidate::start(opts, &file, true)?;
    let halt = Drive {
        net,
        index,
        cfg: &cfg,
        opts,
        report,
        cand: &mut cand,
        ports: &ports,
        wires: &wires,
        tcheck: TelemetryCheck::new(&cfg),
        record: LawRecord::default(),
    }
    .drive();
    let killed = halt == Err(Halt::Kill);
    if killed {
        cand.kill();
    }
    check_clean(&cand, &ports, killed, report);
    Ok(())
}

/// Rule `clean`: after the candidate's exit, only our own node remains,
/// and nothing is left in its process group.
fn check_clean(cand: &Candidate, ports: &Ports, killed: bool, report: &mut Report) {
    let leftovers = cand.leftovers();
    if !leftovers.is_empty() {
        report.fail(
            RuleId::Clean,
            format!(
                "processes {leftovers:?} of its process group were still running after it exited"
            ),
        );
        cand.kill_group();
    }
    let mut others = Vec::new();
    let own = ports.node();
    let _ = Node::<ipc::Service>::list(own.config(), |state| {
        match &state {
            NodeState::Alive(v) if v.id() == own.id() => {}
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
}

impl Drive<'_> {
    /// Everything from start-up to exit.
    pub(super) fn drive(mut self) -> Result<(), Halt> {
        self.connect()?;
        self.lockstep()?;
        self.finish()
    }

    /// Marks every rule after `connects` not checked, for `why`.
    pub(super) fn skip_rest(&mut self, why: &str) {
        for r in LATER {
            self.report.not_checked(r, why);
        }
    }

    /// Reads the candidate's telemetry that has arrived.
    pub(super) fn drain_telemetry(&mut self) {
        self.tcheck.drain(self.ports, self.cfg.id, self.cfg.steps);
    }

    /// Rule `connects`: `Ready` within the start timeout; then `Start`.
    fn connect(&mut self) -> Result<(), Halt> {
        let deadline = Instant::now() + Duration::from_secs_f64(self.opts.start_timeout);
        while !self.tcheck.ready {
            self.drain_telemetry();
            if let Some(st) = self.cand.try_exit() {
                let tail = log_tail(self.opts);
                let hint = if tail.contains("IncompatibleTypes") || tail.contains("ncompatible") {
                    " — iceoryx2 refused its payload type or service settings (IncompatibleTypes): \
                     check type names, sizes and limits against PROTOCOL.md"
                } else {
                    ""
                };
                let why = format!(
                    "it ended ({}) before reporting Ready{hint}; its last output:\n{tail}",
                    describe(&st)
                );
                self.report.fail(RuleId::Connects, why);
                self.skip_rest("it never connected");
                return Err(Halt::Exited);
            }
            if Instant::now() > deadline {
                let why = format!("no Ready within {} s", self.opts.start_timeout);
                self.report.fail(RuleId::Connects, why);
                self.skip_rest("it never connected");
                return Err(Halt::Kill);
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        self.report.pass(RuleId::Connects);
        if self.ports.start(None).is_err() {
            self.report
                .fail(RuleId::Connects, "attsync could not send Start");
            return Err(Halt::Kill);
        }
        Ok(())
    }

    /// Rules `telemetry` (after waiting for `Done`) and `stops`.
    fn finish(&mut self) -> Result<(), Halt> {
        let deadline = Instant::now() + Duration::from_secs_f64(self.opts.stage_timeout);
        while !self.tcheck.done && Instant::now() < deadline {
            self.drain_telemetry();
            std::thread::sleep(Duration::from_millis(1));
        }
        match self.tcheck.verdict() {
            Ok(()) => self.report.pass(RuleId::Telemetry),
            Err(why) => self.report.fail(RuleId::Telemetry, why.to_string()),
        }
        self.record.samples = std::mem::take(&mut self.tcheck.samples);
        super::law::judge(self.cfg, &self.record, self.opts.law, self.report);
        if self.ports.stop().is_err() {
            self.report
                .not_checked(RuleId::Stops, "attsync could not send Stop");
            return Err(Halt::Kill);
        }
        match self.cand.wait_exit(EXIT_TIMEOUT) {
            Some(st) if success(&st) => self.report.pass(RuleId::Stops),
            Some(st) => self.report.fail(
                RuleId::Stops,
                format!("told to stop, it ended with {}", describe(&st)),
            ),
            None => {
                let why = format!("still running {} s after Stop", EXIT_TIMEOUT.as_secs());
                self.report.fail(RuleId::Stops, why);
                return Err(Halt::Kill);
            }
        }
        Ok(())
    }
}
