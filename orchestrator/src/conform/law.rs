//! Rule `law`: the candidate's inputs replayed through the built-in law of
//! its scheme.
//!
//! The harness records, at every exchange `(n, s)`, the inputs it delivered
//! to the candidate and the state the candidate published, and every
//! telemetry sample. [`replay`] runs a shadow [`Agent`] built from the
//! candidate's own configuration on the same inputs, walking the same
//! [`Schedule`], and returns the largest deviation of what the candidate
//! published from what the shadow publishes. A refused input (the NaN of
//! rule `refuses-invalid`) is refused by the shadow too, which keeps its
//! previous value, as a conforming candidate must.
//!
//! The exchanges show what the neighbours see (for schemes 1–2 the observer
//! estimate `(R̂, ω̂, σ̂)`, for scheme 3 the body `(R, ω, 0)`); the samples
//! show the whole state, so a wrong body law under an observer scheme is
//! caught too.
//!
//! The shadow is built from the candidate's own `AgentModel`, so it follows
//! the configured `law` (`scheme.law`): under `"as-printed"` the candidate
//! must run the paper's printed `Σᵢ`, `Γᵢ` (the negative control), and the
//! corrected law deviates.

use super::LawMode;
use super::rules::{Report, RuleId};
use attitude::agent::Agent;
use attitude::control::ControlLaw;
use attitude::network::{AgentModel, AgentState, Exchanged, Scheme};
use attitude::schedule::Schedule;
use msgs::config::{NodeConfig, Role};
use nalgebra::{Matrix3, Vector3};
use std::collections::BTreeMap;
use thiserror::Error;

/// Largest relative deviation the rule accepts:
/// `‖q_c − q_b‖ ≤ TOLERANCE · max(1, ‖q_b‖)`.
///
/// The built-in agent in another process computes bit-identical values
/// (deviation 0); a correct independent re-implementation differs by
/// round-off, about 1e-16 per operation, which over the 200-step
/// neighbourhood stays many orders of magnitude below 1e-9 (the shadow is
/// fed the recorded inputs, so differences do not feed back through the
/// neighbours). A wrong gain or sign shows within a step: ≥ 1e-6 at
/// `dt` = 1 ms.
pub const TOLERANCE: f64 = 1e-9;

/// One exchange of the candidate, as the harness saw it.
#[derive(Debug, Clone, PartialEq)]
pub struct ExchangeRecord {
    /// Step n.
    pub step: u64,
    /// Stage s.
    pub stage: u32,
    /// What was delivered to it, in the order of [`NodeConfig::inputs`]
    /// (neighbours by id, then the leader), exactly as sent (including an
    /// injected NaN).
    pub inputs: Vec<Exchanged>,
    /// What it published at `(n, s)`, unvalidated.
    pub published: Exchanged,
}

/// What the candidate did that its law determines.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LawRecord {
    /// Its exchanges, in order.
    pub exchanges: Vec<ExchangeRecord>,
    /// Its telemetry samples `(step, state)`, in order received.
    pub samples: Vec<(u64, AgentState)>,
}

/// A compared quantity.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// The published attitude (`R̂` with an observer, `R` without).
    R,
    /// The published angular velocity.
    W,
    /// The published angular acceleration.
    S,
    /// A sample's `Rᵢ`.
    BodyR,
    /// A sample's `ωᵢ`.
    BodyW,
    /// A sample's `R̂ᵢ`.
    RHat,
    /// A sample's `ω̂ᵢ`.
    WHat,
    /// A sample's `σ̂ᵢ`.
    SHat,
}

impl std::fmt::Display for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Quantity::R => "R",
            Quantity::W => "ω",
            Quantity::S => "σ",
            Quantity::BodyR => "sampled R",
            Quantity::BodyW => "sampled ω",
            Quantity::RHat => "sampled R̂",
            Quantity::WHat => "sampled ω̂",
            Quantity::SHat => "sampled σ̂",
        })
    }
}

/// Where a deviation was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum At {
    /// The state published at exchange `(step, stage)`.
    Exchange {
        /// Step n.
        step: u64,
        /// Stage s.
        stage: u32,
    },
    /// The telemetry sample of `step`.
    Sample {
        /// Step n.
        step: u64,
    },
}

