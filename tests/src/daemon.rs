//! `attsync host` daemons for the tests across hosts ([`Daemon`]): each in
//! a mount namespace of its own with a private tmpfs on `/dev/shm` and its
//! own `TMPDIR` (`unshare -m`, as root), so nothing can pass between hosts
//! through shared memory; Zenoh over 127.0.0.1 only, on a free port
//! ([`free_port`]). Killed (SIGKILL) when dropped.

use crate::workspace::{bin, exec_lock};
use std::fs;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};

/// A free TCP port on 127.0.0.1 (bound, then released).
#[must_use]
pub fn free_port() -> u16 {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind 127.0.0.1:0");
    l.local_addr().expect("an address").port()
}

/// A running `attsync host`.
#[derive(Debug)]
pub struct Daemon {
    /// Its name.
    pub name: String,
    /// Its endpoint, `tcp/127.0.0.1:<port>`.
    pub endpoint: String,
    /// Its private `TMPDIR` (the namespace root is `<tmp>/attsync-iox2`).
    pub tmp: PathBuf,
    log: PathBuf,
    child: Option<Child>,
}

impl Daemon {
    /// Starts host `name` with its files under `dir`, dialling `connect`.
    #[must_use]
    pub fn start(dir: &Path, name: &str, connect: &[&Daemon]) -> Self {
        Self::start_on(
            dir,
            name,
            &format!("tcp/127.0.0.1:{}", free_port()),
            connect,
        )
    }

    /// Starts host `name` listening on `endpoint`.
    #[must_use]
    pub fn start_on(dir: &Path, name: &str, endpoint: &str, connect: &[&Daemon]) -> Self {
        let tmp = dir.join(format!("host-{name}"));
        fs::create_dir_all(&tmp).expect("the host's TMPDIR");
        let log = dir.join(format!("host-{name}.log"));
        let mut d = Self {
            name: name.into(),
            endpoint: endpoint.into(),
            tmp,
            log,
            child: None,
        };
        d.spawn(connect.iter().map(|c| c.endpoint.clone()).collect());
        d
    }

    fn spawn(&mut self, connect: Vec<String>) {
        let mut args: Vec<String> = vec![
            "host".into(),
            "--name".into(),
            self.name.clone(),
            "--listen".into(),
            self.endpoint.clone(),
        ];
        for c in connect {
            args.extend(["--connect".into(), c]);
        }
        // A private /dev/shm for this host only: `unshare -m` makes the new
        // mount namespace's mounts private.
        let mut cmd = Command::new("unshare");
        cmd.args([
            "-m",
            "sh",
            "-c",
            "mount -t tmpfs tmpfs /dev/shm && exec \"$0\" \"$@\"",
        ])
        .arg(bin("attsync"))
        .args(&args)
        .env("TMPDIR", &self.tmp)
        .env("ATTSYNC_LOG", "info")
        .env_remove("ATTSYNC_BIN_DIR")
        .stdin(Stdio::null())
        .stdout(fs::File::create(&self.log).expect("log"))
        .stderr(fs::File::create(self.log.with_extension("err")).expect("log"));
        let _g = exec_lock();
        self.child = Some(cmd.spawn().expect("unshare -m attsync host (run as root)"));
    }

    /// Its process id (the daemon itself: `unshare` and `sh` exec it).
    #[must_use]
    pub fn pid(&self) -> u32 {
        self.child.as_ref().expect("running").id()
    }

    /// Kills it with SIGKILL and reaps it.
    pub fn kill(&mut self) {
        if let Some(mut c) = self.child.take() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }

    /// Sends SIGTERM and waits for its exit status (at most 20 s).
    pub fn terminate(&mut self) -> Option<std::process::ExitStatus> {
        let mut c = self.child.take()?;
        crate::namespace::signal(c.id(), "TERM");
        let end = std::time::Instant::now() + std::time::Duration::from_secs(20);
        while std::time::Instant::now() < end {
            if let Ok(Some(s)) = c.try_wait() {
                return Some(s);
            }
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
        let _ = c.kill();
        c.wait().ok()
    }

    /// Starts it again after [`Self::kill`], same name and endpoint.
    pub fn restart(&mut self, connect: &[&Daemon]) {
        self.spawn(connect.iter().map(|c| c.endpoint.clone()).collect());
    }

    /// What the host still holds of runs: its namespace directories, the
    /// files in its private `/dev/shm` (read through its mount namespace),
    /// and node processes it started.
    #[must_use]
    pub fn leftovers(&self) -> Vec<String> {
        let mut out: Vec<String> = fs::read_dir(self.tmp.join("attsync-iox2"))
            .map(|rd| {
                rd.filter_map(Result::ok)
                    .map(|e| e.path().display().to_string())
                    .collect()
            })
            .unwrap_or_default();
        if let Some(c) = &self.child {
            let shm = Command::new("nsenter")
                .args(["-t", &c.id().to_string(), "-m", "ls", "-A", "/dev/shm"])
                .output()
                .expect("nsenter");
            let text = String::from_utf8_lossy(&shm.stdout).into_owned();
            out.extend(
                text.lines()
                    .map(|l| format!("/dev/shm/{l} (host {})", self.name)),
            );
            out.extend(
                children(c.id())
                    .into_iter()
                    .map(|p| format!("process {p} (host {})", self.name)),
            );
        }
        out
    }

    /// Its log (stderr).
    #[must_use]
    pub fn log(&self) -> String {
        fs::read_to_string(self.log.with_extension("err")).unwrap_or_default()
    }
}

/// Child processes of `pid`.
fn children(pid: u32) -> Vec<u32> {
    fs::read_to_string(format!("/proc/{pid}/task/{pid}/children"))
        .unwrap_or_default()
        .split_whitespace()
        .filter_map(|p| p.parse().ok())
        .collect()
}

impl Drop for Daemon {
    fn drop(&mut self) {
        self.kill();
    }
}
