//! A trial's outcome: what is recorded of its run ([`Trace`]: the largest
//! error over agents at each sample, not whole trajectories) and its
//! classification ([`classify`]).

use crate::results::summary::settle_time;
use attitude::engine::Snapshot;
use attitude::metrics::errors;
use serde::Serialize;

/// How a trial ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outcome {
    /// Complete, and every agent's final attitude error `|Rᵢ R₀ᵀ|_I` and
    /// angular-velocity error `‖ωᵢ − ω₀‖` below the tolerance.
    Converged,
    /// Complete, but some final error at or above the tolerance (how far:
    /// the final errors).
    NotConverged,
    /// A state left the envelope (`[guard]`, `attitude::guard`).
    Diverged,
    /// A node process failed (process engine).
    Failed,
}

impl Outcome {
    /// The name in `trials.csv` and `mc.json`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::NotConverged => "not-converged",
            Outcome::Diverged => "diverged",
            Outcome::Failed => "failed",
        }
    }

    /// Every outcome, in the order of the summary table.
    pub const ALL: [Outcome; 4] = [
        Outcome::Converged,
        Outcome::NotConverged,
        Outcome::Diverged,
        Outcome::Failed,
    ];
}

/// How the engine finished a trial's run.
#[derive(Debug, Clone, PartialEq)]
pub enum End {
    /// It reached the horizon.
    Complete,
    /// A state left the envelope (the run's message).
    Diverged(String),
    /// A node failed (the run's reason).
    Failed(String),
}

/// The largest errors over agents at each output sample of a run.
#[derive(Debug, Clone, Default)]
pub struct Trace {
    /// Sample times, s (as `errors.csv` writes them).
    pub t: Vec<f64>,
    /// `max over agents of max(|Rᵢ R₀ᵀ|_I, ‖ωᵢ − ω₀‖)` at each sample (NaN
    /// if any is NaN).
    pub max_err: Vec<f64>,
    /// The largest attitude error over agents at the last sample.
    pub final_att: f64,
    /// The largest angular-velocity error over agents at the last sample.
    pub final_angvel: f64,
    dt: f64,
    has_observer: bool,
}

/// `max` that keeps a NaN (`f64::max` drops it).
pub(super) fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

impl Trace {
    /// An empty trace for a network with step `dt`.
    #[must_use]
    pub fn new(dt: f64, has_observer: bool) -> Self {
        Self {
            final_att: f64::NAN,
            final_angvel: f64::NAN,
            dt,
            has_observer,
            ..Self::default()
        }
    }

    /// Records the errors of `snap` (the same numbers `errors.csv` has).
    pub fn record(&mut self, snap: &Snapshot<'_>) {
        let t_str = crate::results::fmt_time(snap.step, self.dt);
        let (mut att, mut angvel) = (0.0_f64, 0.0_f64);
        for x in snap.agents {
            let e = errors(x, snap.leader, self.has_observer);
            att = nan_max(att, e.att);
            angvel = nan_max(angvel, e.angvel);
        }
        self.push(
            t_str.parse().expect("fmt_time prints a number"),
            att,
            angvel,
        );
    }

    /// Appends a sample at time `t` whose largest errors over agents are
    /// `att` and `angvel`.
    pub fn push(&mut self, t: f64, att: f64, angvel: f64) {
        self.t.push(t);
        self.max_err.push(nan_max(att, angvel));
        (self.final_att, self.final_angvel) = (att, angvel);
    }
}

/// One trial's result: a row of `trials.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrialResult {
    /// Trial index (0-based).
    pub trial: u64,
    /// The trial's seed ([`super::trial_seed`]).
    pub seed: u64,
    /// How it ended.
    pub outcome: Outcome,
    /// Largest final attitude error over agents (at the last sample).
    pub final_max_att_err: f64,
    /// Largest final angular-velocity error over agents, rad/s.
    pub final_max_angvel_err: f64,
    /// Time of the last sample, s.
    pub t_end: f64,
    /// First sample time after which every agent's attitude and
    /// angular-velocity errors stay below 1e-3 to the end (`None`: never).
    pub settle_1e3: Option<f64>,
    /// The same for 1e-6.
    pub settle_1e6: Option<f64>,
    /// Why a diverged or failed trial stopped.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// Classifies a trial that ended as `end` with `trace` recorded, against
