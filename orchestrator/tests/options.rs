//! Every numeric option is checked before anything starts: exit code 2, a
//! message naming the option, and nothing written (no results directory, no
//! staging directory, no node process: the checks come before the engine).

mod common;

use common::{PAPER, attsync};
use std::fs;

/// Asserts `args` exit 2 naming `option`, with nothing written in `cwd`.
fn refused(args: &[&str], option: &str) {
    let tmp = tempfile::tempdir().expect("tempdir");
    let out = attsync(tmp.path(), args);
    let (code, stderr) = (out.code, out.stderr);
    assert_eq!(code, Some(2), "{args:?}: {stderr}");
    assert!(stderr.contains(option), "{args:?}: {stderr}");
    let left: Vec<_> = fs::read_dir(tmp.path()).expect("dir").collect();
    assert!(left.is_empty(), "{args:?} wrote {left:?}");
}

fn run(engine: &str, extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = ["run", PAPER, "--engine", engine, "--quiet"]
        .iter()
        .map(|s| (*s).to_string())
        .collect();
    v.extend(extra.iter().map(|s| (*s).to_string()));
    v
}

fn sweep(extra: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = [
        "sweep",
        PAPER,
        "--param",
        "network.delay",
        "--values",
        "0,0.1",
        "--engine",
        "in-process",
    ]
    .iter()
    .map(|s| (*s).to_string())
    .collect();
    v.extend(extra.iter().map(|s| (*s).to_string()));
    v
}

fn strs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[test]
fn stage_timeout_out_of_range_is_refused() {
    for t in ["nan", "inf", "-1", "0", "1e300", "86401"] {
        // `--option=VALUE`: clap takes `-1` after a space for a flag.
        let flag = format!("--stage-timeout={t}");
        for engine in ["processes", "in-process"] {
            let args = run(engine, &[&flag]);
            refused(&strs(&args), "--stage-timeout");
        }
        let args = sweep(&[&flag]);
        refused(&strs(&args), "--stage-timeout");
    }
}

#[test]
fn realtime_factor_out_of_range_is_refused() {
    for f in ["nan", "inf", "-1", "0", "1e300"] {
        let args = run("processes", &[&format!("--realtime={f}")]);
        refused(&strs(&args), "--realtime");
    }
}

#[test]
fn sweep_options_out_of_range_are_refused() {
    let cases: [(&[&str], &str); 9] = [
        (&["--jobs", "0"], "--jobs"),
        (&["--tolerance", "0"], "--tolerance"),
        (&["--tolerance", "nan"], "--tolerance"),
        (&["--tolerance=-1e-3"], "--tolerance"),
        (&["--find-margin", "--bisect", "1000"], "--bisect"),
        (&["--find-margin", "--quantum", "0"], "--quantum"),
        (&["--find-margin", "--quantum", "nan"], "--quantum"),
        (&["--find-margin", "--quantum", "inf"], "--quantum"),
        (&["--find-margin", "--quantum=-0.001"], "--quantum"),
    ];
    for (extra, option) in cases {
        let args = sweep(extra);
        refused(&strs(&args), option);
    }
}

#[test]
fn sweep_value_that_makes_an_invalid_scenario_is_refused_before_any_run() {
    let args = [
        "sweep",
        PAPER,
        "--param",
        "network.delay",
        "--values",
        "0,-1",
        "--engine",
        "in-process",
    ];
    refused(&args, "network.delay");
}

#[test]
fn conform_timeouts_and_agent_are_checked() {
    for (extra, option) in [
        (["--stage-timeout", "0"], "--stage-timeout"),
        (["--start-timeout", "inf"], "--start-timeout"),
        (["--agent", "9"], "--agent"),
    ] {
        let mut args = vec!["conform"];
        args.extend(extra);
        args.extend(["--", "/bin/true"]);
        refused(&args, option);
    }
}

#[test]
fn gen_tree_options_are_checked() {
    for (extra, option) in [
        (["--agents", "0"], "--agents"),
        (["--leader-links", "4"], "--leader-links"),
        (["--duration", "nan"], "--duration"),
        (["--duration", "0"], "--duration"),
    ] {
        let mut args = vec!["gen", "tree", "--agents", "3"];
        args.extend(extra);
        refused(&args, option);
    }
}

#[test]
fn check_node_config_of_no_node_is_refused() {
    refused(&["check", PAPER, "--node-config", "99"], "--node-config");
}
