//! Real-time mode: the node runs free against the wall clock and never
//! waits for its inputs.
//!
//! Stage s of step n begins at wall time `T₀ + (n + c_s)·dt / factor`
//! (`c_s` = [`Slot::time_fraction`], `T₀` the `start_unix_ns` of the `Start` command, the
//! same for every node). At an exchange the node publishes its stage state
//! stamped with (n, s) and the wall clock, takes everything that has arrived
//! on each input, keeps the freshest valid value, and advances with the
//! values it holds, whatever their age. The only wait is for every input's
//! state at t = 0 (bounded by the stage timeout): the initial condition is
//! shared, as in lockstep.
//!
//! Measured per input ([`LinkStats`]): `delivered` = valid messages
//! received, `lost` = exchanges the sender made that were not received
//! before this node's last step, and the **age of information** at every
//! exchange, `(now − sent_unix_ns of the held value) · factor` in simulated
//! seconds: the real transport and scheduling latency.

use super::hooks::{Hooked, Hooks};
use super::{
    Inputs, NodeError, Orphan, Stepper, after_stage_0, after_step, before_step, check_origin,
};
use attitude::link::LinkStats;
use attitude::schedule::{Schedule, Slot};
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::{Pacing, StateMsg, unix_ns_now};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// The wall-clock schedule of the run.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Clock {
    t0: Instant,
    /// Wall seconds per step.
    step_wall: f64,
    factor: f64,
}

impl Clock {
    /// Simulated time 0 at `start_unix_ns` (now if 0), `factor` simulated
    /// seconds per wall second.
    pub(crate) fn new(start_unix_ns: u64, factor: f64, dt: f64) -> Self {
        let now = Instant::now();
        let now_unix = unix_ns_now();
        let t0 = if start_unix_ns >= now_unix {
            now + Duration::from_nanos(start_unix_ns - now_unix)
        } else {
            now.checked_sub(Duration::from_nanos(now_unix - start_unix_ns))
                .unwrap_or(now)
        };
        Self {
            t0,
            step_wall: dt / factor,
            factor,
        }
    }

    /// When `slot` is due.
    fn due(&self, slot: Slot) -> Instant {
        self.t0
            + Duration::from_secs_f64((slot.step as f64 + slot.time_fraction()) * self.step_wall)
    }
}

/// Per input: what the node has had from it so far.
#[derive(Debug, Clone, Copy, Default)]
struct Held {
    /// Newest (step, stage) received.
    newest: Option<(u64, u32)>,
    /// Send time of the value held.
    sent: Option<u64>,
}

/// How far behind the clock the node ran.
#[derive(Debug, Default)]
struct Lateness {
    late_stages: u64,
    max_late: f64,
}

/// Steps `cfg.steps` steps paced by `clock`; returns how well it kept to it.
pub(crate) fn run<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &mut N,
    inputs: &mut Inputs,
    clock: Clock,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<Pacing, NodeError> {
    let mut held = vec![Held::default(); cfg.inputs.len()];
    let mut late = Lateness::default();
    let mut exchanges = 0u64;
    io.report(stepper.sample(0))?;
    for slot in Schedule::new(cfg.coupling, cfg.steps).slots() {
        if slot.starts_step() {
            before_step(slot.step, shutdown, orphan)?;
        }
        wait_until(clock, slot, &mut late, orphan)?;
        if slot.exchange {
            exchanges += 1;
            exchange(io, cfg, stepper, inputs, &mut held, slot, clock.factor)?;
        }
        stepper.advance();
        if slot.starts_step() {
            after_stage_0(io, cfg, stepper, slot.step)?;
        }
        if slot.ends_step() {
            after_step(io, cfg, stepper, slot.step + 1)?;
        }
    }
    for (st, ages) in inputs.measured.iter_mut().zip(&inputs.ages) {
        // Every node makes the same exchanges: what a sender sent is what we made.
        *st = LinkStats {
            sent: exchanges,
            lost: exchanges.saturating_sub(st.delivered),
            age_p50: ages.quantile(0.5),
            age_p99: ages.quantile(0.99),
            ..*st
        };
    }
    tracing::info!(
        late_stages = late.late_stages,
        max_late_s = late.max_late,
        "real-time pacing"
    );
    Ok(Pacing {
        late_stages: late.late_stages,
        max_lateness: late.max_late,
    })
}

/// Sleeps until `slot` is due (checking the parent meanwhile), or records
/// how late it is.
fn wait_until(
    clock: Clock,
    slot: Slot,
    late: &mut Lateness,
    orphan: &Orphan,
) -> Result<(), NodeError> {
    let due = clock.due(slot);
    let now = Instant::now();
    if now >= due {
        let by = (now - due).as_secs_f64();
        late.max_late = late.max_late.max(by);
        if by > clock.step_wall {
            late.late_stages += 1;
        }
        return Ok(());
    }
    loop {
        let now = Instant::now();
        if now >= due {
            return Ok(());
        }
        std::thread::sleep((due - now).min(Duration::from_millis(100)));
        orphan.poll()?;
    }
}

/// Exchange `slot`: publish, take everything that has arrived on each
/// input, keep the freshest valid value, and measure its age.
fn exchange<S: Service, N: Stepper, H: Hooks>(
    io: &mut Hooked<'_, S, H>,
    cfg: &NodeConfig,
    stepper: &mut N,
    inputs: &mut Inputs,
    held: &mut [Held],
    slot: Slot,
    factor: f64,
) -> Result<(), NodeError> {
    let first = slot.step == 0 && slot.stage == 0;
    let msg = StateMsg::new(cfg.id, slot.step, slot.stage, &stepper.stage_exchange()).stamped_now();
    // Woken at every exchange: a receiver on another host is a bridge that
    // sleeps on its wake event (a node here never waits on it after t = 0).
    io.publish(slot, msg, true)?;
    if !first {
        // What our senders' notifications left on our own wake event.
        let _ = io.ports.listener.try_wait(|_| {});
    }
    for k in 0..cfg.inputs.len() {
        let deadline = Instant::now() + Duration::from_secs_f64(cfg.stage_timeout);
        let mut fresh = None;
        loop {
            while let Some(m) = io.receive(k)? {
                check_origin(&m, cfg.inputs[k])?;
                if held[k].newest.is_some_and(|st| st >= (m.step, m.stage)) {
                    continue;
                }
                held[k].newest = Some((m.step, m.stage));
                if let Some(x) = inputs.accept(cfg, k, &m) {
                    inputs.measured[k].delivered += 1;
                    fresh = Some((x, m.sent_unix_ns));
                }
            }
            // Only the state at t = 0 is awaited.
            if !first || held[k].newest.is_some() {
                break;
            }
            if Instant::now() > deadline {
                return Err(NodeError::InputTimeout {
                    from: cfg.inputs[k],
                    step: 0,
                    stage: 0,
                    waited: cfg.stage_timeout,
                });
            }
            let _ = io
                .ports
                .listener
                .timed_wait(|_| {}, Duration::from_millis(1));
        }
        if let Some((x, sent)) = fresh {
            stepper.receive(k, x);
            held[k].sent = Some(sent);
        }
        if let Some(sent) = held[k].sent {
            let age = unix_ns_now().saturating_sub(sent) as f64 * 1e-9 * factor;
            let st = &mut inputs.measured[k];
            st.age_sum += age;
            st.age_max = st.age_max.max(age);
            st.evaluations += 1;
            inputs.ages[k].record(age);
        }
    }
    Ok(())
}
