//! Telemetry collection: one [`NodeSlot`] per node (what it reported so
//! far), every message checked and booked, samples joined into the same
//! snapshots the in-process engine produces ([`Session::collect`]).
//!
//! An agent's sample of step n waits for its torque of step n (telemetry
//! `Torque`, sent after stage 0 of step n) before it joins a snapshot. The
//! torque is optional: a sample whose node reported anything after it
//! (its next sample, `Done`, `Failed`) without its torque has NaN, as has
//! every sample of the run's last step (no torque follows it). When the
//! run fails, the snapshots whose samples all came are still handed out,
//! missing torques NaN.

use super::startup::POLL;
use super::{Ports, Session};
use crate::failure::Failure;
use crate::outcome::{Outcome, Restart};
use attitude::agent::Carried;
use attitude::engine::{NO_TORQUE, Snapshot};
use attitude::guard::{self, Divergence, Envelope, Violation};
use attitude::link::LinkStats;
use attitude::network::AgentState;
use attitude::reference::LeaderState;
use msgs::{Done, FailReason, Telemetry, TelemetryMsg};
use nalgebra::Vector3;
use std::collections::VecDeque;
use std::time::{Duration, Instant};

/// A decoded sample waiting for the rest of its snapshot.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Sampled {
    /// The leader's.
    Leader(LeaderState),
    /// An agent's.
    Agent(AgentSample),
}

/// An agent's sample: its state, its peak torque so far and, once
/// reported, its torque at stage 0 of the sample's step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct AgentSample {
    /// The state at the step's start.
    pub state: AgentState,
    /// The largest `‖τᵢ‖` so far, N·m.
    pub peak_torque: f64,
    /// `τᵢ` at stage 0 of the step, once reported.
    pub tau: Option<Vector3<f64>>,
}

/// A snapshot as the collector assembles it: step, leader, agents and
/// their torques.
type Assembled = (u64, LeaderState, Vec<AgentState>, Vec<Vector3<f64>>);

/// What the orchestrator knows of one node (its telemetry subscriber is the
/// [`Ports`] subscriber of the same index).
#[derive(Debug, Clone)]
pub(crate) struct NodeSlot {
    /// `leader`, `agent-<id>`: its log's name.
    pub name: String,
    /// Its name in messages (a plug-in's says so).
    pub label: String,
    /// Its node id: the only sender its telemetry may carry.
    pub id: u32,
    /// Samples not yet in a snapshot: (step, sample).
    pub pending: VecDeque<(u64, Sampled)>,
    /// It reported `Ready`.
    pub ready: bool,
    /// It reported `Done`.
    pub done: bool,
    /// Largest torque it reported, N·m.
    pub peak_torque: f64,
    /// Its peak torque in the last complete snapshot, N·m (what a diverged
    /// run reports, as the in-process engine does).
    pub snapshot_peak_torque: f64,
    /// Its `Done` report, once it came.
    pub report: Option<Done>,
    /// It reported giving up.
    pub gave_up: bool,
}

impl NodeSlot {
    /// A node that has reported nothing yet.
    pub(crate) fn new(name: String, label: String, id: u32) -> Self {
        Self {
            name,
            label,
            id,
            pending: VecDeque::new(),
            ready: false,
            done: false,
            peak_torque: 0.0,
            snapshot_peak_torque: 0.0,
            report: None,
            gave_up: false,
        }
    }
}

