//! Issue 10: the machine's limits and a full disk, said plainly.
//! - a run the open-file limit cannot take is refused before anything
//!   starts (exit 2, the limit named, nothing left behind), and the advice
//!   it gives (`--engine in-process`) works under the same limit;
//! - a full disk names the results file (not bincode's debug struct) and
//!   leaves no half-written results; a node log that cannot be written is
//!   named with its node;
//! - a start-up timeout names the plug-in that never connected, not the
//!   neighbours left waiting for it.
//!
//! The full disk is a small tmpfs mounted in the test (the tests run as
//! root); where mounting is not allowed, a file-size limit (`ulimit -f`,
//! SIGXFSZ ignored: writes fail with EFBIG) stands in for it.

use attsync_tests::{
    Attsync, Finished, Sandbox, bin, paper, run_args, sh_plugin, with_agent_lines,
};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `sh -c "PRELUDE; exec attsync ARGS…"` in `tmp`, arguments quoted.
fn attsync_under(tmp: &Sandbox, prelude: &str, args: &[std::ffi::OsString]) -> Finished {
    let quoted: Vec<String> = (args.iter())
        .map(|a| format!("'{}'", a.to_string_lossy().replace('\'', r"'\''")))
        .collect();
    let script = format!(
        "{prelude}; exec '{}' {}",
        bin("attsync").display(),
        quoted.join(" ")
    );
    Attsync::with_program(Path::new("/bin/sh"), tmp.path())
        .args(["-c", &script])
        .output()
}

/// `attsync gen tree` of `agents` observerless agents, 10 steps.
fn tree(tmp: &Sandbox, agents: u32) -> PathBuf {
    let file = tmp.join(format!("tree-{agents}.toml"));
    let n = agents.to_string();
    let f = file.to_string_lossy().into_owned();
    let args = ["gen", "tree", "--agents", &n, "--scheme", "observerless"];
    let args = args.into_iter().chain(["--duration", "0.01", "--out", &f]);
    Attsync::new(tmp.path()).args(args).output().assert_ok();
    file
}

/// Entries of `dir` (names), sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| Some(e.ok()?.file_name().to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default();
    v.sort();
    v
}

#[test]
fn a_run_past_the_open_file_limit_is_refused_before_anything_starts() {
    let tmp = Sandbox::new("limits-nofile");
    let scenario = tree(&tmp, 99);
    let out = tmp.join("out");
    let before = entries(tmp.path());
    let args = run_args(&scenario, "processes", &out, &[]);
    let r = attsync_under(&tmp, "ulimit -n 64", &args);
    r.assert_code(2).assert_no_leftovers();
    for word in [
        "100 nodes",
        "RLIMIT_NOFILE",
        "`ulimit -n",
        "is 64",
        "--engine in-process",
    ] {
        assert!(r.stderr.contains(word), "no `{word}`: {}", r.describe());
    }
    assert!(r.runs.is_empty(), "a namespace was created: {:?}", r.runs);
    assert_eq!(entries(tmp.path()), before, "the run left files behind");
    // The advice works under the same limit.
    let args = run_args(&scenario, "in-process", &out, &[]);
    attsync_under(&tmp, "ulimit -n 64", &args).assert_ok();
    assert!(out.join("summary.json").is_file());
}

/// A tmpfs of `kb` KiB mounted on a fresh directory of `tmp`; unmounted on drop.
struct SmallDisk(PathBuf);

