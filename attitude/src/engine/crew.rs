//! The in-process engine on several threads: persistent workers, each
//! stepping a contiguous chunk of the agents; the calling thread steps the
//! first chunk and the leader.
//!
//! Per exchange, one barrier: every value of the exchange is on the board
//! (two buffers, alternating, so nobody overwrites a buffer another thread
//! may still read); after it each thread runs one [`pass`] over its agents
//! (receive, advance, publish the next exchange's value into the other
//! buffer). Per step, two more: the step's end (each share's first agent
//! outside the envelope, checked in its pass, and at a sample every
//! agent's state and peak torque, on the board for the caller) and the
//! go-ahead (the caller is done with them, or says stop). At a sample with
//! per-agent work ([`super::InProcess::run_with`]) one more: each thread
//! does its share's work, then the caller takes every share's results.
//! At a sample before the last step, after the go-ahead, every thread
//! evaluates stage 0 of the sampled step and leaves its agents' torques on
//! the board ([`Share::begin`]); a barrier, then the caller samples and
//! gives a second go-ahead, and the step goes on from stage 1.
//!
//! Every agent does exactly the arithmetic of the one-thread loop, on the
//! same values in the same order, so the trajectories are bit-identical
//! for any number of threads.

use super::PerAgent;
use super::barrier::SpinBarrier;
use super::board::{AGENT_STATE, EXCHANGED, JUDGED, Judged, Lined, Slot as Shared, VECTOR, slots};
use super::pass::{Stage, pass};
use crate::agent::Agent;
use crate::guard::{Envelope, Violation};
use crate::network::{AgentState, Exchanged};
use crate::reference::{Leader, LeaderState};
use crate::schedule::{Schedule, Slot};
use nalgebra::Vector3;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering::SeqCst};

/// What the threads share.
#[derive(Debug)]
pub(super) struct Board {
    /// Published stage states as their receivers hold them
    /// ([`Judged::held`]), two buffers used in turn (exchange k of the run
    /// reads buffer k mod 2; between exchanges the last one's is read):
    /// agents in network order, then the leader.
    published: [Vec<Lined<Shared<JUDGED>>>; 2],
    /// Every agent's state at the end of the last sampled step.
    states: Vec<Shared<AGENT_STATE>>,
    /// Every agent's peak torque at the end of the last sampled step.
    peaks: Vec<Shared<1>>,
    /// Every agent's torque at stage 0 of the last sampled step.
    torques: Vec<Shared<VECTOR>>,
    /// The leader's state at the end of the last sampled step.
    leader: Shared<EXCHANGED>,
    /// Per share, the first agent (network index) outside the envelope
    /// after the last step, if any.
    found: Vec<Mutex<Option<(usize, Violation)>>>,
    barrier: SpinBarrier,
    stop: AtomicBool,
}

impl Board {
    /// A board for `threads` threads whose agents' values are
    /// `published` (the one-thread step's buffers, as it left them).
    pub(super) fn new(published: &[Vec<Judged>; 2], threads: usize) -> Self {
        let agents = published[0].len();
        Self {
            published: published.each_ref().map(|values| {
                let buffer: Vec<Lined<Shared<JUDGED>>> =
                    (0..=agents).map(|_| Lined::default()).collect();
                for (slot, x) in buffer.iter().zip(values) {
                    slot.store(x);
                }
                buffer
            }),
            states: slots(agents),
            peaks: slots(agents),
            torques: slots(agents),
            leader: Shared::default(),
            found: (0..threads).map(|_| Mutex::new(None)).collect(),
            barrier: SpinBarrier::new(threads),
            stop: AtomicBool::new(false),
        }
    }
}

/// What every thread reads and nobody writes.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plan<'a> {
    /// The run's schedule.
    pub schedule: Schedule,
    /// For each agent, the index of each neighbour.
    pub nbr_index: &'a [Vec<usize>],
    /// Output sample period, steps.
    pub sample_every: u64,
    /// The envelope every state is checked against after every step.
    pub guard: &'a Envelope,
}

