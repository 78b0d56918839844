//! `attsync-bench conclusions` (issue 32): how long `attsync margin` takes
//! (the paper's scenarios and generated trees), and what `--until settled`
//! costs beyond the extra simulated time (an extended in-process run against
//! one run of the same final horizon, interleaved repetitions, medians).

use crate::stats::median;
use attsync::generate::{self, TreeParams};
use attsync::interrupt::Interrupt;
use attsync::processes::ProcessOptions;
use attsync::run::{Engine, Judging, RunOptions};
use attsync::scenario::schema::SchemeKind;
use attsync::scenario::{self, Loaded};
use attsync::until::Until;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// A generated tree of `agents` agents (seed 1, 3 leader links) of `scheme`, loaded.
fn tree(agents: u32, scheme: SchemeKind) -> anyhow::Result<Loaded> {
    let g = generate::tree(&TreeParams {
        agents,
        leader_links: 3.min(agents),
        seed: 1,
        scheme,
        duration: None,
    })
    .map_err(anyhow::Error::msg)?;
    let text = toml::to_string(&g.scenario)?;
    Ok(scenario::load_str(Path::new("generated.toml"), &text, &[])?)
}

/// One row of the margin table: the median wall time of `reps` analyses.
fn margin_row(name: &str, loaded: &Loaded, reps: usize) -> String {
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..reps.max(1) {
        let started = Instant::now();
        let r = attsync::margin::margin(loaded);
        times.push(started.elapsed().as_secs_f64());
        last = Some(r);
    }
    let t = median(&times).unwrap_or(f64::NAN);
    match last {
        Some(Ok(r)) => {
            let j = r.json();
            format!(
                "| {name} | {} | {} | {} | {:.6} ± {:.4}i | {:.3} |",
                r.states,
                j.margin.map_or("none".into(), |m| format!("{m:.6}")),
                j.omega.map_or("-".into(), |w| format!("{w:.4}")),
                j.rightmost.re,
                j.rightmost.im,
                t
            )
        }
        Some(Err(e)) => format!("| {name} | - | refused: {} | - | - | {t:.3} |", e.reason),
        None => String::new(),
    }
}

/// The margin table.
fn margins(scenarios: &Path, reps: usize) -> anyhow::Result<String> {
    let mut s = String::from(
        "| scenario | states | margin s | ω rad/s | rightmost root 1/s | wall s (median) |\n|---|---:|---:|---:|---:|---:|\n",
    );
    for name in ["constant-observerless", "constant-observer"] {
        let loaded = scenario::load(&scenarios.join(format!("{name}.toml")), &[])?;
        let _ = writeln!(s, "{}", margin_row(name, &loaded, reps));
    }
    for (agents, scheme, label) in [
        (20, SchemeKind::Observerless, "observerless"),
        (50, SchemeKind::Observerless, "observerless"),
        (20, SchemeKind::ObserverConstant, "constant-observer"),
        (1000, SchemeKind::Observerless, "observerless"),
        (1000, SchemeKind::ObserverConstant, "constant-observer"),
    ] {
        let loaded = tree(agents, scheme)?;
        let name = format!("gen tree {agents} ({label})");
        let _ = writeln!(s, "{}", margin_row(&name, &loaded, reps));
    }
    Ok(s)
}

/// In-process options of a run into `out` with `until` (no progress, one thread).
pub(crate) fn options(out: PathBuf, until: Until) -> RunOptions {
    RunOptions {
        engine: Engine::InProcess,
        out,
        processes: ProcessOptions::default(),
        progress: false,
        threads: 1,
        view: false,
        hosts: None,
        judging: Judging {
            tolerance: 1e-3,
            until,
        },
        law: None,
    }
}

/// Wall time of one in-process run of `loaded` with `until` into `out`,
/// and the horizon it ended with.
fn timed(loaded: &Loaded, out: PathBuf, until: Until) -> anyhow::Result<(f64, f64)> {
    let started = Instant::now();
    let s = attsync::run::run(loaded, &options(out, until), &Interrupt::new())?;
    Ok((started.elapsed().as_secs_f64(), s.duration))
}

/// `--until settled` against one run of the final horizon, per delay.
fn until_settled(scenarios: &Path, work: &Path, reps: usize) -> anyhow::Result<String> {
    let mut s = String::from(
        "| delay s | final horizon s | chunks' horizons | settled wall s | one run wall s | settled ÷ one run |\n|---:|---:|---|---:|---:|---:|\n",
    );
    let file = scenarios.join("constant-observerless.toml");
    for d in [0.2, 0.35] {
        let sets = [format!("network.delay={d}")];
        let loaded = scenario::load(&file, &sets)?;
        let until = Until::Settled {
            max_duration: 640.0,
        };
        let (mut settled, mut once, mut horizon) = (Vec::new(), Vec::new(), 0.0);
        for k in 0..reps.max(1) {
            let (t, h) = timed(&loaded, work.join(format!("s{d}-{k}")), until)?;
            settled.push(t);
            horizon = h;
            let sets = [sets[0].clone(), format!("simulation.duration={h}")];
            let plain = scenario::load(&file, &sets)?;
            once.push(timed(&plain, work.join(format!("o{d}-{k}")), Until::Horizon)?.0);
        }
        let (a, b) = (
            median(&settled).unwrap_or(f64::NAN),
            median(&once).unwrap_or(f64::NAN),
        );
        let mut chain = vec![40.0];
        while chain.last().is_some_and(|&h| h < horizon) {
            chain.push((chain.last().unwrap_or(&40.0) * 2.0_f64).min(horizon));
        }
        let chain: Vec<String> = chain.iter().map(|h| format!("{h}")).collect();
        let _ = writeln!(
            s,
            "| {d} | {horizon} | {} | {a:.3} | {b:.3} | {:.3} |",
            chain.join(" → "),
            a / b
        );
    }
    Ok(s)
}

/// The report: both tables, Markdown.
///
/// # Errors
/// A scenario does not load or a run fails.
pub fn report(scenarios: &Path, reps: usize) -> anyhow::Result<String> {
    let work =
        std::env::temp_dir().join(format!("attsync-bench-conclusions-{}", std::process::id()));
    std::fs::create_dir_all(&work)?;
    let result = (|| -> anyhow::Result<String> {
        let mut s = String::from("### `attsync margin`\n\n");
        s += &margins(scenarios, reps)?;
        s += "\n### `--until settled` (in-process, scheme 3)\n\n";
        s += &until_settled(scenarios, &work, reps)?;
        Ok(s)
    })();
    let _ = std::fs::remove_dir_all(&work);
    result
}
