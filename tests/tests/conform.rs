//! `attsync conform`: passes for conforming agents (the built-in one, the
//! Rust saturated example) and fails, with the right reason, for deliberately
//! broken ones (`tests/src/bin/broken_agent.rs`, fault from `ATTSYNC_FAULT`).
//! Also: what the same faults do inside a real run.

use attsync_tests::{
    Attsync, Finished, Sandbox, bin, broken_agent, paper, rule_line, run_args, run_conform,
    summary, with_agent_lines,
};

/// `attsync conform -- PROGRAM` (a workspace binary) in a new sandbox
/// named `test`, with `ATTSYNC_FAULT=fault` if given.
fn conform(test: &str, program: &str, fault: Option<&str>) -> (Finished, Sandbox) {
    let tmp = Sandbox::new(test);
    let env: Vec<(&str, &str)> = fault.map(|f| ("ATTSYNC_FAULT", f)).into_iter().collect();
    let r = run_conform(&tmp, &[], &[bin(program).into()], &env);
    (r, tmp)
}

#[test]
fn the_builtin_agent_conforms() {
    let (r, _t) = conform("conform-builtin", "attsync-agent", None);
    r.assert_ok();
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn the_saturated_rust_example_conforms() {
    // It saturates in the neighbourhood (τ_max = 5 N·m): its law is its own.
    let tmp = Sandbox::new("conform-saturated");
    let law = ["--law".into(), "own".into()];
    let r = run_conform(&tmp, &law, &[bin("saturated-agent").into()], &[]);
    r.assert_ok();
    assert!(r.stdout.contains("9/9 rules pass"), "{}", r.describe());
}

#[test]
fn a_wrong_payload_type_fails_to_connect() {
    let (r, _t) = conform("conform-wrong-type", "broken_agent", Some("wrong-type"));
    r.assert_code(1);
    let l = rule_line(&r, "connects");
    assert!(
        l.starts_with("FAIL") && l.contains("IncompatibleTypes"),
        "{l}\n{}",
        r.describe()
    );
    assert!(
        rule_line(&r, "in-order").starts_with("SKIP"),
        "{}",
        r.describe()
    );
    assert!(
        rule_line(&r, "version").starts_with("PASS"),
        "{}",
        r.describe()
    );
}

#[test]
fn a_skipped_step_breaks_in_order() {
    let (r, _t) = conform("conform-skip-step", "broken_agent", Some("skip-step"));
    r.assert_code(1);
    let l = rule_line(&r, "in-order");
    assert!(
        l.starts_with("FAIL") && l.contains("sent step 4 stage 0 where step 3 stage 0 was due"),
        "{l}\n{}",
        r.describe()
    );
    assert!(rule_line(&r, "connects").starts_with("PASS"));
}

#[test]
fn a_nan_state_is_not_valid() {
    let (r, _t) = conform("conform-nan", "broken_agent", Some("nan"));
    r.assert_code(1);
    let l = rule_line(&r, "valid-states");
    assert!(
        l.starts_with("FAIL") && l.contains("NaN"),
        "{l}\n{}",
        r.describe()
    );
    for ok in [
        "in-order",
        "waits-for-inputs",
        "telemetry",
        "stops",
        "clean",
    ] {
        assert!(
            rule_line(&r, ok).starts_with("PASS"),
            "{ok}\n{}",
            r.describe()
        );
    }
}

#[test]
fn an_agent_that_never_stops_fails_stops_and_is_killed() {
    let (r, _t) = conform("conform-never-stops", "broken_agent", Some("never-stops"));
    r.assert_code(1);
    let l = rule_line(&r, "stops");
    assert!(
        l.starts_with("FAIL") && l.contains("still running"),
        "{l}\n{}",
        r.describe()
    );
    assert!(
        rule_line(&r, "telemetry").starts_with("PASS"),
        "{}",
        r.describe()
    );
    r.assert_no_leftovers();
}

/// The observerless paper scenario with agent 3 the broken agent.
fn broken_scenario(tmp: &Sandbox, fault: &str) -> std::path::PathBuf {
    let base = paper("constant-observerless");
    with_agent_lines(tmp, &base, 3, "broken", &broken_agent(fault))
}

#[test]
fn nan_values_from_a_plugin_are_refused_counted_and_do_not_poison_the_run() {
    let tmp = Sandbox::new("run-nan");
    let out = tmp.join("out");
    Attsync::new(tmp.path())
        .args(run_args(
            &broken_scenario(&tmp, "nan"),
            "processes",
            &out,
            &[],
        ))
        .output()
        .assert_ok()
        .assert_no_leftovers();
    let s = summary(&out);
    assert_eq!(s["complete"], true);
    let max = s["max_final_att_err"].as_f64().unwrap();
    assert!(max < 1e-3, "the run did not converge: {max}");
    let links = s["links"].as_array().unwrap();
    let from3: Vec<_> = links.iter().filter(|l| l["from"] == 3).collect();
    assert_eq!(from3.len(), 3, "{s:#}"); // 3 → 1, 5, 6
    for l in from3 {
        assert_eq!(l["rejected"], 1, "{l}");
    }
    assert!(links.iter().all(|l| l["from"] == 3), "{s:#}");
}

#[test]
fn a_plugin_that_breaks_lockstep_is_named() {
    let tmp = Sandbox::new("run-skip-step");
    let out = tmp.join("out");
    let r = Attsync::new(tmp.path())
        .args(run_args(
            &broken_scenario(&tmp, "skip-step"),
            "processes",
            &out,
            &[],
        ))
        .output();
    r.assert_code(1).assert_no_leftovers();
    assert!(
        r.stderr.contains("agent-3 (plug-in `") && r.stderr.contains("broke the protocol"),
        "{}",
        r.describe()
    );
}
