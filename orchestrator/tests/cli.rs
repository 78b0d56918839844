//! End-to-end tests of the `attsync` binary: `check`, `run` and `gen tree`.
//!
//! Each test runs the built binary as a child process in its own temporary
//! directory (also its working directory, so nothing leaks into the crate).
//! What is checked is the user-visible contract:
//! - exit codes: 0 on success, 2 for a scenario that cannot be loaded
//!   (with `file: field: reason` on stderr), non-zero for other failures;
//! - a results directory holds exactly `errors.csv`, `summary.json`,
//!   `errors.svg`, `states.bin`, `view.html`, `scenario.toml` (the effective scenario after `--set`) and
//!   `manifest.json`,
//!   appears atomically (no `.partial-*` staging directory left behind), and
//!   never replaces a directory that is not earlier attsync results;
//! - runs and generated scenarios are deterministic (byte-identical).

mod common;

use common::{OBSERVERLESS, Out, PAPER, attsync, entries, run_args, summary};
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

const HEADER: &str = "t,agent,att_err,angvel_err,obs_att_err,obs_angvel_err";
const RESULT_FILES: [&str; 8] = [
    ".attsync-run",
    "errors.csv",
    "errors.svg",
    "manifest.json",
    "scenario.toml",
    "states.bin",
    "summary.json",
    "view.html",
];

/// `attsync run SCENARIO --engine in-process --out OUT --quiet --set …`.
fn run(cwd: &Path, scenario: &str, out: &Path, sets: &[&str]) -> Out {
    attsync(cwd, &run_args(scenario, "in-process", out, sets))
}

fn names(list: &[&str]) -> BTreeSet<String> {
    list.iter().map(|s| (*s).to_string()).collect()
}

/// `errors.csv` split into its header and rows of fields.
fn read_csv(dir: &Path) -> (String, Vec<Vec<String>>) {
    let text = fs::read_to_string(dir.join("errors.csv")).expect("errors.csv");
    let mut lines = text.lines();
    let header = lines.next().expect("a header").to_string();
    let rows = lines
        .map(|l| l.split(',').map(str::to_string).collect())
        .collect();
    (header, rows)
}

