//! The agent behind attsync's node loop: its own RKMK4 stepping of the rigid
//! body under the saturated observerless law.

use crate::saturate::saturate;
use attitude::body::body_field;
use attitude::control::{ControlGains, tau_districontrol};
use attitude::integrate::{LieState, Rkmk4};
use attitude::network::{AgentModel, AgentState, Exchanged, Scheme};
use attitude::observer::LeaderInput;
use attsync_agent::Stepper;
use msgs::Telemetry;
use msgs::config::{NodeConfig, Role};
use nalgebra::{Matrix3, Vector3};

/// Agent i under the observerless law with a torque limit:
///
/// ```text
/// (followeri)      Ṙᵢ = Rᵢ ωᵢ^×,   Jᵢ ω̇ᵢ = −ωᵢ × Jᵢωᵢ + sat(τᵢ)
/// (districontrol)  τᵢ = −k_Ř ψ(Ǎ_{i,0} R₀ᵀ Rᵢ) − k_Ř Σ_{j∈N(i)} ψ(Ǎ_{i,j} Rⱼᵀ Rᵢ) − k_ω̌ ωᵢ
/// ```
/// integrated with RKMK4 one stage at a time, like the built-in agent.
/// It publishes `(Rᵢ, ωᵢ, 0)`; inputs are its neighbours by id, then the
/// leader if it hears it (the order of [`NodeConfig::inputs`]).
#[derive(Debug, Clone)]
pub struct SaturatedAgent {
    model: AgentModel,
    control: ControlGains,
    /// `Ǎ_{i,j}` in neighbour order.
    gains: Vec<Matrix3<f64>>,
    /// The initial state: its observer part is reported unchanged (there is none).
    initial: AgentState,
    /// `(Rᵢ; ωᵢ)` at the start of the current step.
    x: LieState<1, 1>,
    step: Rkmk4<1, 1>,
    dt: f64,
    held_nbrs: Vec<Exchanged>,
    held_leader: Option<Exchanged>,
    tau_max: f64,
    peak_torque: f64,
    peak_demanded: f64,
    /// The torque applied at stage 0 of the current step.
    tau0: Vector3<f64>,
    steps: u64,
    saturated_steps: u64,
    /// First and last step that began saturated.
    saturated_span: Option<(u64, u64)>,
}

impl SaturatedAgent {
    /// The agent of `cfg`, with torque limit `tau_max` (N·m). Refuses what
    /// it does not implement: another role or scheme, impaired links.
    pub fn from_config(cfg: &NodeConfig, tau_max: f64) -> Result<Self, String> {
        let (model, initial) = match &cfg.role {
            Role::Agent { model, initial } => ((**model).clone(), *initial),
            Role::Leader { .. } => return Err(format!("node {} is the leader", cfg.id)),
        };
        let Scheme::Observerless { control } = model.scheme else {
            return Err(format!(
                "scheme {:?}: this agent implements only the observerless scheme",
                model.scheme
            ));
        };
        let impaired = model
            .neighbours
            .iter()
            .map(|n| n.link)
            .chain([model.leader_link])
            .any(|l| l.is_some_and(|l| l.is_impaired()));
        if impaired {
            return Err("impaired links (delay, loss, …) are not supported".into());
        }
        let mut expected: Vec<u32> = model.neighbours.iter().map(|n| n.id).collect();
        if model.leader_gain.is_some() {
            expected.push(0);
        }
        if cfg.inputs != expected {
            return Err(format!(
                "inputs {:?} do not match the model's neighbours then leader {expected:?}",
                cfg.inputs
            ));
        }
        if tau_max.is_nan() || tau_max <= 0.0 {
            return Err(format!("torque limit {tau_max} N·m: must be positive"));
        }
        let x = LieState {
            rot: [initial.r],
            vec: [initial.w],
        };
        Ok(Self {
            gains: model.neighbours.iter().map(|n| n.a).collect(),
            held_nbrs: vec![Exchanged::identity(); model.neighbours.len()],
            held_leader: model.leader_gain.map(|_| Exchanged::identity()),
            model,
            control,
            initial,
            x,
            step: Rkmk4::new(x, cfg.dt),
            dt: cfg.dt,
            tau_max,
            peak_torque: 0.0,
            peak_demanded: 0.0,
            tau0: Vector3::zeros(),
            steps: 0,
            saturated_steps: 0,
            saturated_span: None,
        })
    }

