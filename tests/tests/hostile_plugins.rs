//! Plug-ins that misbehave on purpose: one that floods its output (its log
//! is cut at 16 MiB, the run fails naming it), one that prints bytes that
//! are not UTF-8 (its last lines are still shown), one whose child leaves
//! the process group (killed at the end of the run: nothing survives it).

use attsync_tests::{
    Attsync, Finished, Sandbox, paper, run_args, sh_plugin, summary, with_agent_lines,
};
use std::path::{Path, PathBuf};

/// The observerless paper scenario with agent 3 replaced by `sh -c SCRIPT`.
fn with_plugin(tmp: &Sandbox, name: &str, script: &str) -> PathBuf {
    let base = paper("constant-observerless");
    with_agent_lines(tmp, &base, 3, name, &sh_plugin(script))
}

/// Runs `scenario` (processes engine, 5 s, stage timeout 2 s) into `out`.
fn run(tmp: &Sandbox, scenario: &Path, out: &Path) -> Finished {
    let mut args = run_args(scenario, "processes", out, &["simulation.duration=5"]);
    args.extend(["--stage-timeout".into(), "2".into()]);
    Attsync::new(tmp.path()).args(args).output()
}

/// Pids of processes whose command line has an argument equal to `arg`.
fn processes_with_arg(arg: &str) -> Vec<u32> {
    use attsync_sched::process::{cmdline, pids};
    (pids().into_iter())
        .filter(|&pid| cmdline(pid).iter().any(|a| a == arg))
        .collect()
}

#[test]
fn a_flooding_plugin_has_its_log_cut_and_is_named() {
    let tmp = Sandbox::new("hostile-flood");
    let scenario = with_plugin(&tmp, "flood", "yes spam | head -c 40000000; exit 3");
    let out = tmp.join("out");
    let r = run(&tmp, &scenario, &out);
    r.assert_code(1).assert_no_leftovers();
    assert!(
        r.stderr.contains("agent-3 (plug-in `sh -c"),
        "{}",
        r.describe()
    );
    let log = out.join("logs/agent-3.log");
    let len = std::fs::metadata(&log).unwrap().len();
    let cut = "[attsync: log cut at 16 MiB; further output discarded]";
    assert!(
        len <= (16 << 20) + cut.len() as u64 + 2,
        "log of {len} bytes"
    );
    let bytes = std::fs::read(&log).unwrap();
    assert!(
        bytes.ends_with(format!("\n{cut}\n").as_bytes()),
        "log not cut"
    );
    assert!(r.stderr.contains(cut), "{}", r.describe());
    assert_eq!(summary(&out)["complete"], false);
}

#[test]
fn a_plugin_printing_invalid_utf8_shows_its_last_lines() {
    let tmp = Sandbox::new("hostile-utf8");
    let script = r"printf 'first line\n\377\376 not utf-8\n' >&2; exit 1";
    let scenario = with_plugin(&tmp, "utf8", script);
    let out = tmp.join("out");
    let r = run(&tmp, &scenario, &out);
    r.assert_code(1).assert_no_leftovers();
    assert!(
        r.stderr.contains("first line") && r.stderr.contains("\u{fffd}\u{fffd} not utf-8"),
        "{}",
        r.describe()
    );
}

#[test]
fn a_plugins_child_that_leaves_the_group_does_not_survive_the_run() {
    let tmp = Sandbox::new("hostile-setsid");
    // A unique sleep length, to find it among this machine's processes.
    let secs = format!("301.{}", std::process::id());
    let script = format!("setsid sleep {secs} & sleep 0.5; exit 1");
    let scenario = with_plugin(&tmp, "setsid", &script);
    let out = tmp.join("out");
    let r = run(&tmp, &scenario, &out);
    let left = processes_with_arg(&secs);
    for pid in &left {
        let _ = std::process::Command::new("kill")
            .args(["-9", &pid.to_string()])
            .status();
    }
    r.assert_code(1);
    assert!(left.is_empty(), "`sleep {secs}` left running: {left:?}");
}

#[test]
fn a_long_tmpdir_does_not_break_the_processes_engine() {
    let tmp = Sandbox::new("hostile-tmpdir");
    let name = "t".repeat(100 - tmp.path().as_os_str().len() - 1);
    let long = tmp.join(name);
    assert_eq!(long.as_os_str().len(), 100);
    std::fs::create_dir(&long).unwrap();
    let out = tmp.join("out");
    let args = run_args(
        &paper("timevarying"),
        "processes",
        &out,
        &["simulation.duration=0.2"],
    );
    let r = Attsync::new(tmp.path())
        .env("TMPDIR", &long.display().to_string())
        .args(args)
        .output();
    r.assert_ok();
    assert_eq!(summary(&out)["complete"], true);
    // The namespace went to /tmp, and nothing was left in the long TMPDIR.
    assert_eq!(std::fs::read_dir(&long).unwrap().count(), 0);
}
