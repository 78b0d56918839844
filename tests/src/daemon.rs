//! `attsync host` daemons for the tests across hosts ([`Daemon`]): each in
//! a [`HostSandbox`] of its own (private `/dev/shm`, own `TMPDIR`), so
//! nothing can pass between hosts through shared memory; Zenoh over
//! 127.0.0.1 only, on a free port; mutual TLS over QUIC with the test CA
//! ([`crate::certs`]) unless the endpoint is `tcp/` (then `--insecure`).
//! Killed when dropped.

use crate::certs::{self, Identity};
use crate::command::{Attsync, run_args};
use crate::hosts::{HostProcess, HostSandbox, free_udp_port};
use crate::workspace::bin;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus};
use std::time::Duration;

/// A host sandbox and its `attsync host` daemon.
#[derive(Debug)]
pub struct Daemon {
    /// Its sandbox.
    pub host: HostSandbox,
    /// Its endpoint, `tcp/127.0.0.1:<port>`: where the others dial it.
    pub endpoint: String,
    /// Where it listens (its endpoint, unless a relay is in between).
    listen: String,
    connect: Vec<String>,
    /// Its identity (mutual TLS), `None` when insecure (`tcp/`).
    identity: Option<Identity>,
    /// Extra flags (`--allow-plugin PATH`…).
    extra: Vec<String>,
    process: Option<HostProcess>,
}

impl Daemon {
    /// Starts host `name` on a free port (mutual TLS over QUIC), dialling
    /// the hosts `connect`.
    #[must_use]
    pub fn start(name: &str, connect: &[&Daemon]) -> Self {
        Self::start_with(name, connect, &[])
    }

    /// As [`Daemon::start`], with `extra` flags (`--allow-plugin PATH`…).
    #[must_use]
    pub fn start_with(name: &str, connect: &[&Daemon], extra: &[String]) -> Self {
        let endpoint = format!("quic/127.0.0.1:{}", free_udp_port());
        let mut d = Self::new(HostSandbox::new(name), &endpoint, endpoint.clone(), connect);
        d.extra = extra.to_vec();
        d.restart();
        d
    }

    /// Starts a daemon in `host`, listening on `listen`, dialled by the
    /// others at `endpoint` (the same, or a relay's), dialling `connect`.
    #[must_use]
    pub fn start_on(
        host: HostSandbox,
        listen: &str,
        endpoint: String,
        connect: &[&Daemon],
    ) -> Self {
        let mut d = Self::new(host, listen, endpoint, connect);
        d.restart();
        d
    }

    /// Not started yet: its identity, if its endpoint is not `tcp/`,
    /// names the addresses it listens and is dialled at.
    fn new(host: HostSandbox, listen: &str, endpoint: String, connect: &[&Daemon]) -> Self {
        let identity = (!listen.starts_with("tcp/")).then(|| {
            let addresses = [certs::address_of(listen), certs::address_of(&endpoint)];
            certs::host(host.name(), &addresses)
        });
        Self {
            host,
            endpoint,
            listen: listen.to_string(),
            connect: connect.iter().map(|c| c.endpoint.clone()).collect(),
            identity,
            extra: Vec::new(),
            process: None,
        }
    }

    /// What it printed on its stdout so far (empty before it started).
    #[must_use]
    pub fn stdout(&self) -> String {
        self.process
            .as_ref()
            .map(HostProcess::stdout)
            .unwrap_or_default()
    }

    /// Whether it runs without authentication (`--insecure`, `tcp/`).
    #[must_use]
    pub fn insecure(&self) -> bool {
        self.identity.is_none()
    }

    /// Its name.
    #[must_use]
    pub fn name(&self) -> &str {
        self.host.name()
    }

    /// Starts the daemon (again): same name, endpoint and peers.
    pub fn restart(&mut self) {
        let mut cmd = Command::new(bin("attsync"));
        cmd.args(["host", "--name", self.host.name(), "--listen", &self.listen]);
        for c in &self.connect {
            cmd.args(["--connect", c]);
        }
        match &self.identity {
            Some(id) => cmd.args(id.flags()),
            None => cmd.arg("--insecure"),
        };
        cmd.args(&self.extra);
        cmd.env("ATTSYNC_LOG", "info").env_remove("ATTSYNC_BIN_DIR");
        self.process = Some(self.host.spawn(&cmd));
    }

    /// Its process id.
    #[must_use]
    pub fn pid(&self) -> u32 {
        self.process.as_ref().expect("running").pid()
    }

