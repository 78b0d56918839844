//! `[[event]]` (issue 35, item 1): a timeline in simulated time.
//!
//! - each event kind runs in both engines with byte-identical
//!   `errors.csv` and `states.bin`;
//! - neutral timelines give the bits of a run without them: a cut restored
//!   at once, a gain set to its own value, a leader link cut under a
//!   constant reference (holding a constant is the constant);
//! - an event at t = 0 is the scenario with that value from the start;
//! - a cut drops exactly the messages stamped in it (4 per step under
//!   continuous coupling), counted lost; the agents it cuts off are
//!   reported;
//! - `hold = false` removes the edge: cut from t = 0 to the end, it is
//!   bit for bit the network without that edge;
//! - a re-pointing makes the error jump by the angle between the two
//!   references and decay again;
//! - bad events are refused (exit 2) naming the event and the reason.

mod common;

use common::{OBSERVERLESS, PAPER, attsync, json, read, run_args};
use std::fs;
use std::path::{Path, PathBuf};

/// `base` with `events` appended, written into `dir/name.toml`.
fn scenario(dir: &Path, base: &str, name: &str, events: &str) -> PathBuf {
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, read(Path::new(base)) + "\n" + events).expect("write");
    file
}

/// Runs `file` with `engine` for `duration` s into `dir/out`; the run's directory.
fn run(dir: &Path, file: &Path, engine: &str, out: &str, sets: &[&str]) -> PathBuf {
    let out = dir.join(out);
    let mut all = vec!["simulation.duration=2"];
    all.extend_from_slice(sets);
    let o = attsync(dir, &run_args(file, engine, &out, &all));
    o.assert_code(0);
    out
}

fn bytes(dir: &Path, name: &str) -> Vec<u8> {
    fs::read(dir.join(name)).unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
}

/// Whether two runs' `errors.csv` and `states.bin` are the same bytes.
fn same_bits(a: &Path, b: &Path) -> bool {
    ["errors.csv", "states.bin"]
        .iter()
        .all(|f| bytes(a, f) == bytes(b, f))
}

const CUT: &str = "[[event]]\nt = 0.5\ncut = [3, 5]\n\n[[event]]\nt = 1.2\nrestore = [3, 5]\n";
const SILENCE: &str = "[[event]]\nt = 0.4\nagent = 3\naction = \"silence\"\n\n[[event]]\nt = 1.0\nagent = 3\naction = \"resume\"\n";
const LEADER_CUT: &str = "[[event]]\nt = 0.3\ncut = [0, 2]\n";
const RETUNE: &str = "[[event]]\nt = 0.7\nset = { \"scheme.control.k_r\" = 3.0, \"scheme.control.k_omega\" = 4.5 }\n";
const REPOINT: &str = "[[event]]\nt = 1.5\nset = { \"leader.attitude\" = { axis = [0.0, 0.0, 1.0], angle_deg = 60.0 } }\n";

#[test]
fn every_event_kind_is_byte_identical_in_both_engines() {
    let tmp = tempfile::tempdir().unwrap();
    let removed = CUT.replacen("cut = [3, 5]\n", "cut = [3, 5]\nhold = false\n", 1);
    let silence = SILENCE.replacen("\"silence\"\n", "\"silence\"\nhold = false\n", 1);
    let (removed, silence_removed) = (removed.as_str(), silence.as_str());
    let cases = [
        ("cut", PAPER, CUT, "cut 3–5"),
        ("silence", PAPER, SILENCE, "agent 3 falls silent"),
        ("leader-cut", PAPER, LEADER_CUT, "cut 0–2"),
        ("retune", PAPER, RETUNE, "scheme.control.k_omega = 4.5"),
        ("repoint", OBSERVERLESS, REPOINT, "leader.attitude jumps"),
        ("removed", PAPER, removed, "cut 3–5 (removed)"),
        (
            "silence-removed",
            PAPER,
            silence_removed,
            "agent 3 falls silent (removed)",
        ),
    ];
    let plain = run(tmp.path(), Path::new(PAPER), "in-process", "plain", &[]);
    for (name, base, events, label) in cases {
        let file = scenario(tmp.path(), base, name, events);
        let a = run(tmp.path(), &file, "in-process", &format!("{name}-a"), &[]);
        let b = run(tmp.path(), &file, "processes", &format!("{name}-b"), &[]);
        assert!(same_bits(&a, &b), "{name}: the engines differ");
        if base == PAPER {
            assert!(!same_bits(&a, &plain), "{name}: the event changed nothing");
        }
        let listed = json(&a.join("summary.json"))["events"].clone();
        assert_eq!(
            listed.as_array().map(Vec::len),
            Some(events.matches("[[event]]").count() + usize::from(name == "retune")),
            "{name}: {listed}"
        );
        let svg = read(&a.join("errors.svg"));
        assert!(svg.contains(label), "{name}: no mark on errors.svg");
    }
}

