//! The `attsync` orchestrator: scenario → validate → run → results.
//!
//! # Layout
//! - [`scenario`]: the TOML format, `--set` overrides, validation, resolution
//!   into the model's [`attitude::network::Network`].
//! - [`run`]: engines and the run driver (progress, interruption).
//! - [`outcome`]: how a run ended, the same [`outcome::Outcome`] from either engine.
//! - [`processes`]: the process-per-agent engine, phase by phase; the orchestrator's ports.
//! - [`results`]: `errors.csv`, `summary.json`, `errors.svg`, atomic output.
//! - [`generate`]: generated scenarios (random trees).
//! - [`conform`]: the conformance check of a plug-in agent program.

pub mod conform;
pub mod generate;
pub mod outcome;
pub mod processes;
pub mod results;
pub mod run;
pub mod scenario;
pub mod sweep;
