//! The `attsync` orchestrator: scenario → validate → run → results.
//!
//! # Layout
//! - [`scenario`]: the TOML format, `--set` overrides, validation, resolution
//!   into the model's [`attitude::network::Network`].
//! - [`run`]: engines and the run driver (progress, interruption).
//! - [`results`]: `errors.csv`, `summary.json`, `errors.svg`, atomic output.
//! - [`generate`]: generated scenarios (random trees).
//! - [`conform`]: the conformance check of a plug-in agent program.

pub mod conform;
pub mod generate;
pub mod processes;
pub mod results;
pub mod run;
pub mod scenario;
pub mod sweep;
