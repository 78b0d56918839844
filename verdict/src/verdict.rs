//! The verdict on a run, as `summary.json` records it.

use crate::kind::Kind;

/// The verdict on a run. Serialised with every field present: an absent
/// value is written as `null` (and a missing field reads as `None`).
///
/// ```text
/// "verdict": {"kind": "converging", "decay_rate": -0.05, "decay_rate_se": 1e-6,
///             "tolerance": 0.001, "settle_time": null, "projected_time": 138.1, "amplitude": null,
///             "period": null, "window": [50.0, 100.0], "reason": "…"}
/// ```
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Verdict {
    /// The class of the run.
    pub kind: Kind,
    /// Fitted exponential rate of the error envelope over the trailing
    /// window, 1/s (negative = decaying); `None` when it could not be fitted
    /// (too few samples or blocks, a non-finite error, or every block at the
    /// round-off floor).
    #[serde(default)]
    pub decay_rate: Option<f64>,
    /// Standard error of `decay_rate` from the least-squares fit, 1/s (the
    /// scatter of the envelope points about the fitted line; an
    /// oscillation the blocks do not average out shows up here).
    #[serde(default)]
    pub decay_rate_se: Option<f64>,
    /// The tolerance the run was judged against.
    pub tolerance: f64,
    /// Time after which the error stays below the tolerance
    /// ([`crate::settle_time`]), s.
    #[serde(default)]
    pub settle_time: Option<f64>,
    /// [`Kind::Converging`] only: projected time at which the fitted envelope
    /// reaches the tolerance, `t_end + ln(tolerance / envelope_end) / rate`,
    /// never before the window's end, s.
    #[serde(default)]
    pub projected_time: Option<f64>,
    /// [`Kind::Persistent`] only: the largest error over the trailing window
    /// (the offset, or the peak of the oscillation).
    #[serde(default)]
    pub amplitude: Option<f64>,
    /// [`Kind::Persistent`] only: the period of the error signal itself (the
    /// mean spacing of its peaks; `0.2|sin 2t|` has π/2), s; `None` for an
    /// offset.
    #[serde(default)]
    pub period: Option<f64>,
    /// The trailing window the fit used, `[start, end]`, s (`[t, t]` for a
    /// non-finite error at `t`).
    pub window: [f64; 2],
    /// One sentence saying why (for people; nothing parses it).
    pub reason: String,
}

impl Verdict {
    /// A verdict of `kind` over `window` with no measured quantities.
    #[must_use]
    pub fn bare(kind: Kind, tolerance: f64, window: [f64; 2], reason: String) -> Verdict {
        Verdict {
            kind,
            decay_rate: None,
            decay_rate_se: None,
            tolerance,
            settle_time: None,
            projected_time: None,
            amplitude: None,
            period: None,
            window,
            reason,
        }
    }

    /// Whether running longer cannot change the verdict ([`Kind::is_final`]).
    #[must_use]
    pub fn is_final(&self) -> bool {
        self.kind.is_final()
    }
}

/// The verdict of a run the divergence guard stopped at time `t`
/// ([`Kind::Diverging`], window `[t, t]`).
#[must_use]
pub fn diverged(t: f64, tolerance: f64) -> Verdict {
    Verdict::bare(
        Kind::Diverging,
        tolerance,
        [t, t],
        format!("the divergence guard stopped the run at t = {t} s"),
    )
}
