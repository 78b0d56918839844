//! Issue 13 item 4: `scheme.law = "as-printed"`, the paper's printed `Σᵢ`,
//! `Γᵢ` (erratum 1 of `docs/paper.md`) as a negative control, through the
//! `attsync` binary.
//!
//! - Both engines run the printed law bit for bit alike: `errors.csv`,
//!   `states.bin` and `scenario.toml` byte-identical between
//!   `--engine processes` and `--engine in-process` (2 s of scheme 1), and
//!   `summary.json` records `"law": "as-printed"` (a corrected run records
//!   `"corrected"`).
//! - The built-in agent, configured with the printed law, passes rule `law`
//!   of `attsync conform`: the shadow agent follows the configured law.
//! - `run`, `sweep` and `check` warn that the law is known wrong and meant
//!   as a negative control; `check` shows the law.
//! - The observerless scheme (no `Σᵢ`, `Γᵢ`, nothing printed wrong) refuses
//!   it, and a value that is not a law is a schema error; both exit 2
//!   naming `scheme.law`.
//!
//! The stall itself (scheme 1's final error near 1e-2, against an
//! independent RK4) is in `orchestrator/tests/issue_13_as_printed.rs`.

use attsync_tests::{
    Attsync, Finished, Sandbox, assert_same_results, bin, paper, run_args, summary,
};
use std::ffi::OsString;

const PRINTED: &str = "scheme.law=\"as-printed\"";
const TWO_SECONDS: &str = "simulation.duration=2";
const SHORT: &str = "simulation.duration=0.1";

/// `attsync ARGS…` in `tmp`.
fn attsync(tmp: &Sandbox, args: &[OsString]) -> Finished {
    Attsync::new(tmp.path()).args(args).output()
}

fn os(args: &[&str]) -> Vec<OsString> {
    args.iter().map(OsString::from).collect()
}

/// The warning every command prints for the printed law.
#[track_caller]
fn assert_warns(text: &str, r: &Finished) {
    assert!(
        text.contains("warning: ")
            && text.contains("scheme.law: ")
            && text.contains("known wrong")
            && text.contains("negative control"),
        "{}",
        r.describe()
    );
}

#[test]
fn the_printed_law_is_bit_identical_in_both_engines() {
    let tmp = Sandbox::new("as-printed-parity");
    let (p, i) = (tmp.join("processes"), tmp.join("in-process"));
    let scenario = paper("timevarying");
    let sets = [PRINTED, TWO_SECONDS];
    attsync(&tmp, &run_args(&scenario, "processes", &p, &sets))
        .assert_ok()
        .assert_no_leftovers();
    attsync(&tmp, &run_args(&scenario, "in-process", &i, &sets)).assert_ok();
    assert_same_results(&p, &i);
    for dir in [&p, &i] {
        let s = summary(dir);
        assert_eq!(s["law"], "as-printed", "{s:#}");
        assert_eq!(s["complete"], true, "{s:#}");
    }
    let c = tmp.join("corrected");
    attsync(&tmp, &run_args(&scenario, "in-process", &c, &[TWO_SECONDS])).assert_ok();
    assert_eq!(summary(&c)["law"], "corrected");
    // The law is applied: the printed run differs from the corrected one.
    let errors = |d: &std::path::Path| std::fs::read(d.join("errors.csv")).unwrap();
    assert_ne!(errors(&i), errors(&c));
}

#[test]
fn the_builtin_agent_passes_rule_law_under_the_printed_law() {
    let tmp = Sandbox::new("as-printed-conform");
    let mut args = os(&["conform", "--scenario"]);
    args.push(attsync_tests::scenario("plugin/conform-timevarying.toml").into());
    args.extend(os(&["--set", PRINTED, "--log"]));
    args.push(tmp.join("candidate.log").into());
    args.extend(os(&["--"]));
    args.push(bin("attsync-agent").into());
    let r = attsync(&tmp, &args);
    r.assert_ok();
    assert!(r.stdout.contains("10/10 rules pass"), "{}", r.describe());
}

#[test]
fn run_warns_and_check_shows_the_law() {
    let tmp = Sandbox::new("as-printed-warnings");
    let scenario = paper("timevarying");
    let out = tmp.join("run");
    let r = attsync(
        &tmp,
        &run_args(&scenario, "in-process", &out, &[PRINTED, SHORT]),
    );
    r.assert_ok();
    assert_warns(&r.stderr, &r);
    let mut check = os(&["check"]);
    check.push(scenario.clone().into());
    let plain = attsync(&tmp, &check);
    plain.assert_ok();
    assert!(
        plain.stdout.contains("law:       corrected\n"),
        "{}",
        plain.describe()
    );
    assert!(
        !plain.stdout.contains("negative control"),
        "{}",
        plain.describe()
    );
    check.extend(os(&["--set", PRINTED]));
    let r = attsync(&tmp, &check);
    r.assert_ok();
    assert!(
        r.stdout.contains("law:       as-printed"),
        "{}",
        r.describe()
    );
    assert_warns(&r.stdout, &r);
    check.extend(os(&["--node-config", "1"]));
    let r = attsync(&tmp, &check);
    r.assert_ok();
    assert!(
        r.stdout.contains("\"law\": \"as-printed\""),
        "{}",
        r.describe()
    );
}

#[test]
fn sweep_warns() {
    let tmp = Sandbox::new("as-printed-sweep");
    let mut args = os(&["sweep"]);
    args.push(paper("timevarying").into());
    args.extend(os(&[
        "--set",
        PRINTED,
        "--set",
        SHORT,
        "--param",
        "scheme.control.k_r",
        "--values",
        "8,9",
        "--jobs",
        "1",
        "--engine",
        "in-process",
        "--out",
    ]));
    args.push(tmp.join("sweep").into());
    let r = attsync(&tmp, &args);
    r.assert_ok();
    assert_warns(&r.stderr, &r);
}

#[test]
fn the_observerless_scheme_refuses_the_printed_law() {
    let tmp = Sandbox::new("as-printed-observerless");
    for command in ["check", "run"] {
        let mut args = os(&[command]);
        args.push(paper("constant-observerless").into());
        args.extend(os(&["--set", PRINTED, "--set", SHORT]));
        let r = attsync(&tmp, &args);
        r.assert_code(2);
        assert!(
            r.stderr.contains("scheme.law: ") && r.stderr.contains("observer schemes only"),
            "{}",
            r.describe()
        );
    }
}

#[test]
fn a_value_that_is_not_a_law_is_a_schema_error() {
    let tmp = Sandbox::new("as-printed-bad-value");
    let mut args = os(&["check"]);
    args.push(paper("timevarying").into());
    args.extend(os(&["--set", "scheme.law=\"as-typed\""]));
    let r = attsync(&tmp, &args);
    r.assert_code(2);
    assert!(
        r.stderr.contains("scheme.law") && r.stderr.contains("as-printed"),
        "{}",
        r.describe()
    );
}