impl Plan<'_> {
    /// Whether the state after `step` steps is an output sample.
    pub(super) fn sample_due(&self, step: u64) -> bool {
        sample_due(self.sample_every, self.schedule.steps(), step)
    }
}

/// Whether the state after `step` of `steps` steps is an output sample
/// (one every `sample_every` steps, and the last).
pub(super) fn sample_due(sample_every: u64, steps: u64, step: u64) -> bool {
    step % sample_every == 0 || step == steps
}

/// One thread's agents: `agents[0]` is agent `first` of the network.
#[derive(Debug)]
pub(super) struct Share<'a> {
    /// This share's place among the shares.
    index: usize,
    first: usize,
    agents: &'a mut [Agent],
    /// Which published buffer the next exchange reads.
    parity: usize,
    /// The exchange (step, stage) whose values this share's last pass published.
    ready: Option<(u64, u32)>,
    /// Each agent's neighbour values in turn (see `pass`).
    scratch: Vec<Exchanged>,
}

impl<'a> Share<'a> {
    /// Splits `agents` into `threads` contiguous chunks of nearly equal size.
    pub(super) fn split(agents: &'a mut [Agent], threads: usize) -> Vec<Share<'a>> {
        let (n, t) = (agents.len(), threads.max(1));
        let mut rest = agents;
        let mut first = 0;
        (0..t)
            .map(|k| {
                let len = n / t + usize::from(k < n % t);
                let (chunk, tail) = std::mem::take(&mut rest).split_at_mut(len);
                rest = tail;
                let share = Share {
                    index: k,
                    first,
                    agents: chunk,
                    parity: 0,
                    ready: None,
                    scratch: Vec::new(),
                };
                first += len;
                share
            })
            .collect()
    }

    /// Steps this share's agents (and the leader, on the thread that has
    /// it) through step `n` from stage `skip` (1: stage 0 was evaluated by
    /// [`Share::begin`]), one [`pass`] per stage, then leaves on the
    /// board what the caller reads (the first agent outside the envelope;
    /// states and peak torques if the step is sampled) and waits for every
    /// thread (the step's end).
    pub(super) fn step(
        &mut self,
        board: &Board,
        plan: Plan<'_>,
        (n, skip): (u64, usize),
        leader: Option<&mut Leader>,
    ) {
        let mut leader = leader;
        let stages = plan.schedule.stages(n).skip(skip);
        let found = self.stages(board, plan, stages, leader.as_deref_mut());
        self.leave(board, plan.sample_due(n + 1), found, leader.as_deref());
        board.barrier.wait();
    }

    /// Evaluates stage 0 of step `n` for this share's agents (and the
    /// leader, on the thread that has it), leaves their torques on the
    /// board and waits for every thread: a sample's torques.
    pub(super) fn begin(
        &mut self,
        board: &Board,
        plan: Plan<'_>,
        n: u64,
        leader: Option<&mut Leader>,
    ) {
        let first = plan.schedule.stages(n).take(1);
        self.stages(board, plan, first, leader);
        for (slot, agent) in board.torques[self.first..].iter().zip(self.agents.iter()) {
            slot.store(&agent.torque());
        }
        board.barrier.wait();
    }

    /// One [`pass`] per stage of `slots` (the leader's too, with the
    /// thread that has it); the first agent outside the envelope after the
    /// last of them, if it ends a step.
    fn stages(
        &mut self,
        board: &Board,
        plan: Plan<'_>,
        slots: impl Iterator<Item = Slot>,
        mut leader: Option<&mut Leader>,
    ) -> Option<(usize, Violation)> {
        let mut found = None;
        for slot in slots {
            let from_leader = slot
                .exchange
                .then(|| self.exchange(board, slot, leader.as_deref()));
            if let Some(l) = leader.as_deref_mut() {
                l.advance();
            }
            let next = plan.schedule.next(slot).filter(|x| x.exchange);
            let stage = Stage {
                leader: from_leader,
                publish: next.is_some(),
                check: slot.ends_step().then_some(plan.guard),
            };
            // Read this exchange's buffer (between exchanges: the last
            // one's); write the next exchange's (the other one).
            if slot.exchange {
                self.parity ^= 1;
            }
            let read = &board.published[self.parity ^ 1];
            let out = &board.published[self.parity][self.first..];
            let nbrs = &plan.nbr_index[self.first..];
            let before = &read[self.first..];
            found = pass(
                self.agents,
                nbrs,
                (stage, &mut self.scratch),
                |j| read[j].load::<Judged>(),
                |k, a| {
                    let (x, trusted) = a.stage_exchange_judged();
                    let held = before[k].load::<Judged>().0;
                    out[k].store(&Judged::held(x, trusted, &held));
                },
            );
            if let Some(x) = next {
                self.ready = Some((x.step, x.stage));
            }
        }
        found
    }

    /// Which published buffer the next exchange reads.
    pub(super) fn parity(&self) -> usize {
        self.parity
    }

    /// At a sample, `work` for each of this share's agents (network index,
    /// state, the leader's state) into `out`, in order.
    pub(super) fn outputs<T>(
        &self,
        work: &impl PerAgent<T>,
        leader: &LeaderState,
        out: &mut Vec<T>,
    ) {
        out.clear();
        let states = self.agents.iter().map(Agent::state).enumerate();
        out.extend(states.map(|(k, x)| work(self.first + k, x, leader)));
    }

    /// One exchange's meeting: publish (the leader's value, and this
    /// share's unless its last pass did), wait for everyone, then the
    /// leader's value as published.
    fn exchange(&mut self, board: &Board, slot: Slot, leader: Option<&Leader>) -> Judged {
        let buffer = &board.published[self.parity];
        let leader_slot = &buffer[buffer.len() - 1];
        if let Some(l) = leader {
            leader_slot.store(&Judged::of(l.stage_exchange()));
        }
        if self.ready != Some((slot.step, slot.stage)) {
            let last = &board.published[self.parity ^ 1][self.first..];
            let cells = buffer[self.first..].iter().zip(last);
            for ((cell, before), agent) in cells.zip(self.agents.iter_mut()) {
                let (x, trusted) = agent.stage_exchange_judged();
                cell.store(&Judged::held(x, trusted, &before.load::<Judged>().0));
            }
        }
        board.barrier.wait();
        leader_slot.load()
    }

    /// Leaves on the board, after a step, this share's first agent outside
    /// the envelope and, if the step is sampled, its states and peak torques.
    fn leave(
        &self,
        board: &Board,
        sampled: bool,
        found: Option<(usize, Violation)>,
        leader: Option<&Leader>,
    ) {
        if let Some((k, v)) = found {
            *lock(&board.found[self.index]) = Some((self.first + k, v));
        }
        if !sampled {
            return;
        }
        if let Some(l) = leader {
            board.leader.store(l.state());
        }
        for (slot, agent) in board.states[self.first..].iter().zip(self.agents.iter()) {
            slot.store(agent.state());
        }
        for (slot, agent) in board.peaks[self.first..].iter().zip(self.agents.iter()) {
            slot.store(&agent.peak_torque());
        }
    }
}

pub(super) fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// One output list per share (the first unused: the caller gathers into its own).
pub(super) fn outputs<T>(threads: usize) -> Vec<Mutex<Vec<T>>> {
    (0..threads).map(|_| Mutex::new(Vec::new())).collect()
}

/// Whether a sample's per-agent work gives anything (for `()` the
/// outputs and their barrier are skipped, on every thread alike).
pub(super) fn has_outputs<T>() -> bool {
    std::mem::size_of::<T>() != 0
}

/// A worker thread: steps its share from step `from.0` (from its stage 1
/// if `from.1`: stage 0 was evaluated) until the end or until the caller
/// says stop; at each sample, `work` for its agents into `out`, then a
/// barrier (the outputs are ready for the caller); at a sample before the
/// last step, after the go-ahead, stage 0 of the sampled step
/// ([`Share::begin`]) and a second go-ahead.
pub(super) fn work<T: Send>(
    mut share: Share<'_>,
    board: &Board,
    plan: Plan<'_>,
    from: (u64, bool),
    (work, out): (&(impl PerAgent<T> + Sync), &Mutex<Vec<T>>),
) {
    let steps = plan.schedule.steps();
    let mut skip = usize::from(from.1);
    for n in from.0..steps {
        share.step(board, plan, (n, skip), None);
        skip = 0;
        let due = plan.sample_due(n + 1);
        if due && has_outputs::<T>() {
            share.outputs(work, &board.leader.load(), &mut lock(out));
            board.barrier.wait();
        }
        board.barrier.wait();
        if board.stop.load(SeqCst) {
            return;
        }
        if due && n + 1 < steps {
            share.begin(board, plan, n + 1, None);
            board.barrier.wait();
            if board.stop.load(SeqCst) {
                return;
            }
            skip = 1;
        }
    }
}

/// The caller's side at a sample: its own share's outputs, the barrier
/// after which every share's are ready, then all of them in network order
/// into `all`. Work that gives nothing (a zero-sized `T`) is done here,
/// on `states` (every agent's, read from the board).
pub(super) fn gather<T>(
    mine: &Share<'_>,
    board: &Board,
    (work, outs): (&impl PerAgent<T>, &[Mutex<Vec<T>>]),
    (leader, states): (&LeaderState, &[AgentState]),
    all: &mut Vec<T>,
) {
    all.clear();
    if !has_outputs::<T>() {
        all.extend(states.iter().enumerate().map(|(k, x)| work(k, x, leader)));
        return;
    }
    mine.outputs(work, leader, all);
    board.barrier.wait();
    for out in &outs[1..] {
        all.append(&mut lock(out));
    }
}

/// The caller's side after a step's end: the first agent outside the
/// envelope (network index, violation), shares in order.
pub(super) fn read_found(board: &Board) -> Option<(usize, Violation)> {
    board.found.iter().find_map(|f| *lock(f))
}

/// The caller's side after a sampled step's end: reads every agent's state
/// into `states`.
pub(super) fn read_states(board: &Board, states: &mut [AgentState]) {
    for (s, slot) in states.iter_mut().zip(&board.states) {
        *s = slot.load();
    }
}

/// The caller's side after a sample's stage 0 ([`Share::begin`]): every
/// agent's torque into `torques`.
pub(super) fn read_torques(board: &Board, torques: &mut Vec<Vector3<f64>>) {
    torques.clear();
    torques.extend(board.torques.iter().map(|slot| slot.load::<Vector3<f64>>()));
}

/// The caller's side after a sampled step's end: every agent's peak torque into `peaks`.
pub(super) fn read_peaks(board: &Board, peaks: &mut Vec<f64>) {
    peaks.clear();
    peaks.extend(board.peaks.iter().map(|slot| slot.load::<f64>()));
}

/// The caller's side after the run: the agents' published values into
/// `published` as the one-thread step keeps them (the next exchange's
/// first), `parity` being the buffer the next exchange reads.
pub(super) fn read_published(board: &Board, parity: usize, published: &mut [Vec<Judged>; 2]) {
    for (k, values) in published.iter_mut().enumerate() {
        let buffer = &board.published[parity ^ k];
        for (x, slot) in values.iter_mut().zip(buffer) {
            *x = slot.load();
        }
    }
}

/// The caller's go-ahead after a step's end (`go_on: false` stops every
/// worker).
pub(super) fn release(board: &Board, go_on: bool) {
    if !go_on {
        board.stop.store(true, SeqCst);
    }
    board.barrier.wait();
}
