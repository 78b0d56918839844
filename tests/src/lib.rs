//! Helpers shared by attsync's cross-process end-to-end tests (`tests/*.rs`).
//!
//! The tests run the real binaries — `attsync`, `attsync-leader` and
//! `attsync-agent` — as OS processes. They are taken from the cargo target
//! directory the test executable was built into (`target/<profile>/`, the
//! parent of `target/<profile>/deps/<test>-<hash>`), so build them first:
//! `cargo build --release --workspace` (`cargo test --workspace --release`
//! builds them too). A binary older than its sources is not detected.
//!
//! - [`Sandbox`]: a temporary directory per test, kept (and its path printed)
//!   if the test fails.
//! - [`Attsync`]: an `attsync` command line ([`run_args`] builds the usual
//!   `run` arguments); [`Running`]: a started `attsync`, waited for with a
//!   bound ([`Running::wait`]) and killed together with its node processes if
//!   the test gives up on it; [`Finished`]: its exit status, output, the
//!   iceoryx2 runs it owned, and what it left behind ([`Finished::leftovers`]);
//!   [`copy_executable`] to run a copy of a binary.
//! - Run namespaces (`<tmp>/attsync-iox2/<run>/` with an `owner` file holding
//!   the orchestrator's pid, shared memory `/dev/shm/as<run>_*`):
//!   [`iox_base`], [`owned_runs`], [`run_leftovers`], [`run_processes`],
//!   [`node_pid`]; [`signal`], [`kill9`].
//! - Results: [`read`], [`assert_same_file`], [`assert_same_bytes`],
//!   [`csv_agents`], [`csv_rows`], [`summary`], [`assert_same_results`].
//!
//! Every wait is bounded ([`wait_until`], [`RUN_TIMEOUT`]); nothing asserts
//! wall-clock durations.

use serde_json::Value;
use std::collections::BTreeSet;
use std::ffi::{OsStr, OsString};
use std::fs;
use std::io::Read;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Longest a single `attsync` invocation may take before the test fails
/// (generous: the machine may be shared by several test binaries).
pub const RUN_TIMEOUT: Duration = Duration::from_secs(300);

/// Where shared-memory segments live.
const SHM_DIR: &str = "/dev/shm";

/// The directory of the workspace binaries: the parent of the directory
/// holding the test executable (`target/<profile>/deps/`).
#[must_use]
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable has a path");
    exe.parent()
        .and_then(Path::parent)
        .unwrap_or_else(|| panic!("{} is not in target/<profile>/deps/", exe.display()))
        .to_owned()
}

/// The path of workspace binary `name`; panics, saying how to build it, if
/// it is missing.
#[must_use]
pub fn bin(name: &str) -> PathBuf {
    let path = bin_dir().join(name);
    assert!(
        path.is_file(),
        "{} not found: build the workspace binaries first with `cargo build --release --workspace` \
         (into the same target directory and profile as the tests; `cargo test --workspace --release` does it)",
        path.display()
    );
    path
}

/// A scenario file of the repository, e.g. `scenario("paper/timevarying.toml")`.
#[must_use]
pub fn scenario(rel: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(rel);
    path.canonicalize()
        .unwrap_or_else(|e| panic!("scenario {}: {e}", path.display()))
}

/// One of the paper's scenarios: `timevarying`, `constant-observer`,
/// `constant-observerless`.
#[must_use]
pub fn paper(name: &str) -> PathBuf {
    scenario(&format!("paper/{name}.toml"))
}

/// A test's private temporary directory. Removed when dropped, except while
/// panicking: then it is kept for inspection and its path printed.
#[derive(Debug)]
pub struct Sandbox {
    dir: Option<tempfile::TempDir>,
}

impl Sandbox {
    /// A new empty directory named after `test`.
    #[must_use]
    pub fn new(test: &str) -> Self {
        let dir = tempfile::Builder::new()
            .prefix(&format!("attsync-e2e-{test}-"))
            .tempdir()
            .expect("a temporary directory");
        Self { dir: Some(dir) }
    }

