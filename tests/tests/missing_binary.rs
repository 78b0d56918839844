//! `attsync` without its node binaries. A copy of the `attsync` binary alone
//! in an empty directory (and `ATTSYNC_BIN_DIR` unset) cannot find
//! `attsync-agent`/`attsync-leader`. Asserts:
//! - with the processes engine it exits 1, says which binary is missing and
//!   how to build it (`cargo build --release --workspace`), and leaves no
//!   results directory, no staging directory and no iceoryx2 files;
//! - the in-process engine needs no node binaries: the copy runs and gives
//!   the same results as the workspace's `attsync`.

use attsync_tests::{Attsync, Sandbox, assert_same_results, bin, copy_executable, paper, run_args};
use std::path::PathBuf;

/// `tmp/bin/attsync`, a copy of the workspace's `attsync`, alone in its
/// directory (whose parent, `tmp`, has no node binaries either).
fn lonely_attsync(tmp: &Sandbox) -> PathBuf {
    let dir = tmp.join("bin");
    std::fs::create_dir(&dir).expect("create bin/");
    let copy = dir.join("attsync");
    copy_executable(&bin("attsync"), &copy);
    copy
}

#[test]
fn processes_engine_without_node_binaries_fails_clearly() {
    let tmp = Sandbox::new("missing-binary");
    let attsync = lonely_attsync(&tmp);
    let out = tmp.join("results");
    let cwd = attsync.parent().expect("in bin/").to_owned();
    let f = Attsync::with_program(&attsync, &cwd)
        .args(run_args(
            &paper("timevarying"),
            "processes",
            &out,
            &["simulation.duration=0.1"],
        ))
        .output();
    f.assert_code(1).assert_no_leftovers();
    assert!(f.stderr.contains("attsync-agent"), "{}", f.describe());
    assert!(
        f.stderr.contains("cargo build --release --workspace"),
        "{}",
        f.describe()
    );
    assert!(!out.exists(), "{} was created", out.display());
    let mut entries: Vec<String> = std::fs::read_dir(tmp.path())
        .expect("list the sandbox")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    entries.sort();
    assert_eq!(
        entries,
        ["bin"],
        "only bin/ may be in {}",
        tmp.path().display()
    );
    let mut in_bin: Vec<String> = std::fs::read_dir(&cwd)
        .expect("list bin/")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    in_bin.sort();
    assert_eq!(
        in_bin,
        ["attsync"],
        "only attsync may be in {}",
        cwd.display()
    );
}

#[test]
fn in_process_engine_needs_no_node_binaries() {
    let tmp = Sandbox::new("missing-binary-in-process");
    let attsync = lonely_attsync(&tmp);
    let (copy, reference) = (tmp.join("copy"), tmp.join("reference"));
    let cwd = attsync.parent().expect("in bin/").to_owned();
    let sets = ["simulation.duration=0.5"];
    Attsync::with_program(&attsync, &cwd)
        .args(run_args(&paper("timevarying"), "in-process", &copy, &sets))
        .output()
        .assert_ok();
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "in-process",
            &reference,
            &sets,
        ))
        .output()
        .assert_ok();
    assert_same_results(&copy, &reference);
}
