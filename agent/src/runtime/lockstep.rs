//! Deterministic lockstep: the node walks the run's [`Schedule`]; at every
//! exchange (n, s) it publishes its stage state stamped (n, s), wakes its
//! receivers, waits (bounded) until every input's message stamped (n, s)
//! has arrived, then advances one stage.

use super::hooks::{Hooked, Hooks};
use super::{
    Inputs, NodeError, Orphan, Stepper, after_stage_0, after_step, before_step, check_origin,
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
    io.report(stepper.sample(0))?;
    for slot in Schedule::new(cfg.coupling, cfg.steps).slots() {
        if slot.starts_step() {
            before_step(slot.step, shutdown, orphan)?;
        }
        if slot.exchange {
            exchange(io, cfg, stepper, inputs, &mut waiter, slot, orphan)?;
        }
        stepper.advance();
        if slot.starts_step() {
            after_stage_0(io, cfg, stepper, slot.step)?;
        }
        if slot.ends_step() {
            after_step(io, cfg, stepper, slot.step + 1)?;
        }
    }
    Ok(Pacing::default())
}

/// Exchange `slot`: publish, then take every input's message of `slot`.
fn exchange<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &mut N,
    inputs: &mut Inputs,
    waiter: &mut Waiter,
    slot: Slot,
    orphan: &Orphan,
) -> Result<(), NodeError> {
    let (n, s) = (slot.step, slot.stage);
    let msg = StateMsg::new(cfg.id, n, s, &stepper.stage_exchange());
    io.publish(slot, msg, waiter.receivers_may_block())?;
    let deadline = Instant::now() + Duration::from_secs_f64(cfg.stage_timeout);
    waiter.begin();
    for k in 0..cfg.inputs.len() {
        let msg = loop {
            // Take one message at a time: what stays in iceoryx2's
            // buffer holds a fast sender back (flow control).
            if let Some(m) = io.receive(k)? {
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
    Ok(())
}
