//! Validation that scales (issue 11 item 4): `attsync gen tree` of a
//! 20 000-agent tree (100 leader links) followed by `attsync check` succeeds, with the spectrum
//! of `Ξ + LLᵀ` summarised (count and extremes) instead of listed, and
//! Appendix D's condition decided without a dense matrix. On a small
//! scenario the summary agrees with the full list, which is still printed.
//!
//! A valid file is read in one pass, in place; only a file with a schema
//! problem goes through the collecting pass. So: a large file with several
//! problems still gets all of them at once, with their lines; and the two
//! passes agree on every valid file (same `Scenario`, same `Network`). The
//! header of `gen tree`'s file is the whole command that reproduces it.
//!
//! The text is read by a streaming reader (`toml_parser`'s events into a
//! compact tree, no token or event vector): it reads what toml reads, the
//! same `Scenario` and the same `scenario.toml` bytes, with `--set` too.

mod common;

use attsync::generate::{TreeParams, tree};
use attsync::scenario::deserialize::{Kind, collect, deserialize};
use attsync::scenario::schema::SchemeKind;
use attsync::scenario::{ScenarioError, load_str, resolve::resolve};
use common::PAPER;
use std::path::Path;
use toml::Table;

/// `attsync args…` in `cwd`; its stdout, after asserting success.
#[track_caller]
fn attsync_ok(cwd: &Path, args: &[&str]) -> String {
    common::attsync(cwd, args).assert_ok().stdout.clone()
}

/// `(count, λmin, λmax)` from `spectrum of Ξ + LLᵀ: N eigenvalues in [a, b]`.
fn summary(stdout: &str) -> (usize, f64, f64) {
    let line = stdout
        .lines()
        .find(|l| l.starts_with("spectrum of Ξ + LLᵀ: ") && l.contains(" eigenvalues in ["))
        .unwrap_or_else(|| panic!("no spectrum summary:\n{stdout}"));
    let rest = line.trim_start_matches("spectrum of Ξ + LLᵀ: ");
    let (count, range) = rest
        .split_once(" eigenvalues in [")
        .expect("the summary's form");
    let (lo, hi) = range
        .trim_end_matches(']')
        .split_once(", ")
        .expect("two extremes");
    (
        count.parse().expect("a count"),
        lo.parse().expect("λmin"),
        hi.parse().expect("λmax"),
    )
}

