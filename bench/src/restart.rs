//! `attsync-bench restart` (issue 35): what a crash and restart costs in the
//! process engine. The paper's observerless run, plain and with `k` crashes
//! and restarts of agent 3 (each down 1 s), repetitions interleaved; the
//! cost of one restart is the difference of the medians' wall times over
//! `k`, beside the handover the run itself reports (`summary.json`
//! `restarts[].handover_ms`: from the crash's report to the new process's
//! `Ready`).

use crate::stats::median;
use attsync::interrupt::Interrupt;
use attsync::run::{Engine, RunOptions};
use attsync::scenario;
use attsync::until::Until;
use std::fmt::Write as _;
use std::path::Path;

/// `[[event]]`s crashing agent 3 at 2, 5, 8, … s, each restarted 1 s later.
fn crashes(k: usize) -> String {
    (0..k)
        .map(|i| {
            let t = 2.0 + 3.0 * i as f64;
            format!(
                "\n[[event]]\nt = {t}\nagent = 3\naction = \"crash\"\n\n\
                 [[event]]\nt = {}\nagent = 3\naction = \"restart\"\n",
                t + 1.0
            )
        })
        .collect()
}

/// One processes run of `text` into `out`: (wall s, handovers ms).
fn timed(text: &str, out: &Path, duration: f64) -> anyhow::Result<(f64, Vec<f64>)> {
    let sets = [format!("simulation.duration={duration}")];
    let loaded = scenario::load_str(Path::new("restart.toml"), text, &sets)?;
    let opts = RunOptions {
        engine: Engine::Processes,
        ..crate::conclusions::options(out.to_owned(), Until::Horizon)
    };
    let s = attsync::run::run(&loaded, &opts, &Interrupt::new())?;
    anyhow::ensure!(s.complete, "the run did not complete");
    let handovers = s.restarts.iter().filter_map(|r| r.handover_ms).collect();
    Ok((s.wall_seconds, handovers))
}

/// The report: a Markdown table.
///
/// # Errors
/// The scenario does not load or a run fails.
pub fn report(
    scenarios: &Path,
    reps: usize,
    duration: f64,
    restarts: usize,
) -> anyhow::Result<String> {
    let base = std::fs::read_to_string(scenarios.join("constant-observerless.toml"))?;
    let work = std::env::temp_dir().join(format!("attsync-bench-restart-{}", std::process::id()));
    let with = base.clone() + &crashes(restarts);
    let result = (|| -> anyhow::Result<String> {
        let (mut plain, mut crashed, mut handovers) = (Vec::new(), Vec::new(), Vec::new());
        for k in 0..reps.max(1) {
            plain.push(timed(&base, &work.join(format!("p{k}")), duration)?.0);
            let (t, h) = timed(&with, &work.join(format!("c{k}")), duration)?;
            crashed.push(t);
            handovers.extend(h);
        }
        let (a, b) = (
            median(&plain).unwrap_or(f64::NAN),
            median(&crashed).unwrap_or(f64::NAN),
        );
        let h = median(&handovers).unwrap_or(f64::NAN);
        let hmax = handovers.iter().copied().fold(f64::NAN, f64::max);
        let mut s = String::from(
            "| run | wall s (median) | per restart, ms | handover ms (median, max) |\n|---|---:|---:|---:|\n",
        );
        let _ = writeln!(s, "| paper observerless, {duration} s | {a:.3} | | |");
        let _ = writeln!(
            s,
            "| with {restarts} crash + restart of agent 3 | {b:.3} | {:.1} | {h:.1}, {hmax:.1} |",
            (b - a) / restarts.max(1) as f64 * 1e3
        );
        Ok(s)
    })();
    let _ = std::fs::remove_dir_all(&work);
    result
}
