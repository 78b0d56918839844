//! `--until`: how long a run goes, and the verdict it is judged by
//! (`docs/verdicts.md`).
//!
//! `--until horizon` (the default) runs the scenario's `simulation.duration`.
//! `--until settled` extends the horizon in chunks — each chunk doubles it,
//! ending on a multiple of the output sample period — until the verdict is
//! final (`converged`, `persistent` or `diverging`, not `converging` or
//! `undecided`) or `--max-duration` is reached. The in-process engine goes
//! on from where it stopped ([`attitude::engine::InProcess::extend_to`]:
//! the extended run is bit-identical to the run given its final horizon
//! from the start); the processes engine starts its nodes for a fixed
//! horizon, so the in-process engine finds that horizon first
//! ([`settled_horizon`]: lockstep runs are bit-identical in every engine)
//! and the processes run once to it — except with plug-ins, which only the
//! processes engine runs: then it runs again from t = 0 with the doubled
//! horizon (at most twice the work of its final run). Either way the results are exactly
//! those of the scenario with `simulation.duration` = the final horizon,
//! which is what the run's `scenario.toml` then says (so `verify` re-runs it).

use crate::interrupt::Interrupt;
use crate::options::{self, OptionError};
pub use crate::results::until::{Stopped, UntilSummary};
use crate::results::{Series, nan_max};
use attitude::engine::{InProcess, Snapshot};
use attitude::metrics::errors;
use attitude::network::Network;
use attsync_verdict::{Kind, Thresholds, Verdict};

/// How long a run goes.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Until {
    /// The scenario's `simulation.duration`.
    #[default]
    Horizon,
    /// Until the verdict is final, at most `max_duration` seconds.
    Settled {
        /// The longest horizon, s.
        max_duration: f64,
    },
}

/// The default `--max-duration`: this many times the scenario's duration.
pub const DEFAULT_MAX_FACTOR: f64 = 16.0;

/// The default convergence tolerance on the attitude error `|Rᵢ R₀ᵀ|_I`.
pub const DEFAULT_TOLERANCE: f64 = 1e-3;

/// What a run is judged by: the tolerance of `converged` and how long it goes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Judging {
    /// `converged` means the largest attitude error over agents stays
    /// below this (> 0).
    pub tolerance: f64,
    /// How long the run goes.
    pub until: Until,
}

impl Default for Judging {
    fn default() -> Self {
        Self {
            tolerance: DEFAULT_TOLERANCE,
            until: Until::Horizon,
        }
    }
}

impl Judging {
    /// Checks `--tolerance` and `--max-duration`.
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn validate(&self) -> Result<(), OptionError> {
        options::positive("--tolerance", self.tolerance)?;
        if let Until::Settled { max_duration } = self.until {
            options::positive("--max-duration", max_duration)?;
        }
        Ok(())
    }

    /// The longest horizon in steps of `dt`, for a scenario of `steps`
    /// steps (never shorter than the scenario's own).
    #[must_use]
    pub fn max_steps(&self, steps: u64, dt: f64) -> u64 {
        match self.until {
            Until::Horizon => steps,
            Until::Settled { max_duration } => ((max_duration / dt).round() as u64).max(steps),
        }
    }

    /// The verdict on `series` (every agent's errors), with the default
    /// thresholds.
    #[must_use]
    pub fn verdict(&self, series: &[Series]) -> Verdict {
        let (t, x) = largest_attitude_error(series);
        attsync_verdict::classify(&t, &x, self.tolerance, &Thresholds::default())
    }
}

/// The next horizon after `current` steps: twice as long, on a multiple of
/// `sample_every`, at most `max` (then exactly `max`).
#[must_use]
pub fn next_horizon(current: u64, max: u64, sample_every: u64) -> u64 {
    let every = sample_every.max(1);
    let doubled = (current.max(1) * 2).div_ceil(every) * every;
    doubled.min(max)
}

/// Whether a run judged `kind` goes on (when its horizon allows).
#[must_use]
pub fn goes_on(kind: Kind) -> bool {
    !kind.is_final()
}

