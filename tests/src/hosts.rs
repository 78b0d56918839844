//! Separate "hosts" on one machine, for the multi-host tests (issue 12).
//!
//! A [`HostSandbox`] is a mount namespace of its own (`unshare --mount
//! --propagation private`, as root) with a private tmpfs on `/dev/shm` and a
//! `TMPDIR` of its own (a fresh directory), so that nothing passes between
//! hosts through shared memory: what one host's processes create in
//! `/dev/shm` (iceoryx2's segments) no other host sees, and each host's
//! iceoryx2 namespace root (`$TMPDIR/attsync-iox2`) is apart. A holder
//! process keeps the namespace alive for the sandbox's lifetime, so that
//! commands can be started in it one after the other ([`HostSandbox::spawn`]:
//! a daemon, then the same daemon restarted) and its `/dev/shm` can still be
//! listed after they died ([`HostSandbox::shm_entries`]: the "nothing left"
//! check). Dropping the sandbox kills every process in its namespace.
//! Networking is the machine's (use 127.0.0.1 and [`free_port`]), or, for
//! [`HostSandbox::networked`], a network namespace of the host's own with
//! a veth pair to ours ([`Veth`]: its addresses, a real delay with netem).

use crate::netns::Veth;
use crate::{Sandbox, wait_until};
use attsync_sched::process::{self, mount_namespace};
use std::collections::BTreeSet;
use std::fs::{self, File};
use std::io::{BufRead, BufReader};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::Duration;

/// Longest wait for the namespace to be set up, and for killed processes
/// to be gone.
const SETUP_TIMEOUT: Duration = Duration::from_secs(10);

/// How often a bounded wait polls.
const POLL: Duration = Duration::from_millis(10);

/// What the holder prints once `/dev/shm` is its own.
const READY: &str = "attsync-host-sandbox-ready";

/// One simulated host: a mount namespace with its own `/dev/shm` and
/// `TMPDIR`. Its directory (the `TMPDIR` and the logs of its commands) is a
/// [`Sandbox`]: removed when dropped, kept if the test fails.
#[derive(Debug)]
pub struct HostSandbox {
    name: String,
    holder: Child,
    /// The holder's mount namespace, as `readlink /proc/<pid>/ns/mnt` says.
    namespace: PathBuf,
    dir: Sandbox,
    spawned: usize,
    /// The link to a network namespace of its own, if it has one.
    veth: Option<Veth>,
}

impl HostSandbox {
    /// A new host named `name`. Panics, saying why, if the mount namespace
    /// cannot be made (`unshare --mount` needs root: CI runs as root).
    #[must_use]
    pub fn new(name: &str) -> Self {
        Self::start(name, false)
    }

    /// A new host named `name` with, besides, a network namespace of its
    /// own (`unshare --net`: loopback up, nothing else) joined to ours by
    /// a veth pair ([`Self::veth`]). Its commands see only that network:
    /// they reach the test's processes at [`Veth::root_addr`], and are
    /// reached at [`Veth::host_addr`].
    #[must_use]
    pub fn networked(name: &str) -> Self {
        let mut host = Self::start(name, true);
        host.veth = Some(Veth::connect(host.holder.id()));
        host
    }

    /// The veth pair to its network namespace ([`Self::networked`]).
    #[must_use]
    pub fn veth(&self) -> Option<&Veth> {
        self.veth.as_ref()
    }

