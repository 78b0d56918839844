//! `attsync-bench hosts`, second part (issue 37, item 4): what a cut edge
//! costs, hop by hop and with lookahead, in one run. The scenario is split
//! over the orchestrator's machine and one `attsync host` on loopback
//! (plain TCP, a mount namespace of its own: [`crate::hosts`]), its nodes
//! cut in two contiguous blocks, and run beside the same scenario on one
//! machine (processes engine), repetitions interleaved:
//! - **the hops**: the local exchange (one machine's lockstep per
//!   exchange), Zenoh's one-way trip for a state's payload (half the
//!   median round trip of [`crate::zping`] with attsync's low-latency
//!   configuration), the crossing (the two machines' lockstep per exchange)
//!   and the bridge's overhead, crossing − local − one way;
//! - **lookahead**: with `network.delay` = k steps on every link, the two
//!   machines' run time over one machine's (the same delay) for each k;
//! - **real time** (`--realtime`, factor 1): each cut edge's age of
//!   information (median, 99th percentile, mean and largest) and
//!   the share of its states delivered, beside the local links' mean age:
//!   a value waits for the stage that uses it on every link alike, so the
//!   difference of the means is what crossing adds.

use crate::hosts::{self, HostDaemon, Transport};
use crate::measure::{self, AttsyncRun, Bins, Engine};
use anyhow::Context as _;
use attsync::results::summary::LinkSummary;
use msgs::config::WaitStrategy;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// What to measure.
#[derive(Debug, Clone)]
pub struct Options {
    /// The scenario.
    pub scenario: PathBuf,
    /// Simulated seconds.
    pub duration: f64,
    /// Repetitions of every run.
    pub reps: usize,
    /// Delays on every link, in steps.
    pub delays: Vec<u64>,
    /// Scratch directory.
    pub work: PathBuf,
}

/// One delay's runs.
#[derive(Debug, Clone)]
pub struct DelayRuns {
    /// The delay, steps.
    pub k: u64,
    /// On one machine.
    pub one: Vec<AttsyncRun>,
    /// Over two.
    pub two: Vec<AttsyncRun>,
}

/// Everything measured.
#[derive(Debug, Clone)]
pub struct Figures {
    /// Zenoh's round trips for a state's payload, µs.
    pub zenoh_rtt_us: Vec<f64>,
    /// Per delay.
    pub delays: Vec<DelayRuns>,
    /// The real-time run's links, and whether each is a cut edge.
    pub realtime: Vec<(LinkSummary, bool)>,
}

/// Measures everything `o` asks.
///
/// # Errors
/// A daemon that does not start, a run that fails.
pub fn measure(o: &Options, bins: &Bins) -> anyhow::Result<Figures> {
    let loaded = attsync::scenario::load(&o.scenario, &[])?;
    let dt = loaded.scenario.simulation.dt;
    let net = &loaded.resolved.network;
    let nodes = u32::try_from(net.agents.len() + 1)?;
    let host = HostDaemon::start(&bins.attsync, &o.work, ("x1", Transport::Tcp), &[])?;
    let file = o.work.join("hosts-crossing.toml");
    let blocks = hosts::blocks(nodes, 2);
    let text = hosts::hosts_toml(
        std::slice::from_ref(&host),
        &blocks,
        Transport::Tcp,
        &o.work,
    );
    std::fs::write(&file, text)?;
    let hosts = attsync::hosts::load(&file).map_err(|e| anyhow::anyhow!("{e}"))?;
    let placement = attsync::hosts::placement::Placement::of(&hosts, net)
        .map_err(|e| anyhow::anyhow!("{e}"))?;
    let cut: Vec<(u32, u32)> = (placement.cut_edges().iter())
        .map(|c| (c.from, c.to))
        .collect();
    let zenoh_rtt_us = zenoh_rtt()?;
    let mut delays: Vec<DelayRuns> = (o.delays.iter())
        .map(|&k| DelayRuns {
            k,
            one: Vec::new(),
            two: Vec::new(),
        })
        .collect();
    let on_hosts = [OsString::from("--hosts"), file.clone().into_os_string()];
    for rep in 0..o.reps {
        for d in &mut delays {
            let sets = sets(o.duration, d.k, dt);
            let out = o.work.join(format!("crossing-{}-{rep}", d.k));
            d.one
                .push(run(bins, o, &sets, &[], &out).with_context(|| one_machine(d.k))?);
            let r = run(bins, o, &sets, &on_hosts, &out).with_context(|| two_machines(d.k))?;
            eprintln!(
                "k = {}, rep {}: {:.2} s over two machines",
                d.k,
                rep + 1,
                r.run_seconds
            );
            d.two.push(r);
        }
    }
    let out = o.work.join("crossing-realtime");
    let realtime_args = [
        on_hosts[0].clone(),
        on_hosts[1].clone(),
        "--realtime".into(),
    ];
    run(bins, o, &sets(o.duration, 0, dt), &realtime_args, &out).context("real time")?;
    let s = measure::read_summary(&attsync::results::RunLayout::new(&out).summary())?;
    let realtime = (s.links.into_iter())
        .map(|l| {
            let crosses = cut.contains(&(l.from, l.to));
            (l, crosses)
        })
        .collect();
    drop(host);
    Ok(Figures {
        zenoh_rtt_us,
        delays,
        realtime,
    })
}

