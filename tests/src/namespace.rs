//! Run namespaces of the processes engine (`<tmp>/attsync-iox2/<run>/` with
//! an `owner` file holding the orchestrator's pid, shared memory
//! `/dev/shm/as<run>_*`), the node processes of a run, and signals.

use attsync_sched::process::{self, cmdline};
use std::collections::BTreeSet;
use std::ffi::OsStr;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// Where shared-memory segments live.
pub(crate) const SHM_DIR: &str = "/dev/shm";

/// Parent of every run's iceoryx2 root directory, as the orchestrator
/// chooses it (`attsync::launch::namespace::base_dir`): `$TMPDIR/attsync-iox2`
/// where `TMPDIR` is set (as the child sees it), else `/dev/shm/attsync-iox2`
/// if that exists, else `/tmp/attsync-iox2`. (A `TMPDIR` too long for socket
/// paths is the business of the test that sets it.)
#[must_use]
pub fn iox_base() -> PathBuf {
    if let Some(tmp) = std::env::var_os("TMPDIR").filter(|t| !t.is_empty()) {
        return PathBuf::from(tmp).join("attsync-iox2");
    }
    let shm = Path::new(SHM_DIR).join("attsync-iox2");
    if shm.is_dir() {
        shm
    } else {
        PathBuf::from("/tmp/attsync-iox2")
    }
}

/// Every run directory under [`iox_base`] and every `as*` file in /dev/shm.
pub(crate) fn namespace_entries() -> BTreeSet<PathBuf> {
    let list = |dir: &Path, keep: &dyn Fn(&str) -> bool| -> Vec<PathBuf> {
        fs::read_dir(dir)
            .map(|rd| {
                rd.filter_map(Result::ok)
                    .filter(|e| keep(&e.file_name().to_string_lossy()))
                    .map(|e| e.path())
                    .collect()
            })
            .unwrap_or_default()
    };
    let mut out: BTreeSet<PathBuf> = list(&iox_base(), &|_| true).into_iter().collect();
    out.extend(list(Path::new(SHM_DIR), &|n| n.starts_with("as")));
    out
}

/// The runs whose `owner` file holds `pid` (hidden `.<run>.creating`
/// directories are namespaces still being set up and are not counted).
#[must_use]
pub fn owned_runs(pid: u32) -> Vec<String> {
    let Ok(rd) = fs::read_dir(iox_base()) else {
        return Vec::new();
    };
    rd.filter_map(Result::ok)
        .filter(|e| !e.file_name().to_string_lossy().starts_with('.'))
        .filter(|e| {
            fs::read_to_string(e.path().join("owner"))
                .is_ok_and(|owner| owner.trim() == pid.to_string())
        })
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect()
}

/// The run whose `owner` file holds `pid` (see [`owned_runs`]), waited
/// for at most 30 s (the orchestrator creates it as it starts); panics if
/// none appears.
#[must_use]
pub fn owned_run(pid: u32) -> String {
    let poll = std::time::Duration::from_millis(20);
    crate::wait_until(std::time::Duration::from_secs(30), poll, || {
        owned_runs(pid).into_iter().next()
    })
    .unwrap_or_else(|| {
        panic!(
            "no {}/*/owner holds attsync's pid {pid}",
            iox_base().display()
        )
    })
}

/// What is left of run `run`: its root directory and its shared memory.
#[must_use]
pub fn run_leftovers(run: &str) -> Vec<PathBuf> {
    let prefix = format!("as{run}_");
    let mut out: Vec<PathBuf> = fs::read_dir(SHM_DIR)
        .map(|rd| {
            rd.filter_map(Result::ok)
                .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
                .map(|e| e.path())
                .collect()
        })
        .unwrap_or_default();
    let dir = iox_base().join(run);
    if dir.exists() {
        out.push(dir);
    }
    out
}

/// Live processes (pid, command line) with an argument inside run `run`'s
/// root directory: the node processes, started with `--config <root>/node-<id>.json`.
#[must_use]
pub fn run_processes(run: &str) -> Vec<(u32, Vec<String>)> {
    let needle = format!("{}/", iox_base().join(run).display());
    (process::pids().into_iter())
        .filter_map(|pid| {
            let args = cmdline(pid);
            args.iter()
                .any(|a| a.contains(&needle))
                .then_some((pid, args))
        })
        .collect()
}

/// The pid of node `id` of run `run` (`attsync-agent`, or `attsync-leader`
/// for 0, with `--config <root>/node-<id>.json`).
#[must_use]
pub fn node_pid(run: &str, id: u32) -> Option<u32> {
    let program = if id == 0 {
        "attsync-leader"
    } else {
        "attsync-agent"
    };
    let config = iox_base()
        .join(run)
        .join(format!("node-{id}.json"))
        .display()
        .to_string();
    run_processes(run).into_iter().find_map(|(pid, args)| {
        let is_program = args
            .first()
            .is_some_and(|a| Path::new(a).file_name() == Some(OsStr::new(program)));
        let has_config = args
            .windows(2)
            .any(|w| w[0] == "--config" && w[1] == config);
        (is_program && has_config).then_some(pid)
    })
}

/// Live processes started by orchestrator (or host daemon) `parent`, whether
/// it is alive or not: those whose environment holds `ATTSYNC_PARENT_PID=<parent>`
/// (every node, plug-ins included, and whatever they started), or with an
/// argument in a run directory named after `parent`'s pid
/// (`<base>/<pid in hex>r…`), found from `/proc` whatever their parent is now.
#[must_use]
pub fn started_by(parent: u32) -> Vec<u32> {
    let var = format!("{}={parent}", msgs::parent::PARENT_PID_VAR);
    let dir = format!("{}/{parent:x}r", iox_base().display());
    (process::pids().into_iter())
        .filter(|&pid| {
            // (A zombie's environment and command line read empty.)
            let by_env = process::environ(pid).iter().any(|kv| kv == var.as_bytes());
            by_env || cmdline(pid).iter().any(|a| a.starts_with(&dir))
        })
        .collect()
}

/// Sends signal `sig` (`KILL`, `STOP`, `CONT`, …) to `pid` with `kill`;
/// whether `kill` succeeded.
pub fn signal(pid: u32, sig: &str) -> bool {
    Command::new("kill")
        .args([format!("-{sig}"), pid.to_string()])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

/// `kill -9 pid`; whether `kill` succeeded.
pub fn kill9(pid: u32) -> bool {
    signal(pid, "9")
}
