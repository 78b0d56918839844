//! [`VerifyError`]: why `attsync verify` could not say whether a run
//! reproduces, and its exit code ([`VerifyError::exit_code`]).

use crate::results::manifest::ManifestError;
use crate::run::RunError;
use crate::scenario::ScenarioError;
use std::path::PathBuf;
use thiserror::Error;

/// Why a run could not be verified.
#[derive(Debug, Error)]
pub enum VerifyError {
    /// `manifest.json` is missing, unreadable, not a manifest or of another version (exit 2).
    #[error(transparent)]
    Manifest(#[from] ManifestError),
    /// The directory holds a sweep's or a Monte Carlo's results, not one
    /// run's (exit 2): what to verify instead.
    #[error("{}: {what}, not one run's results; {instead}", dir.display())]
    NotARun {
        /// The directory.
        dir: PathBuf,
        /// What it holds.
        what: &'static str,
        /// What to verify instead.
        instead: String,
    },
    /// A recorded setting this attsync does not know (exit 2).
    #[error("{}: {field} {value:?} is not one of {expected}", manifest.display())]
    Setting {
        /// The manifest.
        manifest: PathBuf,
        /// The field (`engine`, `placement`).
        field: &'static str,
        /// Its value.
        value: String,
        /// The values it may take.
        expected: String,
    },
    /// The run's `scenario.toml` cannot be read (exit 2).
    #[error("{}: {source}", path.display())]
    ScenarioFile {
        /// The file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// `scenario_sha256` does not match the run's `scenario.toml`: it is not
    /// the scenario that ran, so it is not re-run (exit 2).
    #[error(
        "{}: scenario_sha256 {recorded} does not match {} (SHA-256 {found}): \
         it is not the scenario that ran; refusing to re-run it",
        manifest.display(), scenario.display()
    )]
    ScenarioHash {
        /// The manifest.
        manifest: PathBuf,
        /// The scenario file.
        scenario: PathBuf,
        /// The manifest's hash.
        recorded: String,
        /// The file's.
        found: String,
    },
    /// A real-time run: not deterministic, nothing to reproduce bit for bit (exit 2).
    #[error(
        "{}: a real-time run (--realtime {factor}) is not deterministic: there is nothing to \
         re-run bit for bit (only lockstep runs can be verified)",
        dir.display()
    )]
    Realtime {
        /// The results directory.
        dir: PathBuf,
        /// The real-time factor.
        factor: f64,
    },
    /// The recorded run was interrupted or failed: its end cannot be
    /// reproduced (a diverged run can be) (exit 2).
    #[error(
        "{}: the recorded run did not complete ({reason}): an interrupted or failed run has \
         no end to reproduce (only complete or diverged runs can be verified)",
        dir.display()
    )]
    Incomplete {
        /// The results directory.
        dir: PathBuf,
        /// `incomplete_reason`.
        reason: String,
    },
    /// The recorded scenario does not load (exit 2).
    #[error(transparent)]
    Scenario(#[from] ScenarioError),
    /// The re-run could not run (exit 2 for an option or a capacity refusal, else 1).
    #[error("re-run: {0}")]
    Run(#[from] RunError),
    /// The re-run did not complete: a node died or stalled (exit 1).
    #[error("the re-run did not complete: {0}")]
    Rerun(String),
    /// A signal stopped the re-run (exit 128 + N).
    #[error("{}", crate::interrupt::reason(*.0))]
    Interrupted(i32),
    /// A file of the re-run cannot be read (exit 1).
    #[error("re-run: {0}")]
    Read(String),
    /// The re-run's temporary directory cannot be made (exit 1).
    #[error("a temporary directory for the re-run: {0}")]
    TempDir(std::io::Error),
}

impl VerifyError {
    /// The process exit code: 2 for a run that cannot be verified (a bad or
    /// missing manifest, a refused run, an invalid option), 128 + N if
    /// interrupted by signal N, else 1.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            Self::Manifest(_)
            | Self::NotARun { .. }
            | Self::Setting { .. }
            | Self::ScenarioFile { .. }
            | Self::ScenarioHash { .. }
            | Self::Realtime { .. }
            | Self::Incomplete { .. }
            | Self::Scenario(_)
            | Self::Run(RunError::Options(_) | RunError::Capacity(_)) => crate::exit::INVALID,
            Self::Interrupted(signal) => crate::interrupt::exit_code(*signal),
            _ => crate::exit::FAILED,
        }
    }
}
