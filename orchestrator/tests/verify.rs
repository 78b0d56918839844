//! `manifest.json` and `attsync verify DIR` (issue 14 item 4: a replay that
//! is checked, not just run), with the in-process engine (the processes
//! engine's cases are in `tests/tests/verify_engines.rs`).
//!
//! - a fresh run verifies: exit 0, "bit-identical", every file as recorded;
//!   so do a run with a lossy, seeded network and a diverged run;
//! - one flipped byte inside a float of `states.bin` is found twice: the
//!   file's SHA-256 mismatch, and the first differing sample of the re-run,
//!   whose time, node, field and both values the test computes itself from
//!   the byte offset and the documented layout (`results/states.rs`);
//! - a manifest whose scenario hash does not match `scenario.toml`, a
//!   missing or garbled manifest, a real-time or interrupted run: refused
//!   with exit 2, saying why;
//! - the manifest lists every file of the directory with its size and the
//!   SHA-256 that coreutils' `sha256sum` computes, and records the build,
//!   the scenario's hash, the seeds, the engine and the platform.

mod common;

use common::{Out, PAPER, attsync, json, run_args};
use serde_json::Value;
use std::collections::BTreeSet;
use std::fs;
use std::path::{Path, PathBuf};
use std::process::Command;

/// `attsync run PAPER --engine in-process --out OUT --quiet --set …` (0.5 s
/// unless `sets` say otherwise), expecting exit code `code`.
fn run(cwd: &Path, out: &Path, sets: &[&str], code: i32) -> PathBuf {
    let sets: Vec<&str> = ["simulation.duration=0.5"]
        .iter()
        .chain(sets)
        .copied()
        .collect();
    attsync(cwd, &run_args(PAPER, "in-process", out, &sets)).assert_code(code);
    out.to_owned()
}

/// `attsync verify DIR --quiet extra…`.
fn verify(cwd: &Path, dir: &Path, extra: &[&str]) -> Out {
    let mut args = vec![
        "verify".to_string(),
        dir.display().to_string(),
        "--quiet".into(),
    ];
    args.extend(extra.iter().map(|s| (*s).to_string()));
    attsync(cwd, &args)
}

#[test]
fn a_fresh_run_verifies_bit_identical() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), &tmp.path().join("out"), &[], 0);
    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(0);
    assert_eq!(
        out.stdout.lines().last(),
        Some("bit-identical"),
        "{}",
        out.stdout
    );
    let files = json(&dir.join("manifest.json"))["files"]
        .as_array()
        .unwrap()
        .len();
    assert!(
        out.stdout
            .contains(&format!("files: {files} listed, all as recorded"))
            && out.stdout.contains("states.bin: the same as recorded")
            && out.stdout.contains("errors.csv: the same as recorded")
            && out.stdout.contains("in-process engine"),
        "{}",
        out.stdout
    );
    // The run directory is left as it was (the re-run went elsewhere).
    let again = verify(tmp.path(), &dir, &[]);
    again.assert_code(0);
}

#[test]
fn a_scenario_without_a_name_verifies_under_its_recorded_one() {
    let tmp = tempfile::tempdir().unwrap();
    let text = fs::read_to_string(PAPER).unwrap();
    let unnamed: String = (text.lines())
        .filter(|l| !l.starts_with("name ="))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(unnamed.len(), text.len(), "the scenario had a name");
    let file = tmp.path().join("unnamed.toml");
    fs::write(&file, unnamed).unwrap();
    let out = tmp.path().join("out");
    let args = run_args(&file, "in-process", &out, &["simulation.duration=0.2"]);
    attsync(tmp.path(), &args).assert_code(0);
    assert_eq!(json(&out.join("manifest.json"))["scenario"], "unnamed");
    let v = verify(tmp.path(), &out, &[]);
    v.assert_code(0);
    assert_eq!(
        v.stdout.lines().last(),
        Some("bit-identical"),
        "{}",
        v.stdout
    );
}

