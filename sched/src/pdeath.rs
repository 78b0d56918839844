//! A child that dies with the thread that started it.
//!
//! [`die_with_parent`] makes a command's process ask, between `fork` and
//! `exec`, for `SIGKILL` when its parent dies (`prctl(PR_SET_PDEATHSIG)`,
//! kept across `exec`), then check that its parent is still the process that
//! forked it (else the parent died before the request counted, and the
//! child exits at once). So no moment of the parent's life, start-up
//! included, leaves the child behind.
//!
//! CAUTION: Linux sends the signal when the *thread* that forked exits, not
//! the process. Start children only from a thread that lives as long as
//! they should (attsync's `Supervisor::spawn` forks on its caller's thread).

use std::os::unix::process::CommandExt;
use std::process::Command;

/// The exit status of a child whose parent died before it could ask to die
/// with it (the status a node gives for any failure).
pub const ORPHANED_AT_BIRTH: i32 = 1;

/// Makes `cmd`'s process get `SIGKILL` when the thread that spawns it exits
/// (see the module's caution), and exit with [`ORPHANED_AT_BIRTH`] before
/// `exec` if its parent is already gone. Only async-signal-safe calls run
/// in the child (`prctl`, `getppid`, `_exit`).
pub fn die_with_parent(cmd: &mut Command) -> &mut Command {
    // The pid the child must find as its parent: ours, read before the fork.
    let parent = crate::kernel_id(std::process::id());
    // SAFETY: the closure runs in the child between fork and exec, and only
    // makes the system calls prctl, getppid and _exit, which are
    // async-signal-safe; it allocates nothing and takes no lock.
    #[allow(unsafe_code)]
    unsafe {
        cmd.pre_exec(move || {
            let sig = libc::SIGKILL as libc::c_ulong;
            if libc::prctl(libc::PR_SET_PDEATHSIG, sig, 0, 0, 0) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            if libc::getppid() != parent {
                libc::_exit(ORPHANED_AT_BIRTH);
            }
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::process::ExitStatusExt;
    use std::time::{Duration, Instant};

    #[test]
    fn the_child_dies_with_the_thread_that_spawned_it() {
        let t = std::thread::spawn(|| {
            die_with_parent(Command::new("sleep").arg("30"))
                .spawn()
                .expect("spawn sleep")
        });
        let mut child = t.join().expect("the spawning thread");
        let deadline = Instant::now() + Duration::from_secs(5);
        let status = loop {
            match child.try_wait().expect("waitpid") {
                Some(s) => break Some(s),
                None if Instant::now() > deadline => break None,
                None => std::thread::sleep(Duration::from_millis(10)),
            }
        };
        if status.is_none() {
            let _ = child.kill();
            let _ = child.wait();
        }
        let signal = status.and_then(|s| s.signal());
        assert_eq!(
            signal,
            Some(libc::SIGKILL),
            "the child outlived the thread that spawned it"
        );
    }

    #[test]
    fn the_child_runs_while_its_parent_thread_lives() {
        let out = die_with_parent(&mut Command::new("true"))
            .status()
            .expect("run true");
        assert!(out.success());
    }
}
