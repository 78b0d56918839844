//! The agent behind attsync's node loop: its own RKMK4 stepping of the rigid
//! body under the saturated observerless law.

use crate::saturate::saturate;
use attitude::body::body_field;
use attitude::control::{ControlGains, tau_districontrol};
use attitude::integrate::{LieState, Rkmk4};
use attitude::network::{AgentModel, AgentState, Exchanged, Scheme};
use attitude::observer::LeaderInput;
use attsync_agent::Stepper;
use msgs::TelemetryMsg;
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
    id: u32,
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
            id: cfg.id,
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

    fn sample(&self, step: u64) -> TelemetryMsg {
        TelemetryMsg::agent(self.id, step, &self.state(), self.peak_torque)
    }

    fn peak_torque(&self) -> f64 {
        self.peak_torque
    }
}
