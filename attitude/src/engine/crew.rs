//! The in-process engine on several threads: persistent workers, each
//! stepping a contiguous chunk of the agents; the calling thread steps the
//! first chunk and the leader.
//!
//! Per exchange, one barrier: every thread publishes its nodes' stage
//! states into one of two buffers (alternating, so nobody overwrites a
//! buffer another thread may still read), waits, then reads its inputs
//! from that buffer and advances. Per step, two more: the step's end
//! (every agent's state on the board, so the caller can sample or check
//! them) and the go-ahead (the caller is done with them, or says stop).
//!
//! Every agent does exactly the arithmetic of the one-thread loop, on the
//! same values in the same order, so the trajectories are bit-identical
//! for any number of threads.

use super::barrier::SpinBarrier;
use super::board::{AGENT_STATE, JUDGED, Judged, Slot, slots};
use crate::agent::Agent;
use crate::network::AgentState;
use crate::reference::Leader;
use crate::schedule::Schedule;
use std::sync::atomic::{AtomicBool, Ordering::SeqCst};

/// What the threads share.
#[derive(Debug)]
pub(super) struct Board {
    /// Published stage states, two buffers used in turn: agents in network
    /// order, then the leader.
    published: [Vec<Slot<JUDGED>>; 2],
    /// Every agent's state at the end of the last step.
    states: Vec<Slot<AGENT_STATE>>,
    /// Every agent's peak torque at the end of the last step.
    peaks: Vec<Slot<1>>,
    barrier: SpinBarrier,
    stop: AtomicBool,
}

impl Board {
    /// A board for `agents` agents and `threads` threads.
    pub(super) fn new(agents: usize, threads: usize) -> Self {
        Self {
            published: [slots(agents + 1), slots(agents + 1)],
            states: slots(agents),
            peaks: slots(agents),
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
}

/// One thread's agents: `agents[0]` is agent `first` of the network.
#[derive(Debug)]
pub(super) struct Share<'a> {
    first: usize,
    agents: &'a mut [Agent],
    /// Which published buffer the next exchange uses.
    parity: usize,
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
                    first,
                    agents: chunk,
                    parity: 0,
                };
                first += len;
                share
            })
            .collect()
    }

    /// Steps this share's agents (and the leader, on the thread that has
    /// it) through step `n`, then puts their states on the board and
    /// waits for every thread (the step's end).
    pub(super) fn step(
        &mut self,
        board: &Board,
        plan: Plan<'_>,
        n: u64,
        leader: Option<&mut Leader>,
    ) {
        let mut leader = leader;
        for slot in plan.schedule.stages(n) {
            if slot.exchange {
                self.exchange(board, plan, leader.as_deref());
            }
            if let Some(l) = leader.as_deref_mut() {
                l.advance();
            }
            for agent in self.agents.iter_mut() {
                agent.advance();
            }
        }
        for (slot, agent) in board.states[self.first..].iter().zip(self.agents.iter()) {
            slot.store(agent.state());
        }
        for (slot, agent) in board.peaks[self.first..].iter().zip(self.agents.iter()) {
            slot.store(&agent.peak_torque());
        }
        board.barrier.wait();
    }

    /// One exchange: publish, wait for everyone, receive.
    fn exchange(&mut self, board: &Board, plan: Plan<'_>, leader: Option<&Leader>) {
        let buffer = &board.published[self.parity];
        self.parity ^= 1;
        let leader_slot = &buffer[buffer.len() - 1];
        if let Some(l) = leader {
            leader_slot.store(&Judged::of(l.stage_exchange()));
        }
        for (slot, agent) in buffer[self.first..].iter().zip(self.agents.iter()) {
            slot.store(&Judged::of(agent.stage_exchange()));
        }
        board.barrier.wait();
        let Judged(from_leader, leader_trusted) = leader_slot.load();
        let nbrs = &plan.nbr_index[self.first..];
        for (agent, nbrs) in self.agents.iter_mut().zip(nbrs) {
            for (k, &j) in nbrs.iter().enumerate() {
                let Judged(x, trusted) = buffer[j].load();
                agent.receive_neighbour_judged(k, x, trusted);
            }
            agent.receive_leader_judged(from_leader, leader_trusted);
        }
    }
}

/// A worker thread: steps its share from step `from` until the end or
/// until the caller says stop.
pub(super) fn work(mut share: Share<'_>, board: &Board, plan: Plan<'_>, from: u64) {
    for n in from..plan.schedule.steps() {
        share.step(board, plan, n, None);
        board.barrier.wait();
        if board.stop.load(SeqCst) {
            return;
        }
    }
}

/// The caller's side after a step's end: reads every agent's state into
/// `states`.
pub(super) fn read_states(board: &Board, states: &mut [AgentState]) {
    for (s, slot) in states.iter_mut().zip(&board.states) {
        *s = slot.load();
    }
}

/// The caller's side after a step's end: every agent's peak torque into `peaks`.
pub(super) fn read_peaks(board: &Board, peaks: &mut Vec<f64>) {
    peaks.clear();
    peaks.extend(board.peaks.iter().map(|slot| slot.load::<f64>()));
}

/// The caller's go-ahead after a step's end (`go_on: false` stops every
/// worker).
pub(super) fn release(board: &Board, go_on: bool) {
    if !go_on {
        board.stop.store(true, SeqCst);
    }
    board.barrier.wait();
}
