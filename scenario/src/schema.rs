//! The scenario file format (TOML), as serde types. Unknown keys are
//! rejected everywhere. See `docs/scenarios.md`.

use attitude::control::ControlLaw;
use serde::{Deserialize, Serialize};

/// A whole scenario file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Short name, used in outputs.
    #[serde(default)]
    pub name: Option<String>,
    /// Free text.
    #[serde(default)]
    pub description: Option<String>,
    /// Time step, horizon and exchange schedule.
    pub simulation: Simulation,
    /// Output sampling.
    #[serde(default)]
    pub output: Output,
    /// The control scheme and its scalar gains.
    pub scheme: SchemeSpec,
    /// The virtual leader 0.
    pub leader: LeaderSpec,
    /// Agents that hear the leader, with their gains `A_{i,0}`.
    #[serde(default, rename = "leader_link")]
    pub leader_links: Vec<LeaderLinkSpec>,
    /// The followers.
    #[serde(default, rename = "agent")]
    pub agents: Vec<AgentSpec>,
    /// Undirected follower edges with their gains `A_{i,j}`.
    #[serde(default, rename = "edge")]
    pub edges: Vec<EdgeSpec>,
    /// Communication impairments (default: an ideal network).
    #[serde(default)]
    pub network: NetworkSpec,
    /// `[actuator]`: every agent's actuator limits (default: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actuator: Option<ActuatorSpec>,
    /// `[[disturbance]]`: torques from outside (default: none).
    #[serde(default, rename = "disturbance", skip_serializing_if = "Vec::is_empty")]
    pub disturbances: Vec<crate::body::DisturbanceSpec>,
    /// `[sensor]`: every agent's sensor errors (default: exact).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<crate::body::SensorSpec>,
    /// `[controller]`: what every agent's law assumes of its body (default:
    /// the body's inertia).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<crate::body::ControllerSpec>,
    /// `[graph]`: whether the paper's Assumption 1 is enforced.
    #[serde(default, skip_serializing_if = "GraphSpec::is_default")]
    pub graph: GraphSpec,
    /// The envelope of a sane state (default: `attitude::guard::Envelope::default`).
    #[serde(default, skip_serializing_if = "GuardSpec::is_unset")]
    pub guard: GuardSpec,
    /// `[monte_carlo]`: what `attsync mc` disperses (ignored by other commands).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub monte_carlo: Option<crate::monte_carlo::MonteCarloSpec>,
    /// `[[event]]`: the timeline (links cut and restored, agents silenced,
    /// gains and the reference changed), in any order.
    #[serde(default, rename = "event", skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<crate::event::EventSpec>,
}

/// `[guard]`: the largest norms a node's state may reach before the run
/// stops as diverged (unset fields take the defaults, 1e4).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GuardSpec {
    /// Largest `‖ωᵢ‖`, rad/s.
    #[serde(default)]
    pub omega: Option<f64>,
    /// Largest `‖ω̂ᵢ‖` and `‖ω₀‖`, rad/s.
    #[serde(default)]
    pub omega_hat: Option<f64>,
    /// Largest `‖σ̂ᵢ‖` and `‖σ₀‖`, rad/s².
    #[serde(default)]
    pub sigma_hat: Option<f64>,
}

impl GuardSpec {
    /// Whether no bound is set (then the table is not written).
    #[must_use]
    pub fn is_unset(&self) -> bool {
        self.omega.is_none() && self.omega_hat.is_none() && self.sigma_hat.is_none()
    }
}

/// `[network]`: impairments of every link (defaults) and per directed link
/// (`[[network.link]]`), acting on the receiving side in simulated time.
/// Delay, jitter and period are whole multiples of `simulation.dt`.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NetworkSpec {
    /// Seed of the loss and jitter streams.
    #[serde(default)]
    pub seed: u64,
    /// Constant delay of every message, s.
    #[serde(default)]
    pub delay: Option<f64>,
    /// Extra delay uniform in [0, jitter], s.
    #[serde(default)]
    pub jitter: Option<f64>,
    /// Loss: a probability (Bernoulli) or a loss model table.
    #[serde(default)]
    pub loss: Option<LossSpec>,
    /// Exchange period of every link, s (the link then carries only stage-0
    /// messages of every period).
    #[serde(default)]
    pub period: Option<f64>,
    /// Per-link overrides.
    #[serde(default, rename = "link")]
    pub links: Vec<LinkSpec>,
}

