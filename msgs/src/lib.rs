//! attsync's wire contract: the shared-memory payloads every process
//! exchanges, the per-run service names, and **one opener per service** that
//! every process uses, so that all of them ask iceoryx2 for the same limits.
//!
//! Payloads are `#[repr(C)]`, fixed size, made of `u32`/`u64`/`f64` only (no
//! heap data), with stable `type_name`s so that processes in other languages
//! can match them. Matrices are **row-major** `[f64; 9]`.
//!
//! # Layout
//! - [`payload`]: [`StateMsg`], [`TelemetryMsg`], [`ControlMsg`], [`PROTOCOL_VERSION`].
//! - [`config`]: the JSON configuration each node process receives.
//! - [`names`]: service names under `attsync/<run>/…`.
//! - [`open`]: the openers, with limits derived from the topology ([`Limits`]).
//! - [`namespace`]: the per-run iceoryx2 configuration (file prefix, root path).

pub mod config;
pub mod names;
pub mod namespace;
pub mod open;
pub mod payload;

pub use open::Limits;
pub use payload::{
    ControlCommand, ControlMsg, Invalid, PROTOCOL_VERSION, ROTATION_TOLERANCE, StateMsg,
    TelemetryKind, TelemetryMsg, unix_ns_now,
};
