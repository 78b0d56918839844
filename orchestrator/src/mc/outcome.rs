//! A trial's outcome: what is recorded of its run ([`Trace`]: the largest
//! errors over agents at each sample, not whole trajectories) and its
//! classification ([`classify`]) by the verdict (`docs/verdicts.md`), the
//! same as `attsync run`'s.

use crate::failure::Failure;
use crate::results::summary::Settle;
use crate::run::Judging;
use attitude::engine::Snapshot;
use attitude::metrics::{errors, spread};
use attitude::network::Network;
use attsync_verdict::Kind;
use serde::{Deserialize, Deserializer, Serialize};

/// How a trial ended: its verdict, or that a node process failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outcome {
    /// The largest attitude error over agents is below the tolerance and stays there.
    Converged,
    /// It decays, but is not below the tolerance by the end (not a failure).
    Converging,
    /// The error to the leader persists, but the followers agree along
    /// every edge: synchronised among themselves, not to the leader (their
    /// spread, `attitude::metrics::spread`, converges or decays).
    Synchronised,
    /// Bounded and not decaying above the tolerance (an offset or an
    /// oscillation), the followers not synchronised among themselves either.
    Persistent,
    /// Growing, or a state left the envelope (`[guard]`, `attitude::guard`).
    Diverging,
    /// Too short to tell.
    Undecided,
    /// A node process failed (process engine).
    Failed,
}

impl Outcome {
    /// The name in `trials.csv` and `mc.json`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Converged => "converged",
            Outcome::Converging => "converging",
            Outcome::Synchronised => "synchronised-apart",
            Outcome::Persistent => "persistent",
            Outcome::Diverging => "diverging",
            Outcome::Undecided => "undecided",
            Outcome::Failed => "failed",
        }
    }

    /// The outcome of a verdict of kind `kind`.
    #[must_use]
    pub fn of(kind: Kind) -> Self {
        match kind {
            Kind::Converged => Outcome::Converged,
            Kind::Converging => Outcome::Converging,
            Kind::Persistent => Outcome::Persistent,
            Kind::Diverging => Outcome::Diverging,
            Kind::Undecided => Outcome::Undecided,
        }
    }

    /// Whether this outcome counts as a failure: anything but converged or
    /// converging (whose error decays).
    #[must_use]
    pub fn is_failure(self) -> bool {
        !matches!(self, Outcome::Converged | Outcome::Converging)
    }

    /// The outcome named `name` in `trials.csv` ([`Outcome::name`]).
    #[must_use]
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|o| o.name() == name)
    }

    /// Every outcome, in the order of the summary table.
    pub const ALL: [Outcome; 7] = [
        Outcome::Converged,
        Outcome::Converging,
        Outcome::Synchronised,
        Outcome::Persistent,
        Outcome::Diverging,
        Outcome::Undecided,
        Outcome::Failed,
    ];
}

/// How the engine finished a trial's run.
#[derive(Debug, Clone, PartialEq)]
pub enum End {
    /// It reached the horizon.
    Complete,
    /// A state left the envelope at `t` s (the run's message).
    Diverged(f64, String),
    /// A node failed (the run's failure).
    Failed(Failure),
}

/// The largest errors over agents at each output sample of a run.
#[derive(Debug, Clone, Default)]
pub struct Trace {
    /// Sample times, s (as `errors.csv` writes them).
    pub t: Vec<f64>,
    /// The largest `|Rᵢ R₀ᵀ|_I` over agents at each sample (NaN if any is NaN).
    pub att: Vec<f64>,
    /// The largest `‖ωᵢ − ω₀‖` over agents at each sample, rad/s.
    pub angvel: Vec<f64>,
    /// How far the followers are from agreeing along their edges at each
    /// sample (`attitude::metrics::spread`).
    pub spread: Vec<f64>,
    /// The follower edges (index pairs into the agents).
    edges: Vec<(usize, usize)>,
    dt: f64,
    has_observer: bool,
}

use crate::results::nan_max;

impl Trace {
    /// An empty trace for a run of `net`.
    #[must_use]
    pub fn new(net: &Network, has_observer: bool) -> Self {
        let mut edges: Vec<(usize, usize)> = (net.neighbour_indices().iter().enumerate())
            .flat_map(|(i, nbrs)| nbrs.iter().map(move |&j| (i.min(j), i.max(j))))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        Self {
            dt: net.dt,
            has_observer,
            edges,
            ..Self::default()
        }
    }

    /// Records the errors of `snap` (the same numbers `errors.csv` has).
    pub fn record(&mut self, snap: &Snapshot<'_>) {
        let (mut att, mut angvel) = (0.0_f64, 0.0_f64);
        for x in snap.agents {
            let e = errors(x, snap.leader, self.has_observer);
            att = nan_max(att, e.att);
            angvel = nan_max(angvel, e.angvel);
        }
        let t = crate::results::sample_time(snap.step, self.dt);
        self.push(t, [att, angvel, spread(snap.agents, &self.edges)]);
    }

