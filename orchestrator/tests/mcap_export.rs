//! `attsync export DIR/states.bin --mcap`: the recording opens in an
//! independent reader (PyPI `mcap` + `mcap-protobuf-support`, pinned in
//! tests/requirements.txt), which decodes every message through the schemas
//! embedded in the file and checks it against the run's `states.bin` (through
//! `export --csv`) and `errors.csv`: one message per sample per channel, log
//! times = simulated sample times, every transform's rotation, every error.
//!
//! Needs `python3 -m pip install -r tests/requirements.txt` (the README's
//! test command and `.ci/run` run `tools/test-deps.sh`, which does it).
#![cfg(feature = "mcap")]

mod common;

use common::{Out, attsync, paper, run_args};
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn read_check() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../tests/mcap/read_check.py")
}

/// The stdout of the Python checker, after asserting its success.
#[track_caller]
fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "failed ({:?}):\n--- stdout\n{}\n--- stderr\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout.clone()).unwrap()
}

fn require_python_mcap() {
    let ok = Command::new("python3")
        .args(["-c", "import mcap, mcap_protobuf"])
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "python3 cannot import mcap and mcap_protobuf: run `python3 -m pip install -r tests/requirements.txt`"
    );
}

/// `attsync run NAME --engine in-process` for 0.1 s (11 samples) into `out`.
fn paper_run(name: &str, out: &Path) {
    let args = run_args(paper(name), "in-process", out, &["simulation.duration=0.1"]);
    attsync(out.parent().expect("a parent"), &args).assert_ok();
}

/// `attsync export STATES ARGS…`, in the directory of `states`.
fn export(states: &Path, args: &[&str]) -> Out {
    let mut all: Vec<OsString> = vec!["export".into(), states.into()];
    all.extend(args.iter().map(Into::into));
    attsync(states.parent().expect("a parent"), &all)
}

/// The stdout of a successful `export`.
#[track_caller]
fn exported(states: &Path, args: &[&str]) -> String {
    export(states, args).assert_ok().stdout.clone()
}

/// Runs `name`, exports both ways, reads the recording back in Python; returns
/// the exporter's line and the checker's line.
fn round_trip(name: &str) -> (String, String) {
    require_python_mcap();
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    paper_run(name, &run);
    let states = run.join("states.bin");
    let csv = dir.path().join("states.csv");
    exported(&states, &["--csv", "--out", csv.to_str().unwrap()]);
    let said = exported(&states, &["--mcap"]);
    let recording = run.join("states.mcap");
    assert!(
        recording.is_file(),
        "--mcap writes DIR/states.mcap by default"
    );
    let checked = Command::new("python3")
        .arg(read_check())
        .args([&recording, &csv, &run.join("errors.csv")])
        .output()
        .unwrap();
    (said, ok(&checked))
}

#[test]
fn the_observer_run_reads_back_with_every_frame_and_error() {
    let (said, checked) = round_trip("timevarying");
    assert!(
        said.contains("11 samples, 15 channels, 165 messages"),
        "{said}"
    );
    assert!(
        checked.contains(
            "mcap ok: 11 samples, 7 agents, 15 channels, 165 messages, observer true, \
             last log time 100000000 ns"
        ),
        "{checked}"
    );
}

#[test]
fn the_observerless_run_reads_back_without_estimates() {
    let (_, checked) = round_trip("constant-observerless");
    assert!(
        checked
            .contains("mcap ok: 11 samples, 7 agents, 15 channels, 165 messages, observer false"),
        "{checked}"
    );
}

#[test]
fn out_names_the_recording_and_csv_and_mcap_exclude_each_other() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    paper_run("constant-observerless", &run);
    let states = run.join("states.bin");
    let file = dir.path().join("elsewhere.mcap");
    exported(&states, &["--mcap", "--out", file.to_str().unwrap()]);
    let bytes = std::fs::read(&file).unwrap();
    assert_eq!(&bytes[..8], b"\x89MCAP0\r\n", "MCAP magic");
    assert_eq!(&bytes[bytes.len() - 8..], b"\x89MCAP0\r\n", "closed file");
    assert!(!run.join("states.mcap").exists());
    for args in [&["--csv", "--mcap"][..], &[][..]] {
        let r = export(&states, args);
        assert_eq!(r.code, Some(2), "{args:?}: a usage error");
        let err = &r.stderr;
        assert!(err.contains("--csv") && err.contains("--mcap"), "{err}");
    }
}

#[test]
fn a_truncated_states_file_leaves_no_recording() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    paper_run("constant-observerless", &run);
    let states = run.join("states.bin");
    let mut bytes = std::fs::read(&states).unwrap();
    bytes.truncate(bytes.len() - 7);
    std::fs::write(&states, bytes).unwrap();
    let r = export(&states, &["--mcap"]);
    assert_eq!(r.code, Some(1));
    let err = &r.stderr;
    assert!(
        err.contains("states.bin") && err.contains("truncated"),
        "{err}"
    );
    assert!(!run.join("states.mcap").exists());
}

#[test]
fn a_run_replaces_a_directory_holding_its_recording() {
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    paper_run("constant-observerless", &run);
    exported(&run.join("states.bin"), &["--mcap"]);
    assert!(run.join("states.mcap").is_file());
    paper_run("constant-observerless", &run);
    assert!(
        !run.join("states.mcap").exists(),
        "the old recording went with the old results"
    );
}
