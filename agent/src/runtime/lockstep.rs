//! Deterministic lockstep: the node walks the run's [`Schedule`]; at every
//! exchange (n, s) it publishes its stage state stamped (n, s), wakes its
//! receivers, waits (bounded) until every input's message stamped (n, s)
//! has arrived, then advances one stage. An input on a link delayed by d
//! steps is waited for only up to (n − d, s) (`lookahead.rs`).

use super::hooks::{Hooked, Hooks};
use super::lookahead::{self, Ahead, Stamp, Taking};
use super::{
    Inputs, NodeError, Orphan, Stepper, after_stage_0, after_step, before_step, check_origin,
    crash_point,
};
use crate::wait::Waiter;
use attitude::schedule::{Schedule, Slot};
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::{Pacing, StateMsg};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Steps `cfg.steps` steps in lockstep (always on time: no pacing to report).
pub(crate) fn run<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &mut N,
    inputs: &mut Inputs,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<Pacing, NodeError> {
    let mut waiter = Waiter::new(cfg.wait).with_contention(cfg.contention);
    let first = cfg.resume.as_ref().map_or(0, |r| r.step);
    if first == 0 {
        io.report(stepper.sample(0))?;
    }
    let mut held = Held::new(cfg, stepper);
    let mut last: Option<Stamp> = None;
    let slots = Schedule::new(cfg.coupling, cfg.steps).slots();
    for slot in slots.skip_while(|s| s.step < first) {
        if slot.starts_step() {
            before_step(slot.step, shutdown, orphan)?;
            if slot.step > first {
                crash_point(io, (cfg, inputs), stepper, slot.step, (shutdown, orphan))?;
            }
        }
        if slot.exchange && stepper.is_down() {
            stand_in(io, cfg, stepper, (&mut held, &mut waiter), slot, orphan)?;
        } else if slot.exchange {
            let take = (&mut *inputs, &mut held);
            exchange(io, cfg, stepper, take, &mut waiter, slot, orphan)?;
            last = Some((slot.step, slot.stage));
        }
        stepper.advance();
        if slot.starts_step() {
            after_stage_0(io, cfg, stepper, slot.step)?;
        }
        if slot.ends_step() {
            after_step(io, cfg, stepper, slot.step + 1)?;
        }
    }
    if let Some(end) = last.filter(|_| held.ahead.any()) {
        drain(
            io,
            cfg,
            stepper,
            (inputs, &mut held),
            &mut waiter,
            end,
            orphan,
        )?;
    }
    Ok(Pacing::default())
}

/// Takes what the delayed inputs sent up to the last exchange `end`
/// (nothing of it is used any more, but the links count it as lockstep does).
fn drain<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &mut N,
    (inputs, held): (&mut Inputs, &mut Held),
    waiter: &mut Waiter,
    end: Stamp,
    orphan: &Orphan,
) -> Result<(), NodeError> {
    let deadline = Instant::now() + Duration::from_secs_f64(cfg.stage_timeout);
    waiter.begin();
    for k in 0..cfg.inputs.len() {
        if held.ahead.delay[k] > 0 {
            let node = (&mut *io, cfg, &mut *stepper, &mut *inputs);
            held.take_ahead(node, (&mut *waiter, orphan), k, (end, Some(end)), deadline)?;
        }
    }
    Ok(())
}

/// What a new process of a crashed agent took from an input before it
/// was due (PROTOCOL.md § 10.10): while down it reads its inputs without
/// waiting, and keeps the first message stamped after the current
/// exchange for when it is up again. Empty for every other node.
struct Held {
    /// Per input.
    next: Vec<Option<StateMsg>>,
    /// Whether this process took over from a crashed one (then messages
    /// older than the exchange due are leftovers of the time it was down).
    resumed: bool,
    /// The delayed inputs, taken ahead.
    ahead: Ahead,
}

impl Held {
    fn new<N: Stepper>(cfg: &NodeConfig, stepper: &N) -> Self {
        Self {
            next: vec![None; cfg.inputs.len()],
            resumed: cfg.resume.is_some(),
            ahead: Ahead::new(cfg, stepper),
        }
    }

