//! `attsync-bench run --quick`, cut down to its quickest case (one paper
//! scenario, 0.2 simulated seconds, adaptive waiting, one repetition, no
//! waiting for an idle machine), must produce a complete report: every
//! table present with at least one row, every row with every column, and no
//! figure that could not be measured ("—") or repetition that failed. No
//! timing is asserted.
//!
//! It runs the workspace's `attsync`, `attsync-agent` and `attsync-leader`
//! from the same target directory: build them first
//! (`cargo build --release --workspace`).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The tables of the report, by heading.
const TABLES: [&str; 4] = [
    "### In-process engine",
    "### Process engine vs bare iceoryx2 ring",
    "### Bare iceoryx2 lockstep ring",
    "### Where an exchange's time goes",
];

fn bin_dir() -> PathBuf {
    let bench = Path::new(env!("CARGO_BIN_EXE_attsync-bench"));
    let dir = bench.parent().expect("in a directory").to_owned();
    for b in ["attsync", "attsync-agent", "attsync-leader"] {
        assert!(
            dir.join(b).is_file(),
            "{} not found: build the workspace binaries first with `cargo build --release --workspace`",
            dir.join(b).display()
        );
    }
    dir
}

fn cells(row: &str) -> Vec<&str> {
    let inner = row.trim().trim_start_matches('|').trim_end_matches('|');
    inner.split('|').map(str::trim).collect()
}

/// Checks the table under `heading`: a header, a separator, at least one
/// row, every row as wide as the header, every cell measured.
fn check_table(report: &str, heading: &str) {
    let start = report
        .find(heading)
        .unwrap_or_else(|| panic!("no table {heading:?} in the report:\n{report}"));
    let mut lines = report[start..]
        .lines()
        .skip(1)
        .skip_while(|l| l.trim().is_empty());
    let header = cells(lines.next().expect("a header"));
    let sep = lines.next().expect("a separator line");
    assert!(sep.starts_with("|---"), "{heading}: no separator: {sep:?}");
    let rows: Vec<&str> = lines.take_while(|l| l.starts_with('|')).collect();
    assert!(!rows.is_empty(), "{heading}: no rows:\n{report}");
    for row in rows {
        let c = cells(row);
        assert_eq!(
            c.len(),
            header.len(),
            "{heading}: row {row:?} vs {header:?}"
        );
        for (name, value) in header.iter().zip(&c) {
            assert!(
                !value.is_empty() && !value.contains('—'),
                "{heading}: column {name:?} not measured in {row:?}\n{report}"
            );
        }
    }
}

#[test]
fn quickest_case_reports_every_figure() {
    let scenarios = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper");
    let out = Command::new(env!("CARGO_BIN_EXE_attsync-bench"))
        .args([
            "run",
            "--quick",
            "--only",
            "paper-timevarying",
            "--wait",
            "adaptive",
        ])
        .args(["--reps", "1", "--duration", "0.2", "--idle-wait", "0"])
        .arg("--scenarios")
        .arg(&scenarios)
        .arg("--bin-dir")
        .arg(bin_dir())
        .output()
        .expect("attsync-bench starts");
    let (report, log) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{}\n{report}\n{log}", out.status);
    assert!(!log.contains("FAILED"), "a measurement failed:\n{log}");
    for heading in TABLES {
        check_table(&report, heading);
    }
    let leader = report
        .lines()
        .find(|l| l.starts_with("Leader process peak RSS"))
        .unwrap_or_else(|| panic!("no leader RSS line:\n{report}"));
    assert!(!leader.contains('—'), "leader RSS not measured: {leader}");
    assert!(
        !report.contains("repetitions failed"),
        "a repetition failed:\n{report}"
    );
}
