//! [`ScenarioError`]: why a scenario could not be loaded, every problem at
//! once, one line each as `FILE: FIELD: REASON`.

use super::input::ReadError;
use super::resolve::Issue;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a scenario could not be loaded.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The file could not be read, is over the size limit, or is not UTF-8.
    #[error("{}: {error}", file.display())]
    Io {
        /// The scenario file.
        file: PathBuf,
        /// What went wrong (its cause is part of its message).
        error: ReadError,
    },
    /// Not valid TOML; or keys the schema does not know, values of the wrong
    /// type, missing fields (every one found).
    #[error("{}", fmt_issues(file, issues))]
    Parse {
        /// The scenario file.
        file: PathBuf,
        /// Every problem (a syntax error is the only one).
        issues: Vec<Issue>,
    },
    /// Some `--set` overrides could not be applied: those first (field
    /// `--set SPEC`), then every schema problem of the document with the
    /// other overrides applied.
    #[error("{}", fmt_issues(file, issues))]
    Override {
        /// The scenario file.
        file: PathBuf,
        /// Every problem.
        issues: Vec<Issue>,
    },
    /// The scenario parsed but breaks the model's assumptions.
    #[error("{}", fmt_issues(file, issues))]
    Invalid {
        /// The scenario file.
        file: PathBuf,
        /// Every problem found.
        issues: Vec<Issue>,
    },
}

/// `issues` of `file`, one line each as `FILE: FIELD: REASON`.
pub fn fmt_issues(file: &Path, issues: &[Issue]) -> String {
    issues
        .iter()
        .map(|i| format!("{}: {i}", file.display()))
        .collect::<Vec<_>>()
        .join("\n")
}
