//! Classifies an attsync run from its error history.
//!
//! A run records, per sample time, each agent's attitude error
//! `|Rᵢ R₀ᵀ|_I ∈ [0, 1]`. Reading "converged" off the last sample of a fixed
//! horizon makes the conclusion depend on the horizon; [`classify()`] instead
//! fits the exponential rate of the error's *envelope* over a trailing window
//! and sorts the run into one of five [`Kind`]s:
//!
//! - [`Kind::Converged`]: below the tolerance over the last envelope block
//!   and not growing (a round-off floor included);
//! - [`Kind::Converging`]: above it, the envelope decaying significantly,
//!   with a projected time to the tolerance;
//! - [`Kind::Persistent`]: above it, the envelope flat (an offset or a
//!   sustained oscillation), with its amplitude and period;
//! - [`Kind::Diverging`]: the envelope growing significantly, or a
//!   non-finite error;
//! - [`Kind::Undecided`]: too short to tell, or a trend the window cannot
//!   yet resolve (run longer).
//!
//! The method, its thresholds ([`Thresholds`]) and the single definition of
//! a settle time ([`settle_time`]) are described in `docs/verdicts.md`,
//! "How a verdict is reached".
//!
//! ```
//! use attsync_verdict::{classify, Kind, Thresholds};
//! let t: Vec<f64> = (0..=4000).map(|i| f64::from(i) * 0.01).collect();
//! let x: Vec<f64> = t.iter().map(|&t| (-0.1 * t).exp()).collect();
//! let v = classify(&t, &x, 1e-3, &Thresholds::default());
//! assert_eq!(v.kind, Kind::Converging);
//! assert!(v.decay_rate.is_some_and(|r| (r + 0.1).abs() < 1e-3));
//! ```

mod classify;
mod envelope;
mod fit;
mod kind;
mod oscillation;
mod settle;
mod thresholds;
mod trend;
mod verdict;

pub use classify::classify;
pub use kind::Kind;
pub use settle::settle_time;
pub use thresholds::Thresholds;
pub use verdict::{Verdict, diverged};
