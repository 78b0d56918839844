//! SIGTERM and SIGHUP stop a run like Ctrl-C (SIGINT).
//!
//! `attsync run` of the paper's time-varying scenario, with the processes
//! engine and in-process; once the first rows of `errors.csv` are written
//! (and, for the processes engine, the run's namespace and node processes
//! exist), `attsync` gets SIGTERM or SIGHUP. Asserts:
//! - exit code 128 + the signal's number (143, 129);
//! - the results are kept: `summary.json` says `"complete": false` with
//!   `incomplete_reason` `interrupted by SIGTERM` (`SIGHUP`), and
//!   `errors.csv` is there;
//! - nothing is left behind: no staging directory `.NAME.partial-PID`, no
//!   node process of the run (within 10 s), neither `/dev/shm/as<run>_*` nor
//!   `<tmp>/attsync-iox2/<run>`.

use attsync_tests::{
    Attsync, Finished, Running, Sandbox, csv_rows, iox_base, owned_runs, paper, read, run_args,
    run_leftovers, run_processes, signal, staging_dir, summary, wait_until,
};
use std::path::{Path, PathBuf};
use std::time::Duration;

const POLL: Duration = Duration::from_millis(20);

/// Waits until `running` has written rows of `errors.csv` into `staging`;
/// panics with its output if it ended before.
fn wait_for_rows(running: &mut Running, staging: &Path) {
    let csv = staging.join("errors.csv");
    let rows = wait_until(Duration::from_secs(60), POLL, || {
        if running.has_ended() {
            return Some(false);
        }
        std::fs::metadata(&csv)
            .is_ok_and(|m| m.len() > 0)
            .then_some(true)
    });
    match rows {
        Some(true) => {}
        Some(false) => panic!("attsync ended before it was signalled: {}", csv.display()),
        None => panic!("{} stayed empty for 60 s", csv.display()),
    }
}

/// Starts a long run with `engine`, sends `sig` (`TERM`, `HUP`) mid-run.
/// Returns the results directory, the run's namespace (processes engine),
/// the staging directory and how attsync ended.
fn signalled(
    tmp: &Sandbox,
    engine: &str,
    sig: &str,
) -> (PathBuf, Option<String>, PathBuf, Finished) {
    let out = tmp.join("results");
    // Long enough that neither engine finishes before the signal.
    let duration = if engine == "processes" { 40 } else { 4000 };
    let mut running = Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            engine,
            &out,
            &[&format!("simulation.duration={duration}")],
        ))
        .spawn();
    let pid = running.pid();
    let staging = staging_dir(&out, pid);
    wait_for_rows(&mut running, &staging);
    let run = (engine == "processes").then(|| {
        wait_until(Duration::from_secs(10), POLL, || {
            owned_runs(pid).into_iter().next()
        })
        .unwrap_or_else(|| panic!("no {}/*/owner holds pid {pid}", iox_base().display()))
    });
    if let Some(run) = &run {
        assert!(!run_processes(run).is_empty(), "no node process of {run}");
    }
    assert!(signal(pid, sig), "kill -{sig} {pid} failed");
    let finished = running.wait(Duration::from_secs(60));
    (out, run, staging, finished)
}

fn check(engine: &str, sig: &str, name: &str, code: i32) {
    let tmp = Sandbox::new(&format!("signal-{}-{engine}", sig.to_lowercase()));
    let (out, run, staging, f) = signalled(&tmp, engine, sig);
    f.assert_code(code);
    let s = summary(&out);
    assert_eq!(s["complete"], false, "{s:#}\n{}", f.describe());
    assert_eq!(
        s["incomplete_reason"].as_str(),
        Some(format!("interrupted by {name}").as_str()),
        "{s:#}"
    );
    let csv = read(&out.join("errors.csv"));
    assert!(csv_rows(&csv) > 0, "errors.csv has no rows");
    assert!(!staging.exists(), "{} left behind", staging.display());
    if let Some(run) = &run {
        let gone = wait_until(Duration::from_secs(10), POLL, || {
            run_processes(run).is_empty().then_some(())
        });
        assert!(gone.is_some(), "left running: {:#?}", run_processes(run));
        assert!(run_leftovers(run).is_empty(), "{:?}", run_leftovers(run));
    }
    f.assert_no_leftovers();
}

#[test]
fn sigterm_stops_a_process_run_keeping_its_results() {
    check("processes", "TERM", "SIGTERM", 143);
}

#[test]
fn sighup_stops_a_process_run_keeping_its_results() {
    check("processes", "HUP", "SIGHUP", 129);
}

#[test]
fn sigterm_stops_an_in_process_run_keeping_its_results() {
    check("in-process", "TERM", "SIGTERM", 143);
}

#[test]
fn sighup_stops_an_in_process_run_keeping_its_results() {
    check("in-process", "HUP", "SIGHUP", 129);
}

#[test]
fn sigint_stops_a_process_run_with_130() {
    check("processes", "INT", "SIGINT", 130);
}