impl std::fmt::Display for At {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            At::Exchange { step, stage } => write!(f, "step {step} stage {stage}"),
            At::Sample { step } => write!(f, "step {step}"),
        }
    }
}

/// The largest deviation found.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Deviation {
    /// `‖q_c − q_b‖ / max(1, ‖q_b‖)`: Frobenius norm for attitudes,
    /// Euclidean for vectors; infinite if the candidate's value is not finite.
    pub value: f64,
    /// Which quantity.
    pub quantity: Quantity,
    /// Where.
    pub at: At,
}

/// Why the record cannot be replayed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LawError {
    /// The record's exchange is not the one the schedule has next.
    #[error(
        "recorded exchange step {got_step} stage {got_stage} where step {step} stage {stage} was due"
    )]
    OutOfSchedule {
        /// Recorded step.
        got_step: u64,
        /// Recorded stage.
        got_stage: u32,
        /// Due step.
        step: u64,
        /// Due stage.
        stage: u32,
    },
    /// An exchange carries another number of inputs than the model has.
    #[error("{got} inputs recorded at step {step} stage {stage}, the model has {expected}")]
    Inputs {
        /// Step n.
        step: u64,
        /// Stage s.
        stage: u32,
        /// Recorded.
        got: usize,
        /// Neighbours plus the leader link.
        expected: usize,
    },
    /// The configuration is not an agent's.
    #[error("the candidate's configuration has no agent model")]
    NotAnAgent,
}

/// Keeps the larger of two deviations.
fn keep(best: &mut Option<Deviation>, value: f64, quantity: Quantity, at: At) {
    let value = if value.is_nan() { f64::INFINITY } else { value };
    if best.is_none_or(|b| value > b.value) {
        *best = Some(Deviation {
            value,
            quantity,
            at,
        });
    }
}

fn rel_m(c: &Matrix3<f64>, b: &Matrix3<f64>) -> f64 {
    (c - b).norm() / b.norm().max(1.0)
}

fn rel_v(c: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    (c - b).norm() / b.norm().max(1.0)
}

fn compare_exchange(best: &mut Option<Deviation>, c: &Exchanged, b: &Exchanged, at: At) {
    keep(best, rel_m(&c.r, &b.r), Quantity::R, at);
    keep(best, rel_v(&c.w, &b.w), Quantity::W, at);
    keep(best, rel_v(&c.s, &b.s), Quantity::S, at);
}

fn compare_sample(best: &mut Option<Deviation>, c: &AgentState, b: &AgentState, step: u64) {
    let at = At::Sample { step };
    keep(best, rel_m(&c.r, &b.r), Quantity::BodyR, at);
    keep(best, rel_v(&c.w, &b.w), Quantity::BodyW, at);
    keep(best, rel_m(&c.r_hat, &b.r_hat), Quantity::RHat, at);
    keep(best, rel_v(&c.w_hat, &b.w_hat), Quantity::WHat, at);
    keep(best, rel_v(&c.s_hat, &b.s_hat), Quantity::SHat, at);
}

