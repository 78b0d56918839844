//! The process exit codes of `attsync`, in one table (each error type's
//! `exit_code()` picks from it; [`crate::error::Error::exit_code`] asks the
//! one it wraps):
//!
//! | code | meaning |
//! |---|---|
//! | 0 | success |
//! | 2 | invalid scenario, `--set`, hosts file or option, or a run this machine cannot take (nothing was started) |
//! | 1 | any other error (a node died, a rule failed, a file could not be written…) |
//! | 3 | the run diverged: a state left the envelope (`summary.json` `diverged`) |
//! | 128 + N | interrupted by signal N: 130 SIGINT, 143 SIGTERM, 129 SIGHUP |
//!

/// A command that failed for any other reason (a node died, a rule failed,
/// a file could not be written…).
pub const FAILED: u8 = 1;

/// Invalid input, or a run this machine cannot take: nothing was started.
pub const INVALID: u8 = 2;

/// A run that diverged: a state left the envelope.
pub const DIVERGED: u8 = 3;

/// The exit code of a process stopped by `signal`: 128 + its number (the
/// shell's convention: SIGINT 130, SIGTERM 143, SIGHUP 129).
#[must_use]
pub fn interrupted(signal: i32) -> u8 {
    u8::try_from(128 + signal).unwrap_or(u8::MAX)
}

/// [`INVALID`] if the user's input is at fault, else [`FAILED`].
#[must_use]
pub fn invalid_if(invalid: bool) -> u8 {
    if invalid { INVALID } else { FAILED }
}
