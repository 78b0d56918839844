//! `[[monte_carlo.param]]`: any numeric scenario field drawn per trial.
//!
//! ```toml
//! [[monte_carlo.param]]
//! field = "scheme.control.k_r"      # a path as for --set
//! distribution = "uniform"          # min ≤ x ≤ max
//! min = 1.0
//! max = 3.0
//!
//! [[monte_carlo.param]]
//! field = "network.delay"
//! distribution = "normal"           # mean, std; optional bounds min, max (truncated)
//! mean = 0.1
//! std = 0.02
//! min = 0.0
//!
//! [[monte_carlo.param]]
//! field = "agent[0].inertia[0]"
//! distribution = "log-uniform"      # 0 < min ≤ max: ln x uniform
//! min = 0.5
//! max = 2.0
//! ```
//! A bounded normal is the normal conditioned on `[min, max]`, which must
//! hold at least [`MIN_MASS`] of it (a draw is redrawn until it falls in).
//! `step = S` rounds every draw to the nearest multiple of `S`; a timing
//! field (a path ending in `delay`, `jitter` or `period`, which must be
//! whole steps) is rounded to `simulation.dt` unless `step` is given.

use crate::Issue;
use serde::{Deserialize, Serialize};

/// The least share of a normal that its bounds may hold (so that a draw
/// needs on average at most 1 000 tries).
pub const MIN_MASS: f64 = 1e-3;

/// One `[[monte_carlo.param]]` entry as written (unknown keys refused).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamSpec {
    /// The field, as for `--set` (`scheme.control.k_r`, `agent[2].inertia[0]`).
    pub field: String,
    /// Its law.
    pub distribution: Distribution,
    /// Lower bound (uniform, log-uniform: required; normal: optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<f64>,
    /// Upper bound (uniform, log-uniform: required; normal: optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max: Option<f64>,
    /// The normal's mean.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean: Option<f64>,
    /// The normal's standard deviation (≥ 0; 0: always the mean).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Round each draw to a multiple of this (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
}

/// The name of a law in `distribution`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Distribution {
    /// Uniform on `[min, max]`.
    Uniform,
    /// Normal (`mean`, `std`), optionally conditioned on `[min, max]`.
    Normal,
    /// `ln x` uniform on `[ln min, ln max]`.
    LogUniform,
}

