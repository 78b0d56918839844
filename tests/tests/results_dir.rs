//! Results directories off the happy path: attsync replaces only a
//! directory it marked as its own (`.attsync-run`, holding nothing but the
//! files attsync writes), refuses anything else at once (exit 2, naming the
//! directory and the foreign files), serialises runs into one `--out` with a
//! lock (`.<name>.lock`; the second run fails at once), and removes the
//! staging directories of dead runs.

use attsync_tests::{Attsync, Finished, RUN_TIMEOUT, Sandbox, paper, run_args, wait_until};
use std::collections::BTreeSet;
use std::fs;
use std::path::Path;
use std::time::Duration;

/// `attsync run` of the paper's time-varying scenario, in-process, for
/// `duration` simulated seconds, into `out`.
fn run(tmp: &Sandbox, out: &Path, duration: u32) -> Attsync {
    let d = format!("simulation.duration={duration}");
    Attsync::new(tmp.path()).args(run_args(
        &paper("timevarying"),
        "in-process",
        out,
        &[d.as_str()],
    ))
}

fn entries(dir: &Path) -> BTreeSet<String> {
    fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect()
}

/// `out` holds complete results of a run of `duration` s.
#[track_caller]
fn assert_complete(out: &Path, duration: f64) {
    let s = attsync_tests::summary(out);
    assert_eq!(s["complete"].as_bool(), Some(true), "{s}");
    assert_eq!(s["t_end"].as_f64(), Some(duration), "{s}");
    assert!(out.join(".attsync-run").is_file());
    assert!(out.join("errors.csv").is_file() && out.join("states.bin").is_file());
}

#[test]
fn a_foreign_file_is_kept_and_the_run_refused() {
    let tmp = Sandbox::new("results_dir_foreign");
    let proj = tmp.join("proj");
    fs::create_dir(&proj).unwrap();
    fs::write(proj.join("summary.json"), "{}\n").unwrap();
    fs::write(proj.join("analysis.py"), "x\n").unwrap();
    let out = run(&tmp, &proj, 10).output();
    out.assert_code(2);
    assert!(
        out.stderr.contains("proj") && out.stderr.contains("analysis.py"),
        "{}",
        out.describe()
    );
    assert_eq!(fs::read_to_string(proj.join("analysis.py")).unwrap(), "x\n");
    assert_eq!(
        entries(&proj),
        BTreeSet::from(["analysis.py".into(), "summary.json".into()])
    );
    assert_eq!(entries(tmp.path()), BTreeSet::from(["proj".into()]));

    // Marked as attsync's, but with a foreign file added: still refused.
    let marked = tmp.join("marked");
    run(&tmp, &marked, 10).output().assert_ok();
    fs::write(marked.join("notes.txt"), "mine").unwrap();
    let out = run(&tmp, &marked, 10).output();
    out.assert_code(2);
    assert!(out.stderr.contains("notes.txt"), "{}", out.describe());
    assert_eq!(
        fs::read_to_string(marked.join("notes.txt")).unwrap(),
        "mine"
    );
}

#[test]
fn an_attsync_results_directory_is_replaced() {
    let tmp = Sandbox::new("results_dir_replaced");
    let out = tmp.join("out");
    run(&tmp, &out, 10).output().assert_ok();
    let first = fs::read_to_string(out.join(".attsync-run")).unwrap();
    run(&tmp, &out, 5).output().assert_ok();
    assert_complete(&out, 5.0);
    assert_ne!(fs::read_to_string(out.join(".attsync-run")).unwrap(), first);
    assert_eq!(entries(tmp.path()), BTreeSet::from(["out".into()]));
}

#[test]
fn a_second_run_into_the_same_out_fails_at_once_naming_the_lock() {
    let tmp = Sandbox::new("results_dir_lock");
    let out = tmp.join("out");
    let lock = tmp.join(".out.lock");
    // A long run holds the lock; a second one started meanwhile is refused.
    let long = run(&tmp, &out, 200).spawn();
    let pid = long.pid();
    wait_until(RUN_TIMEOUT, Duration::from_millis(5), || {
        lock.exists().then_some(())
    })
    .expect("the first run takes the lock");
    let second = run(&tmp, &out, 10).output();
    second.assert_code(2);
    assert!(
        second
            .stderr
            .contains(&format!("another attsync run (pid {pid})"))
            && second.stderr.contains(".out.lock"),
        "{}",
        second.describe()
    );
    long.wait(RUN_TIMEOUT).assert_ok();
    assert_complete(&out, 200.0);
    assert_eq!(entries(tmp.path()), BTreeSet::from(["out".into()]));

    // Two 10 s runs started together: each succeeds or is refused by the
    // lock, never a lost or half result.
    for _ in 0..4 {
        let (a, b) = (run(&tmp, &out, 10).spawn(), run(&tmp, &out, 10).spawn());
        let ends: Vec<Finished> = vec![a.wait(RUN_TIMEOUT), b.wait(RUN_TIMEOUT)];
        for f in &ends {
            if f.code() != Some(0) {
                f.assert_code(2);
                assert!(f.stderr.contains(".out.lock"), "{}", f.describe());
            }
        }
        assert!(ends.iter().any(|f| f.code() == Some(0)));
        assert_complete(&out, 10.0);
        assert_eq!(entries(tmp.path()), BTreeSet::from(["out".into()]));
    }
}

#[test]
fn a_dead_runs_staging_directory_is_removed() {
    let tmp = Sandbox::new("results_dir_stale");
    let stale = tmp.join(".x.partial-999999");
    fs::create_dir_all(stale.join("logs")).unwrap();
    fs::write(stale.join("errors.csv"), "half").unwrap();
    let out = tmp.join("x");
    run(&tmp, &out, 10).output().assert_ok();
    assert_complete(&out, 10.0);
    assert_eq!(entries(tmp.path()), BTreeSet::from(["x".into()]));
}
