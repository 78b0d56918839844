//! `attsync sweep` over two fields (issue 35): two `--param`, each with its
//! `--values`, run the grid of both.
//!
//! - `sweep.csv`'s first two columns are named by the fields' paths, one
//!   row per pair of values, every pair once; each run's `scenario.toml`
//!   holds both values it was given (no dispersion silently not applied);
//! - each row's `linear_rate_per_s` is the linearisation of that pair's
//!   scenario, computed here apart (`attitude::linear`);
//! - `sweep.svg` has one cell per run and a label per value;
//! - bad combinations of options, or one invalid pair of values, are
//!   refused with exit code 2 before anything runs.

mod common;

use common::{OBSERVERLESS, attsync, load_paper};
use std::collections::BTreeSet;
use std::fs;
use std::path::Path;

const DELAYS: &str = "0,0.2";
const GAINS: &str = "1,1.9,3";

/// `attsync sweep OBSERVERLESS --param network.delay --values DELAYS
/// --param scheme.control.k_r --values GAINS … EXTRA`.
fn grid(cwd: &Path, out: &str, extra: &[&str]) -> common::Out {
    let mut args = vec![
        "sweep",
        OBSERVERLESS,
        "--param",
        "network.delay",
        "--values",
        DELAYS,
        "--param",
        "scheme.control.k_r",
        "--values",
        GAINS,
        "--jobs",
        "2",
        "--engine",
        "in-process",
        "--out",
        out,
        "--set",
        "simulation.duration=3",
    ];
    args.extend_from_slice(extra);
    attsync(cwd, &args)
}

/// A TOML number as f64 (`--set` writes `1` as an integer).
fn num(v: &toml::Value) -> f64 {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .expect("a number")
}

#[test]
fn a_grid_runs_every_pair_once_with_both_values_applied() {
    let tmp = tempfile::tempdir().expect("tempdir");
    grid(tmp.path(), "g", &[]).assert_ok();
    let dir = tmp.path().join("g");
    let text = fs::read_to_string(dir.join("sweep.csv")).expect("sweep.csv");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    assert_eq!(
        header[..3],
        ["network.delay", "scheme.control.k_r", "verdict"]
    );
    let col = |name: &str| header.iter().position(|h| *h == name).expect(name);
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    let pairs: BTreeSet<(String, String)> = rows
        .iter()
        .map(|r| (r[0].to_string(), r[1].to_string()))
        .collect();
    assert_eq!(rows.len(), 6);
    assert_eq!(pairs.len(), 6, "every pair once: {pairs:?}");
    for r in &rows {
        let (delay, gain) = (r[0], r[1]);
        let run = dir.join(r[col("run")]);
        let used: toml::Value =
            toml::from_str(&fs::read_to_string(run.join("scenario.toml")).expect("scenario.toml"))
                .expect("toml");
        assert_eq!(
            num(&used["network"]["delay"]),
            delay.parse::<f64>().unwrap()
        );
        let k_r = num(&used["scheme"]["control"]["k_r"]);
        assert_eq!(k_r, gain.parse::<f64>().unwrap());
        // The linearisation of this pair's scenario, computed apart.
        let set = [
            "simulation.duration=3".to_string(),
            format!("network.delay={delay}"),
            format!("scheme.control.k_r={gain}"),
        ];
        let set: Vec<&str> = set.iter().map(String::as_str).collect();
        let net = load_paper("constant-observerless", &set).resolved.network;
        let l = attitude::linear::Linearisation::of(&net).expect("linearisable");
        let rate: f64 = r[col("linear_rate_per_s")].parse().expect("a rate");
        let re = l.rightmost().re;
        assert!((rate - re).abs() < 1e-9, "{delay}, {gain}: {rate} vs {re}");
    }
    let svg = fs::read_to_string(dir.join("sweep.svg")).expect("sweep.svg");
    assert!(svg.contains("network.delay × scheme.control.k_r"));
    for v in ["0.2", "1.9", "3"] {
        assert!(svg.contains(&format!(">\n{v}\n</text>")) || svg.contains(&format!(">{v}</text>")));
    }
}

#[test]
fn bad_grids_are_refused_before_anything_runs() {
    let tmp = tempfile::tempdir().expect("tempdir");
    let cases: [(&[&str], &str); 2] = [
        (&["--find-margin"], "--find-margin bisects one field"),
        (&["--param", "network.loss"], "--param is given 3 times"),
    ];
    for (k, (extra, says)) in cases.iter().enumerate() {
        let out = format!("bad-{k}");
        let o = grid(tmp.path(), &out, extra);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{extra:?}: {}", o.stderr);
        assert!(!tmp.path().join(&out).exists());
    }
    let twice = [
        "sweep",
        OBSERVERLESS,
        "--param",
        "network.delay",
        "--values",
        "0",
        "--param",
        "network.delay",
        "--values",
        "0.1",
        "--out",
        "twice",
    ];
    let o = attsync(tmp.path(), &twice);
    o.assert_code(2);
    assert!(
        o.stderr.contains("--param network.delay is given twice"),
        "{}",
        o.stderr
    );
    // One pair of values that makes an invalid scenario: nothing runs.
    let bad_pair = [
        "sweep",
        OBSERVERLESS,
        "--param",
        "network.delay",
        "--values",
        "0,0.1",
        "--param",
        "scheme.control.k_r",
        "--values",
        "1,-2",
        "--out",
        "pair",
    ];
    let o = attsync(tmp.path(), &bad_pair);
    o.assert_code(2);
    assert!(o.stderr.contains("k_r"), "{}", o.stderr);
    assert!(!tmp.path().join("pair").exists());
}
