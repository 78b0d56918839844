//! [`McOptions`]: what `attsync mc` runs and how.

use crate::options::{self, OptionError};
use crate::processes::ProcessOptions;
use crate::run::Engine;
use crate::scenario::StiffnessCheck;
use std::path::PathBuf;

/// Default `--tolerance`: the largest `|Rᵢ R₀ᵀ|_I` over agents below it and
/// staying there (chosen by measurement on the paper's scenarios,
/// `docs/monte-carlo.md`).
pub const DEFAULT_TOLERANCE: f64 = 1e-4;

/// A Monte Carlo's options.
#[derive(Debug, Clone)]
pub struct McOptions {
    /// Scenario file.
    pub scenario: PathBuf,
    /// `--set` overrides of every trial.
    pub set: Vec<String>,
    /// Number of trials (≥ 1).
    pub trials: u64,
    /// Master seed.
    pub seed: u64,
    /// Trials at once (≥ 1).
    pub jobs: usize,
    /// Engine of each trial (in-process: on one thread).
    pub engine: Engine,
    /// Process-engine options.
    pub processes: ProcessOptions,
    /// The tolerance of `converged` and how long each trial goes.
    pub judging: crate::run::Judging,
    /// Results directory.
    pub out: PathBuf,
    /// Draw a progress bar on stderr.
    pub progress: bool,
    /// `--no-stiffness-check`.
    pub stiffness: StiffnessCheck,
    /// A control law from outside in place of the scheme's (in-process only;
    /// [`attitude::law`]).
    pub law: Option<attitude::law::SharedLaw>,
    /// `--shard K/N`: only that slice of the trials ([`super::shard`]).
    pub shard: Option<super::shard::Shard>,
}

impl McOptions {
    /// Checks `--trials`, `--jobs`, `--tolerance`, `--max-duration`,
    /// `--shard` and the process engine's timeouts.
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn validate(&self) -> Result<(), OptionError> {
        options::count("--trials", self.trials, 1, u64::MAX)?;
        options::count("--jobs", self.jobs as u64, 1, u64::MAX)?;
        self.judging.validate()?;
        if let Some(shard) = self.shard {
            shard.check(self.trials)?;
        }
        options::seconds("--stage-timeout", self.processes.stage_timeout)?;
        options::seconds("--start-timeout", self.processes.start_timeout)
    }

    /// The trials this run makes: all, or its `--shard`'s slice.
    #[must_use]
    pub fn range(&self) -> std::ops::Range<u64> {
        self.shard.map_or(0..self.trials, |s| s.range(self.trials))
    }
}

/// The default results directory: `results/<scenario name>-mc`.
#[must_use]
pub fn default_out(scenario_name: &str) -> PathBuf {
    crate::results::layout::default_mc_dir(scenario_name)
}
