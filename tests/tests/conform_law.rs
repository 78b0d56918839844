//! `attsync conform`, rule `law` (PROTOCOL.md § 12): the candidate's inputs
//! are replayed through the built-in law of its scheme. The built-in agent
//! matches it in every scheme; an agent with a wrong sign in its law
//! (`tests/src/bin/wrong_sign_agent.rs`) speaks the protocol perfectly and
//! fails only `law`; a deliberately different controller (the saturated
//! example, saturating) fails it by default and is reported as INFO with
//! `--law own`.

use attsync_tests::{Finished, Sandbox, bin, paper, rule_line, run_conform};
use std::ffi::OsString;

/// `attsync conform ARGS… -- PROGRAM` (a workspace binary) in a new
/// sandbox named `test`, with `env`.
fn conform(test: &str, args: &[OsString], program: &str, env: &[(&str, &str)]) -> Finished {
    run_conform(&Sandbox::new(test), args, &[bin(program).into()], env)
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

/// `attsync conform` of the built-in agent as agent `id` of the paper's
/// scenario `name`: it passes, rule `law` included.
fn builtin_follows_the_law(test: &str, name: &str, id: &str) -> Finished {
    let r = conform(test, &paper_args(name, id), "attsync-agent", &[]);
    r.assert_ok();
    assert!(rule_line(&r, "law").starts_with("PASS"), "{}", r.describe());
    r
}

#[test]
fn the_builtin_agent_follows_the_law_of_scheme_1() {
    let r = builtin_follows_the_law("law-builtin-1", "timevarying", "1");
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn the_builtin_agent_follows_the_law_of_scheme_2() {
    builtin_follows_the_law("law-builtin-2", "constant-observer", "2");
}

#[test]
fn the_builtin_agent_follows_the_law_of_scheme_3() {
    builtin_follows_the_law("law-builtin-3", "constant-observerless", "3");
}

#[test]
fn a_wrong_sign_passes_the_protocol_and_fails_the_law() {
    let r = conform("law-wrong-sign", &[], "wrong_sign_agent", &[]);
    r.assert_code(1);
    let l = rule_line(&r, "law");
    assert!(
        l.starts_with("FAIL") && l.contains("differs from the built-in scheme-3 law by"),
        "{l}\n{}",
        r.describe()
    );
    for ok in PROTOCOL_RULES {
        assert!(
            rule_line(&r, ok).starts_with("PASS"),
            "{ok}\n{}",
            r.describe()
        );
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
    let l = rule_line(&r, "law");
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
    let l = rule_line(&r, "law");
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
    let l = rule_line(&r, "law");
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
