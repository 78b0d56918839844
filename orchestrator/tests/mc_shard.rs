//! `attsync mc --shard K/N` and `attsync mc merge` (issue 36, part 6): a
//! Monte Carlo spread over a job array gives, once merged, the files of one
//! run byte for byte (`trials.csv`, `initial.csv`, `mc.json`, `mc.svg`),
//! whatever the slices' `--jobs` and the order the directories are given
//! in; shards of different Monte Carlos, a missing, doubled or incomplete
//! slice, and a whole run given as a shard are refused (exit code 2) naming
//! the directory and what is wrong, and nothing is written.

mod common;

use common::{Out, attsync, json, paper, read};
use std::fs;
use std::path::{Path, PathBuf};

/// The files of a Monte Carlo's directory.
const FILES: [&str; 4] = ["trials.csv", "initial.csv", "mc.json", "mc.svg"];

/// The observerless paper run, 4 s, its gain `k_r` drawn per trial (a
/// `trials.csv` column of its own), written into `dir`.
fn scenario(dir: &Path) -> PathBuf {
    let mut text = read(Path::new(&paper("constant-observerless")));
    text = text.replace("duration = 40.0", "duration = 4.0");
    text += "\n[[monte_carlo.param]]\nfield = \"scheme.control.k_r\"\n\
             distribution = \"uniform\"\nmin = 0.5\nmax = 4.0\n";
    let file = dir.join("sharded.toml");
    fs::write(&file, text).expect("write");
    file
}

/// `attsync mc FILE --trials T --out OUT --quiet EXTRA…`, with `--seed 11`
/// unless `extra` has a seed.
fn mc(cwd: &Path, file: &Path, trials: u64, out: &str, extra: &[&str]) -> Out {
    let (file, trials) = (file.display().to_string(), trials.to_string());
    let mut args = vec!["mc", &file, "--trials", &trials];
    if !extra.contains(&"--seed") {
        args.extend_from_slice(&["--seed", "11"]);
    }
    args.extend_from_slice(&["--out", out, "--quiet"]);
    args.extend_from_slice(extra);
    attsync(cwd, &args)
}

/// `attsync mc merge DIRS… --out OUT`.
fn merge(cwd: &Path, dirs: &[&str], out: &str) -> Out {
    let mut args = vec!["mc", "merge"];
    args.extend_from_slice(dirs);
    args.extend_from_slice(&["--out", out]);
    attsync(cwd, &args)
}

fn same_files(a: &Path, b: &Path) {
    for f in FILES {
        assert_eq!(
            fs::read(a.join(f)).unwrap(),
            fs::read(b.join(f)).unwrap(),
            "{f} differs between {} and {}",
            a.display(),
            b.display()
        );
    }
}

#[test]
fn three_shards_merged_are_one_run_byte_for_byte() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(tmp.path());
    mc(tmp.path(), &file, 8, "whole", &[]).assert_code(0);
    for (k, jobs) in [(1, "1"), (2, "2"), (3, "1")] {
        let shard = format!("{k}/3");
        let out = mc(
            tmp.path(),
            &file,
            8,
            &format!("s{k}"),
            &["--shard", &shard, "--jobs", jobs],
        );
        out.assert_code(0);
        assert!(
            out.stdout.contains(&format!("shard {shard}: trials ")),
            "{}",
            out.stdout
        );
    }
    // A shard holds its slice only: ⌊(K−1)·8/3⌋..⌊K·8/3⌋ = 2..5 for K = 2.
    let s2 = json(&tmp.path().join("s2/mc.json"));
    assert_eq!(s2["shard"]["first"], 2);
    assert_eq!(s2["shard"]["end"], 5);
    assert_eq!(
        (s2["trials"].as_u64(), s2["trials_run"].as_u64()),
        (Some(8), Some(3))
    );
    assert_eq!(s2["complete"], true);
    // Merged in any order: the whole run's files.
    let out = merge(tmp.path(), &["s3", "s1", "s2"], "merged");
    out.assert_code(0);
    assert!(out.stdout.contains("3 shards merged"), "{}", out.stdout);
    same_files(&tmp.path().join("whole"), &tmp.path().join("merged"));
    let m = json(&tmp.path().join("merged/mc.json"));
    assert!(m.get("shard").is_none(), "{m}");
    // The k_r column is there (a dispersed field, read back exactly).
    assert!(read(&tmp.path().join("merged/trials.csv")).contains("scheme.control.k_r"));
}

