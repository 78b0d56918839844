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

/// Whether process `pid` has a thread named `name` (its `comm`).
fn has_thread(pid: u32, name: &str) -> bool {
    use attsync_sched::process::{thread_name, threads};
    (threads(pid).into_iter()).any(|tid| thread_name(pid, tid).is_some_and(|c| c.trim() == name))
}

/// A signal before anything is written — here attsync is blocked opening
/// its scenario, a FIFO nobody writes to, as it would be reading and
/// validating a large one — ends attsync at once with 128 + the signal's
/// number, naming it, and leaves nothing (no `--out`, no lock, no staging).
#[test]
fn sigterm_while_the_scenario_is_read_ends_attsync_at_once() {
    let tmp = Sandbox::new("signal-term-loading");
    let fifo = tmp.join("scenario.toml");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    assert!(made.is_ok_and(|s| s.success()), "mkfifo {}", fifo.display());
    let out = tmp.join("results");
    let running = Attsync::new(tmp.path())
        .args(run_args(&fifo, "processes", &out, &[]))
        .spawn();
    let pid = running.pid();
    // The handler's watching thread exists: the signal comes after install.
    let installed = wait_until(Duration::from_secs(10), POLL, || {
        has_thread(pid, "attsync-signals").then_some(())
    });
    assert!(installed.is_some(), "no thread attsync-signals in {pid}");
    std::thread::sleep(Duration::from_millis(200));
    assert!(signal(pid, "TERM"), "kill -TERM {pid} failed");
    let f = running.wait(Duration::from_secs(10));
    f.assert_code(143);
    assert!(
        f.stderr.contains("interrupted by SIGTERM"),
        "{}",
        f.describe()
    );
    let left: Vec<_> = std::fs::read_dir(tmp.path())
        .expect("the sandbox")
        .flatten()
        .map(|e| e.file_name())
        .filter(|n| n != "scenario.toml")
        .collect();
    assert!(left.is_empty(), "left in the sandbox: {left:?}");
    f.assert_no_leftovers();
}

/// SIGTERM between two samples far apart (20 000 s of simulated time, some
/// 20 million steps) stops an in-process run within a step, not at the next
/// sample: exit 143, the results so far kept (the sample at t = 0),
/// `summary.json` counting the steps that were recorded.
#[test]
fn sigterm_between_far_samples_stops_an_in_process_run_at_once() {
    let tmp = Sandbox::new("signal-term-far-samples");
    let out = tmp.join("results");
    let sets = ["simulation.duration=40000", "output.sample_period=20000"];
    let mut running = Attsync::new(tmp.path())
        .args(run_args(&paper("timevarying"), "in-process", &out, &sets))
        .spawn();
    let pid = running.pid();
    // The rows of t = 0 sit in a buffer until the run ends: wait for the
    // staging directory, then for the engine to be well inside the steps.
    let marker = staging_dir(&out, pid).join(".attsync-run");
    let staged = wait_until(Duration::from_secs(60), POLL, || {
        (running.has_ended() || marker.exists()).then_some(())
    });
    assert!(staged.is_some() && !running.has_ended(), "never staged");
    std::thread::sleep(Duration::from_millis(1500));
    assert!(!running.has_ended(), "ended before it was signalled");
    assert!(signal(pid, "TERM"), "kill -TERM {pid} failed");
    let f = running.wait(Duration::from_secs(5));
    f.assert_code(143);
    let s = summary(&out);
    assert_eq!(s["complete"], false, "{s:#}");
    assert_eq!(s["incomplete_reason"], "interrupted by SIGTERM", "{s:#}");
    assert_eq!(s["steps"], 0, "the last recorded sample is t = 0: {s:#}");
    assert_eq!(csv_rows(&read(&out.join("errors.csv"))), 7, "t = 0's rows");
    f.assert_no_leftovers();
}
