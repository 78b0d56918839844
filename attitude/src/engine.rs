//! The in-process engine: every node in one loop, in lockstep, on one
//! thread or several.
//!
//! It runs exactly the protocol of [`crate::agent`] that the
//! process-per-agent engine runs over shared memory, so both produce
//! bit-identical trajectories. On several threads ([`InProcess::with_threads`])
//! each thread steps a contiguous chunk of the agents and the exchanges are
//! barriers; an agent's arithmetic depends only on its own state and the
//! values it holds, so the results are bit-identical for any thread count.
//!
//! # Layout
//! - `crew`: the parallel step (shares of agents, the exchange barrier).
//! - `board`: the values threads leave for each other (atomic words, bit-exact).
//! - `barrier`: a barrier that spins briefly, then blocks.

mod barrier;
mod board;
mod crew;

use crate::agent::Agent;
use crate::guard::{self, Divergence};
use crate::network::{AgentState, Network};
use crate::reference::{Leader, LeaderState};
use crate::schedule::Schedule;
use board::Judged;
use crew::{Board, Plan, Share};

/// Fewest agents per thread [`InProcess::with_threads`] gives a thread:
/// below it the barriers cost more than the thread saves (measured in
/// BENCHMARKS.md, "In-process engine at scale").
pub const MIN_AGENTS_PER_THREAD: usize = 64;

/// The network's state at an output sample.
#[derive(Debug)]
pub struct Snapshot<'a> {
    /// Step index (t = step · dt).
    pub step: u64,
    /// Leader state.
    pub leader: &'a LeaderState,
    /// Agent states, in the order of `Network::agents`.
    pub agents: &'a [AgentState],
}

/// All nodes of a network in one process.
#[derive(Debug)]
pub struct InProcess {
    net: Network,
    leader: Leader,
    agents: Vec<Agent>,
    /// For each agent, the index in `agents` of each neighbour.
    nbr_index: Vec<Vec<usize>>,
    step: u64,
    states: Vec<AgentState>,
    /// The step of the last snapshot `run` handed out, and each agent's
    /// peak torque then.
    sampled: (u64, Vec<f64>),
    /// Threads [`Self::run`] uses (1: the calling thread only).
    threads: usize,
    /// The one-thread step's published values and their verdicts
    /// ([`crate::network::Exchanged::trust`], judged once per sender).
    published: Vec<Judged>,
}

impl InProcess {
    /// Builds the nodes of `net`, to run on the calling thread.
    #[must_use]
    pub fn new(net: &Network) -> Self {
        let leader = Leader::new(net.p, net.leader, net.dt);
        let agents: Vec<Agent> = net
            .agents
            .iter()
            .map(|a| Agent::new(a.model.clone(), a.initial, net.dt))
            .collect();
        let nbr_index = net.neighbour_indices();
        let states = agents.iter().map(|a| *a.state()).collect();
        Self {
            net: net.clone(),
            leader,
            agents,
            nbr_index,
            step: 0,
            states,
            sampled: (0, Vec::new()),
            threads: 1,
            published: Vec::new(),
        }
    }

    /// Runs on up to `threads` threads, each with at least
    /// [`MIN_AGENTS_PER_THREAD`] agents (so a small network stays on one).
    #[must_use]
    pub fn with_threads(self, threads: usize) -> Self {
        let most = (self.agents.len() / MIN_AGENTS_PER_THREAD).max(1);
        self.with_exact_threads(threads.min(most))
    }

    /// Runs on exactly `threads` threads (at most one per agent), however
    /// few agents each gets.
    #[must_use]
    pub fn with_exact_threads(mut self, threads: usize) -> Self {
        self.threads = threads.min(self.agents.len()).max(1);
        self
    }

    /// Threads [`Self::run`] uses.
    #[must_use]
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Steps done so far.
    #[must_use]
    pub fn step_index(&self) -> u64 {
        self.step
    }

    /// The nodes' agents (for peak torques and models).
    #[must_use]
    pub fn agents(&self) -> &[Agent] {
        &self.agents
    }