    /// Largest ‖τᵢ‖ the law asked for at a step start (before saturation), N·m.
    #[must_use]
    pub fn peak_demanded(&self) -> f64 {
        self.peak_demanded
    }

    /// Steps completed, and how many of them began saturated.
    #[must_use]
    pub fn saturated_steps(&self) -> (u64, u64) {
        (self.steps, self.saturated_steps)
    }

    /// The first and the last step that began saturated, if any did.
    #[must_use]
    pub fn saturated_span(&self) -> Option<(u64, u64)> {
        self.saturated_span
    }

    /// The full agent state at the start of the current step.
    fn state(&self) -> AgentState {
        AgentState {
            r: self.x.rot[0],
            w: self.x.vec[0],
            ..self.initial
        }
    }
}

impl Stepper for SaturatedAgent {
    fn stage_exchange(&self) -> Exchanged {
        let y = self.step.stage_state();
        Exchanged {
            r: y.rot[0],
            w: y.vec[0],
            s: Vector3::zeros(),
        }
    }

    fn receive(&mut self, k: usize, x: Exchanged) {
        match self.held_nbrs.get_mut(k) {
            Some(h) => *h = x,
            None => {
                if let Some(h) = &mut self.held_leader {
                    *h = x;
                }
            }
        }
    }

    fn advance(&mut self) {
        let y = self.step.stage_state();
        let leader = match (&self.held_leader, &self.model.leader_gain) {
            (Some(x), Some(a)) => Some(LeaderInput { a, x }),
            _ => None,
        };
        let demanded = tau_districontrol(
            &self.control,
            &y.rot[0],
            &y.vec[0],
            &self.gains,
            &self.held_nbrs,
            leader,
        );
        let tau = saturate(&demanded, self.tau_max);
        if self.step.stage() == 0 {
            // As attsync's agent: the peak over step starts.
            self.peak_torque = self.peak_torque.max(tau.norm());
            self.tau0 = tau;
            self.peak_demanded = self.peak_demanded.max(demanded.norm());
            if tau != demanded {
                self.saturated_steps += 1;
                let n = self.steps;
                self.saturated_span = Some(self.saturated_span.map_or((n, n), |(a, _)| (a, n)));
            }
        }
        if let Some(next) = self
            .step
            .push_derivative(&body_field(&self.model.inertia, &y, &tau))
        {
            self.x = next;
            self.step = Rkmk4::new(next, self.dt);
            self.steps += 1;
        }
    }

    fn sample(&self, step: u64) -> Telemetry {
        Telemetry::Sample {
            step,
            state: self.state(),
            peak_torque: self.peak_torque,
        }
    }

    fn peak_torque(&self) -> f64 {
        self.peak_torque
    }