/// The sample times and, at each, the largest attitude error over agents
/// (NaN if any is NaN): the signal a verdict classifies.
#[must_use]
pub fn largest_attitude_error(series: &[Series]) -> (Vec<f64>, Vec<f64>) {
    let Some(first) = series.first() else {
        return (Vec::new(), Vec::new());
    };
    let x = (0..first.t.len())
        .map(|k| {
            (series.iter()).fold(0.0_f64, |m, s| {
                nan_max(m, s.att.get(k).copied().unwrap_or(f64::NAN))
            })
        })
        .collect();
    (first.t.clone(), x)
}

/// The horizon `--until settled` ends with for `net`, and the number of
/// chunks it took, found by the in-process engine extending one run —
/// lockstep runs are bit-identical in every engine, so a processes run of
/// that horizon reaches the same verdict, and need not run again from
/// t = 0 for each doubling. `None` if `interrupt` stopped it, or the run
/// diverged (the processes run will say where).
#[must_use]
pub fn settled_horizon(
    net: &Network,
    judging: &Judging,
    interrupt: &Interrupt,
) -> Option<(u64, u32)> {
    let max = judging.max_steps(net.steps, net.dt);
    let mut engine = InProcess::new(net);
    let (mut t, mut x, mut chunks) = (Vec::new(), Vec::new(), 0);
    loop {
        chunks += 1;
        let diverged = engine.run_until(
            |_, _, _| (),
            |snap: &Snapshot<'_>, _: &[()]| {
                let largest = (snap.agents.iter()).fold(0.0_f64, |m, a| {
                    nan_max(m, errors(a, snap.leader, false).att)
                });
                t.push(crate::results::sample_time(snap.step, net.dt));
                x.push(largest);
                !interrupt.is_set()
            },
            || interrupt.is_set(),
        );
        if diverged.is_some() || engine.step_index() < engine.horizon() {
            return None;
        }
        let kind =
            attsync_verdict::classify(&t, &x, judging.tolerance, &Thresholds::default()).kind;
        if !goes_on(kind) || engine.horizon() >= max {
            return Some((engine.horizon(), chunks));
        }
        engine.extend_to(next_horizon(engine.horizon(), max, net.sample_every));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn horizons_double_on_sample_multiples_up_to_the_bound() {
        assert_eq!(next_horizon(4000, 100_000, 10), 8000);
        assert_eq!(next_horizon(4005, 100_000, 10), 8010);
        assert_eq!(next_horizon(60_000, 100_000, 10), 100_000);
        assert_eq!(next_horizon(100_000, 100_000, 10), 100_000);
        assert_eq!(next_horizon(0, 100, 7), 7);
    }

    #[test]
    fn the_largest_error_over_agents_keeps_a_nan() {
        let s = |att: Vec<f64>| Series {
            id: 1,
            t: vec![0.0, 1.0, 2.0],
            att,
            ..Series::default()
        };
        let (t, x) = largest_attitude_error(&[s(vec![0.5, 0.1, f64::NAN]), s(vec![0.2, 0.3, 0.0])]);
        assert_eq!(t, vec![0.0, 1.0, 2.0]);
        assert_eq!(&x[..2], &[0.5, 0.3]);
        assert!(x[2].is_nan());
    }

    #[test]
    fn options_are_checked() {
        let ok = Judging {
            tolerance: 1e-3,
            until: Until::Settled { max_duration: 10.0 },
        };
        assert_eq!(ok.validate(), Ok(()));
        let bad = Judging {
            until: Until::Settled { max_duration: 0.0 },
            ..ok
        };
        assert!(
            bad.validate()
                .unwrap_err()
                .to_string()
                .starts_with("--max-duration")
        );
        assert_eq!(ok.max_steps(40_000, 1e-3), 40_000);
        let long = Judging {
            until: Until::Settled {
                max_duration: 100.0,
            },
            ..ok
        };
        assert_eq!(long.max_steps(40_000, 1e-3), 100_000);
    }
}
