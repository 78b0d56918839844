//! The in-process engine: every node in one loop, in lockstep.
//!
//! It runs exactly the protocol of [`crate::agent`] that the
//! process-per-agent engine runs over shared memory, so both produce
//! bit-identical trajectories.

use crate::agent::Agent;
use crate::guard::{self, Divergence};
use crate::network::{AgentState, Network};
use crate::reference::{Leader, LeaderState};
use crate::schedule::Schedule;

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
}

impl InProcess {
    /// Builds the nodes of `net`.
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
        }
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
    /// coupling says).
    pub fn step(&mut self) {
        let mut published = Vec::with_capacity(self.agents.len());
        for slot in Schedule::new(self.net.coupling, self.net.steps).stages(self.step) {
            if slot.exchange {
                let from_leader = self.leader.stage_exchange();
                published.clear();
                published.extend(self.agents.iter().map(Agent::stage_exchange));
                for (agent, nbrs) in self.agents.iter_mut().zip(&self.nbr_index) {
                    for (k, &j) in nbrs.iter().enumerate() {
                        agent.receive_neighbour(k, published[j]);
                    }
                    agent.receive_leader(from_leader);
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
        while self.step < self.net.steps {
            self.step();
            if let Some(d) = self.divergence() {
                return Some(d);
            }
            if (self.step % self.net.sample_every == 0 || self.step == self.net.steps)
                && !self.sample(&mut on_sample)
            {
                return None;
            }
        }
        None
    }
}
