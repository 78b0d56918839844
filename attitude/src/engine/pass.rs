//! One stage of a run of agents, in one pass: each agent receives its
//! inputs (at an exchange; the values stay on the board), advances, publishes its next stage state (when
//! the next stage is an exchange) and, at the end of a step, is checked
//! against the envelope ([`crate::guard`]; before publishing, so that the
//! check settles the published value's verdict too). Each agent's data is touched
//! once per stage, while it is in the cache.
//!
//! Both the one-thread step and every thread of the crew run this pass:
//! the same calls on each agent, in the same order, as receiving for
//! every agent, then advancing every agent, then publishing and checking
//! every agent (an agent's calls touch only its own state), so the
//! results are those of separate passes, bit for bit.

use super::board::Judged;
use crate::agent::Agent;
use crate::guard::{Envelope, Violation};
use crate::network::Exchanged;
use std::borrow::Borrow;

/// What a stage's pass does besides advancing every agent.
#[derive(Debug, Clone, Copy)]
pub(super) struct Stage<'a> {
    /// At an exchange: the leader's published value (every agent then
    /// receives its inputs first).
    pub leader: Option<Judged>,
    /// Whether the next stage is an exchange (every agent then publishes
    /// its new stage state).
    pub publish: bool,
    /// At the end of a step: the envelope every agent's new state is
    /// checked against.
    pub check: Option<&'a Envelope>,
}

/// Runs `stage` over `agents` (`nbr_index[k]`: the network indices of agent
/// `k`'s neighbours). `read(j)` is (or borrows) what agent `j` of the
/// network published for this exchange (between exchanges: the last one),
/// as its receivers hold it ([`Judged::held`]); `write(k, agent)` publishes
/// agent `k`'s value for the next one ([`Agent::publish_into`]). Each
/// agent's neighbour values go from the board into `scratch` (one buffer
/// for all agents, so it stays in the cache) and are evaluated there
/// ([`Agent::advance_with`]): no agent keeps a copy. Returns the first
/// agent (index in `agents`) whose new state is outside the envelope, and
/// its violation.
pub(super) fn pass<J: Borrow<Judged>>(
    agents: &mut [Agent],
    nbr_index: &[Vec<usize>],
    (stage, scratch): (Stage<'_>, &mut Vec<Exchanged>),
    read: impl Fn(usize) -> J,
    mut write: impl FnMut(usize, &mut Agent),
) -> Option<(usize, Violation)> {
    let mut first = None;
    for (k, (agent, nbrs)) in agents.iter_mut().zip(nbr_index).enumerate() {
        scratch.clear();
        for (m, &j) in nbrs.iter().enumerate() {
            let held = read(j);
            let Judged(x, ok) = held.borrow();
            if stage.leader.is_some() {
                agent.hear_neighbour(m, x, *ok);
            }
            scratch.push(*x);
        }
        if let Some(Judged(from_leader, trusted)) = &stage.leader {
            agent.receive_leader_judged(*from_leader, *trusted);
        }
        agent.advance_with(scratch);
        // The check first: a state it passes needs no second look when
        // published at the next stage 0 (`Agent::check`).
        if let Some(env) = stage.check.filter(|_| first.is_none()) {
            first = agent.check(env).map(|v| (k, v));
        }
        if stage.publish {
            write(k, agent);
        }
    }
    first
}
