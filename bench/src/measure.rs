//! One measurement each: an `attsync run` (either engine), or a bare
//! lockstep (ring, or the scenario's own graph) of `ring-node` processes.
//! Used by `attsync-bench run` (see `main.rs` for how to run it).

use crate::procs::{self, Group};
use crate::ring::{RingReport, files};
use msgs::config::WaitStrategy;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

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
    /// Process engine: from the first node's `started` to the last node's
    /// `done` (log timestamps), s: the lockstep itself.
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
) -> Result<AttsyncRun, String> {
    let _ = std::fs::remove_dir_all(out);
    let parent = out.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(parent).map_err(|e| format!("{}: {e}", parent.display()))?;
    let log = out.with_extension("console.txt");
    let console = std::fs::File::create(&log).map_err(|e| format!("{}: {e}", log.display()))?;
    let mut cmd = Command::new(&bins.attsync);
    cmd.arg("run").arg(scenario);
    match engine {
        Engine::InProcess => cmd.args(["--engine", "in-process"]),
        Engine::Processes(w) => cmd.args(["--engine", "processes", "--wait", wait_name(w)]),
    };
    cmd.arg("--out").arg(out).arg("--quiet");
    for s in sets {
        cmd.arg("--set").arg(s);
    }
    cmd.stdin(Stdio::null())
        .stdout(console.try_clone().map_err(|e| e.to_string())?)
        .stderr(console);
    let fin = procs::run_timed(&mut cmd, timeout)?;
    if !fin.status.success() {
        return Err(format!(
            "attsync exited with {}: {}",
            fin.status,
            procs::tail(&log, 3).replace('\n', " / ")
        ));
    }
    let summary_path = out.join("summary.json");
    let text = std::fs::read_to_string(&summary_path)
        .map_err(|e| format!("{}: {e}", summary_path.display()))?;
    let v: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| format!("{}: {e}", summary_path.display()))?;
    if v["complete"] != serde_json::Value::Bool(true) {
        return Err(format!("incomplete run: {}", v["incomplete_reason"]));
    }
    let steps = v["steps"].as_u64().ok_or("summary.json: no steps")?;
    let run_seconds = v["wall_seconds"]
        .as_f64()
        .ok_or("summary.json: no wall_seconds")?;
    let mut r = AttsyncRun {
        wall: fin.wall,
        run_seconds,
        steps,
        lockstep: None,
        agent_rss_kb: Vec::new(),
        leader_rss_kb: None,
    };
    if matches!(engine, Engine::Processes(_)) {
        let logs = read_logs(&out.join("logs"))?;
        let first = logs.iter().map(|l| l.started).fold(f64::INFINITY, f64::min);
        let last = logs
            .iter()
            .map(|l| l.done)
            .fold(f64::NEG_INFINITY, f64::max);
        r.lockstep = Some(last - first);
        for l in &logs {
            if l.steps != steps {
                return Err(format!("{}: done after {} steps", l.name, l.steps));
            }
            if l.name == "leader" {
                r.leader_rss_kb = Some(l.peak_rss_kb);
            } else {
                r.agent_rss_kb.push(l.peak_rss_kb);
            }
        }
    }
    Ok(r)
}

/// What a node's log says.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeLog {
    /// `leader`, `agent-<id>`.
    pub name: String,
    /// Time of the `started` line, s since the epoch.
    pub started: f64,
    /// Time of the `done` line, s since the epoch.
    pub done: f64,
    /// `steps=` of the `done` line.
    pub steps: u64,
    /// `peak_rss_kb=` of the `done` line.
    pub peak_rss_kb: u64,
}

