//! `--find-margin`: the stability boundary the bisection brackets, and the
//! linearisation's exact margin beside it.
//!
//! The bisection classifies each run by whether its error decays
//! ([`super::SweepRow::decays`]), with every run extended until its verdict
//! is final: so the bracket is the system's, not the horizon's. For a swept
//! `network.delay`, the linearisation's margin ([`attitude::linear`]: the
//! smallest common delay at which a characteristic root crosses the
//! imaginary axis) is written beside it, with a warning when the two
//! disagree by more than the bracket's width and one quantum.

use super::SweepOptions;
use crate::run::Judging;
use crate::scenario::Loaded;
use crate::until::{DEFAULT_MAX_FACTOR, Until};
use attitude::linear::{Linearisation, Margin};
use serde::Serialize;

/// The swept field whose linear margin is known: the delay of every link.
pub const DELAY_FIELD: &str = "network.delay";

/// The linearisation's margin (`attsync margin`) for a swept delay.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum LinearMargin {
    /// A root crosses the imaginary axis at `delay` s, frequency `omega` rad/s.
    Crossing {
        /// The delay margin, s.
        delay: f64,
        /// The crossing frequency, rad/s.
        omega: f64,
    },
    /// No root ever crosses: stable for every delay.
    DelayIndependent,
    /// Unstable already without delay.
    UnstableWithoutDelay,
    /// The scenario cannot be linearised (why).
    Unavailable {
        /// Why.
        reason: String,
    },
}

/// What `--find-margin` found (`sweep.json` `margin`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MarginResult {
    /// The largest value whose error decays.
    pub converges_up_to: f64,
    /// The smallest value whose error does not.
    pub fails_from: f64,
    /// The linear margin, for a swept `network.delay`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub linear: Option<LinearMargin>,
    /// Set when the linear margin lies outside the bracket (widened by one
    /// quantum each side).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warning: Option<String>,
}

/// `o` with every run extended until its verdict is final when it finds a
/// margin and `--until` was left at the horizon: the bracket must not
/// depend on the horizon.
#[must_use]
pub fn settled_for_margin(o: &SweepOptions, base: &Loaded) -> SweepOptions {
    let mut o = o.clone();
    if o.find_margin.is_some() && o.run.judging.until == Until::Horizon {
        let net = &base.resolved.network;
        o.run.judging = Judging {
            until: Until::Settled {
                max_duration: DEFAULT_MAX_FACTOR * net.steps as f64 * net.dt,
            },
            ..o.run.judging
        };
    }
    o
}

/// The linear margin of `base` when `param` is the delay of every link.
#[must_use]
pub fn linear(param: &str, base: &Loaded) -> Option<LinearMargin> {
    (param == DELAY_FIELD).then(|| match Linearisation::of(&base.resolved.network) {
        Ok(l) => match l.margin() {
            Margin::Crossing { delay, omega, .. } => LinearMargin::Crossing { delay, omega },
            Margin::DelayIndependent => LinearMargin::DelayIndependent,
            Margin::UnstableWithoutDelay { .. } => LinearMargin::UnstableWithoutDelay,
        },
        Err(e) => LinearMargin::Unavailable {
            reason: e.to_string(),
        },
    })
}

/// The result of a bisection that ended with `[lo, hi]`.
#[must_use]
pub fn result(param: &str, base: &Loaded, lo: f64, hi: f64, quantum: Option<f64>) -> MarginResult {
    let linear = linear(param, base);
    let warning = linear
        .as_ref()
        .and_then(|l| disagreement(l, lo, hi, quantum));
    MarginResult {
        converges_up_to: lo,
        fails_from: hi,
        linear,
        warning,
    }
}

/// A warning when the linear margin `l` is not within `[lo, hi]` widened by
/// one `quantum` (the bisection's resolution) each side.
#[must_use]
pub fn disagreement(l: &LinearMargin, lo: f64, hi: f64, quantum: Option<f64>) -> Option<String> {
    let q = quantum.unwrap_or(0.0);
    match *l {
        LinearMargin::Crossing { delay, .. } if delay < lo - q || delay > hi + q => Some(format!(
            "the linearisation's margin {delay:.6} s lies outside the simulated bracket \
             [{lo}, {hi}] s: the nonlinear system's boundary differs from the linear one \
             (large initial errors, or runs too short to decide: raise --max-duration)"
        )),
        LinearMargin::DelayIndependent => Some(format!(
            "the linearisation is stable for every delay, yet the simulated error stops \
             decaying between {lo} and {hi} s: a nonlinear effect"
        )),
        LinearMargin::UnstableWithoutDelay => {
            Some("the linearisation is unstable without delay".to_string())
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_margin_inside_the_bracket_is_no_warning() {
        let l = |delay| LinearMargin::Crossing { delay, omega: 1.0 };
        assert_eq!(disagreement(&l(0.36), 0.35, 0.37, Some(0.001)), None);
        assert_eq!(disagreement(&l(0.3705), 0.35, 0.37, Some(0.001)), None);
        let w = disagreement(&l(0.5), 0.35, 0.37, Some(0.001)).unwrap();
        assert!(w.contains("outside the simulated bracket"), "{w}");
        assert!(disagreement(&l(0.2), 0.35, 0.37, None).is_some());
        assert!(disagreement(&LinearMargin::DelayIndependent, 0.3, 0.4, None).is_some());
    }
}
