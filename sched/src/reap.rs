//! Orphans: this process adopts the orphaned descendants of its children
//! (a child subreaper) and kills them ([`crate::process::children_outside_own_group`]
//! finds them).

use nix::sys::signal::{Signal, kill};
use nix::sys::wait::waitpid;
use nix::unistd::Pid;

/// Makes this process a child subreaper (`prctl(PR_SET_CHILD_SUBREAPER)`):
/// a descendant whose parent dies is re-parented to it instead of init.
pub fn become_subreaper() -> std::io::Result<()> {
    nix::sys::prctl::set_child_subreaper(true).map_err(std::io::Error::from)
}

/// Sends `SIGKILL` to child `pid` and waits for it (the failures of a
/// child already gone ignored).
pub fn kill_and_reap(pid: u32) {
    let pid = Pid::from_raw(crate::kernel_id(pid));
    let _ = kill(pid, Signal::SIGKILL);
    let _ = waitpid(pid, None);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    // The child is waited for by `kill_and_reap`, the function under test.
    #[allow(clippy::zombie_processes)]
    fn a_killed_child_is_reaped_and_gone() {
        let child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .expect("sleep");
        let pid = child.id();
        kill_and_reap(pid);
        assert!(!crate::process::exists(pid));
        assert!(become_subreaper().is_ok());
    }
}