    /// Kills it (SIGKILL) and the nodes it started.
    pub fn kill(&mut self) {
        if let Some(mut p) = self.process.take() {
            p.kill();
        }
        self.host.kill_all();
    }

    /// SIGTERM; its exit status (at most 20 s).
    pub fn terminate(&mut self) -> Option<ExitStatus> {
        let mut p = self.process.take()?;
        crate::namespace::signal(p.pid(), "TERM");
        p.wait_timeout(Duration::from_secs(20))
    }

    /// What the host still holds of runs: files in its `/dev/shm`, its
    /// namespace directories, and processes other than the daemon.
    #[must_use]
    pub fn leftovers(&self) -> Vec<String> {
        let mut out: Vec<String> = (self.host.shm_entries().into_iter())
            .map(|f| format!("/dev/shm/{f}"))
            .collect();
        let iox = self.host.tmpdir().join("attsync-iox2");
        if let Ok(rd) = std::fs::read_dir(&iox) {
            out.extend(
                rd.filter_map(Result::ok)
                    .map(|e| e.path().display().to_string()),
            );
        }
        let daemon = self.process.as_ref().map(HostProcess::pid);
        out.extend(
            (self.host.processes().into_iter())
                .filter(|&p| Some(p) != daemon)
                .map(|p| format!("process {p}")),
        );
        out
    }

    /// Its log (stderr).
    #[must_use]
    pub fn log(&self) -> String {
        self.process
            .as_ref()
            .map(HostProcess::stderr)
            .unwrap_or_default()
    }
}

/// Writes `dir/name`, a HOSTS.toml placing on each `(daemon, leader,
/// agents)` the leader (if `leader`) and `agents`; with the test user's
/// `[tls]` table, or `insecure = true` if the daemons are.
#[must_use]
pub fn hosts_file(dir: &Path, name: &str, hosts: &[(&Daemon, bool, &[u32])]) -> PathBuf {
    let insecure = hosts.iter().all(|(d, _, _)| d.insecure());
    assert!(
        insecure || hosts.iter().all(|(d, _, _)| !d.insecure()),
        "a hosts file's daemons are all secure or all insecure"
    );
    let mut text = if insecure {
        "insecure = true\n\n".to_string()
    } else {
        certs::user().table()
    };
    for (d, leader, agents) in hosts {
        text.push_str(&format!(
            "[[host]]\nname = \"{}\"\nendpoint = \"{}\"\nleader = {leader}\nagents = {agents:?}\n\n",
            d.name(),
            d.endpoint
        ));
    }
    let file = dir.join(name);
    std::fs::write(&file, text).expect("HOSTS.toml");
    file
}

/// `attsync run SCENARIO --engine processes --out OUT --quiet --set S…
/// --hosts HOSTS`, in `cwd`.
#[must_use]
pub fn run_on_hosts(
    cwd: &Path,
    scenario: &Path,
    out: &Path,
    sets: &[&str],
    hosts: &Path,
) -> Attsync {
    Attsync::new(cwd)
        .args(run_args(scenario, "processes", out, sets))
        .args(["--hosts".as_ref(), hosts.as_os_str()])
}

/// Runs the paper's time-varying run (1 s simulated) over `hosts` into
/// `tmp/again` and asserts that it completes and that `daemons` keep
/// nothing of it: after a failure, the daemons serve the next run.
#[track_caller]
pub fn assert_serves_again(tmp: &crate::Sandbox, hosts: &Path, daemons: &[&Daemon]) {
    let again = tmp.join("again");
    let scenario = crate::paper("timevarying");
    run_on_hosts(
        tmp.path(),
        &scenario,
        &again,
        &["simulation.duration=1"],
        hosts,
    )
    .output()
    .assert_ok()
    .assert_no_leftovers();
    assert_eq!(crate::summary(&again)["complete"], true);
    assert_hosts_clean(daemons);
}

/// Asserts no daemon of `daemons` kept anything of its runs ([`Daemon::leftovers`]).
#[track_caller]
pub fn assert_hosts_clean(daemons: &[&Daemon]) {
    for d in daemons {
        let left = d.leftovers();
        assert!(
            left.is_empty(),
            "host {} kept {left:?}\n{}",
            d.name(),
            d.log()
        );
    }
}

impl Drop for Daemon {
    fn drop(&mut self) {
        self.kill();
    }
}