#[test]
fn neutral_timelines_give_the_bits_of_a_run_without_them() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        // Down for no step at all.
        (
            "instant",
            PAPER,
            "[[event]]\nt = 0.5\ncut = [3, 5]\n\n[[event]]\nt = 0.5\nrestore = [3, 5]\n",
        ),
        // The scheme's own gain (paper: scheme 1, k_r = 8).
        (
            "same-gain",
            PAPER,
            "[[event]]\nt = 0.5\nset = { \"scheme.control.k_r\" = 8.0 }\n",
        ),
        // A constant reference held is the reference.
        (
            "constant-held",
            OBSERVERLESS,
            "[[event]]\nt = 0.2\ncut = [0, 1]\n",
        ),
    ];
    for (name, base, events) in cases {
        let file = scenario(tmp.path(), base, name, events);
        let with = run(tmp.path(), &file, "in-process", name, &[]);
        let without = run(
            tmp.path(),
            Path::new(base),
            "in-process",
            &format!("{name}-0"),
            &[],
        );
        assert!(same_bits(&with, &without), "{name}");
    }
}

#[test]
fn an_event_at_t0_is_the_scenario_with_that_value_from_the_start() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(
        tmp.path(),
        PAPER,
        "t0",
        "[[event]]\nt = 0.0\nset = { \"scheme.control.k_r\" = 5.0, \"scheme.observer.k_sigma\" = 7.0 }\n",
    );
    let event = run(tmp.path(), &file, "in-process", "event", &[]);
    let sets = ["scheme.control.k_r=5.0", "scheme.observer.k_sigma=7.0"];
    let set = run(tmp.path(), Path::new(PAPER), "in-process", "set", &sets);
    assert!(same_bits(&event, &set));
    let file = scenario(
        tmp.path(),
        OBSERVERLESS,
        "t0-attitude",
        "[[event]]\nt = 0.0\nset = { \"leader.attitude\" = { axis = [0.0, 1.0, 0.0], angle_deg = 30.0 } }\n",
    );
    let event = run(tmp.path(), &file, "in-process", "event-r0", &[]);
    let set = ["leader.attitude={axis=[0.0, 1.0, 0.0], angle_deg=30.0}"];
    let set = run(
        tmp.path(),
        Path::new(OBSERVERLESS),
        "in-process",
        "set-r0",
        &set,
    );
    assert!(same_bits(&event, &set));
}

#[test]
fn a_cut_drops_exactly_the_messages_stamped_in_it_and_reports_whom_it_cuts_off() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(tmp.path(), PAPER, "cut", CUT);
    let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
    o.assert_code(0);
    assert!(o.stdout.contains("t = 0.5 s: cut 3–5"), "{}", o.stdout);
    let said = "agents 4, 5 unreachable from the leader during [0.5, 1.2) s";
    assert!(
        o.stderr.contains(said) || o.stdout.contains(said),
        "{}{}",
        o.stdout,
        o.stderr
    );
    let out = run(tmp.path(), &file, "in-process", "out", &[]);
    let s = json(&out.join("summary.json"));
    let unreachable = &s["unreachable"][0];
    assert_eq!(unreachable["agents"], serde_json::json!([4, 5]));
    assert_eq!(
        (unreachable["from"].as_f64(), unreachable["to"].as_f64()),
        (Some(0.5), Some(1.2))
    );
    // dt = 1e-3, continuous coupling: 4 messages per step, steps [500, 1200).
    let lost = |from: u64, to: u64| {
        let links = s["links"].as_array().expect("links");
        let l = links.iter().find(|l| l["from"] == from && l["to"] == to);
        l.unwrap_or_else(|| panic!("no link {from}→{to}: {links:?}"))["lost"].as_u64()
    };
    assert_eq!(lost(3, 5), Some(4 * 700));
    assert_eq!(lost(5, 3), Some(4 * 700));
}

#[test]
fn a_removed_edge_is_the_network_without_it() {
    let tmp = tempfile::tempdir().unwrap();
    let off = "\n[graph]\nassumptions = \"off\"\n";
    let cut = scenario(
        tmp.path(),
        PAPER,
        "removed",
        &format!("[[event]]\nt = 0.0\ncut = [4, 5]\nhold = false\n{off}"),
    );
    let edge = "[[edge]]\nagents = [4, 5]\n";
    let text = read(Path::new(PAPER));
    assert!(text.contains(edge));
    // The edge's gain line follows it: drop both.
    let mut lines: Vec<&str> = text.lines().collect();
    let at = lines.iter().position(|l| *l == "agents = [4, 5]").unwrap();
    lines.drain(at - 1..=at + 1);
    let without = tmp.path().join("without.toml");
    fs::write(&without, lines.join("\n") + off).unwrap();
    let a = run(tmp.path(), &cut, "in-process", "a", &[]);
    let b = run(tmp.path(), &without, "in-process", "b", &[]);
    assert!(same_bits(&a, &b));
}