/// `[[network.link]]`: one directed link's impairments (unset fields take
/// the `[network]` defaults).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkSpec {
    /// Sender id (0 = leader).
    pub from: u32,
    /// Receiver id.
    pub to: u32,
    /// Constant delay, s.
    #[serde(default)]
    pub delay: Option<f64>,
    /// Jitter bound, s.
    #[serde(default)]
    pub jitter: Option<f64>,
    /// Loss.
    #[serde(default)]
    pub loss: Option<LossSpec>,
    /// Exchange period, s.
    #[serde(default)]
    pub period: Option<f64>,
}

/// `loss = 0.1` (Bernoulli) or `loss = { model = "gilbert-elliott", p_gb, p_bg, loss_good, loss_bad }`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a probability, or a table { model = \"gilbert-elliott\", p_gb, p_bg, loss_good, loss_bad }"
)]
pub enum LossSpec {
    /// Bernoulli loss probability.
    Probability(f64),
    /// A loss model.
    Model(LossModelSpec),
}

/// A loss model table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LossModelSpec {
    /// `"bernoulli"` or `"gilbert-elliott"`.
    pub model: String,
    /// Bernoulli probability.
    #[serde(default)]
    pub p: Option<f64>,
    /// Gilbert–Elliott P(good → bad) per message.
    #[serde(default)]
    pub p_gb: Option<f64>,
    /// Gilbert–Elliott P(bad → good) per message.
    #[serde(default)]
    pub p_bg: Option<f64>,
    /// Loss probability in the good state (default 0).
    #[serde(default)]
    pub loss_good: Option<f64>,
    /// Loss probability in the bad state (default 1).
    #[serde(default)]
    pub loss_bad: Option<f64>,
}

/// `[simulation]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Simulation {
    /// Integrator step, s.
    pub dt: f64,
    /// Simulated horizon, s (a multiple of `dt`).
    pub duration: f64,
    /// Exchange semantics.
    #[serde(default)]
    pub coupling: CouplingKind,
    /// Exchange period for `coupling = "sampled"`, s (a multiple of `dt`).
    #[serde(default)]
    pub period: Option<f64>,
}

/// `simulation.coupling`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum CouplingKind {
    /// Exchange at every integrator stage (the continuous-time closed loop).
    #[default]
    Continuous,
    /// Exchange once per `period`, hold in between.
    Sampled,
}

/// `[output]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Output {
    /// Period of the rows of `errors.csv`, s (a multiple of `dt`).
    #[serde(default = "default_sample_period")]
    pub sample_period: f64,
    /// Draw the torque each agent applied, `‖τᵢ‖`, in a panel of
    /// `errors.svg` (default false: the plot as without it).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub torque_plot: bool,
}

fn default_sample_period() -> f64 {
    0.01
}

impl Default for Output {
    fn default() -> Self {
        Self {
            sample_period: default_sample_period(),
            torque_plot: false,
        }
    }
}

/// `[scheme]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SchemeSpec {
    /// Which of the paper's schemes.
    pub kind: SchemeKind,
    /// Observer gains (schemes 1 and 2).
    #[serde(default)]
    pub observer: Option<ObserverGainsSpec>,
    /// Control gains.
    pub control: ControlGainsSpec,
    /// `"corrected"` (the default) or `"as-printed"`: the signs of `Σᵢ`,
    /// `Γᵢ` as the paper prints them (erratum 1 of `docs/paper.md`), a
    /// negative control for the observer schemes.
    #[serde(default, skip_serializing_if = "ControlLaw::is_corrected")]
    pub law: ControlLaw,
}

