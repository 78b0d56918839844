//! The JSON summary.json holds.

mod common;

use attsync_verdict::{Kind, Verdict, diverged};
use common::judge;

#[test]
fn field_names_and_kebab_case_kinds() {
    let v = judge(40.0, 1e-3, |t| (-0.1 * t).exp());
    let j = serde_json::to_value(&v).expect("serialise");
    assert_eq!(j["kind"], "converging");
    assert!(j["decay_rate"].as_f64().expect("rate") < 0.0);
    assert!(j["settle_time"].is_null());
    assert!(j["amplitude"].is_null());
    let back: Verdict = serde_json::from_value(j).expect("deserialise");
    assert_eq!(back, v);
    let kinds: Vec<_> = Kind::ALL
        .iter()
        .map(|k| serde_json::to_value(k).expect("kind"))
        .collect();
    assert_eq!(
        kinds,
        [
            "converged",
            "converging",
            "persistent",
            "diverging",
            "undecided"
        ]
    );
}

#[test]
fn missing_optional_fields_read_as_none() {
    let j = r#"{"kind": "diverging", "tolerance": 0.001, "window": [2.0, 2.0], "reason": "r"}"#;
    let v: Verdict = serde_json::from_str(j).expect("deserialise");
    assert_eq!(v.decay_rate, None);
    assert_eq!(v.kind, diverged(2.0, 1e-3).kind);
}
