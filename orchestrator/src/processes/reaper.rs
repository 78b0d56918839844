//! No descendant of a node outlives the run: the orchestrator becomes a
//! child subreaper (`prctl(PR_SET_CHILD_SUBREAPER)`), so a plug-in's child
//! that left the node's process group (`setsid`) and lost its parent is
//! re-parented to the orchestrator instead of init; when the last run of
//! this process ends ([`Reaper`] dropped), every such orphan is killed.
//!
//! An orphan is a child of the orchestrator in another process group than
//! the orchestrator's ([`attsync_sched::process::children_outside_own_group`];
//! the nodes it still supervises have all been waited for by then; children
//! it spawned itself outside runs stay in its group and are left alone).

use attsync_sched::{process, reap};
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
        let _ = reap::become_subreaper();
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
        let orphans = process::children_outside_own_group();
        if orphans.is_empty() {
            break;
        }
        for pid in orphans {
            reap::kill_and_reap(pid);
            killed += 1;
        }
    }
    killed
}