    /// The current state as a snapshot.
    #[must_use]
    pub fn snapshot(&self) -> Snapshot<'_> {
        Snapshot {
            step: self.step,
            leader: self.leader.state(),
            agents: &self.states,
        }
    }

    /// Advances every node by one step (four stages, exchanging as the
    /// coupling says), on the calling thread.
    pub fn step(&mut self) {
        let published = &mut self.published;
        for slot in Schedule::new(self.net.coupling, self.net.steps).stages(self.step) {
            if slot.exchange {
                let from_leader = Judged::of(self.leader.stage_exchange());
                published.clear();
                published.extend(self.agents.iter().map(|a| Judged::of(a.stage_exchange())));
                for (agent, nbrs) in self.agents.iter_mut().zip(&self.nbr_index) {
                    for (k, &j) in nbrs.iter().enumerate() {
                        let Judged(x, trusted) = published[j];
                        agent.receive_neighbour_judged(k, x, trusted);
                    }
                    agent.receive_leader_judged(from_leader.0, from_leader.1);
                }
            }
            self.leader.advance();
            for agent in &mut self.agents {
                agent.advance();
            }
        }
        self.step += 1;
        for (s, a) in self.states.iter_mut().zip(&self.agents) {
            *s = *a.state();
        }
    }

    /// The step of the last snapshot [`InProcess::run`] handed out, and
    /// each agent's peak torque at that step (what a diverged run reports).
    #[must_use]
    pub fn last_sample(&self) -> (u64, &[f64]) {
        (self.sampled.0, &self.sampled.1)
    }

    /// Books the current step as sampled, then hands its snapshot to `f`.
    fn sample(&mut self, f: &mut impl FnMut(&Snapshot<'_>) -> bool) -> bool {
        self.sampled.0 = self.step;
        self.sampled.1.clear();
        (self.sampled.1).extend(self.agents.iter().map(Agent::peak_torque));
        f(&self.snapshot())
    }

    /// The first node (the leader, then agents in network order) whose
    /// current state is outside the network's envelope ([`crate::guard`]).
    #[must_use]
    pub fn divergence(&self) -> Option<Divergence> {
        guard::first(&self.net, self.step, self.leader.state(), &self.states)
    }

    /// Runs to the end, calling `on_sample` at t = 0 and every
    /// `sample_every` steps. Stops early if `on_sample` returns `false`,
    /// and at once (before sampling) when a state leaves the envelope:
    /// then it returns the divergence. The state is checked at t = 0 and
    /// after every step.
    pub fn run(&mut self, mut on_sample: impl FnMut(&Snapshot<'_>) -> bool) -> Option<Divergence> {
        if self.step == 0 {
            if let Some(d) = self.divergence() {
                return Some(d);
            }
            if !self.sample(&mut on_sample) {
                return None;
            }
        }
        if self.threads > 1 && self.step < self.net.steps {
            return self.run_parallel(on_sample);
        }
        while self.step < self.net.steps {
            self.step();
            if let Some(d) = self.divergence() {
                return Some(d);
            }
            if sample_due(&self.net, self.step) && !self.sample(&mut on_sample) {
                return None;
            }
        }
        None
    }

    /// [`Self::run`] on `self.threads` threads: the calling thread steps
    /// the leader and the first share and samples; a worker steps each
    /// other share (see `crew`).
    fn run_parallel(
        &mut self,
        mut on_sample: impl FnMut(&Snapshot<'_>) -> bool,
    ) -> Option<Divergence> {
        let Self {
            net,
            leader,
            agents,
            nbr_index,
            step,
            states,
            threads,
            sampled,
            ..
        } = self;
        let board = Board::new(agents.len(), *threads);
        let plan = Plan {
            schedule: Schedule::new(net.coupling, net.steps),
            nbr_index,
        };
        let from = *step;
        std::thread::scope(|scope| {
            let mut shares = Share::split(agents, *threads).into_iter();
            let mut mine = shares.next().expect("at least one share");
            for share in shares {
                let board = &board;
                scope.spawn(move || crew::work(share, board, plan, from));
            }
            while *step < net.steps {
                mine.step(&board, plan, *step, Some(leader));
                crew::read_states(&board, states);
                *step += 1;
                if let Some(d) = guard::first(net, *step, leader.state(), states) {
                    crew::release(&board, false);
                    return Some(d);
                }
                let due = sample_due(net, *step);
                if due {
                    sampled.0 = *step;
                    crew::read_peaks(&board, &mut sampled.1);
                }
                let snapshot = Snapshot {
                    step: *step,
                    leader: leader.state(),
                    agents: states,
                };
                let go_on = !due || on_sample(&snapshot);
                crew::release(&board, go_on);
                if !go_on {
                    return None;
                }
            }
            None
        })
    }
}

/// Whether the state after `step` steps is an output sample.
fn sample_due(net: &Network, step: u64) -> bool {
    step % net.sample_every == 0 || step == net.steps
}