#[test]
fn a_lossy_seeded_network_and_a_diverged_run_verify_too() {
    let tmp = tempfile::tempdir().unwrap();
    let lossy = ["network.loss=0.3", "network.jitter=0.002", "network.seed=7"];
    let dir = run(tmp.path(), &tmp.path().join("lossy"), &lossy, 0);
    let m = json(&dir.join("manifest.json"));
    assert_eq!(m["seeds"]["network"], 7);
    let links = m["seeds"]["links"].as_array().expect("links");
    assert!(
        !links.is_empty() && links.iter().all(|l| l["seed"].is_u64()),
        "{m:#}"
    );
    verify(tmp.path(), &dir, &[]).assert_code(0);
    // The paper's scheme 1 with k_σ = 700 diverges within the first second (exit 3).
    let stiff = ["simulation.duration=1", "scheme.observer.k_sigma=700"];
    let dir = run(tmp.path(), &tmp.path().join("diverged"), &stiff, 3);
    let m = json(&dir.join("manifest.json"));
    assert_eq!(
        (&m["complete"], &m["diverged"]),
        (&Value::Bool(false), &Value::Bool(true))
    );
    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(0);
    assert_eq!(
        out.stdout.lines().last(),
        Some("bit-identical"),
        "{}",
        out.stdout
    );
}

/// Reads a little-endian u64 at `at`.
fn u64_at(b: &[u8], at: usize) -> u64 {
    u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
}

#[test]
fn a_flipped_byte_of_states_bin_is_found_and_placed() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), &tmp.path().join("out"), &[], 0);
    let file = dir.join("states.bin");
    let mut bytes = fs::read(&file).unwrap();
    // Header (results/states.rs): magic 8, version 4, scenario (u64 length +
    // bytes), dt 8, sample_every 8, agent_ids (u64 length + 4 each), has_observer 1.
    let name_len = u64_at(&bytes, 12) as usize;
    let ids_at = 20 + name_len + 16;
    let n = u64_at(&bytes, ids_at) as usize;
    let id = |k: usize| u32::from_le_bytes(bytes[ids_at + 8 + 4 * k..][..4].try_into().unwrap());
    let agent_id = id(1); // the agent index below
    let header = ids_at + 8 + 4 * n + 1;
    // Record: step 8, leader 15 f64, agents (u64 length + 30 f64 each:
    // r 9, w 3, r_hat 9, w_hat 3, s_hat 3, tau 3). Sample 3, agent index 1, R̂[1][2].
    let record = 8 + 15 * 8 + 8 + 30 * 8 * n;
    let sample = 3;
    let start = header + sample * record;
    let (agent, r_hat, row, col) = (1, 9 + 3, 1, 2);
    let at = start + 8 + 15 * 8 + 8 + 30 * 8 * agent + (r_hat + 3 * row + col) * 8;
    let value = |b: &[u8]| f64::from_le_bytes(b[at..at + 8].try_into().unwrap());
    let original = value(&bytes);
    let step = u64_at(&bytes, start);
    bytes[at] ^= 0x01;
    let tampered = value(&bytes);
    assert_ne!(original.to_bits(), tampered.to_bits());
    fs::write(&file, &bytes).unwrap();
    // The sample's time as errors.csv writes it: the first column of its rows.
    let csv = fs::read_to_string(dir.join("errors.csv")).unwrap();
    let row = csv.lines().nth(1 + sample * n).unwrap();
    let t = row.split(',').next().unwrap();

    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(1);
    let place = format!(
        "states.bin: first differing sample: t = {t} s (step {step}), agent-{agent_id}, \
         R_hat[1][2]: recorded {tampered:?}, re-run {original:?}"
    );
    assert!(
        out.stdout.contains("states.bin: SHA-256 mismatch")
            && out.stdout.contains("files: ")
            && out.stdout.contains(" 1 not as recorded")
            && out.stdout.contains(&place)
            && out.stdout.contains("errors.csv: the same as recorded"),
        "expected {place:?} in:\n{}",
        out.stdout
    );
    let verdict = out.stdout.lines().last().unwrap();
    assert!(verdict.starts_with("different: 1 of "), "{verdict}");
    assert!(!out.stdout.contains("bit-identical"), "{}", out.stdout);
}

