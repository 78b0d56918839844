//! Service names. Every run has its own namespace `attsync/<run>/`; node ids
//! are the agents' ids, 0 for the leader.

use iceoryx2::prelude::ServiceName;

fn name(s: String) -> ServiceName {
    s.as_str()
        .try_into()
        .unwrap_or_else(|e| panic!("invalid service name {s:?}: {e:?}"))
}

/// `attsync/<run>/node/<id>/state`: the node's exchanged state ([`crate::StateMsg`]).
#[must_use]
pub fn state(run: &str, id: u32) -> ServiceName {
    name(format!("attsync/{run}/node/{id}/state"))
}

/// `attsync/<run>/node/<id>/wake`: event on which node `id` sleeps while it
/// waits for its inputs; senders notify it after publishing.
#[must_use]
pub fn wake(run: &str, id: u32) -> ServiceName {
    name(format!("attsync/{run}/node/{id}/wake"))
}

/// `attsync/<run>/node/<id>/telemetry`: the node's reports ([`crate::TelemetryMsg`]).
#[must_use]
pub fn telemetry(run: &str, id: u32) -> ServiceName {
    name(format!("attsync/{run}/node/{id}/telemetry"))
}

/// `attsync/<run>/orchestrator/wake`: event nodes notify after each telemetry message.
#[must_use]
pub fn orchestrator_wake(run: &str) -> ServiceName {
    name(format!("attsync/{run}/orchestrator/wake"))
}

/// `attsync/<run>/control`: orchestrator commands ([`crate::ControlMsg`]).
#[must_use]
pub fn control(run: &str) -> ServiceName {
    name(format!("attsync/{run}/control"))
}
