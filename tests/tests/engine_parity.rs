//! The process-per-agent engine against the in-process engine.
//!
//! Every node's arithmetic depends only on its own state and the values it
//! holds, so an engine that delivers the same values must produce
//! bit-identical trajectories (ARCHITECTURE.md, "The step protocol"). Each
//! test runs a scenario with `--engine processes` (one OS process per node,
//! iceoryx2 in lockstep) and with `--engine in-process` and asserts:
//! - both exit 0;
//! - `errors.csv`, `states.bin` and `scenario.toml` are byte-identical, and
//!   `summary.json` is equal except `engine` and `wall_seconds` (so the peak
//!   torques and settle times agree too);
//! - the processes run left no iceoryx2 files (its `<tmp>/attsync-iox2/<run>`
//!   directory and `/dev/shm/as<run>_*`) behind.
//!
//! Covered: the three paper scenarios (2 s each), sampled coupling, every
//! `--wait` strategy, and two processes runs in a row (determinism).

use attsync_tests::{
    Attsync, Sandbox, assert_same_results, paper, read, reference_run, run_args, summary,
};
use std::path::Path;

const TWO_SECONDS: &str = "simulation.duration=2";

/// Runs `scenario` with both engines (`extra` only for the processes run)
/// and asserts identical results.
fn parity(test: &str, scenario: &Path, sets: &[&str], extra: &[&str]) -> Sandbox {
    let tmp = Sandbox::new(test);
    let (p, i) = (tmp.join("processes"), tmp.join("in-process"));
    Attsync::new(tmp.path())
        .args(run_args(scenario, "processes", &p, sets))
        .args(extra)
        .output()
        .assert_ok()
        .assert_no_leftovers();
    reference_run(tmp.path(), scenario, &i, sets);
    assert_same_results(&p, &i);
    let s = summary(&p);
    assert_eq!(s["engine"], "processes");
    assert_eq!(s["complete"], true, "{s:#}");
    tmp
}

#[test]
fn paper_timevarying() {
    parity("timevarying", &paper("timevarying"), &[TWO_SECONDS], &[]);
}

#[test]
fn paper_constant_observer() {
    parity(
        "constant-observer",
        &paper("constant-observer"),
        &[TWO_SECONDS],
        &[],
    );
}

#[test]
fn paper_constant_observerless() {
    parity(
        "constant-observerless",
        &paper("constant-observerless"),
        &[TWO_SECONDS],
        &[],
    );
}

/// Sampled coupling (exchange at stage 0 of every 10th step, hold between):
/// the same in both engines, and really different from continuous coupling.
#[test]
fn sampled_coupling() {
    let tmp = parity(
        "sampled",
        &paper("timevarying"),
        &[
            TWO_SECONDS,
            "simulation.coupling=sampled",
            "simulation.period=0.01",
        ],
        &[],
    );
    let effective = read(&tmp.join("processes/scenario.toml"));
    assert!(
        effective.contains("coupling = \"sampled\""),
        "--set did not reach the scenario:\n{effective}"
    );
    let continuous = tmp.join("continuous");
    Attsync::new(tmp.path())
        .args(run_args(
            &paper("timevarying"),
            "in-process",
            &continuous,
            &[TWO_SECONDS],
        ))
        .output()
        .assert_ok();
    assert_ne!(
        read(&continuous.join("errors.csv")),
        read(&tmp.join("processes/errors.csv")),
        "sampled and continuous coupling gave the same errors: the test would prove nothing"
    );
}

/// Busy polling: 8 spinning processes on few cores are slow, so 0.1 s only.
#[test]
fn wait_spin() {
    parity(
        "wait-spin",
        &paper("timevarying"),
        &["simulation.duration=0.1"],
        &["--wait", "spin"],
    );
}

#[test]
fn wait_yield() {
    parity(
        "wait-yield",
        &paper("timevarying"),
        &[TWO_SECONDS],
        &["--wait", "yield"],
    );
}

#[test]
fn wait_block() {
    parity(
        "wait-block",
        &paper("timevarying"),
        &[TWO_SECONDS],
        &["--wait", "block"],
    );
}

#[test]
fn wait_adaptive() {
    parity(
        "wait-adaptive",
        &paper("timevarying"),
        &[TWO_SECONDS],
        &["--wait", "adaptive"],
    );
}

/// Two processes runs of the same scenario, one after the other, give the
/// same results (every file but the wall-clock time). 5 s of the
/// time-varying scenario: agent 5 starts on the invariant set of an unstable
/// equilibrium and leaves it (≈ 3 s) at a time set by round-off, the part
/// most sensitive to any difference.
#[test]
fn processes_engine_is_deterministic() {
    let tmp = Sandbox::new("determinism");
    let dirs = [tmp.join("first"), tmp.join("second")];
    for d in &dirs {
        Attsync::new(tmp.path())
            .args(run_args(
                &paper("timevarying"),
                "processes",
                d,
                &["simulation.duration=5"],
            ))
            .output()
            .assert_ok()
            .assert_no_leftovers();
    }
    assert_same_results(&dirs[0], &dirs[1]);
}
