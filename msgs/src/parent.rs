//! Which process a node lives and dies with (PROTOCOL.md § 1, § 6).
//!
//! The process that starts a node (the orchestrator, or the `attsync host`
//! daemon on another machine) sets [`PARENT_PID_VAR`] to its own pid. A node
//! that only remembered "whatever parent I have at start-up" could be
//! orphaned before it looked (its parent killed between the fork and its
//! first check) and would then watch init instead; the variable tells it
//! whom to expect, so it notices at once ([`watched`]).
//!
//! A plug-in's command may be a wrapper (`sh -c …`, a script) whose child is
//! the real node: that node's parent is the wrapper, not the pid in the
//! variable. It then watches the wrapper, as long as the expected parent
//! lives (the wrapper itself dies with the orchestrator: `PR_SET_PDEATHSIG`).

/// The environment variable holding the pid of the process that started
/// the node (decimal).
pub const PARENT_PID_VAR: &str = "ATTSYNC_PARENT_PID";

/// The node's expected parent is gone: it was orphaned, possibly before it
/// could look.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("the orchestrator (pid {parent}) has exited")]
pub struct Orphaned {
    /// The pid of the parent that is gone.
    pub parent: u32,
}

/// The pid in [`PARENT_PID_VAR`], if it is set and a number.
#[must_use]
pub fn expected() -> Option<u32> {
    std::env::var(PARENT_PID_VAR).ok()?.trim().parse().ok()
}

/// The process to watch: the node exits once its parent is not this pid any
/// more. Without [`PARENT_PID_VAR`]: the current parent. With it: that pid
/// if it is our parent; our current parent (a wrapper) if the expected one
/// is alive but not our parent; [`Orphaned`] if the expected one is gone.
pub fn watched() -> Result<u32, Orphaned> {
    let parent = std::os::unix::process::parent_id();
    match expected() {
        None => Ok(parent),
        Some(e) if e == parent => Ok(parent),
        Some(e) if alive(e) => Ok(parent),
        Some(e) => Err(Orphaned { parent: e }),
    }
}

/// Whether process `pid` exists and is not a zombie (a killed process stays
/// a zombie until its own parent reaps it: it is gone all the same).
pub use attsync_sched::process::alive;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_is_alive_and_a_reaped_one_is_not() {
        assert!(alive(std::process::id()));
        let mut child = std::process::Command::new("true")
            .spawn()
            .expect("spawn true");
        let pid = child.id();
        child.wait().expect("wait");
        assert!(!alive(pid));
    }

    #[test]
    fn a_zombie_is_not_alive() {
        let mut child = std::process::Command::new("true")
            .spawn()
            .expect("spawn true");
        let pid = child.id();
        // Not reaped yet: a zombie once it exits.
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
        while alive(pid) && std::time::Instant::now() < deadline {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(!alive(pid), "an exited child still counts as alive");
        child.wait().expect("wait");
    }
}
