//! `attsync verify --engine`: the engines are bit-identical, so a run of
//! one verifies with the other (issue 14 item 4). A processes run
//! (one OS process per node, iceoryx2 in lockstep) re-run in-process, an
//! in-process run re-run with the processes engine, and a processes run
//! re-run as recorded (the processes engine again, the recorded wait
//! strategy): each exits 0 with "bit-identical", and the processes re-runs
//! leave no iceoryx2 files behind. The in-process cases are in
//! `orchestrator/tests/verify.rs`.

use attsync_tests::{Attsync, Finished, Sandbox, paper, run_args, summary};
use std::ffi::OsStr;
use std::path::Path;

const HALF_SECOND: &str = "simulation.duration=0.5";

/// `attsync verify DIR --quiet extra…`, expected bit-identical.
fn verifies(tmp: &Sandbox, dir: &Path, extra: &[&str]) -> Finished {
    let out = Attsync::new(tmp.path())
        .args([OsStr::new("verify"), dir.as_os_str(), OsStr::new("--quiet")])
        .args(extra)
        .output();
    out.assert_ok();
    assert_eq!(
        out.stdout.lines().last(),
        Some("bit-identical"),
        "{}",
        out.describe()
    );
    out
}

#[test]
fn a_processes_run_verifies_in_process_and_as_recorded() {
    let tmp = Sandbox::new("verify-processes");
    let dir = tmp.join("processes");
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "processes",
            &dir,
            &[HALF_SECOND],
        ))
        .args(["--wait", "block"])
        .output()
        .assert_ok();
    assert_eq!(summary(&dir)["engine"], "processes");
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["engine"], "processes");
    assert_eq!(m["wait"], "block");
    assert!(
        m["files"]
            .as_array()
            .unwrap()
            .iter()
            .any(|f| f["path"] == "logs/leader.log"),
        "the node logs are listed too: {m:#}"
    );
    let out = verifies(&tmp, &dir, &["--engine", "in-process"]);
    assert!(
        out.stdout.contains("in-process engine"),
        "{}",
        out.describe()
    );
    let out = verifies(&tmp, &dir, &[]);
    assert!(
        out.stdout.contains("processes engine"),
        "{}",
        out.describe()
    );
    out.assert_no_leftovers();
}

#[test]
fn an_in_process_run_verifies_with_the_processes_engine() {
    let tmp = Sandbox::new("verify-in-process");
    let dir = tmp.join("in-process");
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("constant-observer"),
            "in-process",
            &dir,
            &[HALF_SECOND],
        ))
        .output()
        .assert_ok();
    let out = verifies(&tmp, &dir, &["--engine", "processes", "--wait", "yield"]);
    assert!(
        out.stdout.contains("processes engine"),
        "{}",
        out.describe()
    );
    out.assert_no_leftovers();
}
