//! A crash and restart of an agent (`[[event]] action = "crash"`, PROTOCOL.md
//! § 10.10): the agent reports `Crashed` at the step its timeline says and
//! waits; the orchestrator kills it (SIGKILL, a real crash) and starts a new
//! process of it with the crashed one's state and counters (`resume` in its
//! configuration). That process stands in for it, publishing what nobody
//! uses, until its restart step, then runs it again.

use super::Session;
use super::configs::{node_configs, node_name, plugin_of};
use crate::failure::Failure;
use crate::launch::supervise::Launch;
use crate::outcome::Restart;
use attitude::agent::Carried;
use std::time::{Duration, Instant};

/// Longest wait for a crashed process to end once killed.
const KILLED_WITHIN: Duration = Duration::from_secs(5);

impl Session<'_> {
    /// Replaces every process that reported a crash since the last call.
    pub(super) fn restart_crashed(&mut self) -> Result<(), Failure> {
        while let Some((i, carried)) = self.nodes.crashes.pop_front() {
            self.restart(i, carried)?;
        }
        Ok(())
    }

    /// Kills node index `i` (which crashed as `carried` says) and starts
    /// its new process.
    fn restart(&mut self, i: usize, carried: Carried) -> Result<(), Failure> {
        let begun = Instant::now();
        let expected = i > 0
            && plugin_of(self.net, &self.opts.plugins, i).is_none()
            && (self.net.agents[i - 1].model.timeline.as_deref())
                .is_some_and(|t| t.crash_at(carried.step).is_some());
        if !expected {
            return Err(self
                .nodes
                .sent_garbage(i, "of a crash its timeline does not have"));
        }
        let step = carried.step;
        let ended = |e: &str| Failure::NodeEnded {
            label: self.nodes.slots[i].label.clone(),
            status: e.to_string(),
            log: self.nodes.slots[i].name.clone(),
            tail: String::new(),
        };
        let Some(pid_before) = self.sup.kill_node(i, KILLED_WITHIN) else {
            return Err(ended("its crashed process did not end when killed"));
        };
        let k = self
            .nodes
            .restarts
            .iter()
            .filter(|(_, (j, _))| *j == i)
            .count()
            + 1;
        let mut cfg =
            node_configs(self.net, self.ports.run(), self.ports.dir(), self.opts).swap_remove(i);
        cfg.resume = Some(carried);
        let file = (self.ports.dir()).join(format!("node-{}.restart-{k}.json", cfg.id));
        let log = (self.logs).join(crate::results::layout::node_log_file(&format!(
            "{}.restart-{k}",
            node_name(self.net, i)
        )));
        let agent_bin = self.binaries.0.clone();
        let spawned = cfg
            .write(&file)
            .map_err(std::io::Error::other)
            .and_then(|()| (self.sup).spawn_node(i, &Launch::Builtin(&agent_bin), &file, &log));
        let pid_after = match spawned {
            Ok(Some(pid)) => pid,
            Ok(None) => return Err(ended("its new process could not start")),
            Err(e) => return Err(ended(&format!("its new process could not start: {e}"))),
        };
        tracing::info!(
            agent = cfg.id,
            step,
            pid_before,
            pid_after,
            "restarted a crashed agent"
        );
        let restart = Restart {
            agent: cfg.id,
            step,
            pid_before,
            pid_after,
            handover_ms: None,
        };
        self.nodes.restarts.push((restart, (i, begun)));
        Ok(())
    }
}