    /// Appends a sample at time `t` whose largest errors over agents are
    /// `att` and `angvel`, the followers' spread `spread`.
    pub fn push(&mut self, t: f64, [att, angvel, spread]: [f64; 3]) {
        self.t.push(t);
        self.att.push(att);
        self.angvel.push(angvel);
        self.spread.push(spread);
    }

    /// Forgets every sample (a run started again with a longer horizon).
    pub fn clear(&mut self) {
        self.t.clear();
        self.att.clear();
        self.angvel.clear();
        self.spread.clear();
    }

    /// The verdict on the attitude errors recorded so far.
    #[must_use]
    pub fn verdict(&self, judging: &Judging) -> attsync_verdict::Verdict {
        Self::judge(&self.t, &self.att, judging)
    }

    /// The outcome of a complete run whose attitude errors' verdict is
    /// `v`; for a persistent error, the followers' spread decides: below
    /// the tolerance and staying ([`Outcome::Synchronised`]), still
    /// decaying or too short to tell ([`Outcome::Undecided`]: a decay may
    /// end in a twisted state, so only `--until settled` or a longer run
    /// tells), or not ([`Outcome::Persistent`]).
    #[must_use]
    pub fn outcome(&self, v: &attsync_verdict::Verdict, judging: &Judging) -> Outcome {
        if v.kind != Kind::Persistent {
            return Outcome::of(v.kind);
        }
        match Self::judge(&self.t, &self.spread, judging).kind {
            Kind::Converged => Outcome::Synchronised,
            Kind::Converging | Kind::Undecided => Outcome::Undecided,
            Kind::Persistent | Kind::Diverging => Outcome::Persistent,
        }
    }

    /// Whether `--until settled` runs on: the outcome so far is not final.
    #[must_use]
    pub fn goes_on(&self, judging: &Judging) -> bool {
        let o = self.outcome(&self.verdict(judging), judging);
        matches!(o, Outcome::Converging | Outcome::Undecided)
    }

    fn judge(t: &[f64], e: &[f64], judging: &Judging) -> attsync_verdict::Verdict {
        let thresholds = attsync_verdict::Thresholds::default();
        attsync_verdict::classify(t, e, judging.tolerance, &thresholds)
    }
}

/// One trial's result: a row of `trials.csv` (and, read back by `attsync
/// mc merge`, an entry of `mc.json` `slowest`, where JSON writes NaN as
/// `null`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrialResult {
    /// Trial index (0-based).
    pub trial: u64,
    /// The trial's seed ([`super::trial_seed`]).
    pub seed: u64,
    /// How it ended.
    pub outcome: Outcome,
    /// The verdict's decay rate, 1/s (negative = decaying).
    pub decay_rate: Option<f64>,
    /// Largest final attitude error over agents (at the last sample).
    #[serde(deserialize_with = "nan_if_null")]
    pub final_max_att_err: f64,
    /// Largest final angular-velocity error over agents, rad/s.
    #[serde(deserialize_with = "nan_if_null")]
    pub final_max_angvel_err: f64,
    /// Time of the last sample, s.
    #[serde(deserialize_with = "nan_if_null")]
    pub t_end: f64,
    /// When the largest errors over agents settled ([`Settle`]).
    #[serde(flatten)]
    pub settle: Settle,
    /// Why a diverged or failed trial stopped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// The values of the `[[monte_carlo.param]]` fields the trial ran
    /// with, in file order, read back from its scenario.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<f64>,
}

