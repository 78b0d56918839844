//! `attsync margin` end to end (issue 32): the paper's margins and the
//! `--json` contract (`margin`, `omega`, `rightmost`), a delay-independent
//! network, and bad input (exit 2 naming the field, nothing written).
//!
//! The figures are checked independently in `attitude/src/linear/tests.rs`
//! (Lambert W, the Jacobian of the model, a second method) and against long
//! simulations in `issue_32_verdicts.rs`; here the command's contract.

mod common;

use common::{attsync, entries, json, paper};

#[test]
fn the_paper_margins_and_the_json_contract() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        ("constant-observerless", 0.389_232, 4.4503, -0.8156),
        ("constant-observer", 0.092_514, 23.931, -0.5976),
    ];
    for (name, margin, omega, re) in cases {
        let file = format!("{name}.json");
        let out = attsync(tmp.path(), &["margin", &paper(name), "--json", &file]);
        out.assert_ok();
        assert!(out.stdout.contains("delay margin: d = "), "{}", out.stdout);
        let j = json(&tmp.path().join(&file));
        let m = j["margin"].as_f64().expect("margin");
        assert!((m - margin).abs() < 1e-5, "{name}: {j:#}");
        assert!(
            (j["omega"].as_f64().unwrap() - omega).abs() < 1e-3,
            "{name}: {j:#}"
        );
        assert!(
            (j["rightmost"]["re"].as_f64().unwrap() - re).abs() < 1e-4,
            "{name}: {j:#}"
        );
        assert!(
            j["rightmost"]["im"].as_f64().unwrap() > 0.0,
            "{name}: {j:#}"
        );
        assert_eq!(j["kind"], "crossing");
    }
    // `--json -`: the document alone on stdout.
    let out = attsync(
        tmp.path(),
        &["margin", &paper("constant-observerless"), "--json", "-"],
    );
    out.assert_ok();
    let j: serde_json::Value = serde_json::from_str(&out.stdout).expect("JSON on stdout");
    assert!(j["margin"].is_number());
    // At the scenario's own delay the rightmost root moves right.
    let out = attsync(
        tmp.path(),
        &[
            "margin",
            &paper("constant-observerless"),
            "--set",
            "network.delay=0.35",
            "--json",
            "-",
        ],
    );
    out.assert_ok();
    let j: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    let re = j["rightmost"]["re"].as_f64().unwrap();
    assert!((re + 0.05184).abs() < 1e-4, "{j:#}");
    assert_eq!(j["delays"], serde_json::json!([0.35]));
}

/// Weak coupling (the neighbours' gains small against the leader's and the
/// damping): no root ever reaches the imaginary axis.
#[test]
fn a_network_stable_for_every_delay_says_so() {
    let tmp = tempfile::tempdir().unwrap();
    let mut args = vec![
        "margin".to_string(),
        paper("constant-observerless"),
        "--json".into(),
        "-".into(),
    ];
    for k in 0..5 {
        args.push("--set".into());
        args.push(format!("edge[{k}].gain=[0.01, 0.02, 0.03]"));
    }
    args.push("--set".into());
    args.push("scheme.control.k_omega=20".into());
    let out = attsync(tmp.path(), &args);
    out.assert_ok();
    let j: serde_json::Value = serde_json::from_str(&out.stdout).unwrap();
    assert_eq!(j["kind"], "delay-independent", "{j:#}");
    assert!(j["margin"].is_null() && j["omega"].is_null(), "{j:#}");
}

#[test]
fn what_cannot_be_linearised_exits_2_naming_the_field_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let cases: [(&str, &[&str], &str); 4] = [
        ("timevarying", &[], "scheme.kind"),
        (
            "constant-observerless",
            &["network.loss=0.1"],
            "network.loss",
        ),
        (
            "constant-observer",
            &["simulation.coupling=\"sampled\"", "simulation.period=0.002"],
            "simulation.coupling",
        ),
        // Not a whole number of steps: refused when the scenario is read.
        (
            "constant-observerless",
            &["network.delay=0.0005"],
            "network.delay",
        ),
    ];
    for (name, sets, field) in cases {
        let mut args = vec!["margin".to_string(), paper(name)];
        for s in sets {
            args.push("--set".into());
            args.push((*s).into());
        }
        args.push("--json".into());
        args.push("m.json".into());
        let out = attsync(tmp.path(), &args);
        out.assert_code(2);
        assert!(
            out.stderr.contains(field),
            "{name} {sets:?}: {}",
            out.stderr
        );
        assert!(
            out.stderr.contains(&format!("{name}.toml")),
            "{}",
            out.stderr
        );
        assert!(entries(tmp.path()).is_empty(), "{:?}", entries(tmp.path()));
    }
}
