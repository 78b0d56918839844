//! Processes as `/proc` shows them: which exist, whether one is alive, its
//! group and parent ([`crate::stat`]), its threads, command line and
//! environment.

use crate::error::dir;
use std::path::PathBuf;

/// The pids of every process now (those that end meanwhile included).
#[must_use]
pub fn pids() -> Vec<u32> {
    numbered_entries("/proc")
}

/// The numeric names in directory `path` (pids, thread ids).
fn numbered_entries(path: impl AsRef<std::path::Path>) -> Vec<u32> {
    let Ok(rd) = std::fs::read_dir(path) else {
        return Vec::new();
    };
    rd.filter_map(|e| e.ok()?.file_name().to_str()?.parse().ok())
        .collect()
}

/// Whether process `pid` exists, a zombie included.
#[must_use]
pub fn exists(pid: u32) -> bool {
    dir(pid).exists()
}

/// Whether process `pid` exists and is not a zombie (a killed process stays
/// a zombie until its own parent reaps it: it is gone all the same).
#[must_use]
pub fn alive(pid: u32) -> bool {
    crate::stat::read_pid(pid).is_ok_and(|s| !s.is_dead())
}

/// The processes of process group `pgid` that are still alive.
#[must_use]
pub fn group_members(pgid: u32) -> Vec<u32> {
    let member =
        |pid: &u32| crate::stat::read_pid(*pid).is_ok_and(|s| s.pgrp == pgid && s.state != 'Z');
    pids().into_iter().filter(member).collect()
}

/// The children of this process outside its own process group (zombies
/// included, for the caller to reap).
#[must_use]
pub fn children_outside_own_group() -> Vec<u32> {
    let Ok(me) = crate::stat::own() else {
        return Vec::new();
    };
    let own = std::process::id();
    let orphan =
        |pid: &u32| crate::stat::read_pid(*pid).is_ok_and(|s| s.ppid == own && s.pgrp != me.pgrp);
    pids().into_iter().filter(orphan).collect()
}

/// The thread ids of process `pid` (none if it is gone).
#[must_use]
pub fn threads(pid: u32) -> Vec<u32> {
    numbered_entries(dir(pid).join("task"))
}

/// The name (`comm`) of thread `tid` of process `pid`.
#[must_use]
pub fn thread_name(pid: u32, tid: u32) -> Option<String> {
    let path = dir(pid).join(format!("task/{tid}/comm"));
    Some(std::fs::read_to_string(path).ok()?.trim_end().to_owned())
}

/// The calling thread's id (`/proc/thread-self` names it).
#[must_use]
pub fn current_thread() -> Option<u32> {
    let link = std::fs::read_link("/proc/thread-self").ok()?;
    link.file_name()?.to_str()?.parse().ok()
}

/// The NUL-separated strings of file `name` of process `pid`.
fn nul_separated(pid: u32, name: &str) -> Vec<Vec<u8>> {
    let bytes = std::fs::read(dir(pid).join(name)).unwrap_or_default();
    bytes
        .split(|&c| c == 0)
        .filter(|a| !a.is_empty())
        .map(<[u8]>::to_vec)
        .collect()
}

/// The command line of process `pid` (empty if it is gone or a zombie).
#[must_use]
pub fn cmdline(pid: u32) -> Vec<String> {
    let args = nul_separated(pid, "cmdline");
    args.iter()
        .map(|a| String::from_utf8_lossy(a).into_owned())
        .collect()
}

/// The environment of process `pid`, `KEY=value` each (empty if it is
/// gone, a zombie, or not ours).
#[must_use]
pub fn environ(pid: u32) -> Vec<Vec<u8>> {
    nul_separated(pid, "environ")
}

/// The mount namespace of process `pid`, as `readlink /proc/<pid>/ns/mnt`
/// names it (`None`: gone, or a zombie).
#[must_use]
pub fn mount_namespace(pid: u32) -> Option<PathBuf> {
    std::fs::read_link(dir(pid).join("ns/mnt")).ok()
}

/// The root directory of process `pid` as this process reaches it (into
/// its mount namespace: `/proc/<pid>/root`).
#[must_use]
pub fn root(pid: u32) -> PathBuf {
    dir(pid).join("root")
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Command;

    #[test]
    fn this_process_is_alive_and_a_reaped_one_is_not() {
        let me = std::process::id();
        assert!(alive(me) && exists(me) && pids().contains(&me));
        let mut child = Command::new("true").spawn().expect("spawn true");
        let pid = child.id();
        child.wait().expect("wait");
        assert!(!alive(pid) && !exists(pid));
    }

    #[test]
    fn a_childs_group_command_line_and_threads_are_read() {
        let mut child = Command::new("sleep").arg("30").spawn().expect("sleep");
        let pid = child.id();
        // `spawn` returns once the child is forked, not once it has exec'd
        // `sleep`: until then its name is ours and its command line empty.
        let exec = std::time::Instant::now() + std::time::Duration::from_secs(10);
        while (thread_name(pid, pid).as_deref() != Some("sleep") || cmdline(pid).is_empty())
            && std::time::Instant::now() < exec
        {
            std::thread::sleep(std::time::Duration::from_millis(1));
        }
        let group = crate::stat::own().expect("own stat").pgrp;
        let seen = (
            group_members(group).contains(&pid),
            cmdline(pid),
            threads(pid),
            thread_name(pid, pid),
        );
        let _ = child.kill();
        let _ = child.wait();
        assert!(seen.0, "the child is in our group");
        assert_eq!(seen.1, ["sleep", "30"]);
        assert_eq!((seen.2, seen.3.as_deref()), (vec![pid], Some("sleep")));
        assert!(children_outside_own_group().is_empty());
        assert!(current_thread().is_some_and(|t| threads(std::process::id()).contains(&t)));
    }
}
