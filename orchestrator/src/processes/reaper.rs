//! No descendant of a node outlives the run: the orchestrator becomes a
//! child subreaper (`prctl(PR_SET_CHILD_SUBREAPER)`), so a plug-in's child
//! that left the node's process group (`setsid`) and lost its parent is
//! re-parented to the orchestrator instead of init; when the last run of
//! this process ends ([`Reaper`] dropped), every such orphan is killed.
//!
//! An orphan is a child of the orchestrator (`/proc/<pid>/stat` ppid) in
//! another process group than the orchestrator's (the nodes it still
//! supervises have all been waited for by then; children it spawned itself
//! outside runs stay in its group and are left alone).

use nix::sys::signal::{Signal, kill};
use nix::sys::wait::waitpid;
use nix::unistd::{Pid, getpgrp, getpid};
use std::sync::atomic::{AtomicUsize, Ordering};

/// Processes-engine runs going on in this process.
static ACTIVE: AtomicUsize = AtomicUsize::new(0);

/// Held for the duration of one processes-engine run; reaps the orphans
/// when the last one ends.
#[derive(Debug)]
pub struct Reaper(());

impl Reaper {
    /// Makes this process a child subreaper (best effort) and counts the run.
    #[must_use]
    pub fn start() -> Self {
        let _ = nix::sys::prctl::set_child_subreaper(true);
        ACTIVE.fetch_add(1, Ordering::SeqCst);
        Self(())
    }
}

impl Drop for Reaper {
    fn drop(&mut self) {
        if ACTIVE.fetch_sub(1, Ordering::SeqCst) == 1 {
            kill_orphans();
        }
    }
}

/// Kills (SIGKILL) and reaps every orphan, until none is left (killing one
/// re-parents its own children to us); returns how many.
pub fn kill_orphans() -> usize {
    let mut killed = 0;
    for _ in 0..16 {
        let orphans = orphans();
        if orphans.is_empty() {
            break;
        }
        for pid in orphans {
            let pid = Pid::from_raw(pid);
            let _ = kill(pid, Signal::SIGKILL);
            let _ = waitpid(pid, None);
            killed += 1;
        }
    }
    killed
}

/// Children of this process outside its process group.
fn orphans() -> Vec<i32> {
    let (me, group) = (getpid().as_raw(), getpgrp().as_raw());
    let Ok(rd) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    rd.filter_map(Result::ok)
        .filter_map(|e| e.file_name().to_str()?.parse::<i32>().ok())
        .filter(|&pid| {
            stat_parent_and_group(pid).is_some_and(|(ppid, pgrp)| ppid == me && pgrp != group)
        })
        .collect()
}

/// `(ppid, pgrp)` from `/proc/<pid>/stat` (`pid (comm) state ppid pgrp …`).
fn stat_parent_and_group(pid: i32) -> Option<(i32, i32)> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = &text[text.rfind(')')? + 1..];
    let mut fields = rest.split_whitespace().skip(1);
    Some((fields.next()?.parse().ok()?, fields.next()?.parse().ok()?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stat_is_parsed_past_the_command_name() {
        let me = std::process::id() as i32;
        let (ppid, pgrp) = stat_parent_and_group(me).expect("own stat");
        assert_eq!(ppid, nix::unistd::getppid().as_raw());
        assert_eq!(pgrp, getpgrp().as_raw());
    }
}