/// The sample time `k · 0.01` as `errors.csv` prints it: no binary noise.
fn time_str(k: usize) -> String {
    let s = format!("{:.2}", k as f64 * 0.01);
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Checks `errors.csv` of a 7-agent run sampled every 0.01 s up to `t_end`.
#[track_caller]
fn check_csv(dir: &Path, t_end: f64, observer: bool) {
    let (header, rows) = read_csv(dir);
    assert_eq!(header, HEADER);
    let samples = (t_end / 0.01).round() as usize + 1;
    assert_eq!(rows.len(), 7 * samples, "7 agents × {samples} samples");
    for (r, row) in rows.iter().enumerate() {
        let (k, agent) = (r / 7, r % 7 + 1);
        assert_eq!(row.len(), 6, "row {r}: {row:?}");
        assert_eq!(row[0], time_str(k), "row {r}: time");
        assert_eq!(row[1], agent.to_string(), "row {r}: agent");
        for (c, field) in row.iter().enumerate().skip(2) {
            if c >= 4 && !observer {
                assert_eq!(
                    field, "",
                    "row {r}: observer column {c} of an observerless run"
                );
                continue;
            }
            let x: f64 = field
                .parse()
                .unwrap_or_else(|_| panic!("row {r}, column {c}: `{field}` is not a number"));
            assert!(x.is_finite() && x >= 0.0, "row {r}, column {c}: {x}");
        }
    }
    let last: f64 = rows.last().unwrap()[0].parse().unwrap();
    assert!(
        (last - t_end).abs() < 1e-12,
        "last sample at {last}, not {t_end}"
    );
}

// ------------------------------------------------------------------ check

#[test]
fn check_paper_scenario_prints_spectrum_and_gain_condition() {
    let tmp = tempfile::tempdir().unwrap();
    let out = attsync(tmp.path(), &["check", PAPER]);
    out.assert_ok();
    let spectrum = out
        .stdout
        .lines()
        .find(|l| l.starts_with("spectrum of Ξ + LLᵀ: ["))
        .unwrap_or_else(|| panic!("no spectrum line:\n{}", out.stdout));
    // Lemma le1: every agent reachable ⇒ Ξ + LLᵀ is positive definite.
    let inner = spectrum.split_once('[').unwrap().1.trim_end_matches(']');
    let eigs: Vec<f64> = inner.split(", ").map(|x| x.parse().unwrap()).collect();
    assert_eq!(eigs.len(), 7, "{spectrum}");
    assert!(eigs.iter().all(|&e| e > 0.0), "{spectrum}");
    assert!(
        out.stdout
            .contains("gain condition (Appendix D, F > 0): holds"),
        "{}",
        out.stdout
    );
    assert!(out.stdout.contains(": OK"), "{}", out.stdout);
    assert!(!out.stdout.contains("warning"), "{}", out.stdout);
    // Nothing written by a check.
    assert!(entries(tmp.path()).is_empty());
}

#[test]
fn check_invalid_scenario_exits_2_naming_file_field_and_reason() {
    let tmp = tempfile::tempdir().unwrap();
    let text = fs::read_to_string(PAPER).unwrap();
    let bad = tmp.path().join("bad.toml");
    fs::write(&bad, text.replacen("dt = 0.001", "dt = -0.001", 1)).unwrap();
    let out = attsync(tmp.path(), &["check", "bad.toml"]);
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(
        out.stderr
            .contains("bad.toml: simulation.dt: must be > 0, got -0.001"),
        "{}",
        out.stderr
    );
    assert!(out.stdout.is_empty(), "{}", out.stdout);

    // The same through --set: a self-loop.
    let out = attsync(
        tmp.path(),
        &["check", PAPER, "--set", "edge[0].agents=[1, 1]"],
    );
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(
        out.stderr
            .contains("timevarying.toml: edge[0].agents: self-loop 1–1"),
        "{}",
        out.stderr
    );

    // A parse error (unknown key) is a scenario error too.
    fs::write(
        &bad,
        text.replacen("coupling = ", "colour = 1\ncoupling = ", 1),
    )
    .unwrap();
    let out = attsync(tmp.path(), &["check", "bad.toml"]);
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(
        out.stderr.contains("bad.toml") && out.stderr.contains("unknown field `colour`"),
        "{}",
        out.stderr
    );
}

#[test]
fn check_missing_file_fails_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let out = attsync(tmp.path(), &["check", "no-such-scenario.toml"]);
    assert_ne!(out.code, Some(0));
    assert!(out.code.is_some(), "killed by a signal");
    assert!(
        out.stderr.contains("no-such-scenario.toml"),
        "{}",
        out.stderr
    );
    assert!(entries(tmp.path()).is_empty());
}

// -------------------------------------------------------------------- run

