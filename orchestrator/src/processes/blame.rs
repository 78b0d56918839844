//! Who made a run fail: a node that ended before it was done
//! ([`Session::ended_early`]), and, when nodes gave up waiting, the node they
//! waited for ([`Collector::blame`]), put first in the failure's text.

use super::collect::Collector;
use super::supervise::{describe, tail};
use super::{Failure, Session};
use attitude::network::Network;
use std::time::Duration;

impl Session<'_> {
    /// A node that exited before it was done is a failure: name it, its
    /// status and the end of its log.
    pub(super) fn ended_early(&mut self) -> Option<Failure> {
        while let Some(e) = self.sup.try_exit() {
            let clean = matches!(&e.status, Ok(s) if s.success());
            let slot = &self.nodes.slots[e.index];
            if !(slot.done && clean) {
                return Some(format!(
                    "{} ended during the run ({}); last lines of its log (logs/{}.log in the results directory):\n{}",
                    slot.label,
                    describe(&e.status),
                    slot.name,
                    tail(&self.log_of(e.index), 10)
                ));
            }
        }
        None
    }

    /// `failure`, with the nodes others gave up waiting for named first
    /// (after a moment for their last telemetry to arrive).
    pub(super) fn blame(&mut self, failure: Failure) -> Failure {
        std::thread::sleep(Duration::from_millis(20));
        let _ = self.nodes.drain(&self.ports);
        match self.nodes.blame(self.net) {
            Some(b) => format!("{b}\n{failure}"),
            None => failure,
        }
    }
}

impl Collector {
    /// Names the nodes others gave up waiting for, if any did.
    pub(crate) fn blame(&self, net: &Network) -> Option<String> {
        // Node index: 0 the leader, 1 + the agent's index.
        let index_of = |id: u32| net.index_of(id).map_or(0, |i| i + 1);
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
        let silent = if roots.is_empty() { blamed } else { roots };
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