/// A field's law, checked.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "distribution", rename_all = "kebab-case")]
pub enum Law {
    /// Uniform on `[min, max]`.
    Uniform {
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// `ln x` uniform on `[ln min, ln max]`, `0 < min`.
    LogUniform {
        /// Lower bound (> 0).
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// Normal, conditioned on `[min, max]` (each `None`: unbounded).
    Normal {
        /// Mean.
        mean: f64,
        /// Standard deviation.
        std: f64,
        /// Lower bound.
        min: Option<f64>,
        /// Upper bound.
        max: Option<f64>,
    },
}

impl Law {
    /// The values the law can take at its ends (its bounds, or its mean
    /// where unbounded): checked as scenarios before anything runs.
    #[must_use]
    pub fn ends(&self) -> [f64; 2] {
        match *self {
            Law::Uniform { min, max } | Law::LogUniform { min, max } => [min, max],
            Law::Normal { mean, min, max, .. } => [min.unwrap_or(mean), max.unwrap_or(mean)],
        }
    }
}

/// A field drawn per trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Dispersed {
    /// The field, as for `--set`.
    pub field: String,
    /// Its law.
    #[serde(flatten)]
    pub law: Law,
    /// Each draw rounded to a multiple of this (`None`: as drawn, or
    /// `simulation.dt` for a timing field).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
}

/// `specs` checked: each issue names `monte_carlo.param[k].KEY`.
pub fn check(specs: &[ParamSpec], issues: &mut Vec<Issue>) -> Vec<Dispersed> {
    let mut out: Vec<Dispersed> = Vec::new();
    for (k, s) in specs.iter().enumerate() {
        let mut bad = |key: &str, reason: String| {
            issues.push(Issue {
                field: format!("monte_carlo.param[{k}].{key}"),
                reason,
            });
        };
        if s.field.trim().is_empty() || s.field.contains('=') {
            bad("field", format!("{:?}: a field path as for --set", s.field));
            continue;
        }
        if out.iter().any(|d| d.field == s.field) {
            bad("field", format!("`{}` is dispersed twice", s.field));
            continue;
        }
        if let Some(q) = s.step.filter(|q| !(q.is_finite() && *q > 0.0)) {
            bad("step", format!("{q}: must be finite and > 0"));
        }
        if let Some(law) = law(s, &mut bad) {
            out.push(Dispersed {
                field: s.field.clone(),
                law,
                step: s.step,
            });
        }
    }
    out
}

/// The law of `s`, or `None` after reporting each problem to `bad`.
fn law(s: &ParamSpec, bad: &mut impl FnMut(&str, String)) -> Option<Law> {
    let finite = |key: &str, v: Option<f64>, bad: &mut dyn FnMut(&str, String)| match v {
        Some(x) if !x.is_finite() => {
            bad(key, format!("{x}: must be finite"));
            None
        }
        other => other,
    };
    let (min, max) = (finite("min", s.min, bad), finite("max", s.max, bad));
    let (mean, std) = (finite("mean", s.mean, bad), finite("std", s.std, bad));
    let name = match s.distribution {
        Distribution::Uniform => "uniform",
        Distribution::LogUniform => "log-uniform",
        Distribution::Normal => "normal",
    };
    if s.distribution != Distribution::Normal {
        for (key, v) in [("mean", s.mean), ("std", s.std)] {
            if v.is_some() {
                bad(
                    key,
                    format!("a {name} law has no {key} (it takes min and max)"),
                );
            }
        }
        let (Some(lo), Some(hi)) = (min, max) else {
            bad("min", format!("a {name} law needs finite min and max"));
            return None;
        };
        if lo > hi {
            bad("max", format!("{hi} is below min = {lo}"));
            return None;
        }
        if s.distribution == Distribution::LogUniform && lo <= 0.0 {
            bad("min", format!("{lo}: a log-uniform law needs min > 0"));
            return None;
        }
        return Some(match s.distribution {
            Distribution::LogUniform => Law::LogUniform { min: lo, max: hi },
            _ => Law::Uniform { min: lo, max: hi },
        });
    }
    normal(mean, std, min, max, bad)
}

/// A normal law, its bounds holding at least [`MIN_MASS`] of it.
fn normal(
    mean: Option<f64>,
    std: Option<f64>,
    min: Option<f64>,
    max: Option<f64>,
    bad: &mut impl FnMut(&str, String),
) -> Option<Law> {
    let (Some(mean), Some(std)) = (mean, std) else {
        bad("mean", "a normal law needs finite mean and std".into());
        return None;
    };
    if std < 0.0 {
        bad("std", format!("{std}: must be ≥ 0"));
        return None;
    }
    let (lo, hi) = (
        min.unwrap_or(f64::NEG_INFINITY),
        max.unwrap_or(f64::INFINITY),
    );
    let mass = if std == 0.0 {
        f64::from(u8::from(lo <= mean && mean <= hi))
    } else {
        phi((hi - mean) / std) - phi((lo - mean) / std)
    };
    if lo >= hi || mass < MIN_MASS {
        bad(
            "min",
            format!(
                "[{lo}, {hi}] holds {mass:.3e} of normal({mean}, {std}): \
                 the bounds must hold at least {MIN_MASS}"
            ),
        );
        return None;
    }
    Some(Law::Normal {
        mean,
        std,
        min,
        max,
    })
}

/// The standard normal's distribution function, Φ(x) = erfc(−x/√2)/2.
#[must_use]
pub fn phi(x: f64) -> f64 {
    0.5 * libm::erfc(-x / std::f64::consts::SQRT_2)
}