#[test]
fn a_changed_file_alone_makes_it_different() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), &tmp.path().join("out"), &[], 0);
    fs::write(dir.join("errors.svg"), "<svg/>").unwrap();
    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(1);
    assert!(
        out.stdout.contains("errors.svg: SHA-256 mismatch")
            && out.stdout.contains("states.bin: the same as recorded"),
        "{}",
        out.stdout
    );
    fs::remove_file(dir.join("errors.svg")).unwrap();
    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(1);
    assert!(out.stdout.contains("errors.svg: missing"), "{}", out.stdout);
}

/// Edits `dir/manifest.json` with `f`.
fn edit_manifest(dir: &Path, f: impl FnOnce(&mut Value)) {
    let file = dir.join("manifest.json");
    let mut m = json(&file);
    f(&mut m);
    fs::write(&file, serde_json::to_string_pretty(&m).unwrap()).unwrap();
}

#[test]
fn a_wrong_scenario_hash_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), &tmp.path().join("out"), &[], 0);
    let wrong = "0".repeat(64);
    edit_manifest(&dir, |m| {
        m["scenario_sha256"] = Value::String(wrong.clone())
    });
    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(2);
    assert!(
        out.stderr
            .contains(&format!("scenario_sha256 {wrong} does not match"))
            && out.stderr.contains("refusing to re-run"),
        "{}",
        out.stderr
    );
    // A scenario.toml changed after the run: the same refusal.
    let dir = run(tmp.path(), &tmp.path().join("edited"), &[], 0);
    let mut text = fs::read_to_string(dir.join("scenario.toml")).unwrap();
    text.push_str("\n# edited\n");
    fs::write(dir.join("scenario.toml"), text).unwrap();
    let out = verify(tmp.path(), &dir, &[]);
    out.assert_code(2);
    assert!(
        out.stderr.contains("it is not the scenario that ran"),
        "{}",
        out.stderr
    );
}

#[test]
fn a_missing_or_garbled_manifest_and_unverifiable_runs_are_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), &tmp.path().join("out"), &[], 0);
    let file = dir.join("manifest.json");
    let good = fs::read_to_string(&file).unwrap();
    let refused = |why: &str| {
        let out = verify(tmp.path(), &dir, &[]);
        out.assert_code(2);
        assert!(
            out.stderr.contains(why),
            "expected {why:?} in {}",
            out.stderr
        );
    };
    fs::write(&file, "{ not json").unwrap();
    refused("not an attsync manifest");
    edit_manifest_text(&file, &good, |m| m["manifest_version"] = 99.into());
    refused("manifest_version 99 (this attsync reads 1)");
    edit_manifest_text(&file, &good, |m| m["files"][0]["path"] = "../x".into());
    refused("is not a path inside the results directory");
    edit_manifest_text(&file, &good, |m| m["realtime"] = 1.0.into());
    refused("is not deterministic");
    edit_manifest_text(&file, &good, |m| {
        m["complete"] = false.into();
        m["incomplete_reason"] = "interrupted by SIGINT".into();
    });
    refused("did not complete (interrupted by SIGINT)");
    fs::remove_file(&file).unwrap();
    refused("manifest.json");
}

/// Writes `good` with `f` applied to `file`.
fn edit_manifest_text(file: &Path, good: &str, f: impl FnOnce(&mut Value)) {
    let mut m: Value = serde_json::from_str(good).unwrap();
    f(&mut m);
    fs::write(file, serde_json::to_string(&m).unwrap()).unwrap();
}

/// Every file under `dir` (relative, `/`-separated).
fn walk(dir: &Path, rel: &str, out: &mut BTreeSet<String>) {
    for e in fs::read_dir(dir.join(rel)).unwrap() {
        let e = e.unwrap();
        let name = e.file_name().to_string_lossy().into_owned();
        let rel = if rel.is_empty() {
            name
        } else {
            format!("{rel}/{name}")
        };
        if e.file_type().unwrap().is_dir() {
            walk(dir, &rel, out);
        } else {
            out.insert(rel);
        }
    }
}

/// `sha256sum FILE` (coreutils), the digest alone.
fn sha256sum(file: &Path) -> String {
    let out = Command::new("sha256sum")
        .arg(file)
        .output()
        .expect("sha256sum (coreutils) runs");
    assert!(out.status.success());
    String::from_utf8(out.stdout)
        .unwrap()
        .split_whitespace()
        .next()
        .unwrap()
        .to_owned()
}

