//! Lookahead on delayed inputs (conservative synchronisation, PROTOCOL.md
//! § 10.9): a link with a delay of d steps hands the receiver at (n, s) the
//! sender's state of (n − d, s) or older, so at its exchange (n, s) a node
//! waits for that input only until it has taken the message stamped
//! (n − d, s); it takes every message up to its own slot that has come,
//! each placed by its stamp (the link's draws are made in stamp order, so
//! the result is the lockstep one, bit for bit). A sender may thus run up
//! to d steps ahead, as far as the buffers on the path hold (a full buffer
//! holds the sender back: less lookahead, never another result).
//!
//! The node's own exchange stamps since the oldest one some delayed input
//! has not delivered are kept, to check that every input sends each of
//! them, in order (as lockstep checks).

use super::hooks::{Hooked, Hooks};
use super::{Inputs, NodeError, Orphan, Stepper, check_origin};
use crate::wait::Waiter;
use iceoryx2::prelude::*;
use msgs::StateMsg;
use msgs::config::NodeConfig;
use std::collections::VecDeque;
use std::time::Instant;

/// A stamp: (step, stage).
pub(crate) type Stamp = (u64, u32);

/// What the node knows of its delayed inputs.
pub(crate) struct Ahead {
    /// Per input: how many steps ahead it may be taken (0: lockstep).
    pub delay: Vec<u64>,
    /// Per input: messages taken.
    taken: Vec<u64>,
    /// Per input: the stamp of the last message taken.
    last: Vec<Option<Stamp>>,
    /// The node's exchange stamps from index `base` on.
    own: VecDeque<Stamp>,
    base: u64,
}

impl Ahead {
    /// `stepper`'s lookahead per input; none for a process that took over
    /// from a crashed one.
    pub(crate) fn new<N: Stepper>(cfg: &NodeConfig, stepper: &N) -> Self {
        let n = cfg.inputs.len();
        let delay = (0..n)
            .map(|k| {
                if cfg.resume.is_some() {
                    0
                } else {
                    stepper.lookahead(k)
                }
            })
            .collect();
        Self {
            delay,
            taken: vec![0; n],
            last: vec![None; n],
            own: VecDeque::new(),
            base: 0,
        }
    }

    /// Whether any input is taken ahead.
    pub(crate) fn any(&self) -> bool {
        self.delay.iter().any(|&d| d > 0)
    }

    /// The node reached exchange `now`.
    pub(crate) fn reached(&mut self, now: Stamp) {
        if self.any() {
            self.own.push_back(now);
        }
    }

    /// Forgets the stamps every delayed input has sent.
    pub(crate) fn trim(&mut self) {
        let Some(oldest) = (self.delay.iter().zip(&self.taken))
            .filter(|(d, _)| **d > 0)
            .map(|(_, t)| *t)
            .min()
        else {
            return;
        };
        while self.base < oldest && self.own.pop_front().is_some() {
            self.base += 1;
        }
    }

    /// The stamp input `k`'s next message must have, if the node has
    /// reached it.
    fn expected(&self, k: usize) -> Option<Stamp> {
        let i = usize::try_from(self.taken[k] - self.base).ok()?;
        self.own.get(i).copied()
    }
}

/// What the loop hands [`take`]: the node's ports and model, what it keeps
/// of its inputs, and how it waits.
pub(crate) struct Taking<'a, 'b, S: Service, N: Stepper, H: Hooks> {
    /// The ports.
    pub io: &'a mut Hooked<'b, S, H>,
    /// The node's configuration.
    pub cfg: &'a NodeConfig,
    /// Its model.
    pub stepper: &'a mut N,
    /// Its inputs' counters and trust checks.
    pub inputs: &'a mut Inputs,
    /// Per input, the first message stamped after the node's slot, kept.
    pub next: &'a mut [Option<StateMsg>],
    /// The waiter.
    pub waiter: &'a mut Waiter,
    /// Whether the orchestrator is gone.
    pub orphan: &'a Orphan,
}

/// At the node's exchange `now`, takes input `k`'s messages stamped up to
/// `now` that have come, waiting (until `deadline`) only until the one
/// stamped `due` or later is taken (`None`: nothing is due).
pub(crate) fn take<S: Service, N: Stepper, H: Hooks>(
    t: &mut Taking<'_, '_, S, N, H>,
    ahead: &mut Ahead,
    k: usize,
    (now, due): (Stamp, Option<Stamp>),
    deadline: Instant,
) -> Result<(), NodeError> {
    let from = t.cfg.inputs[k];
    loop {
        let got = match t.next[k].take() {
            Some(m) => Some(m),
            None => t.io.receive(k)?,
        };
        match got {
            Some(m) if (m.step, m.stage) > now => {
                t.next[k] = Some(m);
                return Ok(());
            }
            Some(m) => {
                check_origin(&m, from)?;
                let stamp = (m.step, m.stage);
                if Some(stamp) != ahead.expected(k) {
                    return Err(NodeError::BadInput {
                        from,
                        why: format!(
                            "it sent step {} stage {} out of order (at the receiver's step {} stage {})",
                            stamp.0, stamp.1, now.0, now.1
                        ),
                    });
                }
                ahead.taken[k] += 1;
                ahead.last[k] = Some(stamp);
                if let Some(x) = t.inputs.accept(t.cfg, k, &m) {
                    t.stepper.receive_stamped(k, x, stamp);
                }
            }
            None => {
                if due.is_none_or(|d| ahead.last[k].is_some_and(|l| l >= d)) {
                    return Ok(());
                }
                if t.waiter.polls() % 64 == 63 {
                    t.orphan.poll()?;
                }
                if t.waiter.wait(&t.io.ports.listener, deadline) {
                    let (step, stage) = due.unwrap_or(now);
                    return Err(NodeError::InputTimeout {
                        from,
                        step,
                        stage,
                        waited: t.cfg.stage_timeout,
                    });
                }
            }
        }
    }
}

/// The stamp a delayed input must have delivered by exchange `(n, s)`:
/// `(n − d, s)`, and before step d its first message (it carries the
/// sender's initial state, the link's history before t = 0).
#[must_use]
pub(crate) fn due(delay: u64, (n, s): Stamp) -> Option<Stamp> {
    Some(n.checked_sub(delay).map_or((0, 0), |m| (m, s)))
}
