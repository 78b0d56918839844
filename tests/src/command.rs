//! An `attsync` command line ([`Attsync`]) and the usual `run` arguments
//! ([`run_args`]).

use crate::RUN_TIMEOUT;
use crate::namespace::namespace_entries;
use crate::running::{Finished, Running};
use crate::workspace::{bin, exec_lock};
use std::ffi::{OsStr, OsString};
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs `scenario` (with `sets`) on the in-process engine into `out`, in
/// `cwd`, and asserts it succeeded: the reference that a run of the
/// process engine or over hosts is compared with.
#[track_caller]
pub fn reference_run(cwd: &Path, scenario: &Path, out: &Path, sets: &[&str]) {
    Attsync::new(cwd)
        .args(run_args(scenario, "in-process", out, sets))
        .output()
        .assert_ok();
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
        let child = {
            let _no_open_executable = exec_lock();
            self.cmd.spawn()
        }
        .unwrap_or_else(|e| panic!("cannot start `{}`: {e}", self.what));
        Running::watch(child, self.what, before)
    }

    /// Runs it to the end (at most [`RUN_TIMEOUT`]).
    #[must_use]
    pub fn output(self) -> Finished {
        self.spawn().wait(RUN_TIMEOUT)
    }
}
