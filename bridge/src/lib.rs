//! A run across machines, over Zenoh, below the orchestrator (as
//! iceoryx2 keeps its Zenoh tunnel apart from its core):
//!
//! - [`hosts`]: placement files (`--hosts HOSTS.toml`): which machine runs
//!   which node, and the cut edges between machines.
//! - [`remote`]: the daemon of each machine (`attsync host`), the
//!   orchestrator's side of a run placed over hosts
//!   ([`remote::Remote`]), and the bridges of cut edges and telemetry.
//! - [`trust`]: who may talk to a daemon (mutual TLS or `--insecure`), the
//!   plug-ins it may start, `--gen-certs`.
//!
//! It knows nothing of the orchestrator's engines: the orchestrator
//! adapts [`remote::Remote`] to its "where nodes run" interface
//! (`attsync::processes::site`) and re-exports these modules as
//! `attsync::hosts`, `attsync::remote` and `attsync::trust`.

pub mod hosts;
pub mod remote;
pub mod trust;
