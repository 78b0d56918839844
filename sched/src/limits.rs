//! What the machine and the user allow this process: resource limits, the
//! kernel's task limits, open files, free space.

use std::os::unix::fs::MetadataExt;
use std::path::Path;

/// The soft limit on the line `name` of the text of `/proc/<pid>/limits`
/// (`None`: unlimited, or no such line).
#[must_use]
pub fn soft_limit_in(limits: &str, name: &str) -> Option<u64> {
    let line = limits.lines().find(|l| l.starts_with(name))?;
    line[name.len()..].split_whitespace().next()?.parse().ok()
}

/// This process's soft limit `name` (`Max processes`, `Max open files`, as
/// `/proc/self/limits` names them; `None`: unlimited or unknown).
#[must_use]
pub fn soft_limit(name: &str) -> Option<u64> {
    soft_limit_in(&std::fs::read_to_string("/proc/self/limits").ok()?, name)
}

/// The number in file `path` of `/proc/sys`.
fn sysctl(path: &str) -> Option<u64> {
    std::fs::read_to_string(path).ok()?.trim().parse().ok()
}

/// The largest pid plus one (`/proc/sys/kernel/pid_max`).
#[must_use]
pub fn pid_max() -> Option<u64> {
    sysctl("/proc/sys/kernel/pid_max")
}

/// The most threads the machine may have (`/proc/sys/kernel/threads-max`).
#[must_use]
pub fn threads_max() -> Option<u64> {
    sysctl("/proc/sys/kernel/threads-max")
}

/// This process's effective uid (the owner of `/proc/self`; 0 if unknown).
#[must_use]
pub fn effective_uid() -> u32 {
    std::fs::metadata("/proc/self").map_or(0, |m| m.uid())
}

/// File descriptors this process has open now.
#[must_use]
pub fn open_files() -> u64 {
    std::fs::read_dir("/proc/self/fd").map_or(0, |d| d.count() as u64)
}

/// Threads of the processes whose real uid is `uid`.
#[must_use]
pub fn user_threads(uid: u32) -> u64 {
    let threads = |pid: u32| {
        let s = crate::status::of(pid).ok()?;
        let real_uid = crate::status::number(&s, "Uid")?;
        (real_uid == u64::from(uid)).then(|| crate::status::number(&s, "Threads"))?
    };
    crate::process::pids().into_iter().filter_map(threads).sum()
}

/// Free space of the file system holding `path`, bytes.
#[must_use]
pub fn free_space(path: &Path) -> Option<u64> {
    let s = nix::sys::statvfs::statvfs(path).ok()?;
    Some(s.blocks_available() as u64 * s.fragment_size() as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIMITS: &str = "Limit                     Soft Limit           Hard Limit           Units     \n\
        Max processes             96364                96364                processes \n\
        Max open files            1024                 1048576              files     \n\
        Max locked memory         unlimited            unlimited            bytes     \n";

    #[test]
    fn soft_limits_are_read_and_unlimited_is_none() {
        assert_eq!(soft_limit_in(LIMITS, "Max processes"), Some(96_364));
        assert_eq!(soft_limit_in(LIMITS, "Max open files"), Some(1024));
        assert_eq!(soft_limit_in(LIMITS, "Max locked memory"), None);
        assert_eq!(soft_limit_in(LIMITS, "Max nothing"), None);
    }

    #[test]
    fn this_process_and_machine_are_read() {
        assert!(soft_limit("Max open files").is_some());
        assert!(pid_max().is_some() && threads_max().is_some());
        assert!(open_files() >= 3);
        assert!(user_threads(effective_uid()) >= 1 || effective_uid() == 0);
        assert!(free_space(&std::env::temp_dir()).is_some());
    }
}