/// Replays `record` through the built-in agent of `model` (from `initial`,
/// step `dt`) along `schedule`, up to the last recorded exchange, and
/// returns the largest deviation (`None` if nothing was compared).
pub fn replay(
    model: &AgentModel,
    initial: AgentState,
    dt: f64,
    schedule: Schedule,
    record: &LawRecord,
) -> Result<Option<Deviation>, LawError> {
    let mut shadow = Agent::new(model.clone(), initial, dt);
    let n_nbrs = model.neighbours.len();
    let expected = n_nbrs + usize::from(model.leader_gain.is_some());
    let samples: BTreeMap<u64, &AgentState> = record.samples.iter().map(|(n, x)| (*n, x)).collect();
    let mut best = None;
    let mut exchanges = record.exchanges.iter().peekable();
    for slot in schedule.slots() {
        if slot.stage == 0 {
            if let Some(x) = samples.get(&slot.step) {
                compare_sample(&mut best, x, shadow.state(), slot.step);
            }
        }
        if slot.exchange {
            let Some(x) = exchanges.next() else { break };
            if (x.step, x.stage) != (slot.step, slot.stage) {
                return Err(LawError::OutOfSchedule {
                    got_step: x.step,
                    got_stage: x.stage,
                    step: slot.step,
                    stage: slot.stage,
                });
            }
            if x.inputs.len() != expected {
                return Err(LawError::Inputs {
                    step: x.step,
                    stage: x.stage,
                    got: x.inputs.len(),
                    expected,
                });
            }
            let at = At::Exchange {
                step: x.step,
                stage: x.stage,
            };
            compare_exchange(&mut best, &x.published, &shadow.stage_exchange(), at);
            for (k, input) in x.inputs.iter().enumerate() {
                if k < n_nbrs {
                    shadow.receive_neighbour(k, *input);
                } else {
                    shadow.receive_leader(*input);
                }
            }
        }
        let done = shadow.advance();
        if done && slot.step + 1 == schedule.steps() {
            if let Some(x) = samples.get(&schedule.steps()) {
                compare_sample(&mut best, x, shadow.state(), schedule.steps());
            }
        }
    }
    Ok(best)
}

/// The paper's number of `scheme` (1, 2 or 3).
#[must_use]
pub fn scheme_number(scheme: &Scheme) -> u32 {
    match scheme {
        Scheme::ObserverTimeVarying { .. } => 1,
        Scheme::ObserverConstant { .. } => 2,
        Scheme::Observerless { .. } => 3,
    }
}

