//! Telemetry across hosts: on a host, one thread reads every local node's
//! telemetry service (woken, as an orchestrator is, by the nodes' events)
//! and sends each message, prefixed by the id of the service it came from,
//! on the host's telemetry link; on the orchestrator's side one thread per
//! host publishes each into the local telemetry service of that id, so the
//! orchestrator collects remote nodes exactly as local ones (its sender
//! check included).

use super::bridge::BridgeError;
use super::keys;
use super::link::{LinkReceiver, LinkSender, TELEMETRY_WINDOW};
use super::local::{LocalNs, Shared};
use iceoryx2::prelude::*;
use msgs::TelemetryMsg;
use msgs::bytes::Bytes;
use msgs::iox::iox;
use std::thread::JoinHandle;
use std::time::Duration;

/// How long the forwarder sleeps on the wake event between drains (as the
/// orchestrator does: samples do not notify).
const POLL: Duration = Duration::from_millis(10);

/// A thread of the telemetry bridge; stopped (through `Shared`) and joined on drop.
pub struct TelemetryThread(Option<JoinHandle<()>>, Shared);

impl Drop for TelemetryThread {
    fn drop(&mut self) {
        self.1.stop();
        if let Some(t) = self.0.take() {
            let _ = t.join();
        }
    }
}

/// Prefixes `m` with the id of the service it came from.
fn frame(service: u32, m: &TelemetryMsg) -> Vec<u8> {
    let mut out = service.to_le_bytes().to_vec();
    m.put(&mut out);
    out
}

/// The service id and message of a frame (what the orchestrator's side
/// decodes of each message on a host's telemetry link).
///
/// # Errors
/// [`FrameError`]: too short, or not a telemetry message.
pub fn unframe(b: &[u8]) -> Result<(u32, TelemetryMsg), FrameError> {
    let (id, m) = b.split_at_checked(4).ok_or(FrameError::Short)?;
    let id = u32::from_le_bytes(id.try_into().expect("4 bytes"));
    Ok((id, TelemetryMsg::from_bytes(m)?))
}

/// Why a frame off a host's telemetry link does not decode ([`unframe`]).
#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    /// It is too short to hold a service id.
    #[error("a telemetry frame of under 4 bytes")]
    Short,
    /// Its message is not a telemetry message.
    #[error(transparent)]
    Message(#[from] msgs::bytes::WrongSize),
}

/// What a telemetry thread works with.
struct Ends {
    session: zenoh::Session,
    ns: LocalNs,
    /// The link's key.
    key: String,
    /// The host's name.
    host: String,
    /// The host's nodes.
    ids: Vec<u32>,
    sh: Shared,
}

impl Ends {
    /// Runs `f` on a thread of its own; its error is the run's failure.
    fn spawn(self, what: &'static str, f: fn(&Ends) -> Result<(), BridgeError>) -> TelemetryThread {
        let sh = self.sh.clone();
        let t = std::thread::spawn(move || {
            if let Err(e) = f(&self) {
                self.sh.fail(format!("{what} of host {}: {e}", self.host));
            }
        });
        TelemetryThread(Some(t), sh)
    }
}

/// Which end of a host's telemetry link a thread is.
#[derive(Debug, Clone, Copy)]
pub enum End {
    /// On the host: forwards its nodes' telemetry to the orchestrator.
    Forward,
    /// On the orchestrator's machine: publishes it into local services.
    Sink,
}

/// Starts `end` of host `host`'s telemetry link in run `run`, for its nodes `ids`.
#[must_use]
pub fn start(
    end: End,
    session: &zenoh::Session,
    ns: &LocalNs,
    (run, host): (&str, &str),
    ids: Vec<u32>,
    sh: &Shared,
) -> TelemetryThread {
    let e = Ends {
        session: session.clone(),
        ns: ns.clone(),
        key: keys::telemetry_link(run, host),
        host: host.to_string(),
        ids,
        sh: sh.clone(),
    };
    match end {
        End::Forward => e.spawn("telemetry bridge", forward_loop),
        End::Sink => e.spawn("telemetry", sink_loop),
    }
}

fn forward_loop(e: &Ends) -> Result<(), BridgeError> {
    let (session, ns, key, ids, sh) = (&e.session, &e.ns, e.key.as_str(), e.ids.as_slice(), &e.sh);
    let node = ns.node("host-telemetry")?;
    let wake = msgs::open::orchestrator_wake(&node, &ns.run, &ns.limits)?
        .listener_builder()
        .create()
        .map_err(iox("telemetry wake listener"))?;
    let subs = (ids.iter())
        .map(|&id| {
            msgs::open::telemetry(&node, &ns.run, id, &ns.limits)?
                .subscriber_builder()
                .buffer_size(ns.limits.telemetry_buffer)
                .create()
                .map_err(|e| BridgeError::from(iox("telemetry subscriber")(e)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let mut link = LinkSender::open(session, key, TELEMETRY_WINDOW)?;
    let stop = || false;
    loop {
        // Drain once more after the stop: the last reports (Done, Failed) go too.
        let last = sh.stopping();
        let _ = wake.timed_wait(|_| {}, POLL);
        for (sub, &id) in subs.iter().zip(ids) {
            while let Some(m) = sub
                .receive()
                .map_err(|e| BridgeError::Receive(format!("{e:?}")))?
            {
                let bytes = frame(id, &m);
                drop(m);
                link.send(bytes, ns.stage_timeout, &stop)?;
            }
        }
        if last {
            return Ok(());
        }
    }
}

fn sink_loop(e: &Ends) -> Result<(), BridgeError> {
    let (session, ns, key, ids, sh) = (&e.session, &e.ns, e.key.as_str(), e.ids.as_slice(), &e.sh);
    let host = e.host.as_str();
    let node = ns.node(&format!("telemetry-of-{host}"))?;
    let pubs = (ids.iter())
        .map(|&id| {
            msgs::open::telemetry(&node, &ns.run, id, &ns.limits)?
                .publisher_builder()
                .backpressure_strategy(BackpressureStrategy::RetryUntilDelivered)
                .create()
                .map_err(|e| BridgeError::from(iox("telemetry publisher")(e)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let wake = msgs::open::orchestrator_wake(&node, &ns.run, &ns.limits)?
        .notifier_builder()
        .create()
        .map_err(iox("orchestrator notifier"))?;
    let mut link = LinkReceiver::open(session, key, TELEMETRY_WINDOW)?;
    while !sh.stopping() {
        let Some(b) = link.recv(POLL)? else {
            continue;
        };
        let (id, m) = unframe(&b)?;
        let k = (ids.iter().position(|&i| i == id)).ok_or(BridgeError::NotPlaced(id))?;
        pubs[k].send_copy(m).map_err(iox("telemetry send"))?;
        let sample = m.decode().is_ok_and(|t| t.is_sample());
        if !sample {
            let _ = wake.notify();
        }
        link.delivered()?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use msgs::Telemetry;

    #[test]
    fn a_frame_carries_its_service_id_and_the_exact_message() {
        let m = TelemetryMsg::encode(9, &Telemetry::Ready);
        let (id, back) = unframe(&frame(4, &m)).expect("a frame");
        assert_eq!((id, back), (4, m));
        assert!(unframe(&[1, 2]).is_err());
    }
}