/// Telemetry bookkeeping of every node (index 0 the leader, then agents in
/// network order).
#[derive(Debug)]
pub(crate) struct Collector {
    /// One per node.
    pub slots: Vec<NodeSlot>,
    /// Steps of the last complete snapshot.
    pub steps: u64,
    /// Counters of the impaired links: (from, to, stats).
    pub links: Vec<(u32, u32, LinkStats)>,
    /// (node index, id of the input it gave up waiting for), in arrival order.
    pub blamed: Vec<(usize, u32)>,
    /// Ids of nodes a receiver caught breaking the protocol.
    pub broke_protocol: Vec<u32>,
    /// (node index, divergence): the nodes that left the envelope,
    /// reported by themselves or found in their samples.
    pub diverged: Vec<(usize, Divergence)>,
    /// The envelope every sample is checked against.
    pub guard: Envelope,
    /// The run's steps: the samples of this step have no torque.
    pub horizon: u64,
    /// Nodes that reported a crash, not yet replaced: (node index, what
    /// carries on), in arrival order.
    pub crashes: VecDeque<(usize, Carried)>,
    /// The processes replaced, with (node index, when the crash was booked).
    pub restarts: Vec<(Restart, (usize, Instant))>,
}

impl Collector {
    /// Bookkeeping for `slots`.
    pub(crate) fn new(slots: Vec<NodeSlot>) -> Self {
        Self {
            slots,
            steps: 0,
            links: Vec::new(),
            blamed: Vec::new(),
            broke_protocol: Vec::new(),
            diverged: Vec::new(),
            guard: Envelope::default(),
            horizon: u64::MAX,
            crashes: VecDeque::new(),
            restarts: Vec::new(),
        }
    }

    /// Reads every telemetry message available; `Ok(true)` if any arrived.
    pub(crate) fn drain(&mut self, ports: &Ports) -> Result<bool, Failure> {
        let mut any = false;
        for i in 0..self.slots.len() {
            while let Some(m) = ports
                .receive(i)
                .map_err(|e| Failure::Telemetry(e.to_string()))?
            {
                any = true;
                self.accept(i, &m)?;
            }
        }
        Ok(any)
    }

    /// Checks and books message `m` from node index `i`'s service: it must
    /// carry that node's id and decode.
    pub(crate) fn accept(&mut self, i: usize, m: &TelemetryMsg) -> Result<(), Failure> {
        let slot = &self.slots[i];
        if m.sender != slot.id {
            return Err(Failure::BrokeProtocol {
                node: slot.label.clone(),
                how: format!("its telemetry claims to come from node {}", m.sender),
            });
        }
        let t = m.decode().map_err(|e| Failure::Undecodable {
            node: m.sender,
            why: e.to_string(),
        })?;
        self.take(i, t)
    }

    /// Books report `t` of node index `i`; a sample is checked first
    /// ([`Collector::check_sample`]).
    fn take(&mut self, i: usize, t: Telemetry) -> Result<(), Failure> {
        let env = self.guard;
        match t {
            Telemetry::Ready => {
                self.slots[i].ready = true;
                let restarted = self.restarts.iter_mut().rev().find(|(_, (j, _))| *j == i);
                if let Some((r, (_, begun))) = restarted.filter(|(r, _)| r.handover_ms.is_none()) {
                    r.handover_ms = Some(begun.elapsed().as_secs_f64() * 1e3);
                }
            }
            Telemetry::Crashed {
                step,
                state,
                peak_torque,
            } => self.take_crash(i, step, state, peak_torque)?,
            Telemetry::Sample {
                step,
                state,
                peak_torque,
            } => {
                if !peak_torque.is_finite() {
                    return Err(self.sent_garbage(i, "whose peak_torque is not finite"));
                }
                if self.check_sample(i, step, guard::check_agent(&state, &env))? {
                    let slot = &mut self.slots[i];
                    slot.peak_torque = slot.peak_torque.max(peak_torque);
                    let sample = AgentSample {
                        state,
                        peak_torque,
                        tau: None,
                    };
                    (slot.pending).push_back((step, Sampled::Agent(sample)));
                }
            }
            Telemetry::Torque { step, tau } => self.take_torque(i, step, tau)?,
            Telemetry::LeaderSample { step, state } => {
                if self.check_sample(i, step, guard::check_leader(&state, &env))? {
                    self.slots[i]
                        .pending
                        .push_back((step, Sampled::Leader(state)));
                }
            }
            t => self.take_report(i, t),
        }
        Ok(())
    }