    /// Takes delayed input `k`'s messages in `window` (the node's slot,
    /// the stamp due: [`lookahead::take`]).
    fn take_ahead<S: Service, N: Stepper, H: Hooks>(
        &mut self,
        (io, cfg, stepper, inputs): (&mut Hooked<'_, S, H>, &NodeConfig, &mut N, &mut Inputs),
        (waiter, orphan): (&mut Waiter, &Orphan),
        k: usize,
        window: (Stamp, Option<Stamp>),
        deadline: Instant,
    ) -> Result<(), NodeError> {
        let mut t = Taking {
            io,
            cfg,
            stepper,
            inputs,
            next: &mut self.next,
            waiter,
            orphan,
        };
        lookahead::take(&mut t, &mut self.ahead, k, window, deadline)
    }

    /// Input `k`'s next message, the one kept first.
    fn take<S: Service, H: Hooks>(
        &mut self,
        io: &mut Hooked<'_, S, H>,
        k: usize,
    ) -> Result<Option<StateMsg>, NodeError> {
        match self.next[k].take() {
            Some(m) => Ok(Some(m)),
            None => io.receive(k),
        }
    }
}

/// Exchange `slot` of a node that is down: publishes its stand-in (its
/// receivers' timelines drop it), then reads what its inputs have sent up
/// to `slot`, keeping the first later message. It waits only for inputs
/// that also receive from it, until one message stamped `slot` or later
/// came: that receiver has its stand-in, so this process, new to its
/// receivers, never sends more than their buffers hold before they
/// attach to it (iceoryx2 drops what a full buffer of a receiver not yet
/// attached cannot take). Messages lost before it attached are of no
/// matter: nothing a down node receives is used.
fn stand_in<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &N,
    (held, waiter): (&mut Held, &mut Waiter),
    slot: Slot,
    orphan: &Orphan,
) -> Result<(), NodeError> {
    let now = (slot.step, slot.stage);
    let msg = StateMsg::new(cfg.id, now.0, now.1, &stepper.stage_exchange());
    io.publish(slot, msg, true)?;
    let deadline = Instant::now() + Duration::from_secs_f64(cfg.stage_timeout);
    waiter.begin();
    for k in 0..cfg.inputs.len() {
        let paces = cfg.outputs.contains(&cfg.inputs[k]);
        loop {
            match held.take(io, k)? {
                Some(m) if (m.step, m.stage) < now => continue,
                Some(m) => {
                    if (m.step, m.stage) > now {
                        held.next[k] = Some(m);
                    }
                    break;
                }
                None if !paces => break,
                None => {
                    if waiter.polls() % 64 == 63 {
                        orphan.poll()?;
                    }
                    if waiter.wait(&io.ports.listener, deadline) {
                        return Err(NodeError::InputTimeout {
                            from: cfg.inputs[k],
                            step: now.0,
                            stage: now.1,
                            waited: cfg.stage_timeout,
                        });
                    }
                }
            }
        }
    }
    Ok(())
}

/// Exchange `slot`: publish, then take every input's message of `slot`.
fn exchange<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &mut N,
    (inputs, held): (&mut Inputs, &mut Held),
    waiter: &mut Waiter,
    slot: Slot,
    orphan: &Orphan,
) -> Result<(), NodeError> {
    let (n, s) = (slot.step, slot.stage);
    let msg = StateMsg::new(cfg.id, n, s, &stepper.stage_exchange());
    io.publish(slot, msg, waiter.receivers_may_block())?;
    let deadline = Instant::now() + Duration::from_secs_f64(cfg.stage_timeout);
    waiter.begin();
    held.ahead.reached((n, s));
    for k in 0..cfg.inputs.len() {
        let d = held.ahead.delay[k];
        if d > 0 {
            let window = ((n, s), lookahead::due(d, (n, s)));
            let node = (&mut *io, cfg, &mut *stepper, &mut *inputs);
            held.take_ahead(node, (&mut *waiter, orphan), k, window, deadline)?;
            continue;
        }
        let msg = loop {
            // Take one message at a time: what stays in iceoryx2's
            // buffer holds a fast sender back (flow control).
            if let Some(m) = held.take(io, k)? {
                if held.resumed && (m.step, m.stage) < (n, s) {
                    continue;
                }
                break m;
            }
            if waiter.polls() % 64 == 63 {
                orphan.poll()?;
            }
            if waiter.wait(&io.ports.listener, deadline) {
                return Err(NodeError::InputTimeout {
                    from: cfg.inputs[k],
                    step: n,
                    stage: s,
                    waited: cfg.stage_timeout,
                });
            }
        };
        check_origin(&msg, cfg.inputs[k])?;
        if (msg.step, msg.stage) != (n, s) {
            return Err(NodeError::BadInput {
                from: cfg.inputs[k],
                why: format!(
                    "it sent step {} stage {} where step {n} stage {s} was due",
                    msg.step, msg.stage
                ),
            });
        }
        // A refused value is like a lost message: keep what we had.
        if let Some(x) = inputs.accept(cfg, k, &msg) {
            stepper.receive(k, x);
        }
    }
    held.ahead.trim();
    Ok(())
}
