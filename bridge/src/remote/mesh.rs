//! The links a run needs between hosts, wired by the orchestrator (issue
//! 37): a user starts every daemon with `--listen` only. The orchestrator
//! dials every host itself; for each pair of hosts with cut edges between
//! them, the one listed later in HOSTS.toml dials the earlier one's
//! endpoint for the run ([`dials`]). A host that dials opens a Zenoh
//! session of the run for it ([`Sessions::dial`]): its bridges towards a
//! dialled peer use that session, towards every other side the daemon's
//! (which the orchestrator and the peers that dial it reach). Peers do
//! not route for each other, so each pair needs its own link; the run's
//! session checks each within [`REACH_TIMEOUT`], before the host answers,
//! so a pair that cannot meet fails the run before `Start`, naming both
//! hosts and the endpoint that did not answer.

use super::Side;
use super::client::REACH_TIMEOUT;
use super::keys;
use super::plan::Plan;
use super::wire::{Peer, StateLink};
use super::zconfig::{self, ConfigError};
use crate::trust::Security;
use std::collections::{BTreeMap, BTreeSet};
use std::time::{Duration, Instant};
use thiserror::Error;
use zenoh::Wait;
use zenoh::query::ConsolidationMode;

/// A run's links to its peers could not be made.
#[derive(Debug, Error)]
pub enum MeshError {
    /// The run's session did not open.
    #[error("its session towards {peers}: {source}")]
    Open {
        /// The peers it was to dial.
        peers: String,
        /// Why.
        source: ConfigError,
    },
    /// A peer's daemon did not answer at its endpoint.
    #[error(
        "host {me} cannot reach host {peer} at {endpoint}: no answer within {seconds} s \
         (is {peer}'s daemon listening there, and can {me} reach that address?)"
    )]
    Unreachable {
        /// This host.
        me: String,
        /// The peer.
        peer: String,
        /// Its endpoint, as HOSTS.toml gives it.
        endpoint: String,
        /// The wait.
        seconds: u64,
    },
    /// A Zenoh query failed outright.
    #[error("zenoh: {0}")]
    Zenoh(String),
}

/// The peers each host dials for a run: for every pair of hosts of `plan`
/// with a link of `links` between them, the one listed later dials the
/// one listed earlier (the orchestrator's machine dials every host anyway).
#[must_use]
pub fn dials(plan: &Plan, links: &[StateLink]) -> BTreeMap<String, Vec<Peer>> {
    let rank = |s: &Side| match s {
        Side::Host(h) => plan.hosts.iter().position(|p| &p.name == h),
        Side::Orchestrator => None,
    };
    let pairs: BTreeSet<(usize, usize)> = (links.iter())
        .filter_map(|l| {
            let (a, b) = (rank(&l.from_side)?, rank(&l.to_side)?);
            Some((a.max(b), a.min(b)))
        })
        .collect();
    let mut out: BTreeMap<String, Vec<Peer>> = BTreeMap::new();
    for (later, earlier) in pairs {
        let peer = &plan.hosts[earlier];
        out.entry(plan.hosts[later].name.clone())
            .or_default()
            .push(Peer {
                host: peer.name.clone(),
                endpoint: peer.endpoint.clone(),
            });
    }
    out
}

/// The Zenoh sessions a side's bridges use: the daemon's (or the
/// orchestrator's), and the run's own towards the peers it dialled.
pub struct Sessions {
    main: zenoh::Session,
    dialled: Option<(zenoh::Session, Vec<String>)>,
}

impl Sessions {
    /// One session towards every side (the orchestrator's, or a host's
    /// that dials nobody for the run).
    #[must_use]
    pub fn single(main: &zenoh::Session) -> Self {
        Self {
            main: main.clone(),
            dialled: None,
        }
    }

