//! `attsync conform`: passes for conforming agents (the built-in one, the
//! Rust saturated example) and fails, with the right reason, for deliberately
//! broken ones (`tests/src/bin/broken_agent.rs`, fault from `ATTSYNC_FAULT`).
//! Also: what the same faults do inside a real run.

use attsync_tests::{Attsync, Finished, Sandbox, bin, paper, read, run_args, summary};

fn conform(test: &str, program: &str, fault: Option<&str>) -> (Finished, Sandbox) {
    let tmp = Sandbox::new(test);
    let mut a = Attsync::new(tmp.path())
        .args(["conform", "--log"])
        .args([tmp.join("candidate.log")]);
    if let Some(f) = fault {
        a = a.env("ATTSYNC_FAULT", f);
    }
    let r = a.args(["--".into(), bin(program)]).output();
    (r, tmp)
}

/// The report line of `rule`, with its reason line(s).
fn line<'a>(r: &'a Finished, rule: &str) -> &'a str {
    let start = r
        .stdout
        .find(&format!("  {rule} "))
        .unwrap_or_else(|| panic!("no rule {rule}:\n{}", r.describe()));
    let start = r.stdout[..start].rfind('\n').map_or(0, |i| i + 1);
    let end = r.stdout[start + 6..]
        .find("\nPASS")
        .or_else(|| r.stdout[start + 6..].find("\nFAIL"))
        .or_else(|| r.stdout[start + 6..].find("\nSKIP"))
        .map_or(r.stdout.len(), |e| start + 6 + e);
    &r.stdout[start..end]
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
    let r = Attsync::new(tmp.path())
        .args(["conform", "--law", "own", "--log"])
        .args([tmp.join("candidate.log")])
        .args(["--".into(), bin("saturated-agent")])
        .output();
    r.assert_ok();
    assert!(r.stdout.contains("9/9 rules pass"), "{}", r.describe());
}

#[test]
fn a_wrong_payload_type_fails_to_connect() {
    let (r, _t) = conform("conform-wrong-type", "broken_agent", Some("wrong-type"));
    r.assert_code(1);
    let l = line(&r, "connects");
    assert!(
        l.starts_with("FAIL") && l.contains("IncompatibleTypes"),
        "{l}\n{}",
        r.describe()
    );
    assert!(line(&r, "in-order").starts_with("SKIP"), "{}", r.describe());
    assert!(line(&r, "version").starts_with("PASS"), "{}", r.describe());
}

#[test]
fn a_skipped_step_breaks_in_order() {
    let (r, _t) = conform("conform-skip-step", "broken_agent", Some("skip-step"));
    r.assert_code(1);
    let l = line(&r, "in-order");
    assert!(
        l.starts_with("FAIL") && l.contains("sent step 4 stage 0 where step 3 stage 0 was due"),
        "{l}\n{}",
        r.describe()
    );
    assert!(line(&r, "connects").starts_with("PASS"));
}

#[test]
fn a_nan_state_is_not_valid() {
    let (r, _t) = conform("conform-nan", "broken_agent", Some("nan"));
    r.assert_code(1);
    let l = line(&r, "valid-states");
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
        assert!(line(&r, ok).starts_with("PASS"), "{ok}\n{}", r.describe());
    }
}

#[test]
fn an_agent_that_never_stops_fails_stops_and_is_killed() {
    let (r, _t) = conform("conform-never-stops", "broken_agent", Some("never-stops"));
    r.assert_code(1);
    let l = line(&r, "stops");
    assert!(
        l.starts_with("FAIL") && l.contains("still running"),
        "{l}\n{}",
        r.describe()
    );
    assert!(
        line(&r, "telemetry").starts_with("PASS"),
        "{}",
        r.describe()
    );
    r.assert_no_leftovers();
}

/// The observerless paper scenario with agent 3 the broken agent.
fn broken_scenario(tmp: &Sandbox, fault: &str) -> std::path::PathBuf {
    let text = read(&paper("constant-observerless"));
    let anchor = "[[agent]]\nid = 3\n";
    let file = tmp.join("broken.toml");
    let extra = format!(
        "command = [{:?}]\nenv = {{ ATTSYNC_FAULT = {fault:?} }}\n",
        bin("broken_agent").display().to_string()
    );
    std::fs::write(&file, text.replace(anchor, &format!("{anchor}{extra}"))).unwrap();
    file
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
