//! One bare lockstep (ring, or the scenario's own graph) of `ring-node`
//! processes, measured. Used by `attsync-bench run` (see `main.rs` for how
//! to run it).

use crate::error::{BenchError, Result};
use crate::measure::{Bins, wait_name};
use crate::procs::{self, Group};
use crate::ring::{RingReport, files};
use msgs::config::WaitStrategy;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

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
    /// Each node pinned to one core as `attsync run --placement pin` would
    /// (the same cut of the graph), else left to the scheduler.
    pub pinned: bool,
}

impl std::hash::Hash for BareSpec {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        (
            self.n,
            self.steps,
            wait_name(self.wait),
            &self.graph,
            self.pinned,
        )
            .hash(h);
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
pub fn bare(bins: &Bins, work: &Path, spec: &BareSpec, timeout: Duration) -> Result<BareRun> {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let run = format!(
        "b{:x}x{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    );
    let dir = work.join("iox").join(&run);
    std::fs::create_dir_all(dir.join("iox")).map_err(BenchError::io(&dir))?;
    let result = bare_in(bins, &run, &dir, spec, timeout);
    procs::remove_namespace(&run, &dir);
    result
}

/// The files of node `id` in the run directory: its stdout (the report) and stderr.
fn out_file(dir: &Path, id: u32) -> std::path::PathBuf {
    dir.join(format!("out-{id}.txt"))
}

fn err_file(dir: &Path, id: u32) -> std::path::PathBuf {
    dir.join(format!("err-{id}.txt"))
}

/// Starts the `ring-node` process of node `id`.
fn spawn_node(
    bins: &Bins,
    run: &str,
    dir: &Path,
    spec: &BareSpec,
    (id, topo): (u32, Option<&NodeTopo>),
) -> Result<std::process::Child> {
    let file = |p: std::path::PathBuf| std::fs::File::create(&p).map_err(BenchError::io(p));
    let (out, err) = (file(out_file(dir, id))?, file(err_file(dir, id))?);
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
    cmd.spawn().map_err(|source| BenchError::Spawn {
        program: "ring-node".into(),
        source,
    })
}

fn bare_in(
    bins: &Bins,
    run: &str,
    dir: &Path,
    spec: &BareSpec,
    timeout: Duration,
) -> Result<BareRun> {
    let nodes: Vec<(u32, Option<&NodeTopo>)> = match &spec.graph {
        None => (0..spec.n).map(|i| (i, None)).collect(),
        Some((g, _)) => g.iter().map(|t| (t.id, Some(t))).collect(),
    };
    let mut group = Group::default();
    let mut pids = Vec::new();
    for &node in &nodes {
        let child = spawn_node(bins, run, dir, spec, node)?;
        pids.push(child.id());
        group.push(node.0, child);
    }
    if spec.pinned {
        attsync::processes::placement::pin(&pids, &adjacency(&nodes));
    }
    let failed = |id: u32, status: std::process::ExitStatus, when: &str| BenchError::Failed {
        program: format!("ring-node {id}"),
        outcome: format!("{when} ({status}): {}", procs::tail(&err_file(dir, id), 2)),
    };
    // Start barrier: every node connected.
    let deadline = Instant::now() + Duration::from_secs(120);
    while !nodes
        .iter()
        .all(|(id, _)| dir.join(files::ready(*id)).exists())
    {
        if let Some((id, status)) = group.first_exit() {
            return Err(failed(id, status, "ended before the start"));
        }
        if Instant::now() > deadline {
            return Err(BenchError::Timeout {
                seconds: 120.0,
                what: "waiting for the ring nodes to be ready".into(),
            });
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    let start = dir.join(files::START);
    std::fs::write(&start, b"").map_err(BenchError::io(&start))?;
    let mut reports = Vec::new();
    for (id, status) in group.wait_all(timeout)? {
        if !status.success() {
            return Err(failed(id, status, "failed"));
        }
        let path = out_file(dir, id);
        let text = std::fs::read_to_string(&path).map_err(BenchError::io(&path))?;
        reports.push(text.lines().find_map(RingReport::parse).ok_or_else(|| {
            BenchError::Results {
                path,
                what: format!("ring-node {id} printed no report"),
            }
        })?);
    }
    Ok(BareRun::of(&reports))
}

/// For each of `nodes` the positions of its neighbours (inputs and outputs).
fn adjacency(nodes: &[(u32, Option<&NodeTopo>)]) -> Vec<Vec<usize>> {
    let position = |id: u32| nodes.iter().position(|(i, _)| *i == id);
    let ring = |id: u32| {
        let n = nodes.len() as u32;
        vec![(id + n - 1) % n, (id + 1) % n]
    };
    (nodes.iter())
        .map(|&(id, topo)| {
            let ids = topo.map_or_else(
                || ring(id),
                |t| t.inputs.iter().chain(&t.outputs).copied().collect(),
            );
            let mut ws: Vec<usize> = ids.into_iter().filter_map(position).collect();
            ws.sort_unstable();
            ws.dedup();
            ws
        })
        .collect()
}

impl BareRun {
    /// The span of the nodes' loops and their largest figures.
    fn of(reports: &[RingReport]) -> Self {
        let first = reports
            .iter()
            .map(|r| r.start_unix)
            .fold(f64::INFINITY, f64::min);
        let last = reports
            .iter()
            .map(|r| r.end_unix)
            .fold(f64::NEG_INFINITY, f64::max);
        Self {
            span: last - first,
            max_elapsed: reports.iter().map(|r| r.elapsed).fold(0.0, f64::max),
            peak_rss_kb: reports.iter().map(|r| r.peak_rss_kb).max().unwrap_or(0),
        }
    }
}
