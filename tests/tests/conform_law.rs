//! `attsync conform`, rule `law` (PROTOCOL.md § 12): the candidate's inputs
//! are replayed through the built-in law of its scheme. The built-in agent
//! matches it in every scheme; an agent with a wrong sign in its law
//! (`tests/src/bin/wrong_sign_agent.rs`) speaks the protocol perfectly and
//! fails only `law`; a deliberately different controller (the saturated
//! example, saturating) fails it by default and is reported as INFO with
//! `--law own`.

use attsync_tests::{Attsync, Finished, Sandbox, bin, paper};
use std::ffi::OsString;

/// `attsync conform ARGS… -- PROGRAM`, with `env`.
fn conform(test: &str, args: &[OsString], program: &str, env: &[(&str, &str)]) -> Finished {
    let tmp = Sandbox::new(test);
    let mut a = Attsync::new(tmp.path())
        .args(["conform", "--log"])
        .args([tmp.join("candidate.log")])
        .args(args);
    for (k, v) in env {
        a = a.env(k, v);
    }
    a.args(["--".into(), bin(program)]).output()
}

/// The report line of `rule`, with its reason line(s).
fn line<'a>(r: &'a Finished, rule: &str) -> &'a str {
    let start = r
        .stdout
        .find(&format!("  {rule} "))
        .unwrap_or_else(|| panic!("no rule {rule}:\n{}", r.describe()));
    let start = r.stdout[..start].rfind('\n').map_or(0, |i| i + 1);
    let rest = &r.stdout[start + 6..];
    let end = ["\nPASS", "\nFAIL", "\nSKIP", "\nINFO"]
        .iter()
        .filter_map(|t| rest.find(t))
        .min()
        .map_or(r.stdout.len(), |e| start + 6 + e);
    &r.stdout[start..end]
}

/// The nine protocol rules.
const PROTOCOL_RULES: [&str; 9] = [
    "version",
    "connects",
    "in-order",
    "waits-for-inputs",
    "valid-states",
    "refuses-invalid",
    "telemetry",
    "stops",
    "clean",
];

fn os(args: &[&str]) -> Vec<OsString> {
    args.iter().map(OsString::from).collect()
}

/// A paper scenario, shortened to 0.2 s, with agent `id` the candidate.
fn paper_args(name: &str, id: &str) -> Vec<OsString> {
    let mut v = os(&["--scenario"]);
    v.push(paper(name).into());
    v.extend(os(&["--agent", id, "--set", "simulation.duration=0.2"]));
    v
}

#[test]
fn the_builtin_agent_follows_the_law_of_scheme_1() {
    let r = conform(
        "law-builtin-1",
        &paper_args("timevarying", "1"),
        "attsync-agent",
        &[],
    );
    r.assert_ok();
    assert!(line(&r, "law").starts_with("PASS"), "{}", r.describe());
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn the_builtin_agent_follows_the_law_of_scheme_2() {
    let r = conform(
        "law-builtin-2",
        &paper_args("constant-observer", "2"),
        "attsync-agent",
        &[],
    );
    r.assert_ok();
    assert!(line(&r, "law").starts_with("PASS"), "{}", r.describe());
}

#[test]
fn the_builtin_agent_follows_the_law_of_scheme_3() {
    let r = conform(
        "law-builtin-3",
        &paper_args("constant-observerless", "3"),
        "attsync-agent",
        &[],
    );
    r.assert_ok();
    assert!(line(&r, "law").starts_with("PASS"), "{}", r.describe());
}

#[test]
fn a_wrong_sign_passes_the_protocol_and_fails_the_law() {
    let r = conform("law-wrong-sign", &[], "wrong_sign_agent", &[]);
    r.assert_code(1);
    let l = line(&r, "law");
    assert!(
        l.starts_with("FAIL") && l.contains("differs from the built-in scheme-3 law by"),
        "{l}\n{}",
        r.describe()
    );
    for ok in PROTOCOL_RULES {
        assert!(line(&r, ok).starts_with("PASS"), "{ok}\n{}", r.describe());
    }
    assert!(r.stdout.contains("9/10 rules pass"), "{}", r.describe());
}

#[test]
fn a_wrong_sign_under_an_observer_scheme_shows_in_the_samples() {
    let r = conform(
        "law-wrong-sign-1",
        &paper_args("timevarying", "1"),
        "wrong_sign_agent",
        &[],
    );
    r.assert_code(1);
    let l = line(&r, "law");
    assert!(
        l.starts_with("FAIL") && l.contains("differs from the built-in scheme-1 law by"),
        "{l}\n{}",
        r.describe()
    );
}

const SATURATING: [(&str, &str); 1] = [("SATURATED_TAU_MAX", "1.0")];

#[test]
fn a_saturated_controller_fails_the_builtin_law() {
    let r = conform("law-saturated", &[], "saturated-agent", &SATURATING);
    r.assert_code(1);
    let l = line(&r, "law");
    assert!(
        l.starts_with("FAIL") && l.contains("differs from the built-in scheme-3 law by"),
        "{l}\n{}",
        r.describe()
    );
}

#[test]
fn a_saturated_controller_of_its_own_is_information_only() {
    let r = conform(
        "law-saturated-own",
        &os(&["--law", "own"]),
        "saturated-agent",
        &SATURATING,
    );
    r.assert_ok();
    let l = line(&r, "law");
    assert!(
        l.starts_with("INFO") && l.contains("differs from the built-in scheme-3 law by"),
        "{l}\n{}",
        r.describe()
    );
    assert!(
        r.stdout.contains("9/9 rules pass, 1 for information only"),
        "{}",
        r.describe()
    );
}
