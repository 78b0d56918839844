//! The last phase: after a complete run, `Stop` and every node's exit
//! (a node that does not exit cleanly fails the run); after a failure, every
//! node killed.

use super::Session;
use crate::failure::Failure;
use crate::launch::supervise::describe;
use msgs::{ControlCommand, ControlMsg};
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
            for site in &mut self.sites {
                site.finish(true, self.logs);
            }
            return failure;
        }
        let _ = self.ports.stop();
        for site in &self.sites {
            let _ = site.control(ControlMsg::new(ControlCommand::Stop));
        }
        let mut bad: Vec<String> = (self.sup.wait_all(STOP_TIMEOUT).iter())
            .filter(|e| !matches!(&e.status, Ok(s) if s.success()))
            .map(|e| {
                let label = &self.nodes.slots[e.index].label;
                format!("{label}: {}", describe(&e.status))
            })
            .collect();
        for site in &mut self.sites {
            for e in site.finish(false, self.logs) {
                let label = (self.nodes.slots.iter())
                    .find(|s| s.id == e.id)
                    .map_or_else(|| format!("host {}", e.host), |s| s.label.clone());
                bad.push(format!("{label}: {}", e.status));
            }
        }
        (!bad.is_empty()).then_some(Failure::Shutdown(bad))
    }
}
