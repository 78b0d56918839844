//! The scripted neighbourhood: every node but the candidate, run by attsync
//! on its own model ([`Agent`], [`Leader`]), fed with what the candidate
//! publishes, so that the candidate runs in a real closed loop.

use attitude::agent::Agent;
use attitude::network::{Exchanged, Network};
use attitude::reference::Leader;

/// The other nodes, run by attsync.
pub(super) struct Neighbourhood {
    leader: Leader,
    /// Every agent but the candidate (`None` at its place).
    agents: Vec<Option<Agent>>,
    /// Per agent, the network index of each neighbour.
    nbr_index: Vec<Vec<usize>>,
    candidate: usize,
}

impl Neighbourhood {
    /// Every node of `net` but agent `candidate`, at their initial states.
    pub(super) fn new(net: &Network, candidate: usize) -> Self {
        let agents = net
            .agents
            .iter()
            .enumerate()
            .map(|(i, a)| (i != candidate).then(|| Agent::new(a.model.clone(), a.initial, net.dt)))
            .collect();
        let nbr_index = net.neighbour_indices();
        Self {
            leader: Leader::new(net.p, net.leader, net.dt).with_repoints(net.repoint.clone()),
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
    pub(super) fn exchange(&mut self, cand: Option<Exchanged>) {
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

    /// The candidate's inputs now: (sender id, what it publishes), for each
    /// id of `inputs` (the candidate's configured inputs, in order).
    pub(super) fn inputs(&self, net: &Network, inputs: &[u32]) -> Vec<(u32, Exchanged)> {
        (inputs.iter())
            .map(|&j| (j, self.exchange_of(net, j)))
            .collect()
    }

    /// Every node but the candidate advances one stage.
    pub(super) fn advance(&mut self) {
        self.leader.advance();
        for a in self.agents.iter_mut().flatten() {
            a.advance();
        }
    }
}