/// A number JSON wrote as `null` (serde_json's NaN or infinity) read back as NaN.
fn nan_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Classifies a trial that ended as `end` with `trace` recorded, by its
/// verdict with `judging`'s tolerance. Settle times only count for a
/// complete run.
#[must_use]
pub fn classify(trial: u64, seed: u64, end: End, trace: &Trace, judging: &Judging) -> TrialResult {
    let complete = end == End::Complete;
    let (verdict, outcome, reason) = match end {
        End::Complete => {
            let v = trace.verdict(judging);
            let o = trace.outcome(&v, judging);
            (Some(v), o, None)
        }
        End::Diverged(t, why) => (
            Some(attsync_verdict::diverged(t, judging.tolerance)),
            Outcome::Diverging,
            Some(why),
        ),
        End::Failed(why) => (None, Outcome::Failed, Some(why.to_string())),
    };
    let settle = if complete {
        Settle::of(&trace.t, &trace.att, &trace.angvel)
    } else {
        Settle::default()
    };
    TrialResult {
        trial,
        seed,
        outcome,
        decay_rate: verdict.and_then(|v| v.decay_rate),
        final_max_att_err: trace.att.last().copied().unwrap_or(f64::NAN),
        final_max_angvel_err: trace.angvel.last().copied().unwrap_or(f64::NAN),
        t_end: trace.t.last().copied().unwrap_or(0.0),
        settle,
        reason,
        params: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(att: &[f64], angvel: &[f64], dt: f64) -> Trace {
        Trace {
            t: (0..att.len()).map(|k| k as f64 * dt).collect(),
            att: att.to_vec(),
            angvel: angvel.to_vec(),
            spread: att.to_vec(),
            edges: Vec::new(),
            dt,
            has_observer: false,
        }
    }

    #[test]
    fn followers_that_agree_apart_from_the_leader_are_synchronised_apart() {
        let stall = vec![0.5; 400];
        let agree = decay(1.0, -1.0, 400);
        let apart = Trace {
            spread: agree.clone(),
            ..trace(&stall, &stall, 0.1)
        };
        let r = classify(0, 9, End::Complete, &apart, &judging());
        assert_eq!(r.outcome, Outcome::Synchronised);
        assert!(r.outcome.is_failure());
        // Not agreeing either: persistent.
        let r = classify(1, 9, End::Complete, &trace(&stall, &stall, 0.1), &judging());
        assert_eq!(r.outcome, Outcome::Persistent);
        // Still decaying (it may yet stop in a twisted state): undecided,
        // and --until settled goes on.
        let slow = Trace {
            spread: decay(1.0, -0.05, 400),
            ..trace(&stall, &stall, 0.1)
        };
        assert_eq!(
            classify(3, 9, End::Complete, &slow, &judging()).outcome,
            Outcome::Undecided
        );
        assert!(slow.goes_on(&judging()) && !apart.goes_on(&judging()));
        // Converged to the leader: the spread is not looked at.
        let done = Trace {
            spread: stall.clone(),
            ..trace(&agree, &agree, 0.1)
        };
        let r = classify(2, 9, End::Complete, &done, &judging());
        assert_eq!(r.outcome, Outcome::Converged);
    }

    fn judging() -> Judging {
        Judging {
            tolerance: 1e-4,
            ..Judging::default()
        }
    }

    /// `n` samples of `a e^{λ t}` at 0.1 s.
    fn decay(a: f64, lambda: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| a * (lambda * k as f64 * 0.1).exp())
            .collect()
    }

    #[test]
    fn a_converged_a_converging_a_persistent_and_a_diverged_trial() {
        let fast = decay(1.0, -1.0, 400);
        let r = classify(0, 9, End::Complete, &trace(&fast, &fast, 0.1), &judging());
        assert_eq!(r.outcome, Outcome::Converged);
        assert!(!r.outcome.is_failure());
        assert_eq!(
            r.settle.att_1e3,
            attsync_verdict::settle_time(&trace(&fast, &fast, 0.1).t, &fast, 1e-3)
        );
        assert_eq!(r.t_end, 399.0 * 0.1);
        // Decaying at 0.05/s from 1: at 1.4e-1 after 40 s: converging, no failure.
        let slow = decay(1.0, -0.05, 400);
        let r = classify(1, 9, End::Complete, &trace(&slow, &slow, 0.1), &judging());
        assert_eq!(r.outcome, Outcome::Converging, "{r:?}");
        assert!(!r.outcome.is_failure());
        assert!((r.decay_rate.unwrap() + 0.05).abs() < 0.0025, "{r:?}");
        // Stalled at an error of 0.5: persistent, and how far.
        let stall = vec![0.5; 400];
        let r = classify(2, 9, End::Complete, &trace(&stall, &stall, 0.1), &judging());
        assert_eq!(r.outcome, Outcome::Persistent);
        assert!(r.outcome.is_failure());
        assert_eq!((r.final_max_att_err, r.settle.att_1e3), (0.5, None));
        let r = classify(
            3,
            9,
            End::Diverged(2.0, "diverged at t = 2 s".into()),
            &trace(&fast[..20], &fast[..20], 0.1),
            &judging(),
        );
        assert_eq!(r.outcome, Outcome::Diverging);
        assert_eq!(
            (r.settle.att_1e3, r.reason.as_deref()),
            (None, Some("diverged at t = 2 s"))
        );
        let dead = classify(
            4,
            9,
            End::Failed(Failure::Recorded("agent-2 died".into())),
            &trace(&fast, &fast, 0.1),
            &judging(),
        );
        assert_eq!(dead.outcome, Outcome::Failed);
    }

    #[test]
    fn a_nan_error_is_never_below_the_tolerance() {
        let mut att = decay(1.0, -1.0, 400);
        att[399] = f64::NAN;
        let r = classify(0, 0, End::Complete, &trace(&att, &att, 0.1), &judging());
        assert_eq!((r.outcome, r.settle.att_1e3), (Outcome::Diverging, None));
        assert!(nan_max(1.0, f64::NAN).is_nan() && nan_max(f64::NAN, 1.0).is_nan());
    }
}
