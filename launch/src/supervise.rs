//! Process supervision with tokio: start the node processes (each in its own
//! process group, output piped into its capped log file, [`super::node_log`]),
//! report every exit as soon as it happens, kill them all on demand. The
//! engine polls it ([`Supervisor::try_exit`]); `conform` waits on it
//! ([`Supervisor::next_exit`]) and keeps a candidate's process group after it
//! exits, to check it is empty ([`Supervisor::keep_groups`], [`group_members`]).
//!
//! Every node dies with the process that starts it, at any moment of that
//! process's life: it gets `SIGKILL` from the kernel when its parent dies
//! (`PR_SET_PDEATHSIG`, set before `exec`, [`attsync_sched::pdeath`]), and
//! learns its parent's pid from [`msgs::parent::PARENT_PID_VAR`].
//!
//! CAUTION: the kernel sends that signal when the *thread* that forked
//! exits. [`Supervisor::spawn`] forks on its caller's thread, so a
//! supervisor must be used (and dropped) on one thread that lives until its
//! nodes have ended: `processes::run` (on the main thread, or a sweep's or
//! Monte Carlo's scoped worker, which returns only after the run's
//! shutdown), `conform`'s candidate runs, and the host daemon's per-run
//! thread (`remote/host_run.rs`) all do.

use super::node_log;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{ExitStatus, Stdio};
use std::sync::mpsc;
use std::time::{Duration, Instant};
use tokio::sync::watch;

/// One node process that ended.
#[derive(Debug)]
pub struct Exit {
    /// Index of the node (0 = leader, then agents in network order).
    pub index: usize,
    /// How it ended (or why it could not start).
    pub status: Result<ExitStatus, std::io::Error>,
    /// Its process group (the id of the process), if it started.
    pub pgid: Option<u32>,
}

/// Describes an exit status: `exit code 1`, `killed by signal 9 (SIGKILL)`.
#[must_use]
pub fn describe(status: &Result<ExitStatus, std::io::Error>) -> String {
    match status {
        Err(e) => format!("could not start: {e}"),
        Ok(s) => match (s.code(), s.signal()) {
            (Some(c), _) => format!("exit code {c}"),
            (None, Some(sig)) => format!("killed by signal {sig}{}", signal_name(sig)),
            _ => format!("{s}"),
        },
    }
}

fn signal_name(sig: i32) -> &'static str {
    match sig {
        1 => " (SIGHUP)",
        2 => " (SIGINT)",
        6 => " (SIGABRT)",
        9 => " (SIGKILL)",
        11 => " (SIGSEGV)",
        15 => " (SIGTERM)",
        _ => "",
    }
}

/// The running node processes.
#[derive(Debug)]
pub struct Supervisor {
    rt: tokio::runtime::Runtime,
    kill: watch::Sender<bool>,
    exits_tx: mpsc::Sender<Exit>,
    exits: mpsc::Receiver<Exit>,
    started: usize,
    ended: usize,
    /// Leave a node's process group alone when the node exits.
    keep_groups: bool,
    /// Process ids of the nodes started.
    pids: Vec<u32>,
    /// The node index of each of `pids`.
    indices: Vec<usize>,
    /// Exits read while waiting for another one ([`Self::kill_node`]).
    early: std::collections::VecDeque<Exit>,
}

impl Supervisor {
    /// A supervisor with its own small tokio runtime.
    pub fn new() -> std::io::Result<Self> {
        let rt = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .enable_all()
            .build()?;
        let (kill, _) = watch::channel(false);
        let (exits_tx, exits) = mpsc::channel();
        Ok(Self {
            rt,
            kill,
            exits_tx,
            exits,
            started: 0,
            ended: 0,
            keep_groups: false,
            pids: Vec::new(),
            indices: Vec::new(),
            early: std::collections::VecDeque::new(),
        })
    }

    /// Process ids of the nodes started so far.
    #[must_use]
    pub fn pids(&self) -> &[u32] {
        &self.pids
    }

    /// The node index of each of [`Self::pids`].
    #[must_use]
    pub fn indices(&self) -> &[usize] {
        &self.indices
    }

    /// Leaves the process group of a node that exits by itself alone (by
    /// default whatever it started is killed with it); [`Self::kill_all`]
    /// still kills the groups.
    #[must_use]
    pub fn keep_groups(mut self) -> Self {
        self.keep_groups = true;
        self
    }

