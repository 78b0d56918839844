//! The `attsync` orchestrator: scenario → validate → run → results.
//!
//! # Layout
//! - [`scenario`]: the TOML format, `--set` overrides, validation, resolution
//!   into the model's [`attitude::network::Network`].
//! - [`run`]: engines and the run driver (progress, interruption).
//! - [`outcome`]: how a run ended, the same [`outcome::Outcome`] from either engine.
//! - [`failure`]: why a run stopped early ([`failure::Failure`]), carried to
//!   `summary.json` and the exit code.
//! - [`processes`]: the process-per-agent engine, phase by phase; the orchestrator's ports.
//! - [`results`]: `errors.csv`, `summary.json`, `errors.svg`, atomic output.
//! - [`sweep`]: one field over many values, and the bisection for the margin.
//! - [`until`]: `--tolerance` and `--until settled`: what a run is judged by
//!   (its verdict, `attsync_verdict`) and how long it goes.
//! - [`generate`]: generated scenarios (random trees).
//! - [`hosts`], [`remote`], [`trust`] (the `attsync-bridge` crate): runs
//!   across machines: placement files, the host daemon, the Zenoh bridges,
//!   mutual TLS.
//! - [`mc`]: the Monte Carlo over initial conditions (`attsync mc`).
//! - [`margin`]: `attsync margin`, the linearisation's delay margin and rightmost root.
//! - [`conform`]: the conformance check of a plug-in agent program.
//! - [`verify`]: `attsync verify`, a run's files against its `manifest.json`
//!   and a re-run of its scenario against its `states.bin` and `errors.csv`.
//! - [`options`]: range checks of command-line options, before anything starts.
//! - [`interrupt`]: SIGINT, SIGTERM and SIGHUP as one interrupt that names its signal.
//! - [`error`]: [`enum@Error`], every way a command fails, and its exit code.
//! - [`view`]: `view.html`, a run in 3D in the browser (one self-contained file).
//! - `export` (feature `mcap`, on by default): a run's `states.bin` as an MCAP
//!   recording for Foxglove, Lichtblick and Rerun.
//! - `tables` (feature `parquet`, on by default): a run's errors, states and
//!   leader as Parquet tables.
//!
//! The binary (`src/bin/attsync/`) only parses the command line and calls
//! these; one file per subcommand in `commands/`.

pub mod conform;
pub mod error;
pub mod exit;
#[cfg(feature = "mcap")]
pub mod export;
pub mod failure;
pub mod generate;
pub use ::bridge::hosts;
pub mod interrupt;
pub use ::launch;
pub mod margin;
pub mod mc;
pub mod options;
pub mod outcome;
pub mod pool;
pub mod processes;
pub mod progress;
pub use ::bridge::remote;
mod remote_site;
pub mod results;
pub mod run;
pub use ::scenario;
pub mod sweep;
#[cfg(feature = "parquet")]
pub mod tables;
pub use ::bridge::trust;
pub mod until;
pub mod verify;
pub mod view;

pub use error::Error;
