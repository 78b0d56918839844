//! Real-time mode: the node runs free against the wall clock and never
//! waits for its inputs.
//!
//! Stage s of step n begins at wall time `T₀ + (n + c_s)·dt / factor`
//! (`c = [0, ½, ½, 1]`, `T₀` the `start_unix_ns` of the `Start` command, the
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

use super::ports::Ports;
use super::{Inputs, NodeError, Orphan, Stepper, after_step, before_step, check_origin, port};
use attitude::link::LinkStats;
use iceoryx2::prelude::*;
use msgs::config::NodeConfig;
use msgs::{Pacing, StateMsg, unix_ns_now};
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// Stage offsets of RKMK4 within a step.
const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];

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

    /// When stage s of step n is due.
    fn due(&self, n: u64, s: u32) -> Instant {
        self.t0 + Duration::from_secs_f64((n as f64 + C[s as usize]) * self.step_wall)
    }
}

/// Steps `cfg.steps` steps paced by `clock`; returns how well it kept to it.
pub(crate) fn run<S: Service, N: Stepper>(
    ports: &Ports<S>,
    cfg: &NodeConfig,
    stepper: &mut N,
    inputs: &mut Inputs,
    clock: Clock,
    shutdown: &AtomicBool,
    orphan: &Orphan,
) -> Result<Pacing, NodeError> {
    let k_in = ports.inputs.len();
    let mut newest: Vec<Option<(u64, u32)>> = vec![None; k_in];
    let mut held_sent: Vec<Option<u64>> = vec![None; k_in];
    let (mut late_stages, mut max_late) = (0u64, 0.0f64);
    let mut exchanges = 0u64;
    ports.report(cfg.id, &stepper.sample(0))?;
    for n in 0..cfg.steps {
        before_step(n, shutdown, orphan)?;
        for s in 0..4u32 {
            let due = clock.due(n, s);
            let now = Instant::now();
            if now < due {
                std::thread::sleep(due - now);
            } else {
                let late = (now - due).as_secs_f64();
                max_late = max_late.max(late);
                if late > clock.step_wall {
                    late_stages += 1;
                }
            }
            if !cfg.coupling.exchanges_at(n, s as usize) {
                stepper.advance();
                continue;
            }
            exchanges += 1;
            let first = n == 0 && s == 0;
            let msg = StateMsg::new(cfg.id, n, s, &stepper.stage_exchange()).stamped_now();
            ports.publish(msg, first)?;
            for k in 0..k_in {
                let deadline = Instant::now() + Duration::from_secs_f64(cfg.stage_timeout);
                let mut fresh = None;
                loop {
                    while let Some(sample) =
                        ports.inputs[k].receive().map_err(port("state receive"))?
                    {
                        let m = *sample;
                        check_origin(&m, cfg.inputs[k])?;
                        if newest[k].is_some_and(|st| st >= (m.step, m.stage)) {
                            continue;
                        }
                        newest[k] = Some((m.step, m.stage));
                        if let Some(x) = inputs.accept(cfg, k, &m) {
                            inputs.measured[k].delivered += 1;
                            fresh = Some((x, m.sent_unix_ns));
                        }
                    }
                    // Only the state at t = 0 is awaited.
                    if !first || newest[k].is_some() {
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
                    let _ = ports.listener.timed_wait(|_| {}, Duration::from_millis(1));
                }
                if let Some((x, sent)) = fresh {
                    stepper.receive(k, x);
                    held_sent[k] = Some(sent);
                }
                if let Some(sent) = held_sent[k] {
                    let age = unix_ns_now().saturating_sub(sent) as f64 * 1e-9 * clock.factor;
                    let st = &mut inputs.measured[k];
                    st.age_sum += age;
                    st.age_max = st.age_max.max(age);
                    st.evaluations += 1;
                }
            }
            stepper.advance();
        }
        after_step(ports, cfg, stepper, n + 1)?;
    }
    for st in &mut inputs.measured {
        // Every node makes the same exchanges: what a sender sent is what we made.
        *st = LinkStats {
            sent: exchanges,
            lost: exchanges.saturating_sub(st.delivered),
            ..*st
        };
    }
    tracing::info!(late_stages, max_late_s = max_late, "real-time pacing");
    Ok(Pacing {
        late_stages,
        max_lateness: max_late,
    })
}