    /// Starts `program args…` as node `index` (with `env` added to the
    /// environment, and [`msgs::parent::PARENT_PID_VAR`]; in `cwd` if
    /// given), to die with the calling thread (see the module's caution),
    /// stdout and stderr piped into `log`
    /// (cut at [`super::node_log::LOG_CAP`]). Returns its process id, or
    /// `None` if it could not start (its [`Exit`] says why).
    pub fn spawn(
        &mut self,
        index: usize,
        program: &Path,
        args: &[String],
        env: &[(String, String)],
        cwd: Option<&Path>,
        log: &Path,
    ) -> std::io::Result<Option<u32>> {
        let log_path = log.to_owned();
        let log = std::fs::File::create(log)?;
        let mut cmd = tokio::process::Command::new(program);
        if let Some(dir) = cwd {
            cmd.current_dir(dir);
        }
        cmd.args(args)
            .envs(env.iter().map(|(k, v)| (k, v)))
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .env(msgs::parent::PARENT_PID_VAR, std::process::id().to_string())
            .process_group(0)
            .kill_on_drop(true);
        attsync_sched::pdeath::die_with_parent(cmd.as_std_mut());
        let tx = self.exits_tx.clone();
        let mut kill = self.kill.subscribe();
        self.started += 1;
        let _guard = self.rt.enter();
        let spawned = cmd.spawn();
        let pid = spawned.as_ref().ok().and_then(tokio::process::Child::id);
        self.pids.extend(pid);
        self.indices.extend(pid.map(|_| index));
        let keep_groups = self.keep_groups;
        self.rt.spawn(async move {
            let (mut child, copy) = match spawned {
                Ok(mut c) => {
                    let (out, err) = (c.stdout.take(), c.stderr.take());
                    let copy = node_log::copy_capped(out, err, log, log_path, node_log::LOG_CAP);
                    (c, tokio::spawn(copy))
                }
                Err(e) => {
                    let _ = tx.send(Exit {
                        index,
                        status: Err(e),
                        pgid: None,
                    });
                    return;
                }
            };
            let pgid = child.id();
            let mut killed = false;
            let status = tokio::select! {
                s = child.wait() => s,
                _ = async { let _ = kill.wait_for(|k| *k).await.map(|_| ()); } => {
                    killed = true;
                    let _ = child.start_kill();
                    kill_group(pgid);
                    child.wait().await
                }
            };
            // Whatever the node started (a plug-in's own children) ends with it.
            if killed || !keep_groups {
                kill_group(pgid);
            }
            // The log is complete once the pipes close (unless something that
            // left the group still holds them).
            let _ = tokio::time::timeout(Duration::from_secs(2), copy).await;
            let _ = tx.send(Exit {
                index,
                status,
                pgid,
            });
        });
        Ok(pid)
    }

    /// Starts node `index` as `launch` says, with its configuration file
    /// `config` (`--config FILE` appended, `ATTSYNC_CONFIG` set), output
    /// into `log`: the rules of every run, local or on a host.
    pub fn spawn_node(
        &mut self,
        index: usize,
        launch: &Launch<'_>,
        config: &Path,
        log: &Path,
    ) -> std::io::Result<Option<u32>> {
        let file = config.to_string_lossy().into_owned();
        let mut env = vec![("ATTSYNC_CONFIG".to_string(), file.clone())];
        let config_arg = ["--config".to_string(), file];
        match launch {
            Launch::Plugin {
                command,
                env: extra,
                dir,
            } => {
                env.extend(extra.iter().map(|(k, v)| (k.clone(), v.clone())));
                let args: Vec<String> = command[1..].iter().cloned().chain(config_arg).collect();
                self.spawn(index, Path::new(&command[0]), &args, &env, Some(dir), log)
            }
            Launch::Builtin(bin) => self.spawn(index, bin, &config_arg, &env, None, log),
        }
    }

    /// An exit that happened since the last call, if any.
    pub fn try_exit(&mut self) -> Option<Exit> {
        if let Some(e) = self.early.pop_front() {
            return Some(e);
        }
        let e = self.exits.try_recv().ok()?;
        self.ended += 1;
        Some(e)
    }

    /// The next exit, waiting up to `timeout` for one.
    pub fn next_exit(&mut self, timeout: Duration) -> Option<Exit> {
        if let Some(e) = self.early.pop_front() {
            return Some(e);
        }
        let e = self.exits.recv_timeout(timeout).ok()?;
        self.ended += 1;
        Some(e)
    }