impl SmallDisk {
    /// `None` if mounting is not allowed here.
    fn mount(tmp: &Sandbox, kb: u32) -> Option<Self> {
        let dir = tmp.join("disk");
        std::fs::create_dir_all(&dir).unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={kb}k"), "tmpfs"])
            .arg(&dir)
            .status()
            .is_ok_and(|s| s.success());
        ok.then_some(Self(dir))
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

/// Runs `args` with at most `kb` KiB of room for its output under `tmp`:
/// on a tmpfs that small if one can be mounted (`--out` is moved onto it),
/// else under a file-size limit of that much. Returns the run and the
/// directory that holds `--out` (to check nothing is left in it).
fn with_small_disk(
    tmp: &Sandbox,
    kb: u32,
    engine: &str,
    scenario: &Path,
    sets: &[&str],
) -> (Finished, Vec<String>) {
    let disk = SmallDisk::mount(tmp, kb);
    let parent = disk
        .as_ref()
        .map_or_else(|| tmp.join("big"), |d| d.0.clone());
    std::fs::create_dir_all(&parent).unwrap();
    let mut args = run_args(scenario, engine, &parent.join("out"), sets);
    args.extend(["--stage-timeout".into(), "5".into()]);
    let prelude = match disk {
        Some(_) => "true".to_string(),
        None => format!("trap '' XFSZ; ulimit -f {}", kb * 2),
    };
    let r = attsync_under(tmp, &prelude, &args);
    let left = entries(&parent);
    (r, left)
}

/// Neither the results nor their staging directory are left half-written:
/// `left` (the entries beside `--out`) holds at most the lock file.
#[track_caller]
fn assert_no_results_left(left: &[String], r: &Finished) {
    let stray: Vec<&String> = left
        .iter()
        .filter(|n| !n.starts_with(".out.lock"))
        .collect();
    assert!(stray.is_empty(), "left behind: {stray:?}\n{}", r.describe());
}

#[test]
fn a_full_disk_names_the_results_file_and_leaves_no_results() {
    let tmp = Sandbox::new("limits-full-results");
    let sets = ["simulation.duration=20", "output.sample_period=0.001"];
    let (r, left) = with_small_disk(
        &tmp,
        512,
        "in-process",
        &paper("constant-observerless"),
        &sets,
    );
    r.assert_code(1);
    let named = ["states.bin: ", "errors.csv: "]
        .iter()
        .any(|f| r.stderr.contains(f));
    assert!(named, "the file is not named: {}", r.describe());
    let os = ["No space left on device", "File too large"];
    assert!(os.iter().any(|m| r.stderr.contains(m)), "{}", r.describe());
    for raw in ["Io {", "inner:", "kind:"] {
        assert!(!r.stderr.contains(raw), "a debug struct: {}", r.describe());
    }
    assert_no_results_left(&left, &r);
}

#[test]
fn a_full_disk_names_the_node_log_and_its_node() {
    let tmp = Sandbox::new("limits-full-log");
    let flood = sh_plugin("yes spam | head -c 4000000; exit 3");
    let file = with_agent_lines(&tmp, &paper("constant-observerless"), 3, "flood", &flood);
    let (r, left) = with_small_disk(&tmp, 1024, "processes", &file, &["simulation.duration=5"]);
    r.assert_code(1).assert_no_leftovers();
    let line = (r.stderr.lines())
        .find(|l| l.contains("logs/agent-3.log: "))
        .unwrap_or_else(|| panic!("the log is not named: {}", r.describe()));
    assert!(line.contains("the log of agent-3 stops here"), "{line}");
    assert_no_results_left(&left, &r);
}

#[test]
fn a_start_up_timeout_names_the_silent_plugin_not_its_neighbours() {
    let tmp = Sandbox::new("limits-silent");
    let silent = sh_plugin("sleep 60");
    let file = with_agent_lines(&tmp, &paper("constant-observerless"), 3, "silent", &silent);
    // `attsync run` waits the default start-up timeout (30 s).
    let args = run_args(
        &file,
        "processes",
        &tmp.join("out"),
        &["simulation.duration=1"],
    );
    let r = Attsync::new(tmp.path()).args(args).output();
    r.assert_code(1).assert_no_leftovers();
    let line = (r.stderr.lines())
        .find(|l| l.contains("never connected"))
        .unwrap_or_else(|| panic!("no `never connected`: {}", r.describe()));
    let named = line.split("(opened no ports): ").nth(1).unwrap_or_default();
    assert!(
        named.starts_with("agent-3 (plug-in `sh -c sleep 60`)"),
        "{}",
        r.describe()
    );
    assert!(
        !named.contains("agent-1") && !named.contains("leader"),
        "{line}"
    );
    assert!(
        r.stderr.contains("left waiting for them: "),
        "{}",
        r.describe()
    );
    assert!(!r.stderr.contains("not ready:"), "{}", r.describe());
}