/// Reads every `<name>.log` of a process run.
pub fn read_logs(dir: &Path) -> Result<Vec<NodeLog>, String> {
    let rd = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut out = Vec::new();
    for e in rd.filter_map(Result::ok) {
        let path = e.path();
        if path.extension().is_none_or(|x| x != "log") {
            continue;
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let text =
            std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        out.push(
            parse_log(&name, &text)
                .ok_or_else(|| format!("{}: no `started` and `done` lines", path.display()))?,
        );
    }
    if out.is_empty() {
        return Err(format!("{}: no node logs", dir.display()));
    }
    Ok(out)
}

/// Parses a node log (tracing's default format: `TIMESTAMP  INFO target: message fields`).
#[must_use]
pub fn parse_log(name: &str, text: &str) -> Option<NodeLog> {
    let mut started = None;
    let mut done = None;
    for line in text.lines() {
        let Some((ts, rest)) = line.split_once(' ') else {
            continue;
        };
        if rest.trim_end().ends_with(": started") {
            started = parse_rfc3339(ts);
        } else if let Some((_, fields)) = rest.split_once(": done ") {
            let field = |k: &str| {
                fields
                    .split_whitespace()
                    .find_map(|f| f.strip_prefix(k)?.strip_prefix('=')?.parse::<u64>().ok())
            };
            done = Some((parse_rfc3339(ts)?, field("steps")?, field("peak_rss_kb")?));
        }
    }
    let (done, steps, peak_rss_kb) = done?;
    Some(NodeLog {
        name: name.to_string(),
        started: started?,
        done,
        steps,
        peak_rss_kb,
    })
}

/// `2026-11-22T02:59:03.475293Z` → seconds since the Unix epoch (UTC only).
#[must_use]
pub fn parse_rfc3339(s: &str) -> Option<f64> {
    let s = s.strip_suffix('Z')?;
    let (date, time) = s.split_once('T')?;
    let mut d = date.splitn(3, '-').map(str::parse::<i64>);
    let (y, m, day) = (d.next()?.ok()?, d.next()?.ok()?, d.next()?.ok()?);
    let mut t = time.splitn(3, ':');
    let h: i64 = t.next()?.parse().ok()?;
    let min: i64 = t.next()?.parse().ok()?;
    let sec: f64 = t.next()?.parse().ok()?;
    if !(1..=12).contains(&m) || !(1..=31).contains(&day) {
        return None;
    }
    // Days from civil (H. Hinnant).
    let yy = if m <= 2 { y - 1 } else { y };
    let era = yy.div_euclid(400);
    let yoe = yy - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    Some((days * 86_400 + h * 3600 + min * 60) as f64 + sec)
}

/// One node of a bare lockstep over a given graph.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct NodeTopo {
    /// Node id (0 = the leader).
    pub id: u32,
    /// Ids it reads.
    pub inputs: Vec<u32>,
    /// Ids that read it.
    pub outputs: Vec<u32>,
}

/// A bare lockstep to run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BareSpec {
    /// Number of processes.
    pub n: u32,
    /// Steps (4 exchanges each).
    pub steps: u64,
    /// Waiting strategy.
    pub wait: WaitStrategy,
    /// `None`: the ring i ± 1 (fan-out 2); `Some`: this graph, with this fan-out limit.
    pub graph: Option<(Vec<NodeTopo>, usize)>,
}

impl std::hash::Hash for BareSpec {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (self.n, self.steps, wait_name(self.wait), &self.graph).hash(h);
    }
}

/// What a bare lockstep measured.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BareRun {
    /// From the first node's loop start to the last node's loop end, s.
    pub span: f64,
    /// Longest loop of one node, s.
    pub max_elapsed: f64,
    /// Largest peak RSS of a node, kB.
    pub peak_rss_kb: u64,
}

fn ids(v: &[u32]) -> String {
    v.iter().map(u32::to_string).collect::<Vec<_>>().join(",")
}

