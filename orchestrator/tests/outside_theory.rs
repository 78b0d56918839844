//! `[graph] assumptions = "off"` (issue 35): scenarios outside the paper's
//! Assumption 1 — a cycle of followers, an agent the leader does not
//! reach, no leader link at all — run when asked for, and say so.
//!
//! - by default each departure is refused (exit 2) naming its field and
//!   the key that allows it;
//! - with `assumptions = "off"`, `check` lists each departure and what the
//!   paper no longer guarantees; a run warns once, and `summary.json` and
//!   `manifest.json` carry `outside_theory`; a scenario inside the theory
//!   has no such key;
//! - both engines give byte-identical states for each departure;
//! - one-way edges (`from`, `to`): only the receiver hears the sender —
//!   turning an agent nobody hears changes only its own error history;
//!   malformed, repeated or overlapping edges are refused naming them;
//! - physics: an agent nobody reaches moves as if alone — changing another
//!   agent's initial attitude leaves its error history bit for bit.

mod common;

use common::{OBSERVERLESS, attsync, json, read, run_args};
use std::fs;
use std::path::{Path, PathBuf};

/// The paper's observerless scenario, 3 s, with `edit` applied to its
/// text, written into `dir/name.toml`.
fn scenario(dir: &Path, name: &str, off: bool, edit: impl Fn(String) -> String) -> PathBuf {
    let mut text = edit(read(Path::new(OBSERVERLESS)));
    if off {
        text += "\n[graph]\nassumptions = \"off\"\n";
    }
    let file = dir.join(format!("{name}.toml"));
    fs::write(&file, text).expect("write");
    file
}

/// An edge 1–5, closing the cycle 1–3–5–1.
fn cycle(text: String) -> String {
    text + "\n[[edge]]\nagents = [1, 5]\ngain = [3.0, 2.0, 1.0]\n"
}

/// Without edge 4–5 (agent 4's only one): agent 4 alone.
fn unreachable(text: String) -> String {
    let edge = "[[edge]]\nagents = [4, 5]\ngain = [6.0, 5.0, 4.0]   # diag(10-m, 9-m, 8-m), m = min(i,j)\n";
    assert!(text.contains(edge));
    text.replace(edge, "")
}

/// Edge 4–5 one-way, from 5 to 4: 4 hears 5, 5 does not hear 4.
fn one_way(text: String) -> String {
    let edge = "[[edge]]\nagents = [4, 5]\n";
    assert!(text.contains(edge));
    text.replace(edge, "[[edge]]\nfrom = 5\nto = 4\n")
}

/// Without any `[[leader_link]]`.
fn no_leader(text: String) -> String {
    let mut out = String::new();
    let mut skip = 0;
    for line in text.lines() {
        if line == "[[leader_link]]" {
            skip = 3;
        }
        if skip > 0 {
            skip -= 1;
            continue;
        }
        out += line;
        out.push('\n');
    }
    assert!(!out.contains("leader_link"));
    out
}

type Edit = fn(String) -> String;

const CASES: [(&str, Edit, &str); 4] = [
    ("cycle", cycle, "edge 1–5 closes a cycle"),
    ("one-way", one_way, "edge 5→4 is one-way"),
    (
        "unreachable",
        unreachable,
        "agent 4 unreachable from the leader",
    ),
    ("no-leader", no_leader, "no [[leader_link]]"),
];

#[test]
fn each_departure_is_refused_by_default_naming_the_key_that_allows_it() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, edit, _) in CASES {
        let file = scenario(tmp.path(), name, false, edit);
        let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
        o.assert_code(2);
        assert!(o.stderr.contains("Assumption 1"), "{name}: {}", o.stderr);
        assert!(
            o.stderr.contains("[graph] assumptions = \"off\""),
            "{name}: {}",
            o.stderr
        );
    }
}

#[test]
fn outside_the_theory_check_says_what_is_lost_and_runs_are_marked() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, edit, says) in CASES {
        let file = scenario(tmp.path(), name, true, edit);
        let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
        o.assert_code(0);
        assert!(o.stdout.contains("outside the theory"), "{}", o.stdout);
        assert!(o.stdout.contains(&format!("  - {says}")), "{}", o.stdout);
        let f = file.to_str().unwrap();
        let mut dirs = Vec::new();
        for engine in ["in-process", "processes"] {
            let out = tmp.path().join(format!("{name}-{engine}"));
            let o = attsync(
                tmp.path(),
                &run_args(f, engine, &out, &["simulation.duration=3"]),
            );
            o.assert_code(0);
            let warned = o.stderr.matches("outside the paper's theory").count();
            assert_eq!(warned, 1, "{}", o.stderr);
            for file in ["summary.json", "manifest.json"] {
                let listed = json(&out.join(file))["outside_theory"].clone();
                let listed = listed.as_array().expect("a list").clone();
                assert!(listed.iter().any(|d| d.as_str().unwrap().starts_with(says)));
            }
            dirs.push(out);
        }
        let states = |d: &PathBuf| fs::read(d.join("states.bin")).expect("states.bin");
        assert!(
            states(&dirs[0]) == states(&dirs[1]),
            "{name}: engines differ"
        );
    }
    let inside = tmp.path().join("inside");
    attsync(
        tmp.path(),
        &run_args(
            OBSERVERLESS,
            "in-process",
            &inside,
            &["simulation.duration=1"],
        ),
    )
    .assert_code(0);
    assert!(
        json(&inside.join("summary.json"))
            .get("outside_theory")
            .is_none()
    );
}

