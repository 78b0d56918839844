//! [`HostsError`]: why a hosts file could not be loaded or placed, every
//! problem of a stage at once, one line each as `FILE: FIELD: REASON` (as a
//! scenario's, [`scenario::ScenarioError`]).

use scenario::input::ReadError;
use scenario::{Issue, fmt_issues};
use std::path::PathBuf;
use thiserror::Error;

/// Why a hosts file (the path, first) could not be loaded, or does not fit
/// the scenario.
#[derive(Debug, Error)]
pub enum HostsError {
    /// The file could not be read, is over the size limit, or is not UTF-8.
    #[error("{}: {}", .0.display(), .1)]
    Io(PathBuf, ReadError),
    /// Every problem of the first stage that found any: TOML syntax (the
    /// only one then); or the format (unknown keys, wrong types, missing
    /// fields); or the rules of a file (names, endpoints, the leader,
    /// agents placed twice, empty hosts); or agents the scenario lacks.
    #[error("{}", fmt_issues(.0, .1))]
    Invalid(PathBuf, Vec<Issue>),
}