fn one_machine(k: u64) -> String {
    format!("one machine, k = {k}")
}

fn two_machines(k: u64) -> String {
    format!("two machines, k = {k}")
}

/// The `--set`s of a run of `duration` s with `k` steps of delay on every link.
fn sets(duration: f64, k: u64, dt: f64) -> Vec<String> {
    let mut s = vec![format!("simulation.duration={duration:?}")];
    if k > 0 {
        s.push(format!("network.delay={:?}", k as f64 * dt));
    }
    s
}

/// One `attsync run` with the processes engine (`extra`: `--hosts`…).
fn run(
    bins: &Bins,
    o: &Options,
    sets: &[String],
    extra: &[OsString],
    out: &Path,
) -> anyhow::Result<AttsyncRun> {
    let engine = Engine::Processes(WaitStrategy::Adaptive);
    let timeout = Duration::from_secs(600);
    Ok(measure::attsync_with(
        bins,
        &o.scenario,
        engine,
        sets,
        extra,
        out,
        timeout,
    )?)
}

/// Zenoh's round trips for a `StateMsg`'s payload, attsync's configuration.
fn zenoh_rtt() -> anyhow::Result<Vec<f64>> {
    let port = std::net::TcpListener::bind("127.0.0.1:0")?
        .local_addr()?
        .port();
    crate::zping::ping(crate::zping::Ping {
        payload: std::mem::size_of::<msgs::StateMsg>(),
        rounds: 2000,
        warmup: 200,
        transport: crate::zping::Transport::Lowlatency,
        port,
    })
}

/// The median of `v` (NaN if empty).
fn median(v: impl IntoIterator<Item = f64>) -> f64 {
    let v: Vec<f64> = v.into_iter().collect();
    crate::stats::median(&v).unwrap_or(f64::NAN)
}

/// µs per exchange of runs `r` (their lockstep, 4 exchanges per step).
fn per_exchange(r: &[AttsyncRun]) -> f64 {
    let steps = r.first().map_or(f64::NAN, |r| r.steps as f64);
    median(r.iter().filter_map(|r| r.lockstep)) / (4.0 * steps) * 1e6
}