/// `scheme.kind`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SchemeKind {
    /// Scheme 1: observer `7a`–`7c` + law `control` (time-varying reference).
    ObserverTimeVarying,
    /// Scheme 2: observer `16a`–`16b` + law `controlconstantestimate`.
    ObserverConstant,
    /// Scheme 3: law `districontrol`, no observer.
    Observerless,
}

/// `scheme.observer`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserverGainsSpec {
    /// `k_R` of the observer.
    pub k_r: f64,
    /// `k_ω` of the observer.
    pub k_omega: f64,
    /// `k_σ` (scheme 1 only).
    #[serde(default)]
    pub k_sigma: Option<f64>,
}

/// `scheme.control`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlGainsSpec {
    /// `k_R̄` (schemes 1–2) or `k_Ř` (scheme 3).
    pub k_r: f64,
    /// `k_ω̄` (schemes 1–2) or `k_ω̌` (scheme 3).
    pub k_omega: f64,
}

/// `[leader]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeaderSpec {
    /// Time-varying (eq. `leader`) or constant.
    pub reference: ReferenceKind,
    /// Generator `P` of `σ̇₀ = P σ₀` (3 rows of 3), required by scheme 1.
    #[serde(default)]
    pub p: Option<[[f64; 3]; 3]>,
    /// `R₀(0)`.
    pub attitude: RotationSpec,
    /// `ω₀(0)`, rad/s (time-varying only).
    #[serde(default)]
    pub omega: Option<[f64; 3]>,
    /// `σ₀(0)`, rad/s² (time-varying only).
    #[serde(default)]
    pub sigma: Option<[f64; 3]>,
}

/// `leader.reference`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReferenceKind {
    /// `Ṙ₀ = R₀ω₀^×, ω̇₀ = σ₀, σ̇₀ = Pσ₀`.
    TimeVarying,
    /// `R₀` constant.
    Constant,
}

/// `[[leader_link]]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LeaderLinkSpec {
    /// The agent that hears the leader.
    pub agent: u32,
    /// `A_{i,0}` (or `Ǎ_{i,0}`): 3 numbers (diagonal) or 3 rows of 3.
    pub gain: MatrixSpec,
}

/// `[[agent]]`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentSpec {
    /// Agent id, ≥ 1 (0 is the leader).
    pub id: u32,
    /// Inertia `Jᵢ`, kg·m²: 3 numbers (diagonal) or 3 rows of 3.
    pub inertia: MatrixSpec,
    /// `Rᵢ(0)`.
    pub attitude: RotationSpec,
    /// `ωᵢ(0)`, body frame, rad/s.
    pub omega: [f64; 3],
    /// `Āᵢ` of the control law (schemes 1–2).
    #[serde(default)]
    pub control_gain: Option<MatrixSpec>,
    /// The observer's initial state (schemes 1–2).
    #[serde(default)]
    pub observer: Option<ObserverInit>,
    /// A program of your own to run in place of the built-in agent (a
    /// plug-in, PROTOCOL.md): program and arguments. It is started in the
    /// scenario file's directory with `--config FILE` appended.
    #[serde(default)]
    pub command: Option<Vec<String>>,
    /// Extra environment variables of the plug-in.
    #[serde(default)]
    pub env: Option<std::collections::BTreeMap<String, String>>,
    /// This agent's actuator limits (in place of `[actuator]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actuator: Option<ActuatorSpec>,
    /// This agent's sensor errors (in place of `[sensor]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sensor: Option<crate::body::SensorSpec>,
    /// What this agent's law assumes of its body (in place of `[controller]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<crate::body::ControllerSpec>,
}

/// `[actuator]` or `agent.actuator`: the torque a body can apply.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActuatorSpec {
    /// N·m: one number, the largest `‖τ‖` (norm saturation), or three,
    /// the largest `|τ_k|` per body axis (per-axis saturation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_torque: Option<TorqueLimit>,
    /// N·m/s: the largest rate of change of the applied torque (by norm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_torque_rate: Option<f64>,
}