#[test]
fn run_paper_scenario_writes_complete_results() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    run(tmp.path(), PAPER, &dir, &["simulation.duration=0.5"]).assert_ok();

    assert_eq!(entries(&dir), names(&RESULT_FILES));
    assert_eq!(
        entries(tmp.path()),
        names(&["out"]),
        "staging directory left behind"
    );

    check_csv(&dir, 0.5, true);

    let s = summary(&dir);
    assert_eq!(s["complete"], true, "{s:#}");
    assert!(s["incomplete_reason"].is_null(), "{s:#}");
    assert_eq!(s["t_end"].as_f64(), Some(0.5), "{s:#}");
    assert_eq!(s["duration"].as_f64(), Some(0.5), "{s:#}");
    assert_eq!(s["steps"].as_u64(), Some(500), "{s:#}");
    assert_eq!(s["engine"], "in-process", "{s:#}");
    assert_eq!(s["scenario"], "paper-timevarying", "{s:#}");
    let agents = s["agents"].as_array().expect("agents");
    assert_eq!(agents.len(), 7);
    for (k, a) in agents.iter().enumerate() {
        assert_eq!(a["id"].as_u64(), Some(k as u64 + 1));
        assert!(
            a["final_att_err"].as_f64().is_some_and(f64::is_finite),
            "{a:#}"
        );
        assert!(
            a["final_obs_att_err"].as_f64().is_some_and(f64::is_finite),
            "{a:#}"
        );
    }

    let svg = fs::read_to_string(dir.join("errors.svg")).unwrap();
    assert!(!svg.is_empty());
    assert!(
        svg.starts_with("<svg") || svg.starts_with("<?xml"),
        "{}",
        &svg[..svg.len().min(80)]
    );

    // scenario.toml is the effective scenario (after --set), and loads again.
    let eff: toml::Table = fs::read_to_string(dir.join("scenario.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(eff["simulation"]["duration"].as_float(), Some(0.5));
    assert_eq!(eff["name"].as_str(), Some("paper-timevarying"));
    let again = attsync(tmp.path(), &["check", "out/scenario.toml"]);
    again.assert_ok();
    assert!(again.stdout.contains("500 steps"), "{}", again.stdout);
}

#[test]
fn run_observerless_leaves_observer_columns_empty() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    run(tmp.path(), OBSERVERLESS, &dir, &["simulation.duration=0.5"]).assert_ok();
    assert_eq!(entries(&dir), names(&RESULT_FILES));
    let text = fs::read_to_string(dir.join("errors.csv")).unwrap();
    assert!(
        text.lines().skip(1).all(|l| l.ends_with(",,")),
        "observer columns not empty"
    );
    check_csv(&dir, 0.5, false);
    let s = summary(&dir);
    for a in s["agents"].as_array().unwrap() {
        assert!(a["final_obs_att_err"].is_null(), "{a:#}");
        assert!(a["final_obs_angvel_err"].is_null(), "{a:#}");
    }
}

#[test]
fn run_twice_into_the_same_directory_replaces_the_results() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    run(tmp.path(), PAPER, &dir, &["simulation.duration=0.5"]).assert_ok();
    run(tmp.path(), PAPER, &dir, &["simulation.duration=0.2"]).assert_ok();
    assert_eq!(entries(&dir), names(&RESULT_FILES));
    assert_eq!(
        entries(tmp.path()),
        names(&["out"]),
        "staging or old directory left behind"
    );
    check_csv(&dir, 0.2, true);
    assert_eq!(summary(&dir)["t_end"].as_f64(), Some(0.2));
    let eff: toml::Table = fs::read_to_string(dir.join("scenario.toml"))
        .unwrap()
        .parse()
        .unwrap();
    assert_eq!(eff["simulation"]["duration"].as_float(), Some(0.2));
}

#[test]
fn run_into_an_empty_directory_is_allowed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    fs::create_dir(&dir).unwrap();
    run(tmp.path(), PAPER, &dir, &["simulation.duration=0.1"]).assert_ok();
    assert_eq!(entries(&dir), names(&RESULT_FILES));
    assert_eq!(entries(tmp.path()), names(&["out"]));
}

#[test]
fn run_refuses_to_replace_a_foreign_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    fs::create_dir(&dir).unwrap();
    fs::write(dir.join("thesis.tex"), "precious").unwrap();
    let out = run(tmp.path(), PAPER, &dir, &["simulation.duration=0.1"]);
    assert_ne!(out.code, Some(0), "{}", out.stdout);
    assert!(out.code.is_some(), "killed by a signal");
    assert!(
        out.stderr.contains("not an attsync results directory") && out.stderr.contains("out"),
        "{}",
        out.stderr
    );
    assert_eq!(
        fs::read_to_string(dir.join("thesis.tex")).unwrap(),
        "precious"
    );
    assert_eq!(entries(&dir), names(&["thesis.tex"]));
    assert_eq!(
        entries(tmp.path()),
        names(&["out"]),
        "staging directory left behind"
    );

    // A plain file in the way is refused the same way.
    let file = tmp.path().join("file");
    fs::write(&file, "precious").unwrap();
    let out = run(tmp.path(), PAPER, &file, &["simulation.duration=0.1"]);
    assert_ne!(out.code, Some(0));
    assert_eq!(fs::read_to_string(&file).unwrap(), "precious");
    assert_eq!(entries(tmp.path()), names(&["out", "file"]));
}

