//! `attsync mc`: a Monte Carlo over initial conditions. Each trial draws the
//! agents' initial attitudes Haar-uniformly on SO(3) and their rates with a
//! uniform direction and a bounded norm (`[monte_carlo]`), runs the network
//! and classifies the outcome; the failure rate comes with its exact
//! Clopper–Pearson bound. Trial `k` draws from its own stream, seeded by
//! [`trial_seed`]`(seed, k)`, so it is reproducible alone
//! (`attsync mc … --trial k`, or the printed `attsync run … --set …` line),
//! and the files are identical for any `--jobs`.
//!
//! # Layout
//! - [`dispersion`]: the `[monte_carlo]` table and its resolution ([`Dispersion`]).
//! - [`haar`]: the sampler (Haar-uniform rotations, bounded vectors), pure.
//! - `seed`: per-trial seeds (SplitMix64 of the master seed) and streams (ChaCha8).
//! - [`draws`]: one trial's draws, in a fixed order, as `--set` overrides.
//! - [`params`]: the draws of `[[monte_carlo.param]]` fields (their own stream).
//! - [`trial`]: one trial prepared (draws resolved into the scenario) and run.
//! - [`outcome`]: what a trial records ([`Trace`]) and its classification.
//! - [`stats`]: exact binomial (Clopper–Pearson) bounds.
//! - [`report`]: `trials.csv`, `initial.csv`, `mc.json`, the stdout table.
//! - `plot`: `mc.svg`.
//! - [`shard`]: `--shard K/N`, a slice of the trials; [`mod@merge`]: `attsync
//!   mc merge`, the slices joined into one run's files.
//! - [`options`], `error`, `driver`: [`McOptions`], [`McError`], and
//!   [`monte_carlo`] / [`trial_alone`] (the work queue, the files).

pub use crate::scenario::monte_carlo as dispersion;
pub mod draws;
mod driver;
mod error;
pub mod haar;
pub mod merge;
pub mod options;
pub mod outcome;
pub mod params;
mod plot;
pub mod report;
mod seed;
pub mod shard;
pub mod stats;
pub mod trial;

pub use dispersion::{Dispersion, MonteCarloSpec};
pub use driver::{Alone, McRun, load_base, monte_carlo, run_command, trial_alone};
pub use error::McError;
pub use haar::{angle_of, bounded_vector, haar_quaternion, unit_vector};
pub use merge::{MergeError, merge};
pub use options::McOptions;
pub use outcome::{Outcome, Trace, TrialResult};
pub use seed::{trial_rng, trial_seed};
pub use shard::Shard;
