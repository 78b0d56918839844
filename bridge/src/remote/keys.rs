//! Every Zenoh key expression attsync uses across hosts, in one place
//! (PROTOCOL.md, "Across hosts"). `<run>` is the orchestrator's run id; a
//! side is `orchestrator` or `host-<name>`.

use super::Side;

/// `attsync/host/<name>/<what>`: a daemon's queryables and its liveliness token.
fn host(name: &str, what: &str) -> String {
    format!("attsync/host/{name}/{what}")
}

/// A daemon's ping queryable: replies with its name and version.
#[must_use]
pub fn ping(name: &str) -> String {
    host(name, "ping")
}

/// A daemon's queryable that accepts a run ([`super::wire::RunOffer`]).
#[must_use]
pub fn run(name: &str) -> String {
    host(name, "run")
}

/// A daemon's queryable that ends a run ([`super::wire::EndRequest`]).
#[must_use]
pub fn end(name: &str) -> String {
    host(name, "end")
}

/// The orchestrator's queryable that hands host `host` its
/// [`super::wire::RunRequest`], in pieces ([`super::pieces`]).
#[must_use]
pub fn request(run: &str, host: &str) -> String {
    format!("attsync/{run}/request/{host}")
}

/// A daemon's liveliness token (gone: the daemon or its connection is lost).
#[must_use]
pub fn host_alive(name: &str) -> String {
    host(name, "alive")
}

/// Every daemon's liveliness token.
pub const ANY_HOST_ALIVE: &str = "attsync/host/*/alive";

/// The orchestrator's liveliness token of a run (gone: the daemons clean the run up).
#[must_use]
pub fn orchestrator_alive(run: &str) -> String {
    format!("attsync/{run}/orchestrator/alive")
}

/// The run's control commands (`ControlMsg` bytes), orchestrator → daemons.
#[must_use]
pub fn control(run: &str) -> String {
    format!("attsync/{run}/control")
}

/// A daemon's events of a run ([`super::wire::HostEvent`] JSON), daemon → orchestrator.
#[must_use]
pub fn events(run: &str, host: &str) -> String {
    format!("attsync/{run}/events/{host}")
}

/// The states of every cut edge from side `from` to side `to` (bundles of
/// `StateMsg` bytes, [`super::trunk`]); acks at `<key>/ack`.
#[must_use]
pub fn state_trunk(run: &str, from: &Side, to: &Side) -> String {
    format!("attsync/{run}/states/{}/{}", from.key(), to.key())
}

/// A host's telemetry (service id + `TelemetryMsg` bytes), daemon → orchestrator.
#[must_use]
pub fn telemetry_link(run: &str, host: &str) -> String {
    format!("attsync/{run}/telemetry/{host}")
}

/// The acknowledgements of the link at `data`.
#[must_use]
pub fn ack(data: &str) -> String {
    format!("{data}/ack")
}