    fn torque(&self, step: u64) -> Option<Telemetry> {
        Some(Telemetry::Torque {
            step,
            tau: self.tau0,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use attitude::agent::Agent;
    use attitude::body::Inertia;
    use attitude::network::{Coupling, Neighbour};
    use attitude::so3::rot;
    use msgs::Limits;
    use msgs::config::WaitStrategy;

    /// Agent 3 of the paper's scheme-3 experiment, hearing neighbour 1 and
    /// the leader (a made-up neighbourhood: the inputs are held constant).
    fn config() -> NodeConfig {
        let u2 = Vector3::new(1.0, 1.0, 0.0).normalize();
        let model = AgentModel {
            id: 3,
            inertia: Inertia::new(Matrix3::from_diagonal(&Vector3::new(0.3, 0.5, 0.6))),
            a_bar: Matrix3::identity(),
            neighbours: vec![Neighbour {
                id: 1,
                a: Matrix3::from_diagonal(&Vector3::new(9.0, 8.0, 7.0)),
                link: None,
            }],
            leader_gain: Some(Matrix3::from_diagonal(&Vector3::new(8.0, 9.0, 10.0))),
            leader_link: None,
            scheme: Scheme::Observerless {
                control: ControlGains { k_r: 1.9, k_w: 1.9 },
            },
            p: Matrix3::zeros(),
            law: Default::default(),
            timeline: Default::default(),
            effects: None,
        };
        let initial = AgentState {
            r: rot(0.3 * std::f64::consts::PI, &u2),
            w: Vector3::new(3.5, 3.0, 4.0),
            r_hat: Matrix3::identity(),
            w_hat: Vector3::zeros(),
            s_hat: Vector3::zeros(),
        };
        NodeConfig {
            protocol_version: msgs::PROTOCOL_VERSION,
            run: "test".into(),
            iox_root: "/tmp/".into(),
            id: 3,
            dt: 0.001,
            steps: 3000,
            coupling: Coupling::Continuous,
            sample_every: 10,
            inputs: vec![1, 0],
            outputs: vec![1],
            limits: Limits {
                nodes: 3,
                max_fanout: 1,
                state_buffer: 64,
                telemetry_buffer: 256,
            },
            wait: WaitStrategy::Adaptive,
            stage_timeout: 10.0,
            start_timeout: 30.0,
            realtime: None,
            guard: Default::default(),
            contention: msgs::config::Contention::Waiter,
            role: Role::Agent {
                model: Box::new(model),
                initial,
            },
            resume: None,
        }
    }

    fn inputs() -> [Exchanged; 2] {
        let u = Vector3::new(1.0, 4.0, 2.0).normalize();
        let nbr = Exchanged {
            r: rot(0.1 * std::f64::consts::PI, &u),
            ..Exchanged::identity()
        };
        let leader = Exchanged {
            r: rot(0.8 * std::f64::consts::PI, &u),
            ..Exchanged::identity()
        };
        [nbr, leader]
    }

    /// Runs `steps` steps with constant inputs; returns the final state.
    fn drive(a: &mut SaturatedAgent, steps: u64) -> AgentState {
        for _ in 0..steps * 4 {
            for (k, x) in inputs().into_iter().enumerate() {
                a.receive(k, x);
            }
            a.advance();
        }
        a.state()
    }

    #[test]
    fn without_a_limit_it_is_the_builtin_agent_bit_for_bit() {
        let cfg = config();
        let Role::Agent { model, initial } = &cfg.role else {
            unreachable!()
        };
        let mut builtin = Agent::new((**model).clone(), *initial, cfg.dt);
        let [nbr, leader] = inputs();
        for _ in 0..cfg.steps * 4 {
            builtin.receive_neighbour(0, nbr);
            builtin.receive_leader(leader);
            builtin.advance();
        }
        let mut ours = SaturatedAgent::from_config(&cfg, f64::INFINITY).expect("valid");
        let x = drive(&mut ours, cfg.steps);
        assert_eq!(x, *builtin.state());
        assert_eq!(ours.peak_torque, builtin.peak_torque());
        assert_eq!(ours.saturated_steps(), (cfg.steps, 0));
    }

    #[test]
    fn the_applied_torque_never_exceeds_the_limit() {
        let cfg = config();
        let mut a = SaturatedAgent::from_config(&cfg, 2.0).expect("valid");
        drive(&mut a, cfg.steps);
        assert!(
            a.peak_demanded() > 2.0,
            "the limit must bite: {}",
            a.peak_demanded()
        );
        assert!(
            a.peak_torque <= 2.0 && a.peak_torque > 2.0 - 1e-12,
            "{}",
            a.peak_torque
        );
        assert_eq!(a.saturated_span().map(|s| s.0), Some(0));
    }

    #[test]
    fn what_it_does_not_implement_is_refused() {
        let mut cfg = config();
        cfg.inputs = vec![0, 1];
        assert!(SaturatedAgent::from_config(&cfg, 2.0).is_err());
        assert!(SaturatedAgent::from_config(&config(), 0.0).is_err());
        assert!(SaturatedAgent::from_config(&config(), f64::NAN).is_err());
    }
}
