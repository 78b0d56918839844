//! Divergence is a failure, said plainly (issue 11 item 1), and telemetry
//! is validated like states (issue 10 item 6).
//!
//! An unstable integration (here: the paper's scheme 1 with a huge k_σ,
//! and the 100-agent tree of `attsync gen tree --seed 1` with k_σ raised to
//! 1536 at dt = 1 ms, as the generator once wrote it, run with
//! `--no-stiffness-check`) must stop at once in both engines with exit code 3,
//! `complete: false` and the same `diverged { t, node, quantity, value }`;
//! what was recorded before is kept and byte-identical between the engines,
//! and no row of `errors.csv` invents an error (no `1` for a NaN state). A
//! plug-in that reports garbage in its telemetry fails the run, named.

use attsync_tests::{
    Attsync, Finished, Sandbox, assert_same_results, broken_agent, paper, read, run_args, summary,
    with_agent_lines,
};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The exit code of a diverged run (README, `attsync::Error::exit_code`).
const DIVERGED: i32 = 3;

/// Runs `scenario` with both engines, expects both to diverge, asserts the
/// same results and returns the processes run's summary.
fn diverges_alike(tmp: &Sandbox, scenario: &Path, sets: &[&str]) -> Value {
    diverges_alike_with(tmp, scenario, sets, &[])
}

/// [`diverges_alike`] with more `attsync run` arguments.
fn diverges_alike_with(tmp: &Sandbox, scenario: &Path, sets: &[&str], more: &[&str]) -> Value {
    let (p, i) = (tmp.join("processes"), tmp.join("in-process"));
    let processes = Attsync::new(tmp.path())
        .args(run_args(scenario, "processes", &p, sets))
        .args(more.iter().copied())
        .output();
    processes.assert_code(DIVERGED).assert_no_leftovers();
    let in_process = Attsync::new(tmp.path())
        .args(run_args(scenario, "in-process", &i, sets))
        .args(more.iter().copied())
        .output();
    in_process.assert_code(DIVERGED);
    assert_same_results(&p, &i);
    let s = summary(&p);
    assert_eq!(s["complete"], false, "{s:#}");
    assert_eq!(summary(&i)["diverged"], s["diverged"]);
    let reason = s["incomplete_reason"]
        .as_str()
        .expect("a reason")
        .to_owned();
    assert!(reason.starts_with("diverged at t = "), "{reason}");
    assert!(
        processes.stderr.contains(&reason),
        "{}",
        processes.describe()
    );
    assert_no_invented_errors(&p.join("errors.csv"));
    s
}

/// No row of `errors.csv` pairs an attitude error of exactly 1 with a NaN
/// (a NaN state clamped to 1), and a NaN is written as NaN.
fn assert_no_invented_errors(csv: &Path) {
    for row in read(csv).lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let nan = f.contains(&"NaN");
        assert!(
            !(nan && (f[2] == "1" || f[4] == "1")),
            "invented error: {row}"
        );
        if nan {
            assert!(f[2] == "NaN", "a NaN state with a finite att_err: {row}");
        }
    }
}

/// The paper's scheme 1 with k_σ = 700: σ̂ explodes within a few steps.
const STIFF: [&str; 2] = ["simulation.duration=1", "scheme.observer.k_sigma=700"];

#[test]
fn a_state_beyond_the_envelope_stops_both_engines_alike() {
    let tmp = Sandbox::new("diverge-envelope");
    let s = diverges_alike(&tmp, &paper("timevarying"), &STIFF);
    let d = &s["diverged"];
    assert_eq!(d["quantity"], "sigma_hat", "{s:#}");
    assert!(d["value"].as_f64().is_some_and(|v| v > 1e4), "{s:#}");
    assert!(d["t"].as_f64().is_some_and(|t| t > 0.0 && t < 1.0), "{s:#}");
    let reason = s["incomplete_reason"].as_str().unwrap();
    let node = d["node"].as_str().unwrap();
    assert!(
        reason.contains(&format!("{node}'s sigma_hat = ")) && reason.contains("the envelope 1e4"),
        "{reason}"
    );
}

#[test]
fn a_nan_state_stops_both_engines_alike_and_reads_back_as_nan() {
    let tmp = Sandbox::new("diverge-nan");
    // An envelope so wide that only a non-finite value trips it.
    let wide = [
        "guard.omega=1e300",
        "guard.omega_hat=1e300",
        "guard.sigma_hat=1e300",
    ];
    let sets: Vec<&str> = STIFF.iter().chain(&wide).copied().collect();
    let s = diverges_alike(&tmp, &paper("timevarying"), &sets);
    let d = &s["diverged"];
    assert!(d["value"].is_null(), "a NaN is written as null: {s:#}");
    let t = d["t"].as_f64().expect("t");
    // Samples before the divergence are kept (every 0.01 s).
    let rows = read(&tmp.join("processes/errors.csv")).lines().count() - 1;
    assert_eq!(rows, 7 * ((t / 0.01).ceil() as usize), "{s:#}");
    assert!(t > 0.01, "{s:#}");
}