/// The three Markdown tables.
#[must_use]
pub fn tables(f: &Figures) -> String {
    let mut s = String::from("\n### A crossing, hop by hop (medians)\n\n");
    let one_way = median(f.zenoh_rtt_us.iter().copied()) / 2.0;
    if let Some(k0) = f.delays.iter().find(|d| d.k == 0) {
        let (local, crossing) = (per_exchange(&k0.one), per_exchange(&k0.two));
        s.push_str("| local exchange µs | zenoh one way µs | crossing µs | bridge overhead µs |\n");
        s.push_str("|---:|---:|---:|---:|\n");
        s.push_str(&format!(
            "| {local:.1} | {one_way:.1} | {crossing:.1} | {:.1} |\n",
            crossing - local - one_way
        ));
    }
    s.push_str("\n### Lookahead: k steps of delay on every link (medians)\n\n");
    s.push_str("| k | one machine: run s | lockstep s | two machines: run s | lockstep s | ratio, run | ratio, lockstep |\n");
    s.push_str("|---:|---:|---:|---:|---:|---:|---:|\n");
    for d in &f.delays {
        let run = |r: &[AttsyncRun]| median(r.iter().map(|r| r.run_seconds));
        let lock = |r: &[AttsyncRun]| median(r.iter().filter_map(|r| r.lockstep));
        let (one, two) = ((run(&d.one), lock(&d.one)), (run(&d.two), lock(&d.two)));
        s.push_str(&format!(
            "| {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} |\n",
            d.k,
            one.0,
            one.1,
            two.0,
            two.1,
            two.0 / one.0,
            two.1 / one.1
        ));
    }
    s.push_str(&realtime_table(f));
    s
}

/// The real-time section of [`tables`]: every link's ages, then what
/// crossing adds.
fn realtime_table(f: &Figures) -> String {
    let mut s = String::from("\n### Real time: every link\n\n");
    s.push_str(
        "| link | cut | age of information, p50 µs | p99 µs | mean µs | largest µs | delivered |\n",
    );
    s.push_str("|---|---|---:|---:|---:|---:|---:|\n");
    let us = |q: Option<f64>| q.map_or("–".to_string(), |q| format!("{:.0}", q * 1e6));
    for (l, cut) in &f.realtime {
        s.push_str(&format!(
            "| {} → {} | {} | {} | {} | {:.0} | {:.0} | {:.2} % |\n",
            l.from,
            l.to,
            if *cut { "yes" } else { "no" },
            us(l.aoi_p50),
            us(l.aoi_p99),
            l.aoi_mean * 1e6,
            l.aoi_max * 1e6,
            100.0 * l.delivered as f64 / l.sent.max(1) as f64
        ));
    }
    let mean_age = |cut: bool| {
        let of: Vec<f64> = (f.realtime.iter())
            .filter(|(_, c)| *c == cut)
            .map(|(l, _)| l.aoi_mean * 1e6)
            .collect();
        (of.iter().sum::<f64>() / of.len() as f64, of.len())
    };
    let ((cut, n_cut), (local, n_local)) = (mean_age(true), mean_age(false));
    s.push_str(&format!(
        "\nMean age: {cut:.0} µs over {n_cut} cut edges, {local:.0} µs over {n_local} local links: \
         crossing adds {:.0} µs.\n",
        cut - local
    ));
    let p = |cut: bool, q: fn(&LinkSummary) -> Option<f64>| {
        median(
            (f.realtime.iter())
                .filter(|(_, c)| *c == cut)
                .filter_map(|(l, _)| q(l).map(|v| v * 1e6)),
        )
    };
    let (p50, p99) = (|l: &LinkSummary| l.aoi_p50, |l: &LinkSummary| l.aoi_p99);
    s.push_str(&format!(
        "Median over the links of their p50: {:.0} µs cut, {:.0} µs local (crossing adds {:.0} µs); \
         of their p99: {:.0} µs cut, {:.0} µs local.\n",
        p(true, p50),
        p(false, p50),
        p(true, p50) - p(false, p50),
        p(true, p99),
        p(false, p99)
    ));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_delay_of_k_steps_is_set_in_seconds_and_none_for_k_zero() {
        assert_eq!(sets(5.0, 0, 1e-3), ["simulation.duration=5.0"]);
        assert_eq!(
            sets(5.0, 20, 1e-3),
            ["simulation.duration=5.0", "network.delay=0.02"]
        );
    }
}