/// `tolerance` (> 0). Settle times only count for a complete run.
#[must_use]
pub fn classify(trial: u64, seed: u64, end: End, trace: &Trace, tolerance: f64) -> TrialResult {
    let complete = end == End::Complete;
    let settle = |eps| {
        complete
            .then(|| settle_time(&trace.t, &trace.max_err, eps))
            .flatten()
    };
    let (outcome, reason) = match end {
        End::Complete => {
            let below = trace.final_att < tolerance && trace.final_angvel < tolerance;
            let o = if below {
                Outcome::Converged
            } else {
                Outcome::NotConverged
            };
            (o, None)
        }
        End::Diverged(why) => (Outcome::Diverged, Some(why)),
        End::Failed(why) => (Outcome::Failed, Some(why)),
    };
    TrialResult {
        trial,
        seed,
        outcome,
        final_max_att_err: trace.final_att,
        final_max_angvel_err: trace.final_angvel,
        t_end: trace.t.last().copied().unwrap_or(0.0),
        settle_1e3: settle(1e-3),
        settle_1e6: settle(1e-6),
        reason,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(errs: &[f64], att: f64, angvel: f64) -> Trace {
        Trace {
            t: (0..errs.len()).map(|k| k as f64).collect(),
            max_err: errs.to_vec(),
            final_att: att,
            final_angvel: angvel,
            dt: 1.0,
            has_observer: false,
        }
    }

    #[test]
    fn a_converging_a_stalling_and_a_diverging_trial() {
        let good = trace(&[1.0, 1e-2, 1e-4, 1e-7], 1e-7, 1e-8);
        let r = classify(0, 9, End::Complete, &good, 1e-4);
        assert_eq!(r.outcome, Outcome::Converged);
        assert_eq!((r.settle_1e3, r.settle_1e6), (Some(2.0), Some(3.0)));
        assert_eq!(r.t_end, 3.0);
        // Stalled at an error of 0.5: not converged, and how far.
        let stall = trace(&[1.0, 0.5, 0.5, 0.5], 0.5, 1e-9);
        let r = classify(1, 9, End::Complete, &stall, 1e-4);
        assert_eq!(r.outcome, Outcome::NotConverged);
        assert_eq!((r.final_max_att_err, r.settle_1e3), (0.5, None));
        // The angular velocity counts too.
        let spin = trace(&[1.0, 1e-5, 1e-5, 1e-5], 1e-9, 1e-3);
        assert_eq!(
            classify(2, 9, End::Complete, &spin, 1e-4).outcome,
            Outcome::NotConverged
        );
        let boom = trace(&[1.0, 1e-7], 1e-7, 1e-7);
        let r = classify(
            3,
            9,
            End::Diverged("diverged at t = 2 s".into()),
            &boom,
            1e-4,
        );
        assert_eq!(r.outcome, Outcome::Diverged);
        assert_eq!(
            (r.settle_1e3, r.reason.as_deref()),
            (None, Some("diverged at t = 2 s"))
        );
        let dead = classify(4, 9, End::Failed("agent-2 died".into()), &boom, 1e-4);
        assert_eq!(dead.outcome, Outcome::Failed);
    }

    #[test]
    fn a_nan_error_is_never_below_the_tolerance() {
        let nan = trace(&[1.0, f64::NAN], f64::NAN, 0.0);
        let r = classify(0, 0, End::Complete, &nan, 1e-4);
        assert_eq!((r.outcome, r.settle_1e3), (Outcome::NotConverged, None));
        assert!(nan_max(1.0, f64::NAN).is_nan() && nan_max(f64::NAN, 1.0).is_nan());
    }
}
