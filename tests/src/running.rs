//! A started `attsync` ([`Running`]: bounded wait, killed with its node
//! processes if given up on) and what it left when it ended ([`Finished`]).

use crate::namespace::{SHM_DIR, kill9, namespace_entries, owned_runs, run_processes};
use crate::wait_until;
use std::collections::BTreeSet;
use std::fs;
use std::io::Read;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, ExitStatus};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

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
    /// Takes over a just-spawned `child` (stdout and stderr piped): reads its
    /// output and records the iceoryx2 runs it owns while it lives. `before`:
    /// the namespace entries present before it started.
    pub(crate) fn watch(mut child: Child, what: String, before: BTreeSet<PathBuf>) -> Self {
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
        Self {
            child: Some(child),
            pid,
            what,
            stdout: Some(stdout),
            stderr: Some(stderr),
            watcher: Some((stop, watcher)),
            runs,
            before,
        }
    }

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

    /// Waits until node `node` of its run is stepping: `staging/logs/<node>.log`
    /// says `started`, then the first rows of `staging/errors.csv` are
    /// flushed (well into stepping), at most 60 s each. Panics saying which
    /// did not happen, with its output if it ended first.
    #[must_use]
    pub fn once_stepping(mut self, staging: &Path, node: &str) -> Self {
        let log = staging.join(format!("logs/{node}.log"));
        let csv = staging.join("errors.csv");
        let started = |p: &Path| fs::read_to_string(p).is_ok_and(|l| l.contains("started"));
        let rows = |p: &Path| fs::metadata(p).is_ok_and(|m| m.len() > 0);
        let stages: [Stage<'_>; 2] = [
            (&log, "said `started`", &started),
            (&csv, "got its first rows", &rows),
        ];
        for (file, what, done) in stages {
            let poll = Duration::from_millis(20);
            let reached = wait_until(Duration::from_secs(60), poll, || {
                (self.has_ended() || done(file)).then_some(())
            });
            if self.has_ended() {
                let finished = self.wait(Duration::from_secs(10));
                panic!(
                    "attsync ended before {} {what}:\n{}",
                    file.display(),
                    finished.describe()
                );
            }
            assert!(
                reached.is_some(),
                "{} never {what} within 60 s",
                file.display()
            );
        }
        self
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

/// One stage [`Running::once_stepping`] waits for: the file, what it shows
/// when reached, and the test on the file.
type Stage<'a> = (&'a Path, &'a str, &'a dyn Fn(&Path) -> bool);