    /// Books a report that is not a sample.
    fn take_report(&mut self, i: usize, t: Telemetry) {
        let slot = &mut self.slots[i];
        match t {
            Telemetry::Ready
            | Telemetry::Sample { .. }
            | Telemetry::LeaderSample { .. }
            | Telemetry::Torque { .. }
            | Telemetry::Crashed { .. } => {}
            Telemetry::LinkStats { from, stats } => self.links.push((from, slot.id, stats)),
            Telemetry::Done(d) => {
                slot.done = true;
                slot.peak_torque = d.peak_torque;
                slot.report = Some(d);
            }
            Telemetry::Failed(reason) => {
                slot.gave_up = true;
                match reason {
                    FailReason::InputTimeout { from } => self.blamed.push((i, from)),
                    FailReason::BadInput { from } => {
                        self.blamed.push((i, from));
                        self.broke_protocol.push(from);
                    }
                    FailReason::Other => {}
                    FailReason::Diverged {
                        step,
                        quantity,
                        value,
                    } => self.diverged.push((
                        i,
                        Divergence {
                            step,
                            node: slot.id,
                            violation: Violation { quantity, value },
                        },
                    )),
                }
            }
        }
    }

    /// Books node index `i`'s crash at `step` (PROTOCOL.md § 10.10): the
    /// counters of its links it reported just before go to its new process,
    /// which reports them, carried on, at its end.
    fn take_crash(
        &mut self,
        i: usize,
        step: u64,
        state: AgentState,
        peak_torque: f64,
    ) -> Result<(), Failure> {
        if i == 0 || guard::check_agent(&state, &self.guard).is_some() || !peak_torque.is_finite() {
            return Err(self.sent_garbage(i, "of a crash with a state out of its envelope"));
        }
        let id = self.slots[i].id;
        let (mine, rest) = std::mem::take(&mut self.links)
            .into_iter()
            .partition(|&(_, to, _)| to == id);
        self.links = rest;
        let links = mine
            .into_iter()
            .map(|(from, _, s)| (from, s))
            .collect::<Vec<_>>();
        let carried = Carried {
            step,
            state,
            peak_torque,
            links,
        };
        self.crashes.push_back((i, carried));
        Ok(())
    }

    /// Books node index `i`'s torque `tau` of step `step` into its sample
    /// of that step, which must be the last it sent (and not of the run's
    /// last step); a diverged node's is ignored, as its samples are.
    fn take_torque(&mut self, i: usize, step: u64, tau: Vector3<f64>) -> Result<(), Failure> {
        if self.diverged.iter().any(|&(j, _)| j == i) {
            return Ok(());
        }
        let horizon = self.horizon;
        match self.slots[i].pending.back_mut() {
            Some((s, Sampled::Agent(a))) if *s == step && a.tau.is_none() && step < horizon => {
                a.tau = Some(tau);
                Ok(())
            }
            _ => Err(self.sent_garbage(
                i,
                &format!("of a torque at step {step} that follows no sample of that step"),
            )),
        }
    }

    /// Whether the first pending sample of `slot` may join a snapshot: the
    /// leader's at once; an agent's once its torque came, or anything after
    /// it (its torque will not come), or at the run's last step; any if
    /// `flush` (the run failed: no more will come).
    fn settled(&self, slot: &NodeSlot, flush: bool) -> bool {
        match slot.pending.front() {
            Some((step, Sampled::Agent(a))) => {
                let later = slot.pending.len() > 1 || slot.done || slot.gave_up;
                flush || later || a.tau.is_some() || *step >= self.horizon
            }
            Some((_, Sampled::Leader(_))) => true,
            None => false,
        }
    }