/// Runs a bare lockstep: starts the `ring-node` processes, waits for every
/// `ready-<i>`, creates `start`, waits for every process (bounded), and
/// reads their reports. Its iceoryx2 namespace is removed afterwards.
pub fn bare(
    bins: &Bins,
    work: &Path,
    spec: &BareSpec,
    timeout: Duration,
) -> Result<BareRun, String> {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let run = format!(
        "b{:x}x{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    let dir = work.join("iox").join(&run);
    std::fs::create_dir_all(dir.join("iox")).map_err(|e| format!("{}: {e}", dir.display()))?;
    let result = bare_in(bins, &run, &dir, spec, timeout);
    procs::remove_namespace(&run, &dir);
    result
}

fn bare_in(
    bins: &Bins,
    run: &str,
    dir: &Path,
    spec: &BareSpec,
    timeout: Duration,
) -> Result<BareRun, String> {
    let nodes: Vec<(u32, Option<&NodeTopo>)> = match &spec.graph {
        None => (0..spec.n).map(|i| (i, None)).collect(),
        Some((g, _)) => g.iter().map(|t| (t.id, Some(t))).collect(),
    };
    let mut group = Group::default();
    for &(id, topo) in &nodes {
        let out =
            std::fs::File::create(dir.join(format!("out-{id}.txt"))).map_err(|e| e.to_string())?;
        let err =
            std::fs::File::create(dir.join(format!("err-{id}.txt"))).map_err(|e| e.to_string())?;
        let mut cmd = Command::new(&bins.bench);
        cmd.arg("ring-node")
            .args(["--run", run])
            .arg("--root")
            .arg(dir)
            .args(["--index", &id.to_string()])
            .args(["--n", &spec.n.to_string()])
            .args(["--steps", &spec.steps.to_string()])
            .args(["--wait", wait_name(spec.wait)]);
        if let (Some(t), Some((_, fanout))) = (topo, &spec.graph) {
            cmd.args(["--inputs", &ids(&t.inputs)])
                .args(["--outputs", &ids(&t.outputs)])
                .args(["--max-fanout", &fanout.to_string()]);
        }
        cmd.stdin(Stdio::null()).stdout(out).stderr(err);
        let child = cmd
            .spawn()
            .map_err(|e| format!("cannot start ring-node: {e}"))?;
        group.push(id, child);
    }
    let err_of = |id: u32| procs::tail(&dir.join(format!("err-{id}.txt")), 2);
    // Start barrier: every node connected.
    let deadline = Instant::now() + Duration::from_secs(120);
    while !nodes
        .iter()
        .all(|(id, _)| dir.join(files::ready(*id)).exists())
    {
        if let Some((id, status)) = group.first_exit() {
            return Err(format!(
                "ring-node {id} ended before the start ({status}): {}",
                err_of(id)
            ));
        }
        if Instant::now() > deadline {
            return Err("ring nodes not ready after 120 s".into());
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    std::fs::write(dir.join(files::START), b"").map_err(|e| e.to_string())?;
    let exits = group.wait_all(timeout)?;
    let mut reports = Vec::new();
    for (id, status) in exits {
        if !status.success() {
            return Err(format!("ring-node {id} failed ({status}): {}", err_of(id)));
        }
        let text = std::fs::read_to_string(dir.join(format!("out-{id}.txt")))
            .map_err(|e| e.to_string())?;
        reports.push(
            text.lines()
                .find_map(RingReport::parse)
                .ok_or_else(|| format!("ring-node {id} printed no report"))?,
        );
    }
    let first = reports
        .iter()
        .map(|r| r.start_unix)
        .fold(f64::INFINITY, f64::min);
    let last = reports
        .iter()
        .map(|r| r.end_unix)
        .fold(f64::NEG_INFINITY, f64::max);
    Ok(BareRun {
        span: last - first,
        max_elapsed: reports.iter().map(|r| r.elapsed).fold(0.0, f64::max),
        peak_rss_kb: reports.iter().map(|r| r.peak_rss_kb).max().unwrap_or(0),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rfc3339_to_unix() {
        assert_eq!(parse_rfc3339("1970-01-01T00:00:00Z"), Some(0.0));
        assert_eq!(parse_rfc3339("2000-03-01T00:00:00Z"), Some(951_868_800.0));
        let t = parse_rfc3339("2026-11-22T02:59:03.475293Z").unwrap();
        assert!((t - 1_795_316_343.475_293).abs() < 1e-6, "{t}");
        assert_eq!(parse_rfc3339("2026-11-22 02:59:03Z"), None);
    }

    #[test]
    fn node_log() {
        let text = "2026-11-22T02:58:59.154131Z  INFO attsync_agent::runtime: ready id=1 inputs=[3, 0] outputs=[3]\n\
                    2026-11-22T02:58:59.181509Z  INFO attsync_agent::runtime: started\n\
                    2026-11-22T02:59:03.475293Z  INFO attsync_agent::runtime: done steps=40000 peak_rss_kb=8100\n";
        let l = parse_log("agent-1", text).unwrap();
        assert_eq!((l.steps, l.peak_rss_kb), (40000, 8100));
        assert!((l.done - l.started - 4.293_784).abs() < 1e-6);
        assert_eq!(
            parse_log("x", "2026-11-22T02:58:59Z  INFO a: started\n"),
            None
        );
    }
}
