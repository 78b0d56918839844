//! `attsync-bench hosts`: one scenario (the paper's time-varying run by
//! default) on one machine and split over 2 and 3 hosts on loopback, in one
//! run, repetitions interleaved (issue 12, BENCHMARKS.md "Across hosts").
//!
//! Each host is an `attsync host` daemon in a mount namespace of its own
//! (`unshare --mount`, as root) with a private tmpfs on `/dev/shm` and a
//! `TMPDIR` of its own, listening on 127.0.0.1: nothing passes between
//! hosts through shared memory, everything across goes over Zenoh and TCP.
//! The nodes `0..N` are cut into H contiguous blocks of near-equal size; the
//! first (with the leader) stays on the orchestrator's machine, host `k`
//! takes block `k`. The figures come from `summary.json` (lockstep: first
//! node's start to last node's end), with the cut edges of each placement.
//! Every placement over hosts is measured twice, side by side: over plain
//! TCP (`--insecure`) and over QUIC with mutual TLS (the default; a test CA
//! made with `attsync host --gen-certs`), so the table gives the cost of
//! the security as a ratio.

use crate::measure::{self, AttsyncRun, Bins, Engine};
use anyhow::{Context as _, bail};
use msgs::config::WaitStrategy;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// What to measure.
#[derive(Debug, Clone)]
pub struct Options {
    /// The scenario.
    pub scenario: PathBuf,
    /// Simulated seconds (`--set simulation.duration`).
    pub duration: f64,
    /// Repetitions of every placement.
    pub reps: usize,
    /// Machine counts (1: no `--hosts`).
    pub machines: Vec<usize>,
    /// Scratch directory (removed at the end).
    pub work: PathBuf,
}

/// How a placement's links are carried.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transport {
    /// Plain TCP, `--insecure`.
    Tcp,
    /// QUIC with mutual TLS (certificates in `work/certs`).
    Quic,
}

impl Transport {
    /// Its name in the table.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Tcp => "tcp (insecure)",
            Self::Quic => "quic (mutual TLS)",
        }
    }
}

/// An `attsync host` in a mount namespace of its own; killed (its whole
/// process group) when dropped.
pub(crate) struct HostDaemon {
    name: String,
    endpoint: String,
    child: Child,
}

/// The flags of `transport` for the party `name` (certificates in `certs`).
fn security_flags(transport: Transport, certs: &Path, name: &str) -> Vec<String> {
    match transport {
        Transport::Tcp => vec!["--insecure".into()],
        Transport::Quic => {
            let f = |ext: &str| certs.join(format!("{name}.{ext}")).display().to_string();
            let ca = certs.join("ca.pem").display().to_string();
            vec![
                "--ca".into(),
                ca,
                "--cert".into(),
                f("pem"),
                "--key".into(),
                f("key"),
            ]
        }
    }
}