#[test]
fn a_repointing_makes_the_error_jump_by_the_angle_and_decay_again() {
    let tmp = tempfile::tempdir().unwrap();
    // Observerless, constant reference R₀ = Rot(0.8π, u0), converged to
    // 3e-4 by t = 10 s; then R₀ jumps to Rot(60°, z), far from it.
    let events = REPOINT.replace("t = 1.5", "t = 10.0");
    let file = scenario(tmp.path(), OBSERVERLESS, "repoint", &events);
    let out = run(
        tmp.path(),
        &file,
        "in-process",
        "out",
        &["simulation.duration=25"],
    );
    let text = read(&out.join("errors.csv"));
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let att = header
        .iter()
        .position(|h| *h == "att_err")
        .expect("att_err");
    let at = |t: f64| -> f64 {
        (text.lines().skip(1))
            .map(|l| l.split(',').collect::<Vec<_>>())
            .filter(|r| (r[0].parse::<f64>().unwrap() - t).abs() < 1e-9)
            .map(|r| r[att].parse::<f64>().unwrap())
            .fold(0.0, f64::max)
    };
    let (before, after, end) = (at(9.99), at(10.0), at(24.99));
    assert!(before < 1e-2 && after > 0.5, "no jump: {before} → {after}");
    assert!(end < 1e-3, "no decay after the jump: {end}");
}

#[test]
fn bad_events_are_refused_naming_the_event() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "unknown-id",
            "[[event]]\nt = 1.0\ncut = [3, 9]\n",
            "event[0].cut: agent 9 does not exist",
        ),
        (
            "not-a-link",
            "[[event]]\nt = 1.0\ncut = [1, 7]\n",
            "event[0].cut: 1–7 is neither",
        ),
        (
            "late",
            "[[event]]\nt = 50.0\ncut = [1, 3]\n",
            "event[0].t: must be in [0, 40)",
        ),
        (
            "off-grid",
            "[[event]]\nt = 1.0005\ncut = [1, 3]\n",
            "event[0].t: must be a whole multiple",
        ),
        (
            "restore-uncut",
            "[[event]]\nt = 1.0\nrestore = [1, 3]\n",
            "event[0].restore: 1–3 is not cut",
        ),
        (
            "cut-twice",
            "[[event]]\nt = 1.0\ncut = [1, 3]\n\n[[event]]\nt = 2.0\ncut = [3, 1]\n",
            "event[1].cut: 3–1 is already cut (event[0])",
        ),
        (
            "resume-unsilenced",
            "[[event]]\nt = 1.0\nagent = 2\naction = \"resume\"\n",
            "event[0].action: agent 2 is not silent",
        ),
        (
            "two-actions",
            "[[event]]\nt = 1.0\ncut = [1, 3]\nagent = 2\naction = \"silence\"\n",
            "event[0]: give exactly one of",
        ),
        (
            "no-action",
            "[[event]]\nt = 1.0\nagent = 2\n",
            "event[0].action: is required",
        ),
        (
            "unknown-field",
            "[[event]]\nt = 1.0\nset = { \"agent[0].inertia\" = 2.0 }\n",
            "event[0].set.agent[0].inertia: agent[0].inertia cannot be set",
        ),
        (
            "negative-gain",
            "[[event]]\nt = 1.0\nset = { \"scheme.control.k_r\" = -1.0 }\n",
            "must be a finite gain > 0",
        ),
        (
            "time-varying-repoint",
            "[[event]]\nt = 1.0\nset = { \"leader.attitude\" = { axis = [0.0, 0.0, 1.0], angle_deg = 5.0 } }\n",
            "only a constant reference",
        ),
        (
            "empty-set",
            "[[event]]\nt = 1.0\nset = {}\n",
            "event[0].set: sets nothing",
        ),
        (
            "restart-without-crash",
            "[[event]]\nt = 1.0\nagent = 2\naction = \"restart\"\n",
            "event[0].action: agent 2 has not crashed by t = 1 s",
        ),
        (
            "hold-on-restore",
            "[[event]]\nt = 1.0\ncut = [1, 3]\n\n[[event]]\nt = 2.0\nrestore = [1, 3]\nhold = false\n",
            "event[1].hold: is only for cut",
        ),
        (
            "unknown-key",
            "[[event]]\nt = 1.0\ncut = [1, 3]\nwhen = 2\n",
            "when",
        ),
    ];
    for (name, events, says) in cases {
        let file = scenario(tmp.path(), PAPER, name, events);
        let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{name}: {}", o.stderr);
        assert!(
            o.stderr.contains(&format!("{name}.toml")),
            "{name}: {}",
            o.stderr
        );
    }
}

#[test]
fn the_ready_experiment_runs_and_its_cut_shows() {
    let tmp = tempfile::tempdir().unwrap();
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenarios/experiments/link-failure.toml"
    );
    let o = attsync(tmp.path(), &["check", file]);
    o.assert_code(0);
    assert!(o.stdout.contains("t = 8 s: cut 3–5"), "{}", o.stdout);
}
