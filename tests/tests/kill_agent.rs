//! An agent process killed with SIGKILL in the middle of a run.
//!
//! `attsync run` of the paper's time-varying scenario (40 s simulated) with
//! the processes engine; once agent 3 has logged `started` and the first
//! rows of `errors.csv` are written, agent 3's process (found by its command
//! line `attsync-agent --config <tmp>/attsync-iox2/<run>/node-3.json`, where
//! `<run>`'s `owner` file holds the orchestrator's pid) gets `kill -9`.
//! Asserts:
//! - `attsync` ends (within 60 s, else it is killed and the test fails) with
//!   exit code 1, and its stderr names `agent-3` and `killed by signal 9`;
//! - the results directory exists (no staging directory left) with the dead
//!   node's log `logs/agent-3.log`, and `summary.json` says
//!   `"complete": false` with an `incomplete_reason` naming agent-3 and every
//!   agent's peak torque so far (non-zero);
//! - `errors.csv` keeps the rows so far: every agent at every sample up to
//!   `t_end`, exactly the first rows of an in-process run of the scenario;
//! - within 10 s no process with an argument in the run's root directory
//!   remains, and neither `/dev/shm/as<run>_*` nor `<tmp>/attsync-iox2/<run>`.
//!
//! One more test (ignored: it fails, see its reason) checks that the log the
//! failure message points to exists.

use attsync_tests::{
    Attsync, Finished, Sandbox, csv_agents, csv_rows, kill9, node_pid, owned_run, paper, read,
    run_args, run_leftovers, run_processes, staging_dir, summary, wait_until,
};
use serde_json::Value;
use std::path::PathBuf;
use std::time::Duration;

const POLL: Duration = Duration::from_millis(20);

/// A run whose agent 3 was killed.
struct Killed {
    tmp: Sandbox,
    out: PathBuf,
    run: String,
    staging: PathBuf,
    finished: Finished,
}

fn kill_agent_3(test: &str) -> Killed {
    let tmp = Sandbox::new(test);
    let out = tmp.join("results");
    let running = Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "processes",
            &out,
            &["simulation.duration=40"],
        ))
        .spawn();
    let pid = running.pid();
    let staging = staging_dir(&out, pid);
    // Wait until agent 3 is stepping (or attsync ended: then fail with its output).
    let running = running.once_stepping(&staging, "agent-3");
    let run = owned_run(pid);
    let agent =
        wait_until(Duration::from_secs(10), POLL, || node_pid(&run, 3)).unwrap_or_else(|| {
            panic!(
                "no attsync-agent process for node 3 of run {run}: {:#?}",
                run_processes(&run)
            )
        });
    assert!(kill9(agent), "kill -9 {agent} failed");
    let finished = running.wait(Duration::from_secs(60));
    Killed {
        tmp,
        out,
        run,
        staging,
        finished,
    }
}

#[test]
fn killed_agent_fails_the_run_and_everything_is_cleaned_up() {
    let k = kill_agent_3("kill-agent");
    let f = &k.finished;
    f.assert_code(1);
    assert!(f.stderr.contains("agent-3"), "{}", f.describe());
    assert!(f.stderr.contains("killed by signal 9"), "{}", f.describe());

    // Results so far, marked incomplete.
    assert!(k.out.is_dir(), "no results directory\n{}", f.describe());
    assert!(
        !k.staging.exists(),
        "staging directory {} left",
        k.staging.display()
    );
    let log = read(&k.out.join("logs/agent-3.log"));
    assert!(log.contains("started"), "agent-3.log: {log}");
    let s = summary(&k.out);
    assert_eq!(s["complete"], false, "{s:#}");
    let reason = s["incomplete_reason"].as_str().unwrap_or_default();
    assert!(reason.contains("agent-3"), "{s:#}");
    let t_end = s["t_end"].as_f64().expect("t_end");
    assert!(t_end < 40.0, "the run cannot have reached its end: {s:#}");
    // Peak torques so far (every agent applies a non-zero torque from the
    // first step on), not only those of nodes that reported `Done`.
    let agents = s["agents"].as_array().expect("agents");
    let zero: Vec<&Value> = agents
        .iter()
        .filter(|a| a["peak_torque"].as_f64().unwrap_or(0.0) <= 0.0)
        .map(|a| &a["id"])
        .collect();
    assert!(
        zero.is_empty(),
        "agents {zero:?} report peak_torque 0: {s:#}"
    );
    let csv = read(&k.out.join("errors.csv"));
    assert_eq!(csv_agents(&csv), (1..=7).collect(), "agents in errors.csv");
    let samples = (t_end / 0.01).round() as usize + 1;
    assert_eq!(
        csv_rows(&csv),
        7 * samples,
        "rows of errors.csv up to t_end = {t_end}"
    );
    let last_t: f64 = csv
        .lines()
        .last()
        .and_then(|l| l.split(',').next())
        .and_then(|t| t.parse().ok())
        .expect("a last row");
    assert!(
        (last_t - t_end).abs() < 1e-9,
        "last row at {last_t}, t_end {t_end}"
    );

    // The rows kept are the beginning of the complete trajectory.
    let full = k.tmp.join("in-process");
    Attsync::new(k.tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "in-process",
            &full,
            &["simulation.duration=40"],
        ))
        .output()
        .assert_ok();
    let full = read(&full.join("errors.csv"));
    let n = csv.lines().count();
    let kept: Vec<&str> = csv.lines().collect();
    let expected: Vec<&str> = full.lines().take(n).collect();
    if let Some(i) = (0..n).find(|&i| kept[i] != expected[i]) {
        panic!(
            "errors.csv of the killed run differs from the in-process run at line {}:\n  {}\n  {}",
            i + 1,
            kept[i],
            expected[i]
        );
    }

    // Nothing left running, nothing left in the namespace.
    let remaining = wait_until(Duration::from_secs(10), POLL, || {
        run_processes(&k.run).is_empty().then_some(())
    });
    assert!(
        remaining.is_some(),
        "node processes of run {} still alive after 10 s: {:#?}",
        k.run,
        run_processes(&k.run)
    );
    let left = run_leftovers(&k.run);
    assert!(left.is_empty(), "run {} left {left:#?}", k.run);
    f.assert_no_leftovers();
}

/// The reason points the user at the dead node's log: that file must exist
/// where the results are.
#[test]
fn incomplete_reason_names_an_existing_log() {
    let k = kill_agent_3("kill-agent-log");
    k.finished.assert_code(1);
    assert!(k.out.join("logs/agent-3.log").is_file());
    let s = summary(&k.out);
    let reason = s["incomplete_reason"].as_str().unwrap_or_default();
    let log = reason
        .split("(logs/")
        .nth(1)
        .and_then(|r| r.split(" in the results directory").next())
        .map(|name| k.out.join("logs").join(name))
        .unwrap_or_else(|| panic!("the reason names no log: {reason:?}"));
    assert!(
        log.is_file(),
        "the reason names {}, which does not exist (reason: {reason:?})",
        log.display()
    );
}
