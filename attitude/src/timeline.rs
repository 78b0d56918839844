//! Events in simulated time, resolved into whole steps: what a scenario's
//! `[[event]]` tables do to the model.
//!
//! - An **outage** of a directed link: during steps `[from, to)` the link
//!   carries nothing. A message stamped `(m, s)` with `from ≤ m < to` is
//!   dropped on the receiving side *after* the link's loss and jitter draws
//!   ([`crate::link`]), so the random streams advance as if the link were
//!   up and the losses after the outage are those of a run without it. A
//!   cut edge, a cut leader link and a silenced agent (all links out of it)
//!   are outages; the receiver holds its last value, as for a lost message,
//!   or, for an outage that says `forget`, leaves the input out of its law
//!   meanwhile (the edge is gone: a switching graph).
//! - A **retune**: from the start of step `step` an agent runs with other
//!   scheme gains (`set = { "scheme.control.k_r" = … }`).
//! - A **repoint**: at the start of step `step` the constant reference
//!   `R₀` jumps to another attitude (`set = { "leader.attitude" = … }`).
//! - A **crash** of an agent at the start of step `from`: until step `to`
//!   (its restart) it is not simulated at all. Its state stays what it was
//!   at the crash, it applies no torque, it hears nothing, and its
//!   receivers get nothing from it (an outage that holds, resolved into
//!   their timelines). At `to` it starts afresh: from the state it had at
//!   the crash (`last`) or its initial state (`initial`), with its links
//!   as at t = 0 (nothing in flight, random streams from their seeds), its
//!   held values the identity until its inputs' next exchange, the body's
//!   random effects and the rate limit's anchor reset; the counters of its
//!   links and its peak torque carry on.
//!
//! Nothing here knows about seconds: the scenario resolves `t` into steps
//! (`t = step · dt`). `PROTOCOL.md` § 10.10 states it for plug-ins.

use crate::network::Scheme;
use nalgebra::Matrix3;
use serde::{Deserialize, Serialize};

/// Steps `[from, to)` in which a link carries nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Outage {
    /// First step of the outage.
    pub from: u64,
    /// First step after it.
    pub to: u64,
    /// Whether the receiver leaves the input out of its law meanwhile (at
    /// every stage of steps `[from, to)`: the edge is removed, a switching
    /// graph) instead of holding the last value it had (`false`, as for a
    /// lost message).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub forget: bool,
}

impl Outage {
    /// Whether a message stamped with step `m` falls in the outage.
    #[must_use]
    pub fn covers(&self, m: u64) -> bool {
        (self.from..self.to).contains(&m)
    }
}

/// The outages of the link from one sender to an agent.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct InputOutages {
    /// The sender's id (0: the leader).
    pub from: u32,
    /// Sorted by (`forget`, `from`); outages of one mode are disjoint.
    pub outages: Vec<Outage>,
}

/// Other scheme gains from the start of step `step`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Retune {
    /// The first step run with `scheme`.
    pub step: u64,
    /// The scheme with its new gains (the kind never changes).
    pub scheme: Scheme,
}

/// The constant reference jumps to `r0` at the start of step `step`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Repoint {
    /// The first step with the new reference.
    pub step: u64,
    /// The new `R₀` (ω₀ = σ₀ = 0: a constant reference).
    pub r0: Matrix3<f64>,
}

/// The agent's process ends at the start of step `from`; a new one takes
/// over at the start of step `to` (`None`: it stays down to the end).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Crash {
    /// The first step it is down.
    pub from: u64,
    /// The step it restarts at, if it does.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<u64>,
    /// Whether it restarts from its initial state (else from the state it
    /// had at the crash).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub initial: bool,
}

/// What one agent's timeline holds (empty: nothing happens to it).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct AgentTimeline {
    /// Outages of its inputs, by ascending sender id.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub down: Vec<InputOutages>,
    /// Changes of its gains, by ascending step.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub retune: Vec<Retune>,
    /// Its crashes, by ascending step, disjoint.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub crashes: Vec<Crash>,
}

impl AgentTimeline {
    /// Whether nothing happens (then it is not written).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.down.is_empty() && self.retune.is_empty() && self.crashes.is_empty()
    }

    /// The crash that starts at step `n`, if one does.
    #[must_use]
    pub fn crash_at(&self, n: u64) -> Option<&Crash> {
        self.crashes.iter().find(|c| c.from == n)
    }

    /// The outages of the input from `sender` (0: the leader).
    #[must_use]
    pub fn outages_of(&self, sender: u32) -> &[Outage] {
        self.down
            .iter()
            .find(|d| d.from == sender)
            .map_or(&[], |d| &d.outages)
    }
}

/// The inputs an agent leaves out of its law at a step (outages with
/// `forget`), and the inputs that remain, gathered once per stage.
#[derive(Debug, Clone, Default)]
pub(crate) struct Absent {
    /// Per input (neighbours, then the leader): left out now.
    pub(crate) now: Vec<bool>,
    /// Whether any is.
    pub(crate) any: bool,
    /// The remaining neighbours' gains and values, in order.
    pub(crate) gains: Vec<Matrix3<f64>>,
    pub(crate) nbrs: Vec<crate::network::Exchanged>,
}

impl Absent {
    /// The neighbours of `gains`, `nbrs` not left out, into `self.gains`, `self.nbrs`.
    pub(crate) fn keep(&mut self, gains: &[Matrix3<f64>], nbrs: &[crate::network::Exchanged]) {
        self.gains.clear();
        self.nbrs.clear();
        for ((a, x), out) in gains.iter().zip(nbrs).zip(&self.now) {
            if !out {
                self.gains.push(*a);
                self.nbrs.push(*x);
            }
        }
    }

    /// Whether the leader (the input after the neighbours) is left out now.
    pub(crate) fn leader(&self, neighbours: usize) -> bool {
        self.now.get(neighbours).copied().unwrap_or(false)
    }
}

/// Walks a list of changes sorted by step: the one due at a step, once.
#[derive(Debug, Clone, Default)]
pub(crate) struct Due {
    next: usize,
}

impl Due {
    /// The change of `list` due at step `n`, if any (each is returned once;
    /// `n` must not decrease between calls).
    pub(crate) fn at<'a, T>(
        &mut self,
        list: &'a [T],
        n: u64,
        step: impl Fn(&T) -> u64,
    ) -> Option<&'a T> {
        let mut due = None;
        while let Some(x) = list.get(self.next).filter(|x| step(x) <= n) {
            due = Some(x);
            self.next += 1;
        }
        due
    }
}