/// The `errors.csv` rows of agent `id` in `out`.
fn rows_of(out: &Path, id: &str) -> Vec<String> {
    let text = read(&out.join("errors.csv"));
    (text.lines())
        .filter(|l| l.split(',').nth(1) == Some(id))
        .map(str::to_string)
        .collect()
}

#[test]
fn a_one_way_edge_carries_states_one_way_only() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(tmp.path(), "one-way", true, one_way);
    let f = file.to_str().unwrap();
    let run = |name: &str, set: &[&str]| {
        let out = tmp.path().join(name);
        let mut sets = vec!["simulation.duration=3"];
        sets.extend_from_slice(set);
        attsync(tmp.path(), &run_args(f, "in-process", &out, &sets)).assert_code(0);
        out
    };
    let turn = |k: usize| format!("agent[{k}].attitude={{axis=[0.0, 0.0, 1.0], angle_pi=0.5}}");
    let base = run("base", &[]);
    // Agent 4 (agent[3]) turned: nobody hears it, so only its own rows change.
    let four = run("four", &[&turn(3)]);
    for id in ["1", "2", "3", "5", "6", "7"] {
        assert_eq!(rows_of(&base, id), rows_of(&four, id), "agent {id}");
    }
    assert_ne!(rows_of(&base, "4"), rows_of(&four, "4"));
    // Agent 5 (agent[4]) turned: 4 hears it.
    let five = run("five", &[&turn(4)]);
    assert_ne!(rows_of(&base, "4"), rows_of(&five, "4"));
}

#[test]
fn bad_edges_are_refused_naming_the_edge() {
    let tmp = tempfile::tempdir().unwrap();
    let cases = [
        (
            "both-forms",
            "\n[[edge]]\nagents = [6, 7]\nfrom = 6\ngain = [3.0, 2.0, 1.0]\n",
            "give `agents = [i, j]`",
        ),
        (
            "from-only",
            "\n[[edge]]\nfrom = 6\ngain = [3.0, 2.0, 1.0]\n",
            "give `agents = [i, j]`",
        ),
        (
            "twice",
            "\n[[edge]]\nfrom = 6\nto = 7\ngain = [3.0, 2.0, 1.0]\n\n[[edge]]\nfrom = 6\nto = 7\ngain = [3.0, 2.0, 1.0]\n",
            "duplicate edge 6→7",
        ),
        (
            "over-an-edge",
            "\n[[edge]]\nfrom = 3\nto = 5\ngain = [3.0, 2.0, 1.0]\n",
            "agent 5 already hears agent 3",
        ),
    ];
    for (name, extra, says) in cases {
        let file = scenario(tmp.path(), name, true, |t| t + extra);
        let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
        o.assert_code(2);
        assert!(o.stderr.contains(says), "{name}: {}", o.stderr);
    }
    // A link override against a one-way edge's direction.
    let file = scenario(tmp.path(), "reverse-link", true, |t| {
        one_way(t) + "\n[[network.link]]\nfrom = 4\nto = 5\ndelay = 0.01\n"
    });
    let o = attsync(tmp.path(), &["check".as_ref(), file.as_os_str()]);
    o.assert_code(2);
    assert!(o.stderr.contains("4 → 5 is not a link"), "{}", o.stderr);
}

#[test]
fn an_agent_nobody_reaches_moves_as_if_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(tmp.path(), "alone", true, unreachable);
    let f = file.to_str().unwrap();
    let rows_of_4 = |out: &Path| rows_of(out, "4");
    let (a, b) = (tmp.path().join("a"), tmp.path().join("b"));
    let set_a = ["simulation.duration=3"];
    // Agent 1 (agent[0]) turned by 90° about z at t = 0.
    let set_b = [
        "simulation.duration=3",
        "agent[0].attitude={axis=[0.0, 0.0, 1.0], angle_pi=0.5}",
    ];
    attsync(tmp.path(), &run_args(f, "in-process", &a, &set_a)).assert_code(0);
    attsync(tmp.path(), &run_args(f, "in-process", &b, &set_b)).assert_code(0);
    assert_ne!(read(&a.join("errors.csv")), read(&b.join("errors.csv")));
    let (ra, rb) = (rows_of_4(&a), rows_of_4(&b));
    assert!(ra.len() > 100);
    assert_eq!(ra, rb, "agent 4 is alone: nothing else moves it");
}
