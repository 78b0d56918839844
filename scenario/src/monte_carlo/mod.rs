//! `[monte_carlo]`: what a Monte Carlo disperses and how, and its
//! resolution against the scenario's scheme and leader ([`Dispersion`]).
//!
//! ```toml
//! [monte_carlo]
//! disperse = ["attitude", "omega", "attitude_hat", "omega_hat", "sigma_hat"]  # default: all the scheme has
//! omega_max = 5.0   # rad/s: ‖ω(0)‖, ‖ω̂(0)‖ (and ‖ω₀(0)‖) uniform in [0, omega_max]
//! sigma_max = 5.0   # rad/s²: ‖σ̂(0)‖ (and ‖σ₀(0)‖) uniform in [0, sigma_max]
//! leader = false    # also disperse R₀(0) (and ω₀(0), σ₀(0) of a time-varying leader)
//! ```
//! Attitudes are drawn Haar-uniformly on SO(3), vectors with a uniform
//! direction (the orchestrator's `mc::haar`). Every field can be set from the command
//! line like any other (`--set monte_carlo.omega_max=2`).
//!
//! Any numeric field can be drawn too, each from its own law
//! (`[[monte_carlo.param]]`, [`param`]).

pub mod param;

pub use param::{Dispersed, Law};

use crate::Issue;
use crate::schema::{ReferenceKind, Scenario, SchemeKind};
use serde::{Deserialize, Serialize};

/// Default `omega_max`, rad/s.
pub const DEFAULT_OMEGA_MAX: f64 = 5.0;
/// Default `sigma_max`, rad/s².
pub const DEFAULT_SIGMA_MAX: f64 = 5.0;

/// The `[monte_carlo]` table as written (unknown keys are refused).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MonteCarloSpec {
    /// The agents' initial values to draw (default: every one the scheme has).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub disperse: Option<Vec<Quantity>>,
    /// Bound of the norms of ω(0) and ω̂(0), rad/s (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_max: Option<f64>,
    /// Bound of the norm of σ̂(0), rad/s² (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sigma_max: Option<f64>,
    /// Disperse the leader's initial state too (default false).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leader: Option<bool>,
    /// Numeric fields drawn per trial (`[[monte_carlo.param]]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub param: Option<Vec<param::ParamSpec>>,
}

/// An agent's initial value that can be drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// `Rᵢ(0)`, Haar-uniform.
    Attitude,
    /// `ωᵢ(0)`.
    Omega,
    /// The observer's `R̂ᵢ(0)`, Haar-uniform (schemes 1–2).
    AttitudeHat,
    /// The observer's `ω̂ᵢ(0)` (schemes 1–2).
    OmegaHat,
    /// The observer's `σ̂ᵢ(0)` (scheme 1).
    SigmaHat,
}

impl Quantity {
    /// The name in `[monte_carlo] disperse`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Attitude => "attitude",
            Quantity::Omega => "omega",
            Quantity::AttitudeHat => "attitude_hat",
            Quantity::OmegaHat => "omega_hat",
            Quantity::SigmaHat => "sigma_hat",
        }
    }

    /// Whether scheme `kind` has this initial value.
    #[must_use]
    pub fn in_scheme(self, kind: SchemeKind) -> bool {
        match self {
            Quantity::Attitude | Quantity::Omega => true,
            Quantity::AttitudeHat | Quantity::OmegaHat => kind != SchemeKind::Observerless,
            Quantity::SigmaHat => kind == SchemeKind::ObserverTimeVarying,
        }
    }

    const ALL: [Quantity; 5] = [
        Quantity::Attitude,
        Quantity::Omega,
        Quantity::AttitudeHat,
        Quantity::OmegaHat,
        Quantity::SigmaHat,
    ];
}

