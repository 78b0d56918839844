//! A host whose link has a real delay ([`DelayedHost`]): an `attsync host`
//! daemon in a [`HostSandbox::networked`] (a network namespace of its own,
//! a veth pair to ours), every packet across the veth held `delay` by
//! `tc … netem delay` on both ends, or, where the kernel has no netem, every
//! byte held `delay` each way by a [`DelayRelay`] in our namespace in front
//! of the daemon. Either way the orchestrator reaches the daemon only
//! across the veth, and `delay` is added to every message each way.

use crate::daemon::Daemon;
use crate::delay_relay::DelayRelay;
use crate::hosts::HostSandbox;
use std::net::SocketAddr;
use std::time::Duration;

/// The daemon's port: the namespace is its own, nothing else listens there.
pub const DAEMON_PORT: u16 = 7447;

/// How the delay is made.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DelayKind {
    /// `tc qdisc add dev <veth> root netem delay …` on both ends.
    Netem,
    /// A [`DelayRelay`]: `tc` refused netem (its words).
    Relay(String),
}

/// A daemon behind a delayed link.
#[derive(Debug)]
pub struct DelayedHost {
    /// The daemon (its `endpoint`: where the orchestrator dials it).
    pub daemon: Daemon,
    /// How the delay is made.
    pub kind: DelayKind,
    /// The root namespace's end of its veth pair (gone once dropped).
    pub root_if: String,
    _relay: Option<DelayRelay>,
}

impl DelayedHost {
    /// Host `name` in a network namespace of its own, `delay` each way.
    #[must_use]
    pub fn start(name: &str, delay: Duration) -> Self {
        let host = HostSandbox::networked(name);
        let veth = host.veth().expect("a networked host has a veth");
        let root_if = veth.root_if.clone();
        let at = SocketAddr::from((veth.host_addr, DAEMON_PORT));
        let listen = format!("tcp/{at}");
        let (kind, relay) = match veth.netem_delay(delay) {
            Ok(()) => (DelayKind::Netem, None),
            Err(why) => {
                let r = DelayRelay::start(SocketAddr::from((veth.root_addr, 0)), at, delay);
                (DelayKind::Relay(why.to_string()), Some(r))
            }
        };
        let endpoint = relay
            .as_ref()
            .map_or_else(|| listen.clone(), |r| format!("tcp/{}", r.addr()));
        Self {
            daemon: Daemon::start_on(host, &listen, endpoint, &[]),
            kind,
            root_if,
            _relay: relay,
        }
    }
}