impl HostDaemon {
    pub(crate) fn start(
        attsync: &Path,
        work: &Path,
        (name, transport): (&str, Transport),
        connect: &[String],
    ) -> anyhow::Result<Self> {
        let endpoint = match transport {
            Transport::Tcp => {
                let port = std::net::TcpListener::bind("127.0.0.1:0")?
                    .local_addr()?
                    .port();
                format!("tcp/127.0.0.1:{port}")
            }
            Transport::Quic => {
                let port = std::net::UdpSocket::bind("127.0.0.1:0")?
                    .local_addr()?
                    .port();
                format!("quic/127.0.0.1:{port}")
            }
        };
        let tmp = work.join(format!("host-{name}"));
        std::fs::create_dir_all(&tmp).with_context(|| tmp.display().to_string())?;
        let log = work.join(format!("host-{name}.log"));
        let mut args: Vec<String> = ["host", "--name", name, "--listen", &endpoint]
            .map(String::from)
            .into();
        args.extend(security_flags(transport, &work.join("certs"), name));
        for c in connect {
            args.extend(["--connect".to_string(), c.clone()]);
        }
        let child = Command::new("unshare")
            .args(["--mount", "--propagation", "private", "--", "sh", "-c"])
            .arg("mount -t tmpfs -o mode=1777 tmpfs /dev/shm && exec \"$@\"")
            .arg("sh")
            .arg(attsync)
            .args(&args)
            .env("TMPDIR", &tmp)
            .env("ATTSYNC_LOG", "info")
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(&log)?)
            .process_group(0)
            .spawn()
            .context("unshare (needs root) for an `attsync host`")?;
        let mut d = Self {
            name: name.to_string(),
            endpoint,
            child,
        };
        d.wait_serving(&log)?;
        Ok(d)
    }

    /// Until its log says it serves (at most 10 s).
    fn wait_serving(&mut self, log: &Path) -> anyhow::Result<()> {
        let deadline = Instant::now() + Duration::from_secs(10);
        let serving = || std::fs::read_to_string(log).is_ok_and(|t| t.contains("serving"));
        while !serving() {
            if let Some(s) = self.child.try_wait()? {
                bail!("host `{}` exited at start: {s}", self.name);
            }
            if Instant::now() > deadline {
                bail!(
                    "host `{}` does not listen on {} after 10 s",
                    self.name,
                    self.endpoint
                );
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        Ok(())
    }
}

impl Drop for HostDaemon {
    fn drop(&mut self) {
        let group = format!("-{}", self.child.id());
        let _ = Command::new("kill").args(["-KILL", "--", &group]).status();
        let _ = self.child.wait();
    }
}

/// Nodes `0..nodes` cut into `parts` contiguous blocks, sizes differing by
/// at most one, the larger first.
#[must_use]
pub fn blocks(nodes: u32, parts: usize) -> Vec<Vec<u32>> {
    let parts = u32::try_from(parts.max(1)).unwrap_or(u32::MAX);
    let (size, extra) = (nodes / parts, nodes % parts);
    let mut start = 0;
    (0..parts)
        .map(|k| {
            let len = size + u32::from(k < extra);
            let b = (start..start + len).collect();
            start += len;
            b
        })
        .collect()
}

/// HOSTS.toml placing block `k + 1` on `hosts[k]`, over `t`.
pub(crate) fn hosts_toml(
    hosts: &[HostDaemon],
    blocks: &[Vec<u32>],
    t: Transport,
    certs: &Path,
) -> String {
    let mut text = match t {
        Transport::Tcp => String::from("insecure = true\n\n"),
        Transport::Quic => format!(
            "[tls]\nca = {:?}\ncert = {:?}\nkey = {:?}\n\n",
            certs.join("ca.pem"),
            certs.join("bench.pem"),
            certs.join("bench.key")
        ),
    };
    for (h, b) in hosts.iter().zip(&blocks[1..]) {
        let agents: Vec<u32> = b.iter().copied().filter(|&id| id != 0).collect();
        text.push_str(&format!(
            "[[host]]\nname = \"{}\"\nendpoint = \"{}\"\nleader = {}\nagents = {agents:?}\n\n",
            h.name,
            h.endpoint,
            b.contains(&0)
        ));
    }
    text
}

/// One placement's figures.
#[derive(Debug, Clone)]
pub struct Placed {
    /// Machines (1: the orchestrator's alone).
    pub machines: usize,
    /// Nodes per machine, the orchestrator's first.
    pub sizes: Vec<usize>,
    /// Directed cut edges.
    pub cut_edges: usize,
    /// What carries the cut edges.
    pub transport: Transport,
    /// Every repetition.
    pub runs: Vec<AttsyncRun>,
}

/// Runs every placement `o.reps` times, interleaved.
pub fn measure(o: &Options, bins: &Bins) -> anyhow::Result<Vec<Placed>> {
    let sets = vec![format!("simulation.duration={:?}", o.duration)];
    let loaded = attsync::scenario::load(&o.scenario, &sets)?;
    let net = &loaded.resolved.network;
    let nodes = u32::try_from(net.agents.len() + 1)?;
    let most = o.machines.iter().copied().max().unwrap_or(1);
    gen_certs(&bins.attsync, &o.work, most)?;
    let mut daemons = Vec::new();
    for t in [Transport::Tcp, Transport::Quic] {
        daemons.push(start_daemons(bins, o, most, t)?);
    }
    let mut placed = Vec::new();
    let mut files = Vec::new();
    for &m in &o.machines {
        let ts: &[Transport] = if m > 1 {
            &[Transport::Tcp, Transport::Quic]
        } else {
            &[Transport::Tcp]
        };
        for (k, &t) in ts.iter().enumerate() {
            let b = blocks(nodes, m);
            let file = (m > 1).then(|| o.work.join(format!("hosts-{m}-{k}.toml")));
            let mut cut_edges = 0;
            if let Some(f) = &file {
                let text = hosts_toml(&daemons[k][..m - 1], &b, t, &o.work.join("certs"));
                std::fs::write(f, text)?;
                let hosts = attsync::hosts::load(f).map_err(|e| anyhow::anyhow!("{e}"))?;
                let p = attsync::hosts::placement::Placement::of(&hosts, net)
                    .map_err(|e| anyhow::anyhow!("{e}"))?;
                cut_edges = p.cut_edges().len();
            }
            files.push(file);
            placed.push(Placed {
                machines: m,
                sizes: b.iter().map(Vec::len).collect(),
                cut_edges,
                transport: t,
                runs: Vec::new(),
            });
        }
    }
    let engine = Engine::Processes(WaitStrategy::Adaptive);
    for rep in 0..o.reps {
        for (p, file) in placed.iter_mut().zip(&files) {
            let out = o.work.join(format!("run-{}-{rep}", p.machines));
            let extra: Vec<std::ffi::OsString> = file
                .iter()
                .flat_map(|f| ["--hosts".into(), f.clone().into_os_string()])
                .collect();
            let timeout = Duration::from_secs(600);
            let r = measure::attsync_with(bins, &o.scenario, engine, &sets, &extra, &out, timeout)
                .with_context(|| {
                    format!(
                        "{} machine(s) ({}), repetition {}",
                        p.machines,
                        p.transport.name(),
                        rep + 1
                    )
                })?;
            eprintln!(
                "{} machine(s) ({}), rep {}: run {:.2} s, lockstep {:.2} s",
                p.machines,
                p.transport.name(),
                rep + 1,
                r.run_seconds,
                r.lockstep.unwrap_or(f64::NAN)
            );
            p.runs.push(r);
        }
    }
    Ok(placed)
}

/// A test CA in `work/certs` with a certificate for each host of either
/// transport (`h1`…, `q1`…) and for the orchestrator (`bench`).
fn gen_certs(attsync: &Path, work: &Path, most: usize) -> anyhow::Result<()> {
    let mut cmd = Command::new(attsync);
    cmd.args(["host", "--gen-certs"]).arg(work.join("certs"));
    for k in 1..most {
        cmd.args(["--for", &format!("q{k}=127.0.0.1")]);
    }
    let out = cmd.args(["--for", "bench"]).output()?;
    if !out.status.success() {
        bail!(
            "attsync host --gen-certs: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    Ok(())
}

/// `most - 1` daemons over `t`, each dialling those before it.
fn start_daemons(
    bins: &Bins,
    o: &Options,
    most: usize,
    t: Transport,
) -> anyhow::Result<Vec<HostDaemon>> {
    let prefix = if t == Transport::Tcp { "h" } else { "q" };
    let mut daemons: Vec<HostDaemon> = Vec::new();
    for k in 1..most {
        let connect: Vec<String> = daemons.iter().map(|d| d.endpoint.clone()).collect();
        let name = format!("{prefix}{k}");
        daemons.push(HostDaemon::start(
            &bins.attsync,
            &o.work,
            (&name, t),
            &connect,
        )?);
    }
    Ok(daemons)
}

/// The Markdown table: medians over the repetitions.
#[must_use]
pub fn table(placed: &[Placed]) -> String {
    let med = |v: Vec<f64>| crate::stats::median(&v).unwrap_or(f64::NAN);
    let one = placed
        .iter()
        .find(|p| p.machines == 1)
        .map(|p| med(p.runs.iter().map(|r| r.run_seconds).collect()));
    let mut s = String::from(
        "| machines | transport | nodes per machine | cut edges | run s (median) | lockstep s | steps/s | µs per exchange | run ÷ 1 machine |\n|---:|---|---|---:|---:|---:|---:|---:|---:|\n",
    );
    for p in placed {
        let run = med(p.runs.iter().map(|r| r.run_seconds).collect());
        let lock = med(p.runs.iter().filter_map(|r| r.lockstep).collect());
        let steps = p.runs.first().map_or(0, |r| r.steps) as f64;
        let sizes: Vec<String> = p.sizes.iter().map(ToString::to_string).collect();
        s.push_str(&format!(
            "| {} | {} | {} | {} | {run:.2} | {lock:.2} | {:.0} | {:.1} | {} |\n",
            p.machines,
            if p.machines > 1 {
                p.transport.name()
            } else {
                "–"
            },
            sizes.join(" + "),
            p.cut_edges,
            steps / lock,
            lock / (steps * 4.0) * 1e6,
            one.map_or("–".into(), |o| format!("{:.1}", run / o)),
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_are_contiguous_and_near_equal() {
        assert_eq!(blocks(8, 1), vec![(0..8).collect::<Vec<_>>()]);
        assert_eq!(blocks(8, 2), vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7]]);
        assert_eq!(blocks(8, 3), vec![vec![0, 1, 2], vec![3, 4, 5], vec![6, 7]]);
    }
}