/// Rule `law`: replays `record` against the candidate's configuration and
/// records the verdict (a deviation is a failure under [`LawMode::Builtin`],
/// information under [`LawMode::Own`]).
pub(super) fn judge(cfg: &NodeConfig, record: &LawRecord, mode: LawMode, report: &mut Report) {
    let Role::Agent { model, initial } = &cfg.role else {
        report.not_checked(RuleId::Law, LawError::NotAnAgent.to_string());
        return;
    };
    let schedule = Schedule::new(cfg.coupling, cfg.steps);
    let n = scheme_number(&model.scheme);
    match replay(model, *initial, cfg.dt, schedule, record) {
        Err(e) => report.not_checked(RuleId::Law, e.to_string()),
        Ok(None) => report.not_checked(RuleId::Law, "nothing was recorded to compare"),
        Ok(Some(d)) if d.value <= TOLERANCE => report.pass(RuleId::Law),
        Ok(Some(d)) => {
            let law = match model.law {
                ControlLaw::Corrected => String::new(),
                other => format!(" ({})", other.name()),
            };
            let why = format!(
                "differs from the built-in scheme-{n} law{law} by {:.1e} ({} at {})",
                d.value, d.quantity, d.at
            );
            match mode {
                LawMode::Builtin => report.fail(RuleId::Law, why),
                LawMode::Own => report.info(RuleId::Law, why),
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use attitude::network::Network;

    fn network() -> Network {
        let loaded = crate::scenario::load_str(
            std::path::Path::new("<test>"),
            super::super::NEIGHBOURHOOD,
            &["simulation.duration=0.02".into()],
        )
        .expect("the built-in neighbourhood loads");
        loaded.resolved.network
    }

    /// The candidate's record when it runs the built-in agent itself, its
    /// inputs constant (the neighbours' initial values).
    fn record_of(agent: &mut Agent, schedule: Schedule, inputs: &[Exchanged]) -> LawRecord {
        let mut rec = LawRecord::default();
        for slot in schedule.slots() {
            if slot.stage == 0 {
                rec.samples.push((slot.step, *agent.state()));
            }
            if slot.exchange {
                rec.exchanges.push(ExchangeRecord {
                    step: slot.step,
                    stage: slot.stage,
                    inputs: inputs.to_vec(),
                    published: agent.stage_exchange(),
                });
                let n = agent.model().neighbours.len();
                for (k, x) in inputs.iter().enumerate() {
                    if k < n {
                        agent.receive_neighbour(k, *x);
                    } else {
                        agent.receive_leader(*x);
                    }
                }
            }
            agent.advance();
        }
        rec.samples.push((schedule.steps(), *agent.state()));
        rec
    }

    fn setup() -> (AgentModel, AgentState, f64, Schedule, Vec<Exchanged>) {
        setup_of(network())
    }

    /// Agent 2 of `net` (which hears the leader) with its neighbours' and
    /// the leader's initial values as constant inputs.
    fn setup_of(net: Network) -> (AgentModel, AgentState, f64, Schedule, Vec<Exchanged>) {
        let a = &net.agents[1];
        let nbrs = net.neighbour_indices();
        let mut inputs: Vec<Exchanged> = nbrs[1]
            .iter()
            .map(|&j| attitude::agent::exchanged_of(&a.model.scheme, &net.agents[j].initial))
            .collect();
        inputs.push(attitude::reference::Leader::new(net.p, net.leader, net.dt).stage_exchange());
        let schedule = Schedule::new(net.coupling, net.steps);
        (a.model.clone(), a.initial, net.dt, schedule, inputs)
    }

    #[test]
    fn the_builtin_agent_replays_exactly_even_with_a_refused_input() {
        let (model, initial, dt, schedule, mut inputs) = setup();
        inputs[0].w[0] = f64::NAN;
        let mut agent = Agent::new(model.clone(), initial, dt);
        let rec = record_of(&mut agent, schedule, &inputs);
        let d = replay(&model, initial, dt, schedule, &rec)
            .unwrap()
            .unwrap();
        assert_eq!(d.value, 0.0, "{d:?}");
    }

    #[test]
    fn a_wrong_sign_shows_in_omega() {
        let (model, initial, dt, schedule, inputs) = setup();
        let mut wrong = model.clone();
        if let Scheme::Observerless { control } = &mut wrong.scheme {
            control.k_r = -control.k_r;
        }
        let mut agent = Agent::new(wrong, initial, dt);
        let rec = record_of(&mut agent, schedule, &inputs);
        let d = replay(&model, initial, dt, schedule, &rec)
            .unwrap()
            .unwrap();
        assert!(d.value > 1e-4, "{d:?}");
        assert!(matches!(d.quantity, Quantity::W | Quantity::BodyW), "{d:?}");
    }

    #[test]
    fn a_record_off_the_schedule_is_refused() {
        let (model, initial, dt, schedule, inputs) = setup();
        let mut agent = Agent::new(model.clone(), initial, dt);
        let mut rec = record_of(&mut agent, schedule, &inputs);
        rec.exchanges.remove(1);
        let e = replay(&model, initial, dt, schedule, &rec).unwrap_err();
        assert!(matches!(e, LawError::OutOfSchedule { .. }), "{e}");
    }

    /// Scheme 1's conformance neighbourhood under `scheme.law = law`.
    fn timevarying(law: &str) -> Network {
        let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../scenarios/plugin/conform-timevarying.toml");
        let set = [
            "simulation.duration=0.02".into(),
            format!("scheme.law=\"{law}\""),
        ];
        crate::scenario::load(&file, &set)
            .expect("the scheme-1 neighbourhood loads")
            .resolved
            .network
    }

    #[test]
    fn the_shadow_follows_the_configured_law() {
        let (model, initial, dt, schedule, inputs) = setup_of(timevarying("as-printed"));
        assert_eq!(model.law, ControlLaw::AsPrinted);
        let mut printed = Agent::new(model.clone(), initial, dt);
        let rec = record_of(&mut printed, schedule, &inputs);
        let d = replay(&model, initial, dt, schedule, &rec);
        assert_eq!(d.unwrap().unwrap().value, 0.0);
        let corrected = AgentModel {
            law: ControlLaw::Corrected,
            ..model.clone()
        };
        let mut agent = Agent::new(corrected, initial, dt);
        let rec = record_of(&mut agent, schedule, &inputs);
        let d = replay(&model, initial, dt, schedule, &rec);
        let d = d.unwrap().unwrap();
        assert!(d.value > 1e-6, "{d:?}");
    }
}