    /// Whether every started process has ended.
    #[must_use]
    pub fn all_ended(&self) -> bool {
        self.ended == self.started
    }

    /// Kills node `index`'s latest process (SIGKILL to its group) and waits
    /// up to `timeout` for it to end: its pid, once it has (`None`: no such
    /// process, or it outlived `timeout`). Other exits meanwhile are kept
    /// for [`Self::try_exit`] and [`Self::next_exit`].
    pub fn kill_node(&mut self, index: usize, timeout: Duration) -> Option<u32> {
        let k = self.indices.iter().rposition(|&i| i == index)?;
        let pid = self.pids[k];
        kill_group(Some(pid));
        let deadline = Instant::now() + timeout;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let e = self.exits.recv_timeout(left).ok()?;
            self.ended += 1;
            if e.index == index && e.pgid == Some(pid) {
                return Some(pid);
            }
            self.early.push_back(e);
        }
    }

    /// Kills every process still running (SIGKILL).
    pub fn kill_all(&self) {
        let _ = self.kill.send(true);
    }

    /// Waits up to `timeout` for every process to end, returning the exits;
    /// kills the rest after that and waits for them too.
    pub fn wait_all(&mut self, timeout: Duration) -> Vec<Exit> {
        let mut out: Vec<Exit> = self.early.drain(..).collect();
        let deadline = Instant::now() + timeout;
        while !self.all_ended() {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                self.kill_all();
                if let Ok(e) = self.exits.recv_timeout(Duration::from_secs(5)) {
                    self.ended += 1;
                    out.push(e);
                    continue;
                }
                break;
            }
            if let Ok(e) = self.exits.recv_timeout(left.min(Duration::from_millis(50))) {
                self.ended += 1;
                out.push(e);
            }
        }
        out
    }
}

impl Drop for Supervisor {
    fn drop(&mut self) {
        if !self.all_ended() {
            self.kill_all();
            let _ = self.wait_all(Duration::from_secs(5));
        }
    }
}

/// What runs a node: a plug-in's command in its directory, or a built-in binary.
#[derive(Debug, Clone, Copy)]
pub enum Launch<'a> {
    /// `command[0] command[1..]… --config FILE`, in `dir`, with `env` added.
    Plugin {
        /// Program and arguments.
        command: &'a [String],
        /// Extra environment variables.
        env: &'a std::collections::BTreeMap<String, String>,
        /// Working directory.
        dir: &'a Path,
    },
    /// `attsync-agent` or `attsync-leader`.
    Builtin(&'a Path),
}

/// SIGKILL to the process group led by `pgid` (each node leads its own).
pub fn kill_group(pgid: Option<u32>) {
    if let Some(pid) = pgid.and_then(|p| i32::try_from(p).ok()) {
        let _ = nix::sys::signal::killpg(
            nix::unistd::Pid::from_raw(pid),
            nix::sys::signal::Signal::SIGKILL,
        );
    }
}

pub use super::node_log::tail;
pub use attsync_sched::process::group_members;

/// Paths of the node binaries, found beside the running executable (or in
/// `ATTSYNC_BIN_DIR`).
///
/// # Errors
/// [`MissingBinaries`] when no directory holds both.
pub fn find_binaries() -> Result<(PathBuf, PathBuf), MissingBinaries> {
    let mut dirs = Vec::new();
    if let Some(d) = std::env::var_os("ATTSYNC_BIN_DIR") {
        dirs.push(PathBuf::from(d));
    }
    if let Ok(exe) = std::env::current_exe() {
        if let Some(d) = exe.parent() {
            dirs.push(d.to_owned());
            // Test executables live in target/<profile>/deps/.
            if let Some(p) = d.parent() {
                dirs.push(p.to_owned());
            }
        }
    }
    for d in &dirs {
        let (a, l) = (d.join("attsync-agent"), d.join("attsync-leader"));
        if a.is_file() && l.is_file() {
            return Ok((a, l));
        }
    }
    Err(MissingBinaries { looked_in: dirs })
}

/// The node binaries are not where [`find_binaries`] looks.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "the node binaries attsync-agent and attsync-leader are not beside attsync (looked in {}); build them with `cargo build --release --workspace` (or set ATTSYNC_BIN_DIR)",
    looked_in.iter().map(|d| d.display().to_string()).collect::<Vec<_>>().join(", ")
)]
pub struct MissingBinaries {
    /// The directories looked in.
    pub looked_in: Vec<PathBuf>,
}
