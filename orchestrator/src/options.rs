//! Checks of command-line options, made before anything starts: a refused
//! option is an [`OptionError`] (exit code 2) that names it, and nothing is
//! written or spawned.
//!
//! Limits (all inclusive):
//! - durations (`--stage-timeout`, `--start-timeout`, `gen tree
//!   --duration`): finite, > 0 and at most [`MAX_SECONDS`] (1 day);
//! - `--realtime` factor: finite, > 0 and at most [`MAX_REALTIME`];
//! - `--tolerance`, `--quantum`: finite and > 0;
//! - `--jobs`, `--threads`: ≥ 1; `--bisect`: 1..=[`MAX_BISECT`].
//!
//! `--no-stiffness-check` (`run`, `check`, `sweep`) is a
//! [`StiffnessCheck`](crate::scenario::StiffnessCheck):
//! it turns validation's refusal of a `simulation.dt` clearly beyond RK4's
//! largest stable step (`docs/stiffness.md`) into a warning.

use attitude::network::Network;
use clap::ValueEnum;
use msgs::config::WaitStrategy;
use thiserror::Error;

pub use launch::bounds::{MAX_REALTIME, MAX_SECONDS};

/// Most bisection iterations (each halves the bracket: 64 reach f64's
/// resolution of any bracket).
pub const MAX_BISECT: u32 = 64;

/// `--wait` (`run`, `sweep`, `mc`, `verify`, and the bench): how a node
/// waits for its inputs.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum WaitArg {
    /// Busy-poll.
    Spin,
    /// Poll with sched_yield.
    Yield,
    /// Sleep on iceoryx2 events (1 ms slices).
    Block,
    /// Yield a while (≤ 200 polls, 2 ms), then block; block at once on a busy machine.
    Adaptive,
}

impl From<WaitArg> for WaitStrategy {
    fn from(w: WaitArg) -> Self {
        match w {
            WaitArg::Spin => WaitStrategy::Spin,
            WaitArg::Yield => WaitStrategy::Yield,
            WaitArg::Block => WaitStrategy::Block,
            WaitArg::Adaptive => WaitStrategy::Adaptive,
        }
    }
}

/// An option that cannot be used.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum OptionError {
    /// A value outside the option's range.
    #[error("{option} {value}: {expected}")]
    OutOfRange {
        /// The option, as written on the command line (`--stage-timeout`).
        option: &'static str,
        /// The value given.
        value: String,
        /// What the option takes.
        expected: String,
    },
    /// Options that do not fit together or with the scenario.
    #[error("{0}")]
    Conflict(String),
}

fn out_of_range(option: &'static str, value: impl ToString, expected: String) -> OptionError {
    OptionError::OutOfRange {
        option,
        value: value.to_string(),
        expected,
    }
}

/// A duration in seconds: finite, > 0, at most [`MAX_SECONDS`].
///
/// # Errors
/// The value is outside that range.
pub fn seconds(option: &'static str, value: f64) -> Result<(), OptionError> {
    Ok(launch::bounds::seconds(option, value)?)
}

/// A real-time factor: finite, > 0, at most [`MAX_REALTIME`].
///
/// # Errors
/// The value is outside that range.
pub fn realtime(value: f64) -> Result<(), OptionError> {
    Ok(launch::bounds::realtime("--realtime", value)?)
}

impl From<launch::bounds::OutOfRange> for OptionError {
    fn from(e: launch::bounds::OutOfRange) -> Self {
        Self::OutOfRange {
            option: e.setting,
            value: e.value,
            expected: e.expected,
        }
    }
}

/// A positive finite number.
///
/// # Errors
/// The value is not finite or not > 0.
pub fn positive(option: &'static str, value: f64) -> Result<(), OptionError> {
    if value.is_finite() && value > 0.0 {
        return Ok(());
    }
    Err(out_of_range(
        option,
        value,
        "must be a finite number > 0".into(),
    ))
}

/// A count in `min..=max`.
///
/// # Errors
/// The value is outside that range.
pub fn count(option: &'static str, value: u64, min: u64, max: u64) -> Result<(), OptionError> {
    if (min..=max).contains(&value) {
        return Ok(());
    }
    let expected = if max == u64::MAX {
        format!("must be at least {min}")
    } else {
        format!("must be in {min}..={max}")
    };
    Err(out_of_range(option, value, expected))
}

/// `--threads` (in-process engine): at least 1.
///
/// # Errors
/// The value is 0.
pub fn threads(value: usize) -> Result<(), OptionError> {
    count("--threads", value as u64, 1, u64::MAX)
}

/// The index of node `id` (`option`'s value) in the list leader, agents…
/// of `net` (`scenario` names it in the message); the leader (0) only if
/// `leader` is allowed.
///
/// # Errors
/// `net` has no such node.
pub fn node_index(
    net: &Network,
    id: u32,
    option: &'static str,
    leader: bool,
    scenario: &std::path::Path,
) -> Result<usize, OptionError> {
    match id {
        0 if leader => Ok(0),
        _ => net.index_of(id).map(|i| i + 1).ok_or_else(|| {
            out_of_range(option, id, format!("{}: no node {id}", scenario.display()))
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seconds_refuse_nan_inf_negative_zero_and_huge() {
        for v in [
            f64::NAN,
            f64::INFINITY,
            -1.0,
            0.0,
            1e300,
            MAX_SECONDS * 1.01,
        ] {
            let e = seconds("--stage-timeout", v).unwrap_err();
            assert!(e.to_string().starts_with("--stage-timeout "), "{e}");
        }
        for v in [1e-3, 10.0, MAX_SECONDS] {
            assert_eq!(seconds("--stage-timeout", v), Ok(()));
        }
    }

    #[test]
    fn realtime_factor_is_positive_and_bounded() {
        for v in [f64::NAN, f64::INFINITY, -2.0, 0.0, 1e300] {
            let e = realtime(v).unwrap_err();
            assert!(e.to_string().contains("positive"), "{e}");
        }
        assert_eq!(realtime(1.0), Ok(()));
        assert_eq!(realtime(MAX_REALTIME), Ok(()));
    }

    #[test]
    fn positive_and_count() {
        assert!(positive("--tolerance", 0.0).is_err());
        assert!(positive("--quantum", f64::NAN).is_err());
        assert!(positive("--quantum", -1e-3).is_err());
        assert_eq!(positive("--tolerance", 1e-3), Ok(()));
        let e = count("--jobs", 0, 1, u64::MAX).unwrap_err();
        assert_eq!(e.to_string(), "--jobs 0: must be at least 1");
        assert_eq!(count("--bisect", 64, 1, 64), Ok(()));
        assert!(count("--bisect", 65, 1, 64).is_err());
    }
}
