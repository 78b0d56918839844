//! attsync's wire contract: the shared-memory payloads every process
//! exchanges, the per-run service names, and **one opener per service** that
//! every process uses, so that all of them ask iceoryx2 for the same limits.
//!
//! Payloads are `#[repr(C)]`, fixed size, made of `u32`/`u64`/`f64` only (no
//! heap data), with stable `type_name`s so that processes in other languages
//! can match them. Matrices are **row-major** `[f64; 9]`.
//!
//! # Layout
//! - [`payload`]: [`StateMsg`], [`ControlMsg`], [`PROTOCOL_VERSION`].
//! - [`telemetry`]: [`Telemetry`] (what a node reports) and its wire form [`TelemetryMsg`], encoded and decoded side by side.
//! - [`bytes`]: the payloads as little-endian bytes, for the bridge across hosts.
//! - [`config`]: the JSON configuration each node process receives.
//! - [`names`]: service names under `attsync/<run>/…`.
//! - [`open`]: the openers, with limits derived from the topology ([`Limits`]).
//! - [`namespace`]: the per-run iceoryx2 configuration (file prefix, root path).
//! - [`parent`]: the process a node dies with ([`parent::PARENT_PID_VAR`]).
//! - [`iox`]: [`IoxError`](iox::IoxError) for any failed iceoryx2 call; [`create_node`](iox::create_node) in a run's namespace.

pub mod bytes;
pub mod config;
pub mod iox;
pub mod names;
pub mod namespace;
pub mod open;
pub mod parent;
pub mod payload;
pub mod telemetry;

pub use open::Limits;
pub use payload::{
    ControlCommand, ControlMsg, Invalid, PROTOCOL_VERSION, ROTATION_TOLERANCE, StateMsg, from_rows,
    to_rows, unix_ns_now,
};
pub use telemetry::{
    Done, FailReason, Pacing, Telemetry, TelemetryError, TelemetryKind, TelemetryMsg,
};