    fn start(name: &str, net: bool) -> Self {
        let dir = Sandbox::new(&format!("host-{name}"));
        fs::create_dir(dir.join("tmp")).expect("the host's TMPDIR");
        let (flags, lo) = if net {
            (["--mount", "--net"].as_slice(), "ip link set lo up && ")
        } else {
            (["--mount"].as_slice(), "")
        };
        let mut holder = Command::new("unshare")
            .args(flags)
            .args(["--propagation", "private", "--", "sh", "-c"])
            // A private tmpfs on /dev/shm, then sleep in the namespace.
            .arg(format!(
                "{lo}mount -t tmpfs -o mode=1777 tmpfs /dev/shm && echo {READY} && exec sleep infinity"
            ))
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .process_group(0)
            .spawn()
            .unwrap_or_else(|e| panic!("host sandbox `{name}`: cannot start `unshare`: {e}"));
        if !ready(&mut holder) {
            let _ = holder.kill();
            let out = holder.wait_with_output().expect("the holder ends");
            panic!(
                "host sandbox `{name}`: `unshare --mount` with a private tmpfs on /dev/shm failed \
                 ({}): {}— the multi-host tests need root (CI runs as root), they are not skipped",
                out.status,
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let namespace = mount_namespace(holder.id()).expect("the holder's mount namespace");
        let ours = mount_namespace(std::process::id()).expect("this process's mount namespace");
        assert_ne!(
            namespace, ours,
            "host sandbox `{name}`: the holder shares our mount namespace"
        );
        Self {
            name: name.to_owned(),
            holder,
            namespace,
            dir,
            spawned: 0,
            veth: None,
        }
    }

    /// The host's name.
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The `TMPDIR` of every command started in this host.
    #[must_use]
    pub fn tmpdir(&self) -> PathBuf {
        self.root().join("tmp")
    }

    fn root(&self) -> &Path {
        self.dir.path()
    }

    /// Starts `cmd` (its program, arguments, environment changes and
    /// working directory; the current one if it sets none) in this host,
    /// with `TMPDIR` set to [`Self::tmpdir`], in a process group of its
    /// own, stdin closed, stdout and stderr into files of the sandbox
    /// ([`HostProcess::stdout`], [`HostProcess::stderr`]).
    pub fn spawn(&mut self, cmd: &Command) -> HostProcess {
        self.spawned += 1;
        let k = self.spawned;
        let log = |stream: &str| self.root().join(format!("{k}.{stream}"));
        let (out, err) = (log("stdout"), log("stderr"));
        let wd = match cmd.get_current_dir() {
            Some(d) => d.to_owned(),
            None => std::env::current_dir().expect("a working directory"),
        };
        let mut nsenter = Command::new("nsenter");
        nsenter
            .arg("--no-fork")
            .arg(format!("--target={}", self.holder.id()))
            .arg("--mount")
            .args(self.veth.as_ref().map(|_| "--net"))
            .arg(format!("--wd={}", wd.display()))
            .arg("--")
            .arg(cmd.get_program())
            .args(cmd.get_args())
            .env("TMPDIR", self.tmpdir());
        for (key, value) in cmd.get_envs() {
            match value {
                Some(v) => nsenter.env(key, v),
                None => nsenter.env_remove(key),
            };
        }
        let child = nsenter
            .stdin(Stdio::null())
            .stdout(File::create(&out).expect("a log file"))
            .stderr(File::create(&err).expect("a log file"))
            .process_group(0)
            .spawn()
            .unwrap_or_else(|e| panic!("host `{}`: cannot start `nsenter`: {e}", self.name));
        HostProcess {
            pid: child.id(),
            child,
            what: format!(
                "{} on host `{}`",
                cmd.get_program().to_string_lossy(),
                self.name
            ),
            stdout: out,
            stderr: err,
        }
    }

    /// The names in this host's `/dev/shm` (what its processes left there).
    #[must_use]
    pub fn shm_entries(&self) -> BTreeSet<String> {
        entries(&process::root(self.holder.id()).join("dev/shm"))
    }

    /// The names in this host's `TMPDIR`.
    #[must_use]
    pub fn tmp_entries(&self) -> BTreeSet<String> {
        entries(&self.tmpdir())
    }

    /// The pids of every live process in this host (the holder left out).
    #[must_use]
    pub fn processes(&self) -> Vec<u32> {
        let holder = self.holder.id();
        (process::pids().into_iter())
            .filter(|&pid| pid != holder)
            .filter(|&pid| mount_namespace(pid).as_ref() == Some(&self.namespace))
            .collect()
    }

    /// Kills every process in this host (the holder stays), until none is
    /// left; whether none is.
    pub fn kill_all(&self) -> bool {
        wait_until(SETUP_TIMEOUT, POLL, || {
            let pids = self.processes();
            if pids.is_empty() {
                return Some(());
            }
            kill(&pids.iter().map(u32::to_string).collect::<Vec<_>>());
            None
        })
        .is_some()
    }
}

impl Drop for HostSandbox {
    fn drop(&mut self) {
        if !self.kill_all() {
            eprintln!("host sandbox `{}`: processes survived SIGKILL", self.name);
        }
        kill(&[format!("-{}", self.holder.id())]);
        let _ = self.holder.wait();
        // After the holder: the veth pair goes with its namespace anyway.
        self.veth.take();
    }
}

/// A command started in a [`HostSandbox`]. Dropping it kills its process
/// group (its children in other groups are killed with the sandbox).
#[derive(Debug)]
pub struct HostProcess {
    child: Child,
    pid: u32,
    what: String,
    stdout: PathBuf,
    stderr: PathBuf,
}

impl HostProcess {
    /// Its pid (and process group id).
    #[must_use]
    pub fn pid(&self) -> u32 {
        self.pid
    }

    /// Its exit status, if it has ended.
    pub fn try_wait(&mut self) -> Option<ExitStatus> {
        self.child.try_wait().expect("waitpid")
    }

    /// Its exit status once it ends, waiting at most `timeout`.
    pub fn wait_timeout(&mut self, timeout: Duration) -> Option<ExitStatus> {
        wait_until(timeout, POLL, || self.try_wait())
    }

    /// Kills its process group (SIGKILL) and reaps it.
    pub fn kill(&mut self) -> ExitStatus {
        kill(&[format!("-{}", self.pid)]);
        self.child.wait().expect("waitpid")
    }

    /// Its standard output so far.
    #[must_use]
    pub fn stdout(&self) -> String {
        fs::read_to_string(&self.stdout).unwrap_or_default()
    }

    /// Its standard error so far.
    #[must_use]
    pub fn stderr(&self) -> String {
        fs::read_to_string(&self.stderr).unwrap_or_default()
    }

    /// What it is, for messages: the program and the host.
    #[must_use]
    pub fn what(&self) -> &str {
        &self.what
    }
}

impl Drop for HostProcess {
    fn drop(&mut self) {
        if self.try_wait().is_none() {
            self.kill();
        }
    }
}

/// A TCP port on 127.0.0.1 that was free a moment ago (bound to port 0 and
/// closed; another program may take it before it is used again).
#[must_use]
pub fn free_port() -> u16 {
    let listener = std::net::TcpListener::bind(("127.0.0.1", 0)).expect("a free port");
    listener.local_addr().expect("a bound address").port()
}

/// A UDP port on 127.0.0.1 that was free a moment ago (QUIC endpoints).
#[must_use]
pub fn free_udp_port() -> u16 {
    let socket = std::net::UdpSocket::bind(("127.0.0.1", 0)).expect("a free port");
    socket.local_addr().expect("a bound address").port()
}

/// Whether the holder said it is ready (within [`SETUP_TIMEOUT`]).
fn ready(holder: &mut Child) -> bool {
    let stdout = holder.stdout.take().expect("piped");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let mut line = String::new();
        let _ = BufReader::new(stdout).read_line(&mut line);
        let _ = tx.send(line);
    });
    rx.recv_timeout(SETUP_TIMEOUT)
        .is_ok_and(|line| line.trim() == READY)
}

/// `kill -KILL -- targets…` (pids, or `-pgid` for a group), its failures
/// (already gone) ignored.
fn kill(targets: &[String]) {
    let _ = Command::new("kill")
        .arg("-KILL")
        .arg("--")
        .args(targets)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status();
}

/// The names in `dir` (none if it cannot be read).
fn entries(dir: &Path) -> BTreeSet<String> {
    fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default()
}
