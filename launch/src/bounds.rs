//! The ranges of a node's timing settings (its configuration's
//! `stage_timeout`, `start_timeout`, `realtime`), checked alike by the
//! command line (`attsync::options`) and by a host daemon receiving a
//! node from another machine.

use thiserror::Error;

/// Longest duration a setting may give, s (one day: a wait past it is a
/// mistake, and `Duration::from_secs_f64` would overflow not far above).
pub const MAX_SECONDS: f64 = 86_400.0;

/// Largest real-time factor (simulated s per wall s): past it, a step of
/// any sensible `dt` is due in less than a nanosecond.
pub const MAX_REALTIME: f64 = 1e6;

/// A value outside its setting's range.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{setting} {value}: {expected}")]
pub struct OutOfRange {
    /// The setting, as the user wrote it (`--stage-timeout`, `stage_timeout`).
    pub setting: &'static str,
    /// The value given.
    pub value: String,
    /// What the setting takes.
    pub expected: String,
}

/// A duration in seconds: finite, > 0, at most [`MAX_SECONDS`].
///
/// # Errors
/// The value is outside that range.
pub fn seconds(setting: &'static str, value: f64) -> Result<(), OutOfRange> {
    if value.is_finite() && value > 0.0 && value <= MAX_SECONDS {
        return Ok(());
    }
    Err(OutOfRange {
        setting,
        value: value.to_string(),
        expected: format!("must be a number of seconds > 0 and at most {MAX_SECONDS} (1 day)"),
    })
}

/// A real-time factor: finite, > 0, at most [`MAX_REALTIME`].
///
/// # Errors
/// The value is outside that range.
pub fn realtime(setting: &'static str, value: f64) -> Result<(), OutOfRange> {
    if value.is_finite() && value > 0.0 && value <= MAX_REALTIME {
        return Ok(());
    }
    Err(OutOfRange {
        setting,
        value: value.to_string(),
        expected: format!(
            "the factor must be a positive number (simulated s per wall s) of at most {MAX_REALTIME}"
        ),
    })
}
