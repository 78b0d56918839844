//! Reading and comparing results directories (`errors.csv`, `summary.json`,
//! `states.bin`, `scenario.toml`, the staging directory).

use serde_json::Value;
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};

/// The staging directory `attsync` (pid `pid`) writes `out` into:
/// `.<name>.partial-<pid>` beside it.
#[must_use]
pub fn staging_dir(out: &Path, pid: u32) -> PathBuf {
    let name = out.file_name().expect("named").to_string_lossy();
    out.with_file_name(format!(".{name}.partial-{pid}"))
}

/// A text file's contents (panics naming the file).
#[must_use]
pub fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Asserts two files are byte-identical; the message names the first
/// differing line.
#[track_caller]
pub fn assert_same_file(a: &Path, b: &Path) {
    let (ta, tb) = (read(a), read(b));
    if ta == tb {
        return;
    }
    let (la, lb): (Vec<&str>, Vec<&str>) = (ta.lines().collect(), tb.lines().collect());
    let k = la
        .iter()
        .zip(&lb)
        .position(|(x, y)| x != y)
        .unwrap_or(la.len().min(lb.len()));
    panic!(
        "{} and {} differ (lines: {} vs {}); first difference at line {}:\n  {:?}\n  {:?}",
        a.display(),
        b.display(),
        la.len(),
        lb.len(),
        k + 1,
        la.get(k).unwrap_or(&"<end of file>"),
        lb.get(k).unwrap_or(&"<end of file>"),
    );
}

/// The agent ids in an `errors.csv`.
#[must_use]
pub fn csv_agents(csv: &str) -> BTreeSet<u32> {
    csv.lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .nth(1)
                .and_then(|a| a.parse().ok())
                .unwrap_or_else(|| panic!("bad errors.csv row {l:?}"))
        })
        .collect()
}

/// The number of data rows (without the header) of an `errors.csv`.
#[must_use]
pub fn csv_rows(csv: &str) -> usize {
    csv.lines().count().saturating_sub(1)
}

/// `dir/summary.json`.
#[must_use]
pub fn summary(dir: &Path) -> Value {
    let path = dir.join("summary.json");
    serde_json::from_str(&read(&path)).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `dir/summary.json` without the fields `drop`.
#[must_use]
pub fn summary_without(dir: &Path, drop: &[&str]) -> Value {
    let mut s = summary(dir);
    let obj = s.as_object_mut().expect("summary.json is an object");
    for k in drop {
        obj.remove(*k);
    }
    s
}

/// Asserts two binary files are byte-identical.
#[track_caller]
pub fn assert_same_bytes(a: &Path, b: &Path) {
    let bytes = |p: &Path| fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    let (ba, bb) = (bytes(a), bytes(b));
    if ba != bb {
        let k = ba
            .iter()
            .zip(&bb)
            .position(|(x, y)| x != y)
            .unwrap_or(ba.len().min(bb.len()));
        panic!(
            "{} and {} differ ({} vs {} bytes), first at byte {k}",
            a.display(),
            b.display(),
            ba.len(),
            bb.len()
        );
    }
}

/// Asserts two results directories hold the same run: byte-identical
/// `errors.csv`, `scenario.toml` and (where written) `states.bin`, and the
/// same `summary.json` except `engine`, `wall_seconds`, `nodes` (wall-clock
/// times and memory of the processes engine's nodes: neither deterministic
/// nor written by the in-process engine) and `threads` (the in-process
/// engine's thread count, absent for the processes engine).
#[track_caller]
pub fn assert_same_results(a: &Path, b: &Path) {
    assert_same_file(&a.join("errors.csv"), &b.join("errors.csv"));
    assert_same_file(&a.join("scenario.toml"), &b.join("scenario.toml"));
    let states = |d: &Path| d.join("states.bin");
    match (states(a).exists(), states(b).exists()) {
        (true, true) => assert_same_bytes(&states(a), &states(b)),
        (false, false) => {}
        (ea, eb) => panic!(
            "states.bin in {} only ({}: {ea}, {}: {eb})",
            if ea { "the first" } else { "the second" },
            a.display(),
            b.display()
        ),
    }
    let skip = ["engine", "wall_seconds", "nodes", "threads", "hosts"];
    assert_eq!(
        summary_without(a, &skip),
        summary_without(b, &skip),
        "summary.json of {} and {} differ",
        a.display(),
        b.display()
    );
}
