//! Child processes with bounded waits, and the iceoryx2 leftovers of a bare
//! ring run. Used by `attsync-bench run` (see `main.rs` for how to run it).
//!
//! Only processes this program started are ever signalled, by their own
//! process id.

use crate::error::{BenchError, Result};
use std::path::Path;
use std::process::{Child, Command, ExitStatus};
use std::sync::mpsc;
use std::time::{Duration, Instant};

/// A finished child.
#[derive(Debug)]
pub struct Finished {
    /// Its exit status.
    pub status: ExitStatus,
    /// Wall time from just before spawning to its exit, s.
    pub wall: f64,
}

fn signal(pid: u32, sig: &str) {
    let _ = Command::new("kill")
        .arg(format!("-{sig}"))
        .arg(pid.to_string())
        .status();
}

/// Runs `cmd` (its stdio already set up) to completion. The wall time is
/// measured from just before the spawn to the moment `waitpid` returns (a
/// helper thread blocks in it, so nothing polls). After `timeout` the child
/// gets SIGINT, 20 s later SIGKILL, and the result is an error.
pub fn run_timed(cmd: &mut Command, timeout: Duration) -> Result<Finished> {
    let program = cmd.get_program().to_string_lossy().into_owned();
    let t0 = Instant::now();
    let mut child = cmd.spawn().map_err(|source| BenchError::Spawn {
        program: program.clone(),
        source,
    })?;
    let pid = child.id();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let status = child.wait();
        let _ = tx.send((status, Instant::now()));
    });
    match rx.recv_timeout(timeout) {
        Ok((status, t1)) => Ok(Finished {
            status: status.map_err(|source| BenchError::Spawn { program, source })?,
            wall: (t1 - t0).as_secs_f64(),
        }),
        Err(_) => {
            signal(pid, "INT");
            if rx.recv_timeout(Duration::from_secs(20)).is_err() {
                signal(pid, "KILL");
                let _ = rx.recv_timeout(Duration::from_secs(5));
            }
            Err(BenchError::Timeout {
                seconds: timeout.as_secs_f64(),
                what: format!("for {program} (interrupted)"),
            })
        }
    }
}

/// A group of children that are killed (SIGKILL, by pid) and reaped if still
/// running when the group is dropped.
#[derive(Debug, Default)]
pub struct Group {
    children: Vec<(u32, Child)>,
}

impl Group {
    /// Adds a started child, known by `index`.
    pub fn push(&mut self, index: u32, child: Child) {
        self.children.push((index, child));
    }

    /// The first child that has already exited, with its status.
    pub fn first_exit(&mut self) -> Option<(u32, ExitStatus)> {
        self.children
            .iter_mut()
            .find_map(|(i, c)| c.try_wait().ok().flatten().map(|s| (*i, s)))
    }

    /// Waits until every child has exited, at most `timeout`; returns the
    /// statuses in start order, or an error naming those still running
    /// (which are then killed).
    pub fn wait_all(&mut self, timeout: Duration) -> Result<Vec<(u32, ExitStatus)>> {
        let deadline = Instant::now() + timeout;
        let mut out: Vec<Option<ExitStatus>> = vec![None; self.children.len()];
        loop {
            for (k, (_, c)) in self.children.iter_mut().enumerate() {
                if out[k].is_none() {
                    out[k] = c.try_wait().map_err(|source| BenchError::Spawn {
                        program: "a ring-node (waiting for it)".into(),
                        source,
                    })?;
                }
            }
            if out.iter().all(Option::is_some) {
                return Ok(self
                    .children
                    .iter()
                    .zip(out)
                    .map(|((i, _), s)| (*i, s.expect("all exited")))
                    .collect());
            }
            if Instant::now() > deadline {
                let running: Vec<String> = self
                    .children
                    .iter()
                    .zip(&out)
                    .filter(|(_, s)| s.is_none())
                    .map(|((i, _), _)| i.to_string())
                    .collect();
                self.kill();
                return Err(BenchError::Timeout {
                    seconds: timeout.as_secs_f64(),
                    what: format!("for nodes {} to end", running.join(", ")),
                });
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }

    /// Kills and reaps every child still running.
    pub fn kill(&mut self) {
        for (_, c) in &mut self.children {
            if c.try_wait().ok().flatten().is_none() {
                let _ = c.kill();
                let _ = c.wait();
            }
        }
    }
}

impl Drop for Group {
    fn drop(&mut self) {
        self.kill();
    }
}

/// Removes run `run`'s iceoryx2 files: its directory `dir` and the shared
/// memory `/dev/shm/as<run>_*` (see [`msgs::namespace::prefix`]).
pub fn remove_namespace(run: &str, dir: &Path) {
    let prefix = msgs::namespace::prefix(run);
    if let Ok(rd) = std::fs::read_dir("/dev/shm") {
        for e in rd.filter_map(Result::ok) {
            if e.file_name().to_string_lossy().starts_with(&prefix) {
                let _ = std::fs::remove_file(e.path());
            }
        }
    }
    let _ = std::fs::remove_dir_all(dir);
}

/// The last `n` lines of a file (empty if unreadable).
#[must_use]
pub fn tail(path: &Path, n: usize) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}
