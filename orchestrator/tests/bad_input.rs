//! Bad input is refused quickly, completely and briefly (issue 10, items 10
//! and 11):
//! - every unknown key, wrong type and bad `--set` of a scenario is reported
//!   in one run, one line each as `FILE: FIELD: REASON`, exit code 2;
//! - a file over the size limit (256 MiB) is refused before it is parsed —
//!   by its size when it has one, by a bounded read when it has none
//!   (`/dev/zero`) — with a message naming the file, the limit and the size;
//! - a huge line of input is never echoed whole in a message.

mod common;

use common::PAPER;
use std::ffi::OsString;
use std::fs;
use std::path::Path;

/// The size limit, in bytes, as printed.
const LIMIT: &str = "268435456";

/// Exit code and stderr of `attsync check FILE --set …`.
fn check(file: &Path, sets: &[&str]) -> (Option<i32>, String) {
    let mut args: Vec<OsString> = vec!["check".into(), file.into()];
    for s in sets {
        args.extend(["--set".into(), (*s).into()]);
    }
    let out = common::attsync(Path::new(env!("CARGO_MANIFEST_DIR")), &args);
    (out.code, out.stderr)
}

/// `text` with the first occurrence of `from` replaced by `to`.
#[track_caller]
fn edit(text: &str, from: &str, to: &str) -> String {
    assert!(text.contains(from), "`{from}` not in the scenario");
    text.replacen(from, to, 1)
}

#[test]
fn unknown_keys_wrong_types_and_bad_sets_are_reported_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("s.toml");
    let text = fs::read_to_string(PAPER).unwrap();
    let text = edit(&text, "[simulation]\n", "[simulation]\ncolour = 1\n");
    let text = edit(&text, "[[agent]]\n", "[[agent]]\nshape = \"round\"\n");
    let text = edit(&text, "dt = 0.001", "dt = \"fast\"");
    fs::write(&file, text).unwrap();
    let (code, stderr) = check(&file, &["agent[99].id=3"]);
    assert_eq!(code, Some(2), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 4, "one line per problem:\n{stderr}");
    let prefix = format!("{}: ", file.display());
    assert!(lines.iter().all(|l| l.starts_with(&prefix)), "{stderr}");
    for (field, reason) in [
        ("--set agent[99].id=3", "index out of range"),
        ("simulation.colour", "unknown field `colour`"),
        ("agent[0].shape", "unknown field `shape`"),
        ("simulation.dt", "invalid type: string \"fast\""),
    ] {
        let start = format!("{prefix}{field}: ");
        assert!(
            lines
                .iter()
                .any(|l| l.starts_with(&start) && l.contains(reason)),
            "no `{start}…{reason}…`:\n{stderr}"
        );
    }
    // Problems in the text say where they are.
    assert_eq!(lines.iter().filter(|l| l.contains("(line ")).count(), 3);
}

#[test]
fn bad_sets_are_reported_with_the_schema_problems_they_leave() {
    let (code, stderr) = check(
        Path::new(PAPER),
        &["no_equals_sign", "leader.colour=1", "scheme.kind=fancy"],
    );
    assert_eq!(code, Some(2), "{stderr}");
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 3, "{stderr}");
    assert!(lines[0].contains(": --set no_equals_sign: "), "{stderr}");
    assert!(
        stderr.contains("leader.colour: unknown field `colour`"),
        "{stderr}"
    );
    assert!(
        stderr.contains("scheme.kind: unknown variant `fancy`"),
        "{stderr}"
    );
}

#[cfg(unix)]
#[test]
fn dev_zero_is_refused_by_a_bounded_read() {
    let (code, stderr) = check(Path::new("/dev/zero"), &[]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.starts_with("/dev/zero: "), "{stderr}");
    assert!(stderr.contains(LIMIT), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}

#[test]
fn a_file_over_the_limit_is_refused_by_its_size() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("huge.toml");
    // Sparse: 300 MiB of size, no blocks written.
    fs::File::create(&file).unwrap().set_len(300 << 20).unwrap();
    let (code, stderr) = check(&file, &[]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.starts_with(&format!("{}: ", file.display())),
        "{stderr}"
    );
    assert!(stderr.contains(&(300u64 << 20).to_string()), "{stderr}");
    assert!(stderr.contains(LIMIT), "{stderr}");
}

#[test]
fn a_huge_line_is_not_echoed_whole() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        ("garbage.toml", "x".repeat(50_000_000)),
        ("key.toml", format!("{} = 1", "k".repeat(50_000_000))),
        ("string.toml", format!("a = \"{}", "s".repeat(50_000_000))),
    ];
    for (name, text) in cases {
        let file = dir.path().join(name);
        fs::write(&file, text).unwrap();
        let (code, stderr) = check(&file, &[]);
        assert_eq!(
            code,
            Some(2),
            "{name}: {}",
            &stderr[..stderr.len().min(2000)]
        );
        assert!(
            stderr.len() < 2048,
            "{name}: {} bytes of error",
            stderr.len()
        );
        assert!(
            stderr.starts_with(&format!("{}: ", file.display())),
            "{name}: {stderr}"
        );
    }
}

#[test]
fn problems_after_a_dropped_array_element_keep_their_written_index() {
    // agent[0] lacks `omega` (so it is set aside); agent[2]'s unknown key
    // must still be reported as agent[2], with its line.
    let text = fs::read_to_string(PAPER).unwrap();
    let text = edit(&text, "omega = [1.5, 1.0, 2.0]", "omegaa = [1.5, 1.0, 2.0]");
    let mut parts: Vec<&str> = text.split("[[agent]]\n").collect();
    let third = format!("colour = 1\n{}", parts[3]);
    parts[3] = &third;
    let text = parts.join("[[agent]]\n");
    match attsync::scenario::load_str(Path::new("x.toml"), &text, &[]) {
        Err(e @ attsync::scenario::ScenarioError::Parse { .. }) => {
            let msg = e.to_string();
            assert!(
                msg.contains("x.toml: agent[2].colour: unknown field"),
                "{msg}"
            );
            assert!(
                msg.contains("x.toml: agent[0].omegaa: unknown field"),
                "{msg}"
            );
            assert!(
                msg.contains("x.toml: agent[0].omega: missing field"),
                "{msg}"
            );
            assert_eq!(msg.lines().count(), 3, "{msg}");
        }
        other => panic!("expected a Parse error, got {:?}", other.map(|_| ())),
    }
}