/// What the leader's draws replace.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LeaderDispersion {
    /// Nothing: the leader as in the scenario.
    None,
    /// `R₀(0)` (a constant reference).
    Attitude,
    /// `R₀(0)`, `ω₀(0)` and `σ₀(0)` (a time-varying reference).
    State,
}

/// The resolved `[monte_carlo]`: what each trial draws and replaces (read
/// back from `mc.json` by `attsync mc merge`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dispersion {
    /// The agents' values replaced by draws (sorted).
    pub disperse: Vec<Quantity>,
    /// Bound of ‖ω(0)‖, ‖ω̂(0)‖, ‖ω₀(0)‖, rad/s.
    pub omega_max: f64,
    /// Bound of ‖σ̂(0)‖, ‖σ₀(0)‖, rad/s².
    pub sigma_max: f64,
    /// The leader's draws.
    pub leader: LeaderDispersion,
    /// Numeric fields drawn per trial, in file order.
    pub params: Vec<Dispersed>,
    /// Number of `[[agent]]` entries (draws are made for each, in file order).
    #[serde(skip)]
    pub agents: usize,
}

impl Dispersion {
    /// Resolves `scenario`'s `[monte_carlo]` (or the defaults): every
    /// problem as an [`Issue`] naming its field.
    ///
    /// # Errors
    /// A bound that is not finite and ≥ 0; a quantity the scheme does not
    /// have, or given twice.
    pub fn resolve(scenario: &Scenario) -> Result<Self, Vec<Issue>> {
        let spec = scenario.monte_carlo.clone().unwrap_or_default();
        let kind = scenario.scheme.kind;
        let mut issues = Vec::new();
        let mut bound = |field: &str, v: Option<f64>, default: f64| {
            let v = v.unwrap_or(default);
            if !(v.is_finite() && v >= 0.0) {
                issues.push(issue(field, format!("{v}: must be finite and ≥ 0")));
            }
            v
        };
        let omega_max = bound("omega_max", spec.omega_max, DEFAULT_OMEGA_MAX);
        let sigma_max = bound("sigma_max", spec.sigma_max, DEFAULT_SIGMA_MAX);
        let disperse = match spec.disperse {
            None => Quantity::ALL
                .into_iter()
                .filter(|q| q.in_scheme(kind))
                .collect(),
            Some(list) => checked(&list, kind, &mut issues),
        };
        let leader = match (spec.leader.unwrap_or(false), scenario.leader.reference) {
            (false, _) => LeaderDispersion::None,
            (true, ReferenceKind::Constant) => LeaderDispersion::Attitude,
            (true, ReferenceKind::TimeVarying) => LeaderDispersion::State,
        };
        let params = param::check(spec.param.as_deref().unwrap_or_default(), &mut issues);
        if !issues.is_empty() {
            return Err(issues);
        }
        Ok(Self {
            disperse,
            omega_max,
            sigma_max,
            leader,
            params,
            agents: scenario.agents.len(),
        })
    }

    /// Whether agents' `q` is drawn.
    #[must_use]
    pub fn has(&self, q: Quantity) -> bool {
        self.disperse.contains(&q)
    }
}

/// `list` sorted, with an issue for each quantity the scheme lacks or repeated.
fn checked(list: &[Quantity], kind: SchemeKind, issues: &mut Vec<Issue>) -> Vec<Quantity> {
    let mut out: Vec<Quantity> = Vec::new();
    for &q in list {
        if !q.in_scheme(kind) {
            issues.push(issue(
                "disperse",
                format!(
                    "`{}`: scheme {} has no such initial value",
                    q.name(),
                    crate::resolve::kind_name(kind)
                ),
            ));
        } else if out.contains(&q) {
            issues.push(issue("disperse", format!("`{}` is listed twice", q.name())));
        } else {
            out.push(q);
        }
    }
    out.sort();
    out
}

fn issue(field: &str, reason: String) -> Issue {
    Issue {
        field: format!("monte_carlo.{field}"),
        reason,
    }
}