#[test]
fn the_generated_100_agent_tree_diverges_alike_in_both_engines() {
    let tmp = Sandbox::new("diverge-tree");
    let tree = tmp.join("t.toml");
    Attsync::new(tmp.path())
        .args([
            "gen",
            "tree",
            "--agents",
            "100",
            "--leader-links",
            "3",
            "--seed",
            "1",
        ])
        .args(["--out".as_ref(), tree.as_os_str()])
        .output()
        .assert_ok();
    // The generator now picks stable gains and dt; the stiff
    // version (k_σ raised alone to 1536 at dt = 1 ms) is refused by
    // validation, naming dt and a step that works …
    let stiff = [
        "simulation.duration=2",
        "scheme.observer.k_sigma=1536",
        "scheme.observer.k_omega=14",
    ];
    let mut check = vec!["check".to_string(), tree.to_string_lossy().into_owned()];
    for s in &stiff {
        check.extend(["--set".to_string(), (*s).to_string()]);
    }
    let refused = Attsync::new(tmp.path()).args(&check).output();
    refused.assert_code(2);
    assert!(
        refused.stderr.contains("simulation.dt") && refused.stderr.contains("--set simulation.dt="),
        "{}",
        refused.describe()
    );
    // … and forced past validation it stops as diverged in both engines.
    let s = diverges_alike_with(&tmp, &tree, &stiff, &["--no-stiffness-check"]);
    let reason = s["incomplete_reason"].as_str().unwrap_or_default();
    assert!(
        reason.contains("probable cause: dt = 0.001 s exceeds the largest stable RK4 step"),
        "{reason}"
    );
    assert!(
        s["diverged"]["node"]
            .as_str()
            .is_some_and(|n| n.starts_with("agent-"))
    );
    assert!(
        s["max_final_att_err"].as_f64().is_some_and(|e| e < 1.0),
        "{s:#}"
    );
}

/// The observerless paper scenario with agent 3 the fixture `broken_agent`
/// injecting `fault`.
fn with_broken_agent_3(tmp: &Sandbox, fault: &str) -> PathBuf {
    let base = paper("constant-observerless");
    with_agent_lines(tmp, &base, 3, fault, &broken_agent(fault))
}

/// Runs [`with_broken_agent_3`] (processes engine, 0.5 s) into `tmp/out`;
/// the run and `out`.
fn run_with_broken_agent_3(tmp: &Sandbox, fault: &str) -> (Finished, PathBuf) {
    let scenario = with_broken_agent_3(tmp, fault);
    let out = tmp.join("out");
    let sets = ["simulation.duration=0.5"];
    let r = Attsync::new(tmp.path())
        .args(run_args(&scenario, "processes", &out, &sets))
        .output();
    (r, out)
}

#[test]
fn a_plugin_reporting_nan_telemetry_diverges_named() {
    let tmp = Sandbox::new("nan-telemetry");
    let (r, out) = run_with_broken_agent_3(&tmp, "nan-telemetry");
    r.assert_code(DIVERGED).assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], false);
    let d = &s["diverged"];
    assert_eq!(
        (&d["node"], &d["quantity"]),
        (&"agent-3".into(), &"omega".into()),
        "{s:#}"
    );
    assert_eq!(d["t"], 0.01, "{s:#}");
    assert!(d["value"].is_null(), "{s:#}");
    let reason = s["incomplete_reason"].as_str().unwrap();
    assert!(reason.contains("agent-3's omega is NaN"), "{reason}");
    // Only the sample before the garbage is kept.
    assert_eq!(read(&out.join("errors.csv")).lines().count(), 1 + 7);
}

#[test]
fn a_plugin_reporting_a_non_rotation_breaks_the_protocol_named() {
    let tmp = Sandbox::new("bad-telemetry");
    let (r, out) = run_with_broken_agent_3(&tmp, "bad-telemetry");
    r.assert_code(1).assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], false);
    assert!(s.get("diverged").is_none(), "{s:#}");
    let reason = s["incomplete_reason"].as_str().unwrap();
    assert!(
        reason.starts_with("agent-3 (plug-in `")
            && reason.contains(
                "broke the protocol: it sent telemetry whose attitude r is not a rotation"
            ),
        "{reason}"
    );
}
