//! The documented knobs of [`crate::classify()`].

/// Thresholds of [`crate::classify()`]; [`Thresholds::default`] is what attsync
/// uses. `docs/verdicts.md`, "How a verdict is reached", explains each.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Thresholds {
    /// Fraction of the run, by time, the trailing window covers: the window
    /// is `[t_end − f·(t_end − t₀), t_end]`. Default 0.5 (the last half).
    pub window_fraction: f64,
    /// Fewest samples in the window; fewer is [`crate::Kind::Undecided`].
    /// Default 24.
    pub min_samples: usize,
    /// Most envelope blocks the window is split into. Default 24.
    pub max_blocks: usize,
    /// Fewest envelope blocks; fewer (blocks must span
    /// [`Self::block_periods`] oscillation periods) is
    /// [`crate::Kind::Undecided`]. At least 3 is used. Default 6.
    pub min_blocks: usize,
    /// Shortest block, in periods of the error's oscillation (when it
    /// oscillates), so that every block holds a full peak. Default 1.5.
    pub block_periods: f64,
    /// Smallest swing of `ln x` (after removing its straight-line trend over
    /// the window), peak to trough on both sides, that counts as an
    /// oscillation: 0.01 is a 1 % ripple. Default 0.01.
    pub oscillation_swing: f64,
    /// Round-off floor: blocks whose largest error is at or below it are left
    /// out of the fit (their trend is noise). Should be below the tolerance.
    /// Default 1e-10.
    pub floor: f64,
    /// Standard errors of the fitted change a trend must exceed for its sign
    /// to count as established. Default 3.
    pub significance: f64,
    /// Smallest fitted change of `ln(envelope)` over the window, in absolute
    /// value, that is a trend (converging or diverging). Default 0.1 (the
    /// envelope changes by ~10 % over the window).
    pub trend_change: f64,
    /// Fitted changes of `ln(envelope)` over the window smaller than this (in
    /// absolute value) are flat even when significant. Default 0.01 (~1 %).
    pub flat_change: f64,
    /// A trend whose window halves have rates differing significantly and by
    /// more than this fraction of the window's rate is not one exponential
    /// (a hump, a bend): [`crate::Kind::Undecided`]. Default 0.2.
    pub rate_agreement: f64,
}

impl Default for Thresholds {
    fn default() -> Self {
        Thresholds {
            window_fraction: 0.5,
            min_samples: 24,
            max_blocks: 24,
            min_blocks: 6,
            block_periods: 1.5,
            oscillation_swing: 0.01,
            floor: 1e-10,
            significance: 3.0,
            trend_change: 0.1,
            flat_change: 0.01,
            rate_agreement: 0.2,
        }
    }
}
