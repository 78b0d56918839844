//! Validation that scales (issue 11 item 4): `attsync gen tree` of a
//! 20 000-agent tree (100 leader links) followed by `attsync check` succeeds, with the spectrum
//! of `Ξ + LLᵀ` summarised (count and extremes) instead of listed, and
//! Appendix D's condition decided without a dense matrix. On a small
//! scenario the summary agrees with the full list, which is still printed.

use std::path::Path;
use std::process::Command;

const PAPER: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenarios/paper/timevarying.toml"
);

/// `attsync args…` in `cwd`; its stdout, after asserting success.
#[track_caller]
fn attsync_ok(cwd: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_attsync"))
        .args(args)
        .current_dir(cwd)
        .output()
        .expect("attsync starts");
    let (stdout, stderr) = (
        String::from_utf8(out.stdout).expect("UTF-8"),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    );
    assert!(
        out.status.success(),
        "attsync {args:?} failed:\n{stdout}\n{stderr}"
    );
    stdout
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
