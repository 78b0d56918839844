//! One `attsync run` (either engine), measured: wall time around the
//! command here, everything else from its `summary.json` — for the process
//! engine the stepping interval (first node's `started_unix_ns` to the last
//! node's `done_unix_ns`) and each node's peak RSS from `nodes`. No log text
//! is read. Used by `attsync-bench run` (see `main.rs` for how to run it).

use crate::error::{BenchError, Result};
use crate::procs;
use attsync::results::summary::NodeSummary;
use attsync::results::{RunLayout, Summary};
use msgs::config::WaitStrategy;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// The programs the benchmark starts.
#[derive(Debug, Clone)]
pub struct Bins {
    /// `attsync` (with `attsync-agent` and `attsync-leader` beside it).
    pub attsync: PathBuf,
    /// This program (for `ring-node`).
    pub bench: PathBuf,
}

/// The command-line name of a wait strategy.
#[must_use]
pub fn wait_name(w: WaitStrategy) -> &'static str {
    match w {
        WaitStrategy::Spin => "spin",
        WaitStrategy::Yield => "yield",
        WaitStrategy::Block => "block",
        WaitStrategy::Adaptive => "adaptive",
    }
}

/// Which attsync engine to run.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engine {
    /// `--engine in-process`.
    InProcess,
    /// `--engine processes --wait W`.
    Processes(WaitStrategy),
}

/// What one `attsync run` measured.
#[derive(Debug, Clone, PartialEq)]
pub struct AttsyncRun {
    /// Wall time around the whole command (start-up, validation, spawning,
    /// the run, writing results), measured here, s.
    pub wall: f64,
    /// `summary.json` `wall_seconds`: the engine's run (for the process
    /// engine this includes spawning the nodes and their connection), s.
    pub run_seconds: f64,
    /// Steps done (`summary.json`).
    pub steps: u64,
    /// Process engine: from the first node's `started_unix_ns` to the last
    /// node's `done_unix_ns` (`summary.json` `nodes`), s: the lockstep itself.
    pub lockstep: Option<f64>,
    /// Process engine: every agent's `peak_rss_kb` (leader excluded).
    pub agent_rss_kb: Vec<u64>,
    /// Process engine: the leader's `peak_rss_kb`.
    pub leader_rss_kb: Option<u64>,
}

/// Runs `attsync run SCENARIO --engine … --out OUT --quiet [--set …]`.
pub fn attsync(
    bins: &Bins,
    scenario: &Path,
    engine: Engine,
    sets: &[String],
    out: &Path,
    timeout: Duration,
) -> Result<AttsyncRun> {
    attsync_with(bins, scenario, engine, sets, &[], out, timeout)
}

/// [`attsync()`] with `extra` arguments (`--hosts FILE`).
pub fn attsync_with(
    bins: &Bins,
    scenario: &Path,
    engine: Engine,
    sets: &[String],
    extra: &[std::ffi::OsString],
    out: &Path,
    timeout: Duration,
) -> Result<AttsyncRun> {
    let _ = std::fs::remove_dir_all(out);
    let parent = out.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(BenchError::io(parent))?;
    let log = out.with_extension("console.txt");
    let console = std::fs::File::create(&log).map_err(BenchError::io(&log))?;
    let mut cmd = Command::new(&bins.attsync);
    cmd.arg("run").arg(scenario);
    match engine {
        Engine::InProcess => cmd.args(["--engine", "in-process"]),
        Engine::Processes(w) => cmd.args(["--engine", "processes", "--wait", wait_name(w)]),
    };
    cmd.arg("--out").arg(out).arg("--quiet").args(extra);
    for s in sets {
        cmd.arg("--set").arg(s);
    }
    let stdout = console.try_clone().map_err(BenchError::io(&log))?;
    cmd.stdin(Stdio::null()).stdout(stdout).stderr(console);
    let fin = procs::run_timed(&mut cmd, timeout)?;
    if !fin.status.success() {
        return Err(BenchError::Failed {
            program: "attsync".into(),
            outcome: format!(
                "exited with {}: {}",
                fin.status,
                procs::tail(&log, 3).replace('\n', " / ")
            ),
        });
    }
    let path = RunLayout::new(out).summary();
    let s = read_summary(&path)?;
    if !s.complete {
        return Err(BenchError::Incomplete(
            (s.incomplete_reason).map_or_else(|| "?".into(), |f| f.to_string()),
        ));
    }
    let mut r = AttsyncRun {
        wall: fin.wall,
        run_seconds: s.wall_seconds,
        steps: s.steps,
        lockstep: None,
        agent_rss_kb: Vec::new(),
        leader_rss_kb: None,
    };
    if matches!(engine, Engine::Processes(_)) {
        r.lockstep = Some(lockstep(&s.nodes).ok_or_else(|| BenchError::Results {
            path,
            what: "no `nodes` (stepping times and peak RSS per node)".into(),
        })?);
        for n in &s.nodes {
            if n.id == 0 {
                r.leader_rss_kb = Some(n.peak_rss_kb);
            } else {
                r.agent_rss_kb.push(n.peak_rss_kb);
            }
        }
    }
    Ok(r)
}

/// Reads a `summary.json`.
pub fn read_summary(path: &Path) -> Result<Summary> {
    let text = std::fs::read_to_string(path).map_err(BenchError::io(path))?;
    serde_json::from_str(&text).map_err(|e| BenchError::Results {
        path: path.to_owned(),
        what: e.to_string(),
    })
}

/// The stepping interval of a process run: first node's start to the last
/// node's end, s (`None` without nodes).
#[must_use]
pub fn lockstep(nodes: &[NodeSummary]) -> Option<f64> {
    let first = nodes.iter().map(|n| n.started_unix_ns).min()?;
    let last = nodes.iter().map(|n| n.done_unix_ns).max()?;
    Some(last.saturating_sub(first) as f64 * 1e-9)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn figures_from_summary_json() {
        let text = r#"{"attsync_version": "0", "scenario": "s", "engine": "processes",
            "complete": true, "incomplete_reason": null, "dt": 0.001, "duration": 40.0,
            "t_end": 40.0, "steps": 40000, "wall_seconds": 3.9, "max_final_att_err": 0.0,
            "agents": [], "links": [],
            "nodes": [
              {"id": 0, "name": "leader", "peak_rss_kb": 7000,
               "started_unix_ns": 1764600000000000000, "done_unix_ns": 1764600001900000000},
              {"id": 1, "name": "agent-1", "peak_rss_kb": 8100,
               "started_unix_ns": 1764600000100000000, "done_unix_ns": 1764600002000000000}
            ]}"#;
        let s: Summary = serde_json::from_str(text).unwrap();
        assert_eq!(s.nodes.len(), 2);
        assert_eq!(s.nodes[1].peak_rss_kb, 8100);
        let l = lockstep(&s.nodes).unwrap();
        assert!((l - 2.0).abs() < 1e-9, "{l}");
        assert_eq!(lockstep(&[]), None);
    }
}