#[test]
fn a_generated_tree_of_20000_agents_passes_check() {
    let tmp = tempfile::tempdir().unwrap();
    let args = ["gen", "tree", "--agents", "20000", "--leader-links", "100"];
    attsync_ok(
        tmp.path(),
        &[&args[..], &["--seed", "1", "--out", "big.toml"]].concat(),
    );
    let out = attsync_ok(tmp.path(), &["check", "big.toml"]);
    let (count, lo, hi) = summary(&out);
    assert_eq!(count, 20000);
    assert!(0.0 < lo && lo < hi, "[{lo}, {hi}]");
    assert!(
        !out.lines().any(|l| l.starts_with("spectrum of Ξ + LLᵀ: [")),
        "no full list for a large N"
    );
    assert!(
        out.contains("gain condition (Appendix D, F > 0): holds"),
        "gen raises k_σ until F > 0:\n{}",
        out.lines()
            .filter(|l| l.contains("gain"))
            .collect::<Vec<_>>()
            .join("\n")
    );
    // gen's k_σ is the first doubling that makes F ≻ 0: half of it fails.
    let text = std::fs::read_to_string(tmp.path().join("big.toml")).unwrap();
    let k_sigma: f64 = text
        .lines()
        .find_map(|l| l.strip_prefix("k_sigma = "))
        .expect("k_sigma in the generated file")
        .parse()
        .unwrap();
    assert!(
        k_sigma > 12.0,
        "a deep tree needs more than the paper's k_σ"
    );
    let half = format!("scheme.observer.k_sigma={}", k_sigma / 2.0);
    let out = attsync_ok(tmp.path(), &["check", "big.toml", "--set", &half]);
    assert!(
        out.contains("gain condition (Appendix D, F > 0): FAILS"),
        "k_σ = {}:\n{}",
        k_sigma / 2.0,
        out.lines()
            .filter(|l| l.contains("gain"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}

#[test]
fn the_summary_agrees_with_the_full_list_on_the_paper_scenario() {
    let tmp = tempfile::tempdir().unwrap();
    let out = attsync_ok(tmp.path(), &["check", PAPER]);
    let (count, lo, hi) = summary(&out);
    let list = out
        .lines()
        .find(|l| l.starts_with("spectrum of Ξ + LLᵀ: ["))
        .expect("the full list for a small N");
    let eigs: Vec<f64> = list
        .split_once('[')
        .unwrap()
        .1
        .trim_end_matches(']')
        .split(", ")
        .map(|x| x.parse().unwrap())
        .collect();
    assert_eq!(count, eigs.len());
    // The list is printed to 6 decimals, the summary to 7 significant digits.
    assert!(
        (lo - eigs[0]).abs() < 1e-6 + 1e-6 * lo,
        "{lo} vs {}",
        eigs[0]
    );
    assert!(
        (hi - eigs[count - 1]).abs() < 1e-6 * hi,
        "{hi} vs {}",
        eigs[count - 1]
    );
}

/// The text `attsync gen tree` writes for `agents` agents (without its header).
fn generated(agents: u32, leader_links: u32, scheme: SchemeKind) -> String {
    let p = TreeParams {
        agents,
        leader_links,
        seed: 1,
        scheme,
        duration: None,
    };
    toml::to_string(&tree(&p).expect("valid parameters").scenario).expect("serialises")
}

/// `text` with `insert` put after the `n`-th (0-based) occurrence of
/// `after`, and the 1-based line the insertion starts on.
#[track_caller]
fn insert_after(text: &str, after: &str, n: usize, insert: &str) -> (String, usize) {
    let at = text
        .match_indices(after)
        .nth(n)
        .unwrap_or_else(|| panic!("no {n}-th `{after}`"))
        .0
        + after.len();
    let line = text[..at].matches('\n').count() + 1;
    (format!("{}{insert}{}", &text[..at], &text[at..]), line)
}

#[test]
fn a_large_scenario_with_schema_errors_gets_every_one_reported_at_once() {
    let text = generated(10_000, 10, SchemeKind::ObserverTimeVarying);
    let (text, colour_line) = insert_after(&text, "[[agent]]\n", 9_000, "colour = 1\n");
    let (text, _) = insert_after(&text, "[[edge]]\n", 7_000, "weight = 2\n");
    let dt = text.find("[simulation]\ndt = ").expect("[simulation] dt") + "[simulation]\n".len();
    let end = dt + text[dt..].find('\n').expect("a line");
    let text = format!("{}dt = \"fast\"{}", &text[..dt], &text[end..]);
    let edge = text
        .match_indices("[[edge]]\nagents = ")
        .nth(4_000)
        .expect("edge[4000]")
        .0;
    let text = format!(
        "{}[[edge]]\nagentz = {}",
        &text[..edge],
        &text[edge + "[[edge]]\nagents = ".len()..]
    );
    let e = load_str(Path::new("big.toml"), &text, &[]).expect_err("schema errors");
    let ScenarioError::Parse { issues, .. } = &e else {
        panic!("expected a Parse error, got {e}");
    };
    let fields: Vec<&str> = issues.iter().map(|i| i.field.as_str()).collect();
    let mut sorted = fields.clone();
    sorted.sort_unstable();
    assert_eq!(
        sorted,
        [
            "agent[9000].colour",
            "edge[4000].agents",
            "edge[4000].agentz",
            "edge[7000].weight",
            "simulation.dt"
        ],
        "{e}"
    );
    let colour = &issues[fields
        .iter()
        .position(|f| *f == "agent[9000].colour")
        .unwrap()];
    assert!(
        colour.reason.starts_with("unknown field `colour`")
            && colour
                .reason
                .ends_with(&format!("(line {colour_line}, column 1)")),
        "{colour}"
    );
    let missing = &issues[fields
        .iter()
        .position(|f| *f == "edge[4000].agents")
        .unwrap()];
    assert!(
        missing.reason.starts_with("missing field `agents`"),
        "{missing}"
    );
    assert_eq!(
        issues
            .iter()
            .filter(|i| i.reason.contains("(line "))
            .count(),
        5,
        "every problem is in the text:\n{e}"
    );
}

/// The fast path's and the collecting pass's `Scenario` and `Network` of
/// `text` (a valid file), asserting they agree.
#[track_caller]
fn agree(what: &str, text: &str) {
    let doc: Table = text.parse().expect("TOML");
    let (fast, slow) = (deserialize(&doc), collect(&doc));
    let (fast, slow) = match (fast, slow) {
        (Ok(f), Ok(s)) => (f, s),
        (f, s) => panic!("{what}: fast {:?}, collecting {:?}", f.err(), s.err()),
    };
    assert_eq!(format!("{fast:?}"), format!("{slow:?}"), "{what}: Scenario");
    let (fast, slow) = (resolve(&fast), resolve(&slow));
    match (fast, slow) {
        (Ok(f), Ok(s)) => assert_eq!(f.network, s.network, "{what}: Network"),
        (Err(f), Err(s)) => assert_eq!(f, s, "{what}: issues"),
        (f, s) => panic!("{what}: fast {:?}, collecting {:?}", f.err(), s.err()),
    }
}

#[test]
fn the_fast_path_and_the_collecting_pass_agree_on_valid_files() {
    for scheme in [
        SchemeKind::ObserverTimeVarying,
        SchemeKind::ObserverConstant,
        SchemeKind::Observerless,
    ] {
        agree(&format!("tree {scheme:?}"), &generated(2_000, 3, scheme));
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
    let mut files = 0;
    for dir in [root.clone(), root.join("paper"), root.join("plugin")] {
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            if f.extension().is_some_and(|e| e == "toml") {
                agree(
                    &f.display().to_string(),
                    &std::fs::read_to_string(&f).unwrap(),
                );
                files += 1;
            }
        }
    }
    assert!(files >= 10, "{files} scenario files");
    // An enum as a table: only toml's own deserializer takes it, so the
    // fast path hands it to the collecting pass. A datetime read as a string.
    let paper = std::fs::read_to_string(PAPER).unwrap();
    let table_enum = paper.replacen(
        "coupling = \"continuous\"",
        "coupling = { continuous = [] }",
        1,
    );
    assert_ne!(table_enum, paper, "the paper scenario sets coupling");
    agree("coupling as a table", &table_enum);
    let dated = paper.replacen("name = \"paper-timevarying\"", "name = 2026-12-01", 1);
    assert_ne!(dated, paper, "the paper scenario has a name");
    agree("a datetime as the name", &dated);
}

#[test]
fn a_failing_file_gets_the_same_problems_from_both() {
    let text = generated(500, 2, SchemeKind::ObserverConstant);
    let (text, _) = insert_after(&text, "[[agent]]\n", 300, "command = 3\n");
    let doc: Table = text.parse().expect("TOML");
    let (fast, slow) = (deserialize(&doc), collect(&doc));
    let (fast, slow) = (fast.expect_err("invalid"), slow.expect_err("invalid"));
    assert_eq!(format!("{fast:?}"), format!("{slow:?}"));
    assert!(
        fast.iter()
            .any(|p| p.path.to_string() == "agent[300].command" && p.kind == Kind::Value),
        "{fast:?}"
    );
}

#[test]
fn the_header_of_a_generated_file_is_the_command_that_reproduces_it() {
    let tmp = tempfile::tempdir().unwrap();
    let first = [
        "gen",
        "tree",
        "--agents",
        "40",
        "--seed",
        "3",
        "--scheme",
        "observer-constant",
        "--duration",
        "30",
        "--out",
        "a.toml",
    ];
    attsync_ok(tmp.path(), &first);
    let a = std::fs::read_to_string(tmp.path().join("a.toml")).unwrap();
    let header = a.lines().next().unwrap();
    let command = header
        .strip_prefix("# Generated by: attsync ")
        .unwrap_or_else(|| panic!("{header}"));
    for flag in [
        "--scheme observer-constant",
        "--duration 30",
        "--leader-links 1",
    ] {
        assert!(command.contains(flag), "{header}");
    }
    let mut again: Vec<&str> = command.split(' ').collect();
    again.extend(["--out", "b.toml"]);
    attsync_ok(tmp.path(), &again);
    let b = std::fs::read_to_string(tmp.path().join("b.toml")).unwrap();
    assert_eq!(a, b, "the header's command writes the same file");
}

/// The scenario files, each with its path.
fn scenario_files() -> Vec<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios");
    let mut out = Vec::new();
    for dir in [root.clone(), root.join("paper"), root.join("plugin")] {
        for f in std::fs::read_dir(&dir).unwrap() {
            let f = f.unwrap().path();
            if f.extension().is_some_and(|e| e == "toml") {
                out.push((
                    f.display().to_string(),
                    std::fs::read_to_string(&f).unwrap(),
                ));
            }
        }
    }
    out
}

/// `text` read by toml into a `Table`, with `sets` applied: the document
/// as it was before the streaming reader.
fn toml_document(text: &str, sets: &[String]) -> Table {
    let mut doc: Table = text.parse().expect("TOML");
    for s in sets {
        attsync::scenario::overrides::apply(&mut doc, s).expect("the override applies");
    }
    doc
}

/// The streaming reader (`load_str`) against toml's `Table` with the same
/// overrides: the same `scenario.toml` bytes and the same `Scenario`.
#[track_caller]
fn reads_as_toml(what: &str, text: &str, sets: &[String]) -> bool {
    let doc = toml_document(text, sets);
    let written = toml::to_string(&doc).expect("serialises");
    match load_str(Path::new("s.toml"), text, sets) {
        Ok(loaded) => {
            let ours = toml::to_string(&loaded.document).expect("serialises");
            assert_eq!(ours, written, "{what}: scenario.toml");
            let slow = collect(&doc).unwrap_or_else(|e| panic!("{what}: {e:?}"));
            assert_eq!(
                format!("{:?}", loaded.scenario),
                format!("{slow:?}"),
                "{what}: Scenario"
            );
            true
        }
        // Valid TOML and schema; a model assumption fails (resolve).
        Err(ScenarioError::Invalid { .. }) => false,
        Err(e) => panic!("{what}: {e}"),
    }
}

#[test]
fn the_streaming_reader_reads_what_toml_reads() {
    let mut read = 0;
    let files = scenario_files();
    for (name, text) in &files {
        read += usize::from(reads_as_toml(name, text, &[]));
    }
    assert!(read >= 4, "{read} of {} files read", files.len());
    for scheme in [
        SchemeKind::ObserverTimeVarying,
        SchemeKind::ObserverConstant,
        SchemeKind::Observerless,
    ] {
        let text = generated(3_000, 4, scheme);
        assert!(reads_as_toml(&format!("tree {scheme:?}"), &text, &[]));
    }
    let sets: Vec<String> = [
        "simulation.duration=0.5",
        "agent[2].omega=[0.25, -1, 3e-2]",
        "agent[7].attitude.angle_deg=12.5",
        "name=\"renamed\"",
        "guard.omega=500.0",
        "network.seed=7",
    ]
    .map(String::from)
    .to_vec();
    let text = generated(1_000, 2, SchemeKind::ObserverTimeVarying);
    assert!(reads_as_toml("tree with --set", &text, &sets));
    let paper = std::fs::read_to_string(PAPER).unwrap();
    // A table defined after one of its sub-tables (TOML allows it): read,
    // and its unknown key reported.
    let late = format!("{paper}\n[guard.extra]\n[guard]\nomega = 100.0\n");
    assert!(late.parse::<Table>().is_ok(), "TOML");
    let e = load_str(Path::new("s.toml"), &late, &[]).expect_err("guard.extra is unknown");
    assert!(e.to_string().contains("guard.extra"), "{e}");
}