#[test]
fn diverged_trials_keep_their_reasons_when_merged() {
    let tmp = tempfile::tempdir().unwrap();
    let file = paper("constant-observerless");
    let file = Path::new(&file);
    // dt far beyond RK4's stable step: every trial diverges, with a reason
    // that only mc.json's `slowest` holds.
    let sets = common::DIVERGING;
    mc(tmp.path(), file, 5, "whole", &sets).assert_code(0);
    for k in 1..=2 {
        let mut extra = sets.to_vec();
        let shard = format!("{k}/2");
        extra.extend_from_slice(&["--shard", &shard]);
        mc(tmp.path(), file, 5, &format!("s{k}"), &extra).assert_code(0);
    }
    merge(tmp.path(), &["s1", "s2"], "merged").assert_code(0);
    same_files(&tmp.path().join("whole"), &tmp.path().join("merged"));
    let m = json(&tmp.path().join("merged/mc.json"));
    let why = m["slowest"][4]["reason"].as_str().unwrap();
    assert!(why.starts_with("diverged at t = "), "{why}");
}

/// The refusal `out` (exit code 2, nothing written to `merged`) says `want`.
fn refused(cwd: &Path, out: Out, want: &[&str]) {
    out.assert_code(2);
    for w in want {
        assert!(out.stderr.contains(w), "{w:?} not in: {}", out.stderr);
    }
    assert!(!cwd.join("merged").exists(), "a refused merge wrote files");
}

#[test]
fn shards_that_are_not_one_whole_monte_carlo_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let cwd = tmp.path();
    let file = scenario(cwd);
    for (k, out, extra) in [
        ("1/3", "a1", &[][..]),
        ("2/3", "a2", &[][..]),
        ("3/3", "a3", &[][..]),
        ("3/3", "seed12", &["--seed", "12"][..]),
        ("2/2", "half", &[][..]),
    ] {
        let mut e = vec!["--shard", k];
        e.extend_from_slice(extra);
        mc(cwd, &file, 8, out, &e).assert_code(0);
    }
    mc(cwd, &file, 4, "whole", &[]).assert_code(0);
    refused(
        cwd,
        merge(cwd, &["a1", "a3"], "merged"),
        &["shards 2 of 3 missing", "trials 2..5"],
    );
    refused(
        cwd,
        merge(cwd, &["a1", "a2", "a2", "a3"], "merged"),
        &["shard 2/3 given twice"],
    );
    refused(
        cwd,
        merge(cwd, &["a1", "a2", "seed12"], "merged"),
        &["seed12", "seed is 12 but 11"],
    );
    refused(
        cwd,
        merge(cwd, &["a1", "a2", "half"], "merged"),
        &["half", "shard.count is 2 but 3"],
    );
    refused(
        cwd,
        merge(cwd, &["a1", "whole"], "merged"),
        &["whole", "has no `shard`"],
    );
    // A shard cut short (as an interrupt leaves it) is not merged.
    let cut = cwd.join("a2/trials.csv");
    let text = read(&cut);
    let kept: Vec<&str> = text.lines().take(text.lines().count() - 1).collect();
    fs::write(&cut, kept.join("\n") + "\n").unwrap();
    refused(
        cwd,
        merge(cwd, &["a1", "a2", "a3"], "merged"),
        &["a2", "incomplete (2 of 3 trials ran)"],
    );
    // A cell that is not a number names its file, line and column.
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<&str> = lines[1].split(',').collect();
    cells[2] = "maybe";
    lines[1] = cells.join(",");
    fs::write(&cut, lines.join("\n") + "\n").unwrap();
    refused(
        cwd,
        merge(cwd, &["a1", "a2", "a3"], "merged"),
        &["trials.csv: line 2: column outcome"],
    );
}

#[test]
fn a_shard_out_of_range_is_refused_before_anything_runs() {
    let tmp = tempfile::tempdir().unwrap();
    let file = scenario(tmp.path());
    for (shard, want) in [
        ("0/3", "--shard 0/3"),
        ("4/3", "--shard 4/3"),
        ("2", "--shard 2"),
        ("1/9", "9 slices of 8 trials"),
    ] {
        let out = mc(tmp.path(), &file, 8, "x", &["--shard", shard]);
        out.assert_code(2);
        assert!(out.stderr.contains(want), "{want:?}: {}", out.stderr);
        assert!(!tmp.path().join("x").exists());
    }
    let out = mc(
        tmp.path(),
        &file,
        8,
        "x",
        &["--shard", "1/2", "--trial", "3"],
    );
    out.assert_code(2);
    assert!(out.stderr.contains("cannot be used with"), "{}", out.stderr);
}