    /// `main`, and for `peers` (if any) a session of the run dialling
    /// their endpoints, each peer's daemon seen answering within
    /// [`REACH_TIMEOUT`]; host `me` is secured as `security` says.
    ///
    /// # Errors
    /// [`MeshError`]: the session did not open, or a peer did not answer.
    pub fn dial(
        main: &zenoh::Session,
        me: &str,
        peers: &[Peer],
        security: &Security,
    ) -> Result<Self, MeshError> {
        if peers.is_empty() {
            return Ok(Self::single(main));
        }
        let endpoints: Vec<String> = peers.iter().map(|p| p.endpoint.clone()).collect();
        let run = zconfig::open(&[], &endpoints, security).map_err(|source| MeshError::Open {
            peers: endpoints.join(", "),
            source,
        })?;
        let until = Instant::now() + REACH_TIMEOUT;
        let mut waiting: Vec<&Peer> = peers.iter().collect();
        while !waiting.is_empty() {
            waiting = unanswered(&run, &waiting)?;
            if let Some(p) = waiting.first().filter(|_| Instant::now() >= until) {
                return Err(MeshError::Unreachable {
                    me: me.to_string(),
                    peer: p.host.clone(),
                    endpoint: p.endpoint.clone(),
                    seconds: REACH_TIMEOUT.as_secs(),
                });
            }
            if !waiting.is_empty() {
                std::thread::sleep(Duration::from_millis(50));
            }
        }
        let names = peers.iter().map(|p| p.host.clone()).collect();
        Ok(Self {
            main: main.clone(),
            dialled: Some((run, names)),
        })
    }

    /// The session towards `side`.
    #[must_use]
    pub fn towards(&self, side: &Side) -> &zenoh::Session {
        match (&self.dialled, side) {
            (Some((run, names)), Side::Host(h)) if names.contains(h) => run,
            _ => &self.main,
        }
    }

    /// The hosts this side dialled for the run.
    #[must_use]
    pub fn dialled(&self) -> &[String] {
        self.dialled.as_ref().map_or(&[], |(_, n)| n)
    }
}

/// The peers of `waiting` whose daemon did not answer a ping over `run`
/// (all asked at once, each given half a second).
fn unanswered<'p>(run: &zenoh::Session, waiting: &[&'p Peer]) -> Result<Vec<&'p Peer>, MeshError> {
    let zerr = |e: zenoh::Error| MeshError::Zenoh(e.to_string());
    let asked = (waiting.iter())
        .map(|p| {
            (run.get(keys::ping(&p.host)))
                .consolidation(ConsolidationMode::None)
                .timeout(Duration::from_millis(500))
                .wait()
                .map_err(zerr)
                .map(|r| (*p, r))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((asked.into_iter())
        .filter(|(_, replies)| !replies.recv().is_ok_and(|r| r.result().is_ok()))
        .map(|(p, _)| p)
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::remote::plan::PlannedHost;

    fn host(name: &str, nodes: Vec<u32>) -> PlannedHost {
        PlannedHost {
            name: name.into(),
            endpoint: format!("tcp/127.0.0.1:{}", 7000 + nodes[0]),
            nodes,
        }
    }

    fn link(from: u32, from_side: &Side, to_side: &Side) -> StateLink {
        StateLink {
            ahead: 0,
            from,
            from_side: from_side.clone(),
            to_side: to_side.clone(),
            receivers: vec![],
        }
    }

    #[test]
    fn the_later_host_of_each_linked_pair_dials_the_earlier_once() {
        let plan = Plan {
            hosts: vec![host("a", vec![1]), host("b", vec![2]), host("c", vec![3])],
            security: Security::Insecure,
        };
        let (a, b, c) = (
            Side::Host("a".into()),
            Side::Host("b".into()),
            Side::Host("c".into()),
        );
        let o = Side::Orchestrator;
        // a ↔ c both ways, b → c, the orchestrator ↔ b; a and b never meet
        let links = [
            link(1, &a, &c),
            link(3, &c, &a),
            link(2, &b, &c),
            link(0, &o, &b),
            link(2, &b, &o),
        ];
        let d = dials(&plan, &links);
        let peer = |h: &str, port: u32| Peer {
            host: h.into(),
            endpoint: format!("tcp/127.0.0.1:{port}"),
        };
        assert_eq!(d.len(), 1, "{d:?}");
        assert_eq!(d["c"], vec![peer("a", 7001), peer("b", 7002)]);
    }
}
