//! A node as an OS process on this machine: the run's iceoryx2 namespace
//! ([`namespace`]), the process itself, started and watched
//! ([`supervise`]), its log ([`node_log`]), and the ranges of its timing
//! settings ([`bounds`]); a node's end as a machine reports it
//! ([`site_exit`]).
//!
//! A crate of its own below the orchestrator, shared by everything that
//! starts nodes: the process engine (`attsync::processes`), a host
//! daemon's runs (`attsync::remote`) and `attsync conform`. It knows
//! nothing of runs, scenarios or hosts.

pub mod bounds;
pub mod namespace;
pub mod node_log;
pub mod site_exit;
pub mod supervise;