    /// Checks a sample of node index `i` at `step` whose check against
    /// the envelope gave `violation`: `Ok(true)` to book it; `Ok(false)`
    /// when a value is out of the envelope or not finite (the node
    /// diverged: booked as its divergence); an error when an attitude is
    /// finite but not a rotation (garbage: the node broke the protocol).
    fn check_sample(
        &mut self,
        i: usize,
        step: u64,
        violation: Option<Violation>,
    ) -> Result<bool, Failure> {
        if self.diverged.iter().any(|&(j, _)| j == i) {
            return Ok(false); // a diverged node's later samples mean nothing
        }
        let Some(violation) = violation else {
            return Ok(true);
        };
        if violation.quantity.is_attitude() && violation.value.is_finite() {
            let q = violation.quantity.name();
            return Err(self.sent_garbage(i, &format!("whose attitude {q} is not a rotation")));
        }
        let node = self.slots[i].id;
        let divergence = Divergence {
            step,
            node,
            violation,
        };
        self.diverged.push((i, divergence));
        Ok(false)
    }

    /// The failure of node index `i`, which sent telemetry `what`.
    pub(super) fn sent_garbage(&self, i: usize, what: &str) -> Failure {
        Failure::BrokeProtocol {
            node: self.slots[i].label.clone(),
            how: format!("it sent telemetry {what}"),
        }
    }

    /// The run's divergence: the earliest step, then the first node (the
    /// leader, then agents in network order), as the in-process engine
    /// finds it.
    pub(crate) fn divergence(&self) -> Option<Divergence> {
        (self.diverged.iter())
            .min_by_key(|(i, d)| (d.step, *i))
            .map(|(_, d)| *d)
    }

    /// Whether every node is done and every sample is in a snapshot.
    fn finished(&self) -> bool {
        (self.slots.iter()).all(|s| s.done && s.pending.is_empty())
    }

    /// The next complete snapshot before step `before`, if every node has
    /// sent it (and every agent its torque: [`Collector::settled`]).
    fn next_snapshot(&mut self, before: u64, flush: bool) -> Result<Option<Assembled>, Failure> {
        if self.slots.iter().any(|s| s.pending.is_empty()) {
            return Ok(None);
        }
        let step = self.slots[0].pending[0].0;
        if step >= before {
            return Ok(None);
        }
        if let Some(s) = self.slots.iter().find(|s| s.pending[0].0 != step) {
            return Err(Failure::OutOfStep {
                node: s.name.clone(),
                step: s.pending[0].0,
                leader: step,
            });
        }
        if !self.slots.iter().all(|s| self.settled(s, flush)) {
            return Ok(None);
        }
        let horizon = self.horizon;
        let mut samples = (self.slots.iter_mut()).map(|s| {
            let sample = s.pending.pop_front().expect("non-empty").1;
            if let Sampled::Agent(a) = sample {
                s.snapshot_peak_torque = a.peak_torque;
            }
            (s.name.as_str(), sample)
        });
        let Some((_, Sampled::Leader(leader))) = samples.next() else {
            return Err(Failure::LeaderSentAgentSample);
        };
        let (agents, torques) = samples
            .map(|(name, s)| match s {
                Sampled::Agent(a) if step < horizon => Ok((a.state, a.tau.unwrap_or(NO_TORQUE))),
                Sampled::Agent(a) => Ok((a.state, NO_TORQUE)),
                Sampled::Leader(_) => Err(Failure::AgentSentLeaderSample(name.to_string())),
            })
            .collect::<Result<Vec<_>, _>>()?
            .into_iter()
            .unzip();
        Ok(Some((step, leader, agents, torques)))
    }