/// `max_torque = 0.5` or `max_torque = [0.2, 0.3, 0.2]`.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number (the largest ‖τ‖, N·m) or 3 numbers (the largest |τ_k| per body axis)"
)]
pub enum TorqueLimit {
    /// The largest norm.
    Norm(f64),
    /// The largest magnitude per axis.
    Axes([f64; 3]),
}

/// `agent.observer`.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObserverInit {
    /// `R̂ᵢ(0)`.
    pub attitude: RotationSpec,
    /// `ω̂ᵢ(0)`, rad/s.
    pub omega: [f64; 3],
    /// `σ̂ᵢ(0)`, rad/s² (scheme 1).
    #[serde(default)]
    pub sigma: Option<[f64; 3]>,
}

/// `[graph]`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GraphSpec {
    /// `"strict"` (default): a scenario outside Assumption 1 (a cycle, an
    /// agent the leader does not reach, no leader link) is refused;
    /// `"off"`: it runs, marked `outside_theory`.
    #[serde(default)]
    pub assumptions: Assumptions,
}

impl GraphSpec {
    /// Whether it is as if absent.
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }
}

/// `[graph] assumptions`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Assumptions {
    /// Assumption 1 holds or the scenario is refused.
    #[default]
    Strict,
    /// Departures from Assumption 1 are allowed and reported.
    Off,
}

/// `[[edge]]`: `agents` (both ways) or `from` and `to` (one way); with
/// neither, `agents` is a missing field, as before one-way edges existed.
#[derive(Debug, Clone, Serialize)]
pub struct EdgeSpec {
    /// The two agent ids of an undirected edge (the paper's: each hears
    /// the other with the same gain).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub agents: Option<[u32; 2]>,
    /// A one-way edge's sender (with `to`; only with `[graph]
    /// assumptions = "off"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub from: Option<u32>,
    /// A one-way edge's receiver: agent `to` hears agent `from`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub to: Option<u32>,
    /// `A_{i,j} = A_{j,i}` (or `Ǎ_{i,j}`), or a one-way edge's gain
    /// `A_{to,from}`: 3 numbers (diagonal) or 3 rows of 3.
    pub gain: MatrixSpec,
}

/// `[[edge]]` as written, before [`EdgeSpec`] asks for its ends.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EdgeFields {
    #[serde(default)]
    agents: Option<[u32; 2]>,
    #[serde(default)]
    from: Option<u32>,
    #[serde(default)]
    to: Option<u32>,
    gain: MatrixSpec,
}

impl<'de> Deserialize<'de> for EdgeSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let e = EdgeFields::deserialize(d)?;
        if e.agents.is_none() && e.from.is_none() && e.to.is_none() {
            return Err(serde::de::Error::missing_field("agents"));
        }
        Ok(Self {
            agents: e.agents,
            from: e.from,
            to: e.to,
            gain: e.gain,
        })
    }
}

/// A 3×3 matrix: its diagonal or its rows.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(untagged, expecting = "3 numbers (a diagonal) or 3 rows of 3 numbers")]
pub enum MatrixSpec {
    /// `diag(a, b, c)`.
    Diagonal([f64; 3]),
    /// Rows.
    Rows([[f64; 3]; 3]),
}

/// A rotation: exactly one of axis + angle (in rad, deg or multiples of π),
/// a unit quaternion `[w, x, y, z]`, or a rotation matrix (rows).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotationSpec {
    /// Rotation axis (normalised on use).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis: Option<[f64; 3]>,
    /// Angle in radians.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_rad: Option<f64>,
    /// Angle in degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// Angle in multiples of π (`angle_pi = 0.1` is π/10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_pi: Option<f64>,
    /// Unit quaternion, scalar first `[w, x, y, z]` (normalised on use).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub quaternion: Option<[f64; 4]>,
    /// Rotation matrix, rows (must be orthogonal with det +1 to 1e-9).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub matrix: Option<[[f64; 3]; 3]>,
}