#[test]
fn run_with_invalid_set_exits_2_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("out");
    let out = run(tmp.path(), PAPER, &dir, &["simulation.dt=-1"]);
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(
        out.stderr
            .contains("timevarying.toml: simulation.dt: must be > 0"),
        "{}",
        out.stderr
    );
    assert!(entries(tmp.path()).is_empty(), "{:?}", entries(tmp.path()));

    // Without --out (default results/<name>) nothing is created either.
    let out = attsync(
        tmp.path(),
        &["run", PAPER, "--set", "simulation.duration=0.0005"],
    );
    assert_eq!(out.code, Some(2), "{}", out.stderr);
    assert!(out.stderr.contains("simulation.duration"), "{}", out.stderr);
    assert!(entries(tmp.path()).is_empty(), "{:?}", entries(tmp.path()));
}

#[test]
fn runs_are_deterministic() {
    let tmp = tempfile::tempdir().unwrap();
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    run(tmp.path(), PAPER, &a, &["simulation.duration=1"]).assert_ok();
    run(tmp.path(), PAPER, &b, &["simulation.duration=1"]).assert_ok();
    let csv_a = fs::read(a.join("errors.csv")).unwrap();
    assert!(
        csv_a == fs::read(b.join("errors.csv")).unwrap(),
        "errors.csv differs between runs"
    );
    check_csv(&a, 1.0, true);
    // summary.json too, apart from the wall-clock time.
    let strip = |d: &PathBuf| {
        let mut s = summary(d);
        s.as_object_mut().unwrap().remove("wall_seconds");
        s
    };
    assert_eq!(strip(&a), strip(&b));
    assert_eq!(
        fs::read(a.join("scenario.toml")).unwrap(),
        fs::read(b.join("scenario.toml")).unwrap()
    );
}

// -------------------------------------------------------------------- gen

#[test]
fn generated_tree_is_valid_and_reproducible() {
    let tmp = tempfile::tempdir().unwrap();
    let gen_tree = |seed: &str, out: &str| {
        attsync(
            tmp.path(),
            &[
                "gen",
                "tree",
                "--agents",
                "30",
                "--leader-links",
                "3",
                "--seed",
                seed,
                "--out",
                out,
            ],
        )
        .assert_ok();
        fs::read(tmp.path().join(out)).unwrap()
    };
    let first = gen_tree("7", "tree.toml");
    let check = attsync(tmp.path(), &["check", "tree.toml"]);
    check.assert_ok();
    assert!(check.stdout.contains("agents:    30"), "{}", check.stdout);
    let leader = check
        .stdout
        .lines()
        .find(|l| l.starts_with("leader:"))
        .unwrap();
    assert_eq!(leader.matches("0→").count(), 3, "{leader}");
    assert!(check.stdout.contains("gain condition"), "{}", check.stdout);

    assert!(
        first == gen_tree("7", "again.toml"),
        "same seed, different file"
    );
    assert!(
        first != gen_tree("8", "other.toml"),
        "different seed, same file"
    );

    // Without --out the same text goes to stdout.
    let out = attsync(
        tmp.path(),
        &[
            "gen",
            "tree",
            "--agents",
            "30",
            "--leader-links",
            "3",
            "--seed",
            "7",
        ],
    );
    out.assert_ok();
    assert!(
        out.stdout.as_bytes() == first.as_slice(),
        "stdout differs from --out"
    );
}

#[test]
fn generated_trees_of_every_scheme_pass_check() {
    let tmp = tempfile::tempdir().unwrap();
    for scheme in ["observer-time-varying", "observer-constant", "observerless"] {
        let file = format!("{scheme}.toml");
        attsync(
            tmp.path(),
            &[
                "gen",
                "tree",
                "--agents",
                "12",
                "--leader-links",
                "2",
                "--seed",
                "3",
                "--scheme",
                scheme,
                "--out",
                &file,
            ],
        )
        .assert_ok();
        let check = attsync(tmp.path(), &["check", &file]);
        check.assert_ok();
        assert!(
            check.stdout.contains(&format!("scheme:    {scheme}")),
            "{}",
            check.stdout
        );
    }
    // Impossible parameters are refused.
    let out = attsync(
        tmp.path(),
        &["gen", "tree", "--agents", "3", "--leader-links", "4"],
    );
    assert_ne!(out.code, Some(0));
    assert!(out.stderr.contains("--leader-links"), "{}", out.stderr);
}