    /// The directory.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.dir.as_ref().expect("present until dropped").path()
    }

    /// `path()/rel`.
    #[must_use]
    pub fn join(&self, rel: impl AsRef<Path>) -> PathBuf {
        self.path().join(rel)
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        if std::thread::panicking() {
            if let Some(dir) = self.dir.take() {
                eprintln!(
                    "test failed; its files are kept in {}",
                    dir.keep().display()
                );
            }
        }
    }
}

/// Serialises writing executables with starting processes in this test
/// binary: a process forked while another thread holds a freshly copied
/// executable open for writing inherits that descriptor, and executing the
/// copy then fails with `ETXTBSY` ("Text file busy").
fn exec_lock() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Copies executable `from` to `to` (safe against concurrent
/// [`Attsync::spawn`]s of this test binary, see `ETXTBSY`).
pub fn copy_executable(from: &Path, to: &Path) {
    let _no_fork = exec_lock();
    fs::copy(from, to)
        .unwrap_or_else(|e| panic!("copy {} to {}: {e}", from.display(), to.display()));
}

/// The arguments of `attsync run SCENARIO --engine ENGINE --out OUT --quiet
/// --set S…`.
#[must_use]
pub fn run_args(scenario: &Path, engine: &str, out: &Path, sets: &[&str]) -> Vec<OsString> {
    let mut args: Vec<OsString> = vec![
        "run".into(),
        scenario.into(),
        "--engine".into(),
        engine.into(),
        "--out".into(),
        out.into(),
        "--quiet".into(),
    ];
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    args
}

/// An `attsync` command line, run in a given working directory with a clean
/// attsync environment (`ATTSYNC_BIN_DIR`, `ATTSYNC_LOG` and
/// `ATTSYNC_DEBUG` removed).
#[derive(Debug)]
pub struct Attsync {
    cmd: Command,
    what: String,
}

impl Attsync {
    /// The workspace's `attsync` binary, in `cwd`.
    #[must_use]
    pub fn new(cwd: &Path) -> Self {
        Self::with_program(&bin("attsync"), cwd)
    }

    /// `program` (an `attsync` binary), in `cwd`.
    #[must_use]
    pub fn with_program(program: &Path, cwd: &Path) -> Self {
        let mut cmd = Command::new(program);
        cmd.current_dir(cwd)
            .env_remove("ATTSYNC_BIN_DIR")
            .env_remove("ATTSYNC_LOG")
            .env_remove("ATTSYNC_DEBUG")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        Self {
            cmd,
            what: program.display().to_string(),
        }
    }

    /// Appends arguments.
    #[must_use]
    pub fn args<I, S>(mut self, args: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: AsRef<OsStr>,
    {
        for a in args {
            self.what.push(' ');
            self.what.push_str(&a.as_ref().to_string_lossy());
            self.cmd.arg(a);
        }
        self
    }

    /// Sets an environment variable.
    #[must_use]
    pub fn env(mut self, key: &str, value: &str) -> Self {
        self.what = format!("{key}={value} {}", self.what);
        self.cmd.env(key, value);
        self
    }

    /// Starts it.
    #[must_use]
    pub fn spawn(mut self) -> Running {
        let before = namespace_entries();
        let mut child = {
            let _no_open_executable = exec_lock();
            self.cmd.spawn()
        }
        .unwrap_or_else(|e| panic!("cannot start `{}`: {e}", self.what));
        let pid = child.id();
        let reader = |mut pipe: Box<dyn Read + Send>| {
            std::thread::spawn(move || {
                let mut bytes = Vec::new();
                let _ = pipe.read_to_end(&mut bytes);
                String::from_utf8_lossy(&bytes).into_owned()
            })
        };
        let stdout = reader(Box::new(child.stdout.take().expect("piped")));
        let stderr = reader(Box::new(child.stderr.take().expect("piped")));
        // Record the iceoryx2 runs the process owns while it lives: they are
        // removed when it ends, and their ids appear nowhere else.
        let runs = Arc::new(Mutex::new(BTreeSet::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let watcher = {
            let (runs, stop) = (runs.clone(), stop.clone());
            std::thread::spawn(move || {
                while !stop.load(Ordering::Relaxed) {
                    let found = owned_runs(pid);
                    runs.lock().expect("not poisoned").extend(found);
                    std::thread::sleep(Duration::from_millis(2));
                }
            })
        };
        Running {
            child: Some(child),
            pid,
            what: self.what,
            stdout: Some(stdout),
            stderr: Some(stderr),
            watcher: Some((stop, watcher)),
            runs,
            before,
        }
    }

    /// Runs it to the end (at most [`RUN_TIMEOUT`]).
    #[must_use]
    pub fn output(self) -> Finished {
        self.spawn().wait(RUN_TIMEOUT)
    }
}

/// A started `attsync`. Dropping it before it ended kills it and the node
/// processes of its runs.
#[derive(Debug)]
pub struct Running {
    child: Option<Child>,
    pid: u32,
    what: String,
    stdout: Option<JoinHandle<String>>,
    stderr: Option<JoinHandle<String>>,
    watcher: Option<(Arc<AtomicBool>, JoinHandle<()>)>,
    runs: Arc<Mutex<BTreeSet<String>>>,
    before: BTreeSet<PathBuf>,
}

impl Running {
    /// Its process id.
    #[must_use]
    pub fn pid(&self) -> u32 {
        self.pid
    }

    /// Whether it has ended (without reaping it for good: [`Running::wait`]
    /// still returns its status).
    pub fn has_ended(&mut self) -> bool {
        let child = self.child.as_mut().expect("not yet waited");
        matches!(child.try_wait(), Ok(Some(_)))
    }

    /// Waits until it ends, at most `timeout`; past that, kills it and its
    /// node processes and panics with its output.
    pub fn wait(mut self, timeout: Duration) -> Finished {
        let deadline = Instant::now() + timeout;
        let status = loop {
            let child = self.child.as_mut().expect("not yet waited");
            if let Some(s) = child.try_wait().expect("waitpid") {
                break s;
            }
            if Instant::now() > deadline {
                self.kill_all();
                let (out, err) = self.collect();
                panic!(
                    "`{}` did not end within {timeout:?}; killed it.\n--- stdout\n{out}\n--- stderr\n{err}",
                    self.what
                );
            }
            std::thread::sleep(Duration::from_millis(10));
        };
        self.child = None;
        let (stdout, stderr) = self.collect();
        Finished {
            what: std::mem::take(&mut self.what),
            status,
            stdout,
            stderr,
            pid: self.pid,
            runs: self.runs.lock().expect("not poisoned").clone(),
            before: std::mem::take(&mut self.before),
        }
    }

    /// Stops the watcher and reads the output (the process must have ended).
    fn collect(&mut self) -> (String, String) {
        if let Some((stop, watcher)) = self.watcher.take() {
            stop.store(true, Ordering::Relaxed);
            let _ = watcher.join();
        }
        let join = |h: Option<JoinHandle<String>>| {
            h.map(|h| h.join().unwrap_or_default()).unwrap_or_default()
        };
        (join(self.stdout.take()), join(self.stderr.take()))
    }

    /// Kills the orchestrator (SIGKILL) and every node process of its runs.
    fn kill_all(&mut self) {
        if let Some(child) = self.child.as_mut() {
            let _ = child.kill();
            let _ = child.wait();
        }
        self.child = None;
        let runs = self.runs.lock().expect("not poisoned").clone();
        for run in runs.iter().chain(owned_runs(self.pid).iter()) {
            for (pid, _) in run_processes(run) {
                kill9(pid);
            }
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        if self.child.is_some() {
            self.kill_all();
            let _ = self.collect();
        }
    }
}

/// What an ended `attsync` left.
#[derive(Debug)]
pub struct Finished {
    /// The command line.
    pub what: String,
    /// Its exit status.
    pub status: ExitStatus,
    /// Its standard output.
    pub stdout: String,
    /// Its standard error.
    pub stderr: String,
    /// Its process id.
    pub pid: u32,
    /// The iceoryx2 runs it was seen owning (`<tmp>/attsync-iox2/<run>/owner`
    /// holding its pid). Best effort: a very short run may be missed.
    pub runs: BTreeSet<String>,
    before: BTreeSet<PathBuf>,
}

impl Finished {
    /// Exit code (`None` if killed by a signal).
    #[must_use]
    pub fn code(&self) -> Option<i32> {
        self.status.code()
    }

    /// Command, status and output, for failure messages.
    #[must_use]
    pub fn describe(&self) -> String {
        format!(
            "`{}` ended with {} (pid {})\n--- stdout\n{}\n--- stderr\n{}",
            self.what,
            match (self.status.code(), self.status.signal()) {
                (Some(c), _) => format!("exit code {c}"),
                (None, Some(s)) => format!("signal {s}"),
                _ => format!("{}", self.status),
            },
            self.pid,
            self.stdout,
            self.stderr
        )
    }

    /// Asserts exit code 0.
    #[track_caller]
    pub fn assert_ok(&self) -> &Self {
        self.assert_code(0)
    }

    /// Asserts exit code `code`.
    #[track_caller]
    pub fn assert_code(&self, code: i32) -> &Self {
        assert_eq!(self.code(), Some(code), "{}", self.describe());
        self
    }

    /// iceoryx2 files and directories of this process's runs still present
    /// that were not there before it started: root directories
    /// `<tmp>/attsync-iox2/<run>` and shared memory `/dev/shm/as<run>_*` of
    /// the runs in [`Finished::runs`], and of any run whose id starts with
    /// the pid in hex followed by `r` (how attsync names runs today, which
    /// covers runs too short for the watcher).
    #[must_use]
    pub fn leftovers(&self) -> Vec<PathBuf> {
        let by_pid = format!("{:x}r", self.pid);
        let ours = |run_part: &str| {
            run_part.starts_with(&by_pid)
                || self
                    .runs
                    .iter()
                    .any(|r| run_part == r || run_part.starts_with(&format!("{r}_")))
        };
        namespace_entries()
            .into_iter()
            .filter(|p| !self.before.contains(p))
            .filter(|p| {
                let name = p.file_name().map(|n| n.to_string_lossy().into_owned());
                let name = name.unwrap_or_default();
                if p.starts_with(SHM_DIR) {
                    name.strip_prefix("as").is_some_and(ours)
                } else {
                    ours(&name)
                }
            })
            .collect()
    }

    /// Asserts [`Finished::leftovers`] is empty.
    #[track_caller]
    pub fn assert_no_leftovers(&self) -> &Self {
        let left = self.leftovers();
        assert!(
            left.is_empty(),
            "the run left iceoryx2 files behind: {left:#?}\n{}",
            self.describe()
        );
        self
    }
}

/// Parent of every run's iceoryx2 root directory: `$TMPDIR/attsync-iox2`
/// (the same `std::env::temp_dir()` the child sees).
#[must_use]
pub fn iox_base() -> PathBuf {
    std::env::temp_dir().join("attsync-iox2")
}

/// Every run directory under [`iox_base`] and every `as*` file in /dev/shm.
fn namespace_entries() -> BTreeSet<PathBuf> {
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

/// The command line of process `pid` (empty if it is gone).
fn cmdline(pid: u32) -> Vec<String> {
    fs::read(format!("/proc/{pid}/cmdline"))
        .map(|b| {
            b.split(|&c| c == 0)
                .filter(|a| !a.is_empty())
                .map(|a| String::from_utf8_lossy(a).into_owned())
                .collect()
        })
        .unwrap_or_default()
}

/// Live processes (pid, command line) with an argument inside run `run`'s
/// root directory: the node processes, started with `--config <root>/node-<id>.json`.
#[must_use]
pub fn run_processes(run: &str) -> Vec<(u32, Vec<String>)> {
    let needle = format!("{}/", iox_base().join(run).display());
    let Ok(rd) = fs::read_dir("/proc") else {
        return Vec::new();
    };
    rd.filter_map(Result::ok)
        .filter_map(|e| e.file_name().to_str()?.parse::<u32>().ok())
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

/// Polls `f` every `poll` until it returns `Some`, at most `timeout`.
pub fn wait_until<T>(
    timeout: Duration,
    poll: Duration,
    mut f: impl FnMut() -> Option<T>,
) -> Option<T> {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(x) = f() {
            return Some(x);
        }
        if Instant::now() > deadline {
            return None;
        }
        std::thread::sleep(poll);
    }
}

/// The staging directory `attsync` (pid `pid`) writes `out` into:
/// `.<name>.partial-<pid>` beside it.
#[must_use]
pub fn staging_dir(out: &Path, pid: u32) -> PathBuf {
    let name = out.file_name().expect("named").to_string_lossy();
    out.with_file_name(format!(".{name}.partial-{pid}"))
}

/// A text file's contents (panics naming the file).
#[must_use]
pub fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Asserts two files are byte-identical; the message names the first
/// differing line.
#[track_caller]
pub fn assert_same_file(a: &Path, b: &Path) {
    let (ta, tb) = (read(a), read(b));
    if ta == tb {
        return;
    }
    let (la, lb): (Vec<&str>, Vec<&str>) = (ta.lines().collect(), tb.lines().collect());
    let k = la
        .iter()
        .zip(&lb)
        .position(|(x, y)| x != y)
        .unwrap_or(la.len().min(lb.len()));
    panic!(
        "{} and {} differ (lines: {} vs {}); first difference at line {}:\n  {:?}\n  {:?}",
        a.display(),
        b.display(),
        la.len(),
        lb.len(),
        k + 1,
        la.get(k).unwrap_or(&"<end of file>"),
        lb.get(k).unwrap_or(&"<end of file>"),
    );
}

/// The agent ids in an `errors.csv`.
#[must_use]
pub fn csv_agents(csv: &str) -> BTreeSet<u32> {
    csv.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .nth(1)
                .and_then(|a| a.parse().ok())
                .unwrap_or_else(|| panic!("bad errors.csv row {l:?}"))
        })
        .collect()
}

/// The number of data rows (without the header) of an `errors.csv`.
#[must_use]
pub fn csv_rows(csv: &str) -> usize {
    csv.lines().count().saturating_sub(1)
}

/// `dir/summary.json`.
#[must_use]
pub fn summary(dir: &Path) -> Value {
    let path = dir.join("summary.json");
    serde_json::from_str(&read(&path)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `dir/summary.json` without the fields `drop`.
#[must_use]
pub fn summary_without(dir: &Path, drop: &[&str]) -> Value {
    let mut s = summary(dir);
    let obj = s.as_object_mut().expect("summary.json is an object");
    for k in drop {
        obj.remove(*k);
    }
    s
}

/// Asserts two binary files are byte-identical.
#[track_caller]
pub fn assert_same_bytes(a: &Path, b: &Path) {
    let bytes = |p: &Path| fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let (ba, bb) = (bytes(a), bytes(b));
    if ba != bb {
        let k = ba
            .iter()
            .zip(&bb)
            .position(|(x, y)| x != y)
            .unwrap_or(ba.len().min(bb.len()));
        panic!(
            "{} and {} differ ({} vs {} bytes), first at byte {k}",
            a.display(),
            b.display(),
            ba.len(),
            bb.len()
        );
    }
}

/// Asserts two results directories hold the same run: byte-identical
/// `errors.csv`, `scenario.toml` and (where written) `states.bin`, and the
/// same `summary.json` except `engine` and `wall_seconds`.
#[track_caller]
pub fn assert_same_results(a: &Path, b: &Path) {
    assert_same_file(&a.join("errors.csv"), &b.join("errors.csv"));
    assert_same_file(&a.join("scenario.toml"), &b.join("scenario.toml"));
    let states = |d: &Path| d.join("states.bin");
    match (states(a).exists(), states(b).exists()) {
        (true, true) => assert_same_bytes(&states(a), &states(b)),
        (false, false) => {}
        (ea, eb) => panic!(
            "states.bin in {} only ({}: {ea}, {}: {eb})",
            if ea { "the first" } else { "the second" },
            a.display(),
            b.display()
        ),
    }
    let skip = ["engine", "wall_seconds"];
    assert_eq!(
        summary_without(a, &skip),
        summary_without(b, &skip),
        "summary.json of {} and {} differ",
        a.display(),
        b.display()
    );
}
