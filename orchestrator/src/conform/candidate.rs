//! The candidate process: its configuration, its start (through
//! [`Supervisor`], the engine's supervision), its exit, and what it leaves
//! in its process group.

use super::{ConformError, ConformOptions};
use crate::launch::supervise::{Supervisor, group_members, kill_group, tail};
use crate::processes::{ProcessOptions, node_configs};
use attitude::network::Network;
use msgs::config::NodeConfig;
use std::path::Path;
use std::process::ExitStatus;
use std::time::Duration;

/// How a candidate ended (or why it could not start).
pub(super) type Status = Result<ExitStatus, std::io::Error>;

/// Longest wait for the candidate to exit (after Stop, or with a bad config).
pub(super) const EXIT_TIMEOUT: Duration = Duration::from_secs(10);

/// Node `index + 1`'s configuration (agent `index` of `net`) in run `run`.
pub(super) fn candidate_config(
    net: &Network,
    index: usize,
    run: &str,
    root: &Path,
    opts: &ConformOptions,
) -> NodeConfig {
    let popts = ProcessOptions {
        stage_timeout: opts.stage_timeout,
        start_timeout: opts.start_timeout,
        // Nothing places a candidate: its waiter copes with competitors.
        placement: crate::processes::placement::Placement::Spread,
        ..ProcessOptions::default()
    };
    node_configs(net, run, root, &popts).swap_remove(index + 1)
}

/// A running candidate.
#[derive(Debug)]
pub(super) struct Candidate {
    sup: Supervisor,
    /// Its process id, which is also its process group's.
    pid: u32,
}

impl Candidate {
    /// Starts `opts.command --config <config>` (also in `ATTSYNC_CONFIG`),
    /// output to `opts.log`. `keep_group`: leave what it started running
    /// when it exits, to be checked with [`Self::leftovers`].
    pub(super) fn start(
        opts: &ConformOptions,
        config: &Path,
        keep_group: bool,
    ) -> Result<Self, ConformError> {
        let io = |source| ConformError::Io {
            path: opts.log.clone(),
            source,
        };
        let mut sup = Supervisor::new().map_err(io)?;
        if keep_group {
            sup = sup.keep_groups();
        }
        let file = config.to_string_lossy().into_owned();
        let args: Vec<String> = (opts.command[1..].iter().cloned())
            .chain(["--config".to_string(), file.clone()])
            .collect();
        let env = [("ATTSYNC_CONFIG".to_string(), file)];
        let program = Path::new(&opts.command[0]);
        let pid = sup
            .spawn(0, program, &args, &env, None, &opts.log)
            .map_err(io)?;
        let Some(pid) = pid else {
            let exit = sup.next_exit(Duration::from_secs(5));
            return Err(ConformError::Start {
                command: opts.command.join(" "),
                reason: (exit.and_then(|e| e.status.err()))
                    .map_or_else(String::new, |e| e.to_string()),
            });
        };
        Ok(Self { sup, pid })
    }

    /// Its status, if it has ended.
    pub(super) fn try_exit(&mut self) -> Option<Status> {
        self.sup.try_exit().map(|e| e.status)
    }

    /// Waits up to `timeout` for it to end.
    pub(super) fn wait_exit(&mut self, timeout: Duration) -> Option<Status> {
        self.sup.next_exit(timeout).map(|e| e.status)
    }

    /// Kills it and its process group, and waits until it is gone.
    pub(super) fn kill(&mut self) {
        self.sup.kill_all();
        let _ = self.sup.wait_all(Duration::from_secs(5));
    }

    /// Processes of its process group still running.
    pub(super) fn leftovers(&self) -> Vec<u32> {
        group_members(self.pid)
    }

    /// Kills whatever is left in its process group.
    pub(super) fn kill_group(&self) {
        kill_group(Some(self.pid));
    }
}

/// Whether `st` is a successful exit.
pub(super) fn success(st: &Status) -> bool {
    matches!(st, Ok(s) if s.success())
}

/// The end of the candidate's output.
pub(super) fn log_tail(opts: &ConformOptions) -> String {
    tail(&opts.log, 6)
}
