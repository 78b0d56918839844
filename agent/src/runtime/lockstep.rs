//! Deterministic lockstep: at every exchange (n, s) a node publishes its
//! stage state stamped (n, s), wakes its receivers, waits (bounded) until
//! every input's message stamped (n, s) has arrived, then advances one stage.

use super::ports::Ports;
use super::{Inputs, NodeError, Orphan, Stepper, after_step, before_step, check_origin, port};
use crate::wait::Waiter;
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::{Pacing, StateMsg};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Steps `cfg.steps` steps in lockstep (always on time: no pacing to report).
pub(crate) fn run<S: Service, N: Stepper>(
    ports: &Ports<S>,
    cfg: &NodeConfig,
    stepper: &mut N,
    inputs: &mut Inputs,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<Pacing, NodeError> {
    let stage_timeout = Duration::from_secs_f64(cfg.stage_timeout);
    let mut waiter = Waiter::new(cfg.wait);
    let notify = waiter.receivers_may_block();
    ports.report(cfg.id, &stepper.sample(0))?;
    for n in 0..cfg.steps {
        before_step(n, shutdown, orphan)?;
        for s in 0..4u32 {
            if cfg.coupling.exchanges_at(n, s as usize) {
                ports.publish(
                    StateMsg::new(cfg.id, n, s, &stepper.stage_exchange()),
                    notify,
                )?;
                let deadline = Instant::now() + stage_timeout;
                waiter.begin();
                for k in 0..ports.inputs.len() {
                    let msg = loop {
                        // Take one message at a time: what stays in iceoryx2's
                        // buffer holds a fast sender back (flow control).
                        if let Some(sample) =
                            ports.inputs[k].receive().map_err(port("state receive"))?
                        {
                            break *sample;
                        }
                        if waiter.polls() % 1024 == 1023 {
                            orphan.check()?;
                        }
                        if waiter.wait(&ports.listener, deadline) {
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
            }
            stepper.advance();
        }
        after_step(ports, cfg, stepper, n + 1)?;
    }
    Ok(Pacing::default())
}
