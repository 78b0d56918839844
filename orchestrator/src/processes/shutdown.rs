//! The last phase: after a complete run, `Stop` and every node's exit
//! (a node that does not exit cleanly fails the run); after a failure, every
//! node killed.

use super::supervise::describe;
use super::{Failure, Session};
use std::time::Duration;

/// Longest wait for the nodes to exit after `Stop`.
const STOP_TIMEOUT: Duration = Duration::from_secs(10);
/// Longest wait for killed nodes to be gone.
const KILL_TIMEOUT: Duration = Duration::from_secs(5);

impl Session<'_> {
    /// Ends every node; returns the run's failure (`failure`, or a node that
    /// failed at shutdown).
    pub(super) fn shutdown(&mut self, failure: Option<Failure>) -> Option<Failure> {
        if failure.is_some() {
            self.sup.kill_all();
            let _ = self.sup.wait_all(KILL_TIMEOUT);
            return failure;
        }
        let _ = self.ports.stop();
        let bad: Vec<String> = (self.sup.wait_all(STOP_TIMEOUT).iter())
            .filter(|e| !matches!(&e.status, Ok(s) if s.success()))
            .map(|e| {
                let label = &self.nodes.slots[e.index].label;
                format!("{label}: {}", describe(&e.status))
            })
            .collect();
        (!bad.is_empty()).then(|| format!("nodes failed at shutdown: {}", bad.join("; ")))
    }
}