    /// What the run produced, ending with `failure` (if it failed).
    pub(crate) fn outcome(mut self, failure: Option<Failure>) -> Outcome {
        self.links.sort_by_key(|&(f, t, _)| (f, t));
        let agents = &self.slots[1..];
        let diverged = self.divergence();
        Outcome {
            peak_torques: (agents.iter())
                .map(|s| match diverged {
                    Some(_) => s.snapshot_peak_torque,
                    None => s.peak_torque,
                })
                .collect(),
            steps: self.steps,
            diverged,
            failure,
            pacing: (agents.iter())
                .map(|s| {
                    (s.report).map_or((0, 0.0), |d| (d.pacing.late_stages, d.pacing.max_lateness))
                })
                .collect(),
            nodes: (self.slots.iter())
                .filter_map(|s| s.report.map(|d| (s.name.clone(), s.id, d)))
                .collect(),
            links: self.links,
            restarts: self.restarts.into_iter().map(|(r, _)| r).collect(),
        }
    }
}

impl Session<'_> {
    /// Collects telemetry into snapshots, handing each to `on_sample`, until
    /// every node is done; fails when a node fails, on an interrupt, or when
    /// no telemetry came for twice the stage timeout (then the snapshots
    /// whose samples all came are handed out first, missing torques NaN).
    pub(super) fn collect(
        &mut self,
        on_sample: &mut impl FnMut(&Snapshot<'_>) -> bool,
    ) -> Result<(), Failure> {
        self.nodes.guard = self.net.guard;
        self.nodes.horizon = self.net.steps;
        let collected = self.collect_until_done(on_sample);
        if let Err(f) = &collected
            && !matches!(f, Failure::WriterStopped)
        {
            // Best effort: the run has failed already.
            let _ = self.hand_out(on_sample, true);
        }
        collected
    }

    /// Hands every complete snapshot before the divergence (if any) to
    /// `on_sample`; `flush`: without waiting for missing torques.
    fn hand_out(
        &mut self,
        on_sample: &mut impl FnMut(&Snapshot<'_>) -> bool,
        flush: bool,
    ) -> Result<(), Failure> {
        let before = self.nodes.divergence().map_or(u64::MAX, |d| d.step);
        while let Some((step, leader, agents, torques)) = self.nodes.next_snapshot(before, flush)? {
            self.nodes.steps = step;
            let snap = Snapshot {
                step,
                leader: &leader,
                agents: &agents,
                torques: &torques,
            };
            if !on_sample(&snap) {
                return Err(Failure::WriterStopped);
            }
        }
        Ok(())
    }

    /// [`Session::collect`] without the last hand-out of a failed run.
    fn collect_until_done(
        &mut self,
        on_sample: &mut impl FnMut(&Snapshot<'_>) -> bool,
    ) -> Result<(), Failure> {
        let stall = Duration::from_secs_f64(self.opts.stage_timeout * 2.0);
        let mut last_progress = Instant::now();
        let mut diverging: Option<Instant> = None;
        loop {
            self.ports.wait(POLL);
            if self.nodes.drain(&self.ports)? {
                last_progress = Instant::now();
            }
            self.restart_crashed()?;
            self.hand_out(on_sample, false)?;
            if !self.nodes.diverged.is_empty() {
                // Every node finishes the step (a diverged node keeps its
                // ports) and reports its own divergence: wait until they
                // are quiet, recording the snapshots before it. The text
                // is the divergence's (`crate::run`).
                let since = *diverging.get_or_insert_with(Instant::now);
                if last_progress.elapsed() >= QUIET || since.elapsed() >= SETTLE {
                    return Err(Failure::Diverged(None));
                }
                continue;
            }
            if self.nodes.finished() {
                return Ok(());
            }
            self.still_running()?;
            if last_progress.elapsed() > stall {
                return Err(Failure::Stalled {
                    seconds: stall.as_secs_f64(),
                });
            }
        }
    }
}

/// After a divergence: the telemetry silent this long, every node has
/// reported whether it diverged at that step.
const QUIET: Duration = Duration::from_millis(300);
/// After a divergence: the longest wait for the other nodes' reports.
const SETTLE: Duration = Duration::from_secs(5);

#[cfg(test)]
mod tests {
    use super::*;

    fn two_nodes() -> Collector {
        Collector::new(vec![
            NodeSlot::new("leader".into(), "leader".into(), 0),
            NodeSlot::new("agent-3".into(), "agent-3 (plug-in `x`)".into(), 3),
        ])
    }

    #[test]
    fn telemetry_from_a_false_sender_fails_naming_the_node() {
        let mut c = two_nodes();
        let m = TelemetryMsg::encode(7, &Telemetry::Ready);
        let e = c.accept(1, &m).expect_err("a false sender").to_string();
        assert!(
            e.starts_with("agent-3 (plug-in `x`) broke the protocol"),
            "{e}"
        );
        assert!(e.contains("node 7"), "{e}");
        assert!(!c.slots[1].ready);
    }

    #[test]
    fn telemetry_from_its_own_node_is_booked() {
        let mut c = two_nodes();
        c.accept(1, &TelemetryMsg::encode(3, &Telemetry::Ready))
            .expect("its own id");
        assert!(c.slots[1].ready && !c.slots[0].ready);
    }

    #[test]
    fn undecodable_telemetry_fails_naming_the_node() {
        let mut c = two_nodes();
        let mut m = TelemetryMsg::encode(3, &Telemetry::Ready);
        m.kind = 99;
        let e = c.accept(1, &m).expect_err("an unknown kind").to_string();
        assert!(e.starts_with("node 3's telemetry"), "{e}");
    }

    fn sample(step: u64, w1: f64, r_scale: f64) -> TelemetryMsg {
        let state = AgentState {
            r: nalgebra::Matrix3::identity() * r_scale,
            w: nalgebra::Vector3::new(0.0, w1, 0.0),
            r_hat: nalgebra::Matrix3::identity(),
            w_hat: nalgebra::Vector3::zeros(),
            s_hat: nalgebra::Vector3::zeros(),
        };
        let t = Telemetry::Sample {
            step,
            state,
            peak_torque: 1.0,
        };
        TelemetryMsg::encode(3, &t)
    }

    fn leader_sample(step: u64) -> TelemetryMsg {
        let state = LeaderState {
            r0: nalgebra::Matrix3::identity(),
            w0: nalgebra::Vector3::zeros(),
            s0: nalgebra::Vector3::zeros(),
        };
        TelemetryMsg::encode(0, &Telemetry::LeaderSample { step, state })
    }

    fn torque(step: u64, x: f64) -> TelemetryMsg {
        let tau = Vector3::new(x, -x, 0.5);
        TelemetryMsg::encode(3, &Telemetry::Torque { step, tau })
    }

    /// A collector of a run of `horizon` steps, the leader's samples at
    /// `steps` booked.
    fn running(horizon: u64, steps: &[u64]) -> Collector {
        let mut c = two_nodes();
        c.horizon = horizon;
        for &s in steps {
            c.accept(0, &leader_sample(s)).expect("the leader's sample");
        }
        c
    }

    #[test]
    fn a_sample_waits_for_its_torque_then_carries_it() {
        let mut c = running(20, &[0, 10, 20]);
        c.accept(1, &sample(0, 1.0, 1.0)).expect("a sample");
        assert!(c.next_snapshot(u64::MAX, false).unwrap().is_none());
        c.accept(1, &torque(0, 0.25)).expect("its torque");
        let (step, _, _, torques) = c.next_snapshot(u64::MAX, false).unwrap().unwrap();
        assert_eq!((step, torques), (0, vec![Vector3::new(0.25, -0.25, 0.5)]));
        // The last step's sample needs none, and has none.
        c.accept(1, &sample(10, 1.0, 1.0)).expect("a sample");
        c.accept(1, &torque(10, 1.0)).expect("its torque");
        c.accept(1, &sample(20, 1.0, 1.0)).expect("the last sample");
        assert!(c.next_snapshot(u64::MAX, false).unwrap().is_some());
        let (step, _, _, torques) = c.next_snapshot(u64::MAX, false).unwrap().unwrap();
        assert_eq!(step, 20);
        assert!(torques[0].iter().all(|x| x.is_nan()));
    }

    #[test]
    fn a_node_that_reports_no_torque_has_nan_once_it_reports_more() {
        let mut c = running(20, &[0, 10]);
        c.accept(1, &sample(0, 1.0, 1.0)).expect("a sample");
        assert!(c.next_snapshot(u64::MAX, false).unwrap().is_none());
        c.accept(1, &sample(10, 1.0, 1.0)).expect("the next sample");
        let (step, _, _, torques) = c.next_snapshot(u64::MAX, false).unwrap().unwrap();
        assert_eq!(step, 0);
        assert!(torques[0].iter().all(|x| x.is_nan()));
        // A failed run hands out what it has, without waiting.
        assert!(c.next_snapshot(u64::MAX, false).unwrap().is_none());
        assert!(c.next_snapshot(u64::MAX, true).unwrap().is_some());
    }

    #[test]
    fn a_torque_without_its_sample_fails_naming_the_node() {
        let mut c = running(20, &[0]);
        c.accept(1, &sample(0, 1.0, 1.0)).expect("a sample");
        let e = c
            .accept(1, &torque(10, 1.0))
            .expect_err("no sample of step 10");
        assert!(
            e.to_string()
                .starts_with("agent-3 (plug-in `x`) broke the protocol")
        );
        assert!(e.to_string().contains("torque at step 10"), "{e}");
    }

    #[test]
    fn a_nan_sample_is_the_nodes_divergence_and_is_not_booked() {
        let mut c = two_nodes();
        c.accept(1, &sample(0, 1.0, 1.0)).expect("a sane sample");
        c.accept(1, &sample(10, f64::NAN, 1.0))
            .expect("a divergence, not an error");
        assert_eq!(c.slots[1].pending.len(), 1);
        let d = c.divergence().expect("diverged");
        assert_eq!((d.step, d.node), (10, 3));
        assert_eq!(d.violation.quantity, attitude::guard::Quantity::Omega);
        assert!(d.violation.value.is_nan());
        // Later samples of a diverged node are not booked either.
        c.accept(1, &sample(20, 1.0, 1.0)).expect("ignored");
        assert_eq!(c.slots[1].pending.len(), 1);
    }

    #[test]
    fn a_sample_whose_attitude_is_not_a_rotation_fails_naming_the_node() {
        let mut c = two_nodes();
        let e = c
            .accept(1, &sample(0, 1.0, 2.0))
            .expect_err("2·I")
            .to_string();
        assert_eq!(
            e,
            "agent-3 (plug-in `x`) broke the protocol: it sent telemetry whose attitude r is not a rotation"
        );
        assert!(c.diverged.is_empty() && c.slots[1].pending.is_empty());
    }

    #[test]
    fn the_earliest_divergence_wins_then_the_first_node() {
        let mut c = two_nodes();
        let diverged = |step, quantity| {
            Telemetry::Failed(FailReason::Diverged {
                step,
                quantity,
                value: 2e4,
            })
        };
        use attitude::guard::Quantity;
        c.accept(
            1,
            &TelemetryMsg::encode(3, &diverged(7, Quantity::SigmaHat)),
        )
        .expect("booked");
        c.accept(0, &TelemetryMsg::encode(0, &diverged(7, Quantity::Omega0)))
            .expect("booked");
        assert_eq!(c.divergence().map(|d| d.node), Some(0));
        c.accept(1, &TelemetryMsg::encode(3, &diverged(6, Quantity::R)))
            .expect("booked");
        let d = c.divergence().expect("diverged");
        assert_eq!((d.step, d.node, d.violation.quantity), (6, 3, Quantity::R));
        assert!(c.slots[1].gave_up);
    }
}
