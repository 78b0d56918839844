//! Runs at the same time on one machine: every run has its own iceoryx2
//! namespace (root directory `<tmp>/attsync-iox2/<run>/` with an `owner`
//! file holding the orchestrator's pid, shared-memory prefix `as<run>_`), so
//! runs started together neither meet nor disturb each other.
//! Each test also checks that the runs were seen owning their namespace
//! (under the same root the orchestrator chooses: `iox_base`).

use attsync_tests::{
    Attsync, Finished, RUN_TIMEOUT, Sandbox, assert_same_file, assert_same_results, paper, run_args,
};
use std::collections::BTreeSet;
use std::path::PathBuf;

/// Starts `n` processes runs of the paper's time-varying scenario (2 s) at
/// once, into `<tmp>/<prefix>-<k>`; waits for all.
fn start_together(tmp: &Sandbox, prefix: &str, n: usize) -> Vec<(PathBuf, Finished)> {
    let dirs: Vec<PathBuf> = (0..n).map(|k| tmp.join(format!("{prefix}-{k}"))).collect();
    let running: Vec<_> = dirs
        .iter()
        .map(|d| {
            Attsync::new(tmp.path())
                .args(run_args(
                    &paper("timevarying"),
                    "processes",
                    d,
                    &["simulation.duration=2"],
                ))
                .spawn()
        })
        .collect();
    dirs.into_iter()
        .zip(running.into_iter().map(|r| r.wait(RUN_TIMEOUT)))
        .collect()
}

/// Each run succeeded, owned exactly one namespace of its own, left nothing,
/// and gave the in-process results.
fn assert_independent(runs: &[(PathBuf, Finished)], reference: &std::path::Path) {
    let mut seen = BTreeSet::new();
    for (dir, f) in runs {
        f.assert_ok().assert_no_leftovers();
        assert_eq!(
            f.runs.len(),
            1,
            "expected one iceoryx2 namespace owned by attsync (pid {}), saw {:?}\n{}",
            f.pid,
            f.runs,
            f.describe()
        );
        assert!(
            seen.insert(f.runs.clone()),
            "two runs shared the namespace {:?}",
            f.runs
        );
        assert_same_results(dir, reference);
    }
}

fn in_process_reference(tmp: &Sandbox) -> PathBuf {
    let dir = tmp.join("in-process");
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "in-process",
            &dir,
            &["simulation.duration=2"],
        ))
        .output()
        .assert_ok();
    dir
}

/// Two `attsync run` of the same scenario started together into two
/// directories: both succeed in distinct namespaces, byte-identical results,
/// equal to an in-process run.
#[test]
fn two_runs_at_the_same_time() {
    let tmp = Sandbox::new("concurrent");
    let reference = in_process_reference(&tmp);
    let runs = start_together(&tmp, "run", 2);
    assert_same_file(&runs[0].0.join("errors.csv"), &runs[1].0.join("errors.csv"));
    assert_independent(&runs, &reference);
}

/// Six runs started together, three times over.
#[test]
fn many_runs_at_once() {
    let tmp = Sandbox::new("concurrent-many");
    let reference = in_process_reference(&tmp);
    for round in 0..3 {
        let runs = start_together(&tmp, &format!("round{round}"), 6);
        assert_independent(&runs, &reference);
    }
}