#[test]
fn the_manifest_lists_every_file_with_its_sha256() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = run(tmp.path(), &tmp.path().join("out"), &[], 0);
    let m = json(&dir.join("manifest.json"));
    let files = m["files"].as_array().expect("files");
    let listed: BTreeSet<String> = files
        .iter()
        .map(|f| f["path"].as_str().unwrap().to_owned())
        .collect();
    let mut present = BTreeSet::new();
    walk(&dir, "", &mut present);
    present.remove("manifest.json");
    assert_eq!(listed, present);
    for f in files {
        let path = dir.join(f["path"].as_str().unwrap());
        assert_eq!(f["size"], fs::metadata(&path).unwrap().len());
        assert_eq!(f["sha256"], sha256sum(&path), "{}", path.display());
    }
    assert_eq!(m["scenario_sha256"], sha256sum(&dir.join("scenario.toml")));
    assert_eq!(m["manifest_version"], 1);
    assert_eq!(m["attsync_version"], env!("CARGO_PKG_VERSION"));
    let commit = m["git_commit"].as_str().unwrap();
    assert!(
        commit == "unknown"
            || (commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit())),
        "{commit}"
    );
    assert_eq!(m["scenario"], json(&dir.join("summary.json"))["scenario"]);
    assert_eq!(m["engine"], "in-process");
    assert_eq!(
        (&m["wait"], &m["placement"], &m["realtime"]),
        (&Value::Null, &Value::Null, &Value::Null)
    );
    assert!(m["threads"].as_u64().is_some_and(|t| t >= 1), "{m:#}");
    assert_eq!(m["seeds"]["network"], 0);
    assert_eq!(m["complete"], true);
    assert_eq!(m["platform"]["os"], std::env::consts::OS);
    assert_eq!(m["platform"]["arch"], std::env::consts::ARCH);
    assert!(m["platform"]["cores"].as_u64().is_some_and(|c| c >= 1));
    let cmd: Vec<&str> = m["command_line"]
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a.as_str().unwrap())
        .collect();
    assert_eq!(&cmd[1..3], ["run", PAPER]);
    let started = m["started_at"].as_str().unwrap();
    assert!(
        started.len() == 20 && started.ends_with('Z') && &started[10..11] == "T",
        "{started}"
    );
}

#[test]
fn a_sweep_or_monte_carlo_directory_says_what_to_verify_instead() {
    let tmp = tempfile::tempdir().unwrap();
    let sweep = tmp.path().join("sweep");
    let args: Vec<String> = [
        "sweep",
        PAPER,
        "--param",
        "network.delay",
        "--values",
        "0,0.01",
        "--set",
        "simulation.duration=0.2",
        "--out",
    ]
    .iter()
    .map(|s| (*s).to_string())
    .chain([sweep.display().to_string()])
    .collect();
    attsync(tmp.path(), &args).assert_code(0);
    let o = verify(tmp.path(), &sweep, &[]);
    o.assert_code(2);
    assert!(o.stderr.contains("a sweep's directory"), "{}", o.stderr);
    let example = sweep.join("runs").join("000-0");
    assert!(
        o.stderr
            .contains(&format!("attsync verify {}", example.display())),
        "{}",
        o.stderr
    );
    // What it suggests verifies.
    verify(tmp.path(), &example, &[]).assert_code(0);

    let mc = tmp.path().join("mc");
    let args: Vec<String> = [
        "mc",
        PAPER,
        "--trials",
        "2",
        "--set",
        "simulation.duration=0.2",
        "--out",
    ]
    .iter()
    .map(|s| (*s).to_string())
    .chain([mc.display().to_string()])
    .collect();
    attsync(tmp.path(), &args).assert_code(0);
    let o = verify(tmp.path(), &mc, &[]);
    o.assert_code(2);
    assert!(
        o.stderr.contains("a Monte Carlo's directory"),
        "{}",
        o.stderr
    );
    assert!(o.stderr.contains("--trial K"), "{}", o.stderr);
}
