//! Helpers shared by the orchestrator's integration tests (each test file
//! that uses them says `mod common;`).
//!
//! - the paper's scenario files: [`PAPER`], [`OBSERVERLESS`], [`paper`];
//!   loaded and run in this process: [`load_paper`], [`stays_finite`];
//! - the built `attsync` binary, run to its end in a working directory with
//!   a clean attsync environment: [`attsync`] → [`Out`]; the usual `attsync
//!   run` arguments: [`run_args`];
//! - results files: [`read`], [`json`], [`summary`], [`entries`].
//!
//! Not every test file uses every helper (hence `dead_code` allowed).
#![allow(dead_code)]

use attitude::engine::InProcess;
use attitude::network::Network;
use attsync::scenario::{Loaded, load};
use std::collections::BTreeSet;
use std::ffi::{OsStr, OsString};
use std::fs;
use std::path::Path;
use std::process::Command;

/// The paper's scheme-1 experiment, `scenarios/paper/timevarying.toml`.
pub const PAPER: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenarios/paper/timevarying.toml"
);

/// The paper's scheme-3 experiment, `scenarios/paper/constant-observerless.toml`.
pub const OBSERVERLESS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenarios/paper/constant-observerless.toml"
);

/// Flags that make every run diverge: a `simulation.dt` far beyond RK4's
/// stable step (the integration blows up), allowed by
/// `--no-stiffness-check`, sampled at that step.
pub const DIVERGING: [&str; 5] = [
    "--no-stiffness-check",
    "--set",
    "simulation.dt=0.5",
    "--set",
    "output.sample_period=0.5",
];

/// `scenarios/paper/<name>.toml`: `timevarying`, `constant-observer`,
/// `constant-observerless`.
#[must_use]
pub fn paper(name: &str) -> String {
    format!(
        "{}/../scenarios/paper/{name}.toml",
        env!("CARGO_MANIFEST_DIR")
    )
}

/// [`paper`] `name` with `--set`s `set`, loaded (panics on an error).
#[must_use]
pub fn load_paper(name: &str, set: &[&str]) -> Loaded {
    let set: Vec<String> = set.iter().map(|s| (*s).to_string()).collect();
    load(Path::new(&paper(name)), &set).unwrap_or_else(|e| panic!("{e}"))
}

/// Whether every state of a run of `net` stays finite and below 1e6 (a
/// diverging RK4 mode grows by a factor > 1 per step: it passes 1e6 within
/// the run), and the divergence guard never stopped it.
#[must_use]
pub fn stays_finite(net: &Network) -> bool {
    let mut ok = true;
    // The divergence guard stops the run at the first state beyond its
    // envelope: that is "not finite" here too.
    let diverged = InProcess::new(net).run(|s| {
        ok = s.agents.iter().all(|a| {
            [a.w, a.w_hat, a.s_hat]
                .iter()
                .all(|v| v.iter().all(|x| x.is_finite() && x.abs() < 1e6))
                && a.r.iter().chain(a.r_hat.iter()).all(|x| x.is_finite())
        });
        ok
    });
    ok && diverged.is_none()
}

/// What a finished `attsync` process left.
#[derive(Debug)]
pub struct Out {
    /// Its exit code (`None`: killed by a signal).
    pub code: Option<i32>,
    /// Its standard output.
    pub stdout: String,
    /// Its standard error.
    pub stderr: String,
}

impl Out {
    /// Asserts exit code `code`; the message shows both outputs.
    #[track_caller]
    pub fn assert_code(&self, code: i32) -> &Self {
        assert_eq!(
            self.code,
            Some(code),
            "attsync exited with {:?}, not {code}:\n--- stdout\n{}\n--- stderr\n{}",
            self.code,
            self.stdout,
            self.stderr
        );
        self
    }

    /// Asserts success (exit code 0).
    #[track_caller]
    pub fn assert_ok(&self) -> &Self {
        self.assert_code(0)
    }

    /// Asserts an exit by itself (not by a signal) with a non-zero code.
    #[track_caller]
    pub fn assert_failed(&self) -> &Self {
        assert!(self.code.is_some(), "killed by a signal: {}", self.stderr);
        assert_ne!(self.code, Some(0), "unexpected success:\n{}", self.stdout);
        self
    }
}

/// Runs the built `attsync args…` to its end in `cwd`, with a clean attsync
/// environment (`ATTSYNC_BIN_DIR`, `ATTSYNC_LOG` and `ATTSYNC_DEBUG`
/// removed) and no standard input.
pub fn attsync<S: AsRef<OsStr>>(cwd: &Path, args: &[S]) -> Out {
    let out = Command::new(env!("CARGO_BIN_EXE_attsync"))
        .args(args)
        .current_dir(cwd)
        .env_remove("ATTSYNC_BIN_DIR")
        .env_remove("ATTSYNC_LOG")
        .env_remove("ATTSYNC_DEBUG")
        .output()
        .expect("attsync starts");
    Out {
        code: out.status.code(),
        stdout: String::from_utf8(out.stdout).expect("UTF-8 stdout"),
        stderr: String::from_utf8(out.stderr).expect("UTF-8 stderr"),
    }
}

/// The arguments of `attsync run SCENARIO --engine ENGINE --out OUT --quiet
/// --set S…`.
#[must_use]
pub fn run_args(
    scenario: impl AsRef<OsStr>,
    engine: &str,
    out: impl AsRef<OsStr>,
    sets: &[&str],
) -> Vec<OsString> {
    let mut args: Vec<OsString> = vec![
        "run".into(),
        scenario.as_ref().into(),
        "--engine".into(),
        engine.into(),
        "--out".into(),
        out.as_ref().into(),
        "--quiet".into(),
    ];
    for s in sets {
        args.push("--set".into());
        args.push((*s).into());
    }
    args
}

/// A text file's contents (panics naming the file).
#[must_use]
pub fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A JSON file's value (panics naming the file).
#[must_use]
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&read(path)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `dir/summary.json`.
#[must_use]
pub fn summary(dir: &Path) -> serde_json::Value {
    json(&dir.join("summary.json"))
}

/// Names of the entries of `dir` (hidden ones included).
#[must_use]
pub fn entries(dir: &Path) -> BTreeSet<String> {
    fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}
