//! Who made a run fail: a node that ended before it was done
//! ([`Session::ended_early`]), and, when nodes gave up waiting, the node they
//! waited for ([`Collector::blame`]), put first in the failure's text.

use super::Session;
use super::collect::Collector;
use crate::failure::Failure;
use crate::launch::supervise::{describe, tail};
use std::time::{Duration, Instant};

impl Session<'_> {
    /// A node that exited before it was done is a failure: name it, its
    /// status and the end of its log.
    pub(super) fn ended_early(&mut self) -> Option<Failure> {
        while let Some(e) = self.sup.try_exit() {
            let clean = matches!(&e.status, Ok(s) if s.success());
            let slot = &self.nodes.slots[e.index];
            if !(slot.done && clean) {
                return Some(Failure::NodeEnded {
                    label: slot.label.clone(),
                    status: describe(&e.status),
                    log: slot.name.clone(),
                    tail: tail(&self.log_of(e.index), 10),
                });
            }
        }
        None
    }

    /// A site's failure (a lost host), or a node placed elsewhere that
    /// exited before it was done (named with its host, status and log's end).
    pub(super) fn ended_elsewhere(&mut self) -> Result<Option<Failure>, Failure> {
        let mut ended = Vec::new();
        for site in &mut self.sites {
            ended.extend(site.ended()?);
        }
        for e in ended {
            let Some(slot) = self.nodes.slots.iter().find(|s| s.id == e.id) else {
                continue;
            };
            if !(slot.done && e.clean) {
                return Ok(Some(Failure::NodeEnded {
                    label: slot.label.clone(),
                    status: e.status,
                    log: slot.name.clone(),
                    tail: e.tail,
                }));
            }
        }
        Ok(None)
    }

    /// `failure`, with the nodes others gave up waiting for named first.
    /// The last reports may come a little after the first failure (a node
    /// held back by a silent receiver gives up when its back-pressure wait
    /// ends, just after its own receivers): wait until the telemetry is
    /// quiet for [`QUIET`], at most [`SETTLE`].
    pub(super) fn blame(&mut self, failure: Failure) -> Failure {
        let end = Instant::now() + SETTLE;
        let mut quiet_since = Instant::now();
        while Instant::now() < end && quiet_since.elapsed() < QUIET {
            std::thread::sleep(Duration::from_millis(10));
            if let Ok(true) = self.nodes.drain(&self.ports) {
                quiet_since = Instant::now();
            }
        }
        match self.nodes.blame() {
            Some(culprits) => Failure::Blamed {
                culprits,
                failure: Box::new(failure),
            },
            None => failure,
        }
    }
}

/// Longest wait for the last reports before naming the culprit.
const SETTLE: Duration = Duration::from_secs(1);
/// Telemetry silent this long: every report that will come has come.
const QUIET: Duration = Duration::from_millis(200);

impl Collector {
    /// Names the nodes others gave up waiting for, if any did: first the
    /// ones that did not give up waiting themselves (the root of a lockstep
    /// cascade), the leader last (it has no inputs: in lockstep it stalls
    /// only when a receiver stops reading, i.e. by back-pressure).
    pub(crate) fn blame(&self) -> Option<String> {
        let index_of = |id: u32| self.slots.iter().position(|s| s.id == id).unwrap_or(0);
        let mut blamed: Vec<u32> = self.blamed.iter().map(|&(_, id)| id).collect();
        blamed.sort_unstable();
        blamed.dedup();
        // Lockstep propagates a hang: the nodes waiting for the silent one
        // stop publishing too. The cause is a blamed node that did not give
        // up waiting itself (if every blamed node did, list them all).
        let roots: Vec<u32> = blamed
            .iter()
            .copied()
            .filter(|&id| !self.slots[index_of(id)].gave_up)
            .collect();
        let mut silent = if roots.is_empty() { blamed } else { roots };
        // Ids ascend, so the leader (0) is first: put it last.
        let leader_first = silent.first() == Some(&0) && silent.len() > 1;
        silent.rotate_left(usize::from(leader_first));
        let lines: Vec<String> = silent
            .iter()
            .map(|&id| self.blame_line(id, &self.slots[index_of(id)].label))
            .collect();
        (!lines.is_empty()).then(|| lines.join("\n"))
    }

    /// What node `id` (labelled `label`) did to those who waited for it.
    fn blame_line(&self, id: u32, label: &str) -> String {
        let waiters: Vec<&str> = (self.blamed.iter())
            .filter(|&&(_, j)| j == id)
            .map(|&(i, _)| self.slots[i].name.as_str())
            .collect();
        if self.broke_protocol.contains(&id) {
            format!(
                "{label} broke the protocol: {} refused its messages (see their logs)",
                waiters.join(", ")
            )
        } else {
            format!(
                "{label} stopped answering: {} timed out waiting for its state",
                waiters.join(", ")
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::collect::NodeSlot;
    use super::*;

    fn three_nodes() -> Collector {
        Collector::new(vec![
            NodeSlot::new("leader".into(), "leader".into(), 0),
            NodeSlot::new("agent-1".into(), "agent-1".into(), 1),
            NodeSlot::new("agent-3".into(), "agent-3 (plug-in `x`)".into(), 3),
        ])
    }

    #[test]
    fn the_node_that_did_not_wait_itself_is_named_before_the_leader() {
        let mut c = three_nodes();
        // agent-1 timed out on the leader (stalled by back-pressure, its
        // report not in yet) and on agent-3 (hung).
        c.blamed = vec![(1, 0), (1, 3)];
        c.slots[1].gave_up = true;
        let b = c.blame().expect("someone is blamed");
        assert!(
            b.starts_with("agent-3 (plug-in `x`) stopped answering"),
            "{b}"
        );
        assert!(
            b.lines().nth(1).is_some_and(|l| l.starts_with("leader")),
            "{b}"
        );
    }

    #[test]
    fn a_leader_that_gave_up_is_not_a_root() {
        let mut c = three_nodes();
        c.blamed = vec![(1, 0), (2, 0), (1, 3)];
        c.slots[0].gave_up = true;
        c.slots[1].gave_up = true;
        let b = c.blame().expect("someone is blamed");
        assert_eq!(b.lines().count(), 1, "{b}");
        assert!(b.starts_with("agent-3"), "{b}");
    }

    #[test]
    fn a_hung_leader_alone_is_named() {
        let mut c = three_nodes();
        c.blamed = vec![(1, 0), (2, 0)];
        c.slots[1].gave_up = true;
        c.slots[2].gave_up = true;
        let b = c.blame().expect("someone is blamed");
        assert!(
            b.starts_with("leader stopped answering: agent-1, agent-3"),
            "{b}"
        );
    }
}
