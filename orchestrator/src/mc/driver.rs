//! The Monte Carlo driver: validate everything first, then trials in
//! parallel over `--jobs` workers (a work queue; each trial isolated, on
//! one thread or in its own process namespace), results gathered by trial
//! index, and the files written atomically ([`monte_carlo`]); and one
//! trial alone as a normal run ([`trial_alone`]).

use super::dispersion::Dispersion;
use super::error::{McError, io_at};
use super::options::McOptions;
use super::outcome::{End, Trace, TrialResult};
use super::plot;
use super::report::{self, McSummary};
use super::trial::{Base, Prepared, Ran, run_in_process, run_processes};
use crate::interrupt::Interrupt;
use crate::options::OptionError;
use crate::pool::Flow;
use crate::processes::capacity::{self, Host, Need};
use crate::results::layout;
use crate::results::staging::Staging;
use crate::run::{Engine, RunOptions};
use crate::scenario::{ScenarioError, input};
use std::path::Path;
use std::time::Instant;

/// A finished Monte Carlo.
#[derive(Debug, Clone)]
pub struct McRun {
    /// `mc.json`.
    pub summary: McSummary,
    /// The trials that ran, by index.
    pub results: Vec<TrialResult>,
    /// Wall time of the trials, s (not in any file).
    pub wall_seconds: f64,
}

/// Loads the scenario (with `o.set`) and its `[monte_carlo]`, and checks
/// that trial 0's draws make a valid scenario; checks the engine.
///
/// # Errors
/// An invalid scenario, dispersion or option.
pub fn load_base(o: &McOptions) -> Result<Base, McError> {
    o.validate()?;
    let text = input::read_bounded(&o.scenario).map_err(|error| ScenarioError::Io {
        file: o.scenario.clone(),
        error,
    })?;
    let loaded = crate::scenario::load_str_with(&o.scenario, &text, &o.set, o.stiffness)?;
    let dispersion =
        Dispersion::resolve(&loaded.scenario).map_err(|issues| ScenarioError::Invalid {
            file: o.scenario.clone(),
            issues,
        })?;
    if o.engine == Engine::InProcess {
        if let Some(p) = loaded.resolved.plugins.first() {
            return Err(McError::Options(OptionError::Conflict(format!(
                "agent {} is a plug-in (`{}`): plug-ins need --engine processes",
                p.agent,
                p.display()
            ))));
        }
    }
    let base = Base {
        file: o.scenario.clone(),
        text,
        set: o.set.clone(),
        check: o.stiffness,
        dispersion,
        seed: o.seed,
        loaded,
    };
    base.check_params()?;
    base.prepare(0)?;
    Ok(base)
}

/// Refuses what this machine cannot run (one trial's needs; in-process,
/// `jobs` of them); logs the process engine's warnings.
fn check_capacity(base: &Base, o: &McOptions) -> Result<(), McError> {
    let need = Need::of(&base.loaded.resolved.network, o.processes.wait);
    let host = Host::read(&crate::launch::namespace::base_dir());
    match o.engine {
        Engine::Processes => {
            for warning in capacity::processes(&host, &need)? {
                tracing::warn!("{warning}");
            }
        }
        Engine::InProcess => capacity::in_process(&host, &need)?,
    }
    Ok(())
}

/// Runs the Monte Carlo `o` and writes `trials.csv`, `initial.csv`,
/// `mc.json` and `mc.svg` into `o.out` (atomically). An interrupt stops it:
/// the trials done are written (`mc.json` `complete: false`) and the error
/// names the signal.
///
/// # Errors
/// See [`McError`]; nothing runs unless every input is valid.
pub fn monte_carlo(o: &McOptions, interrupt: &Interrupt) -> Result<McRun, McError> {
    let base = load_base(o)?;
    check_capacity(&base, o)?;
    interrupt.arm();
    let staging = Staging::claim(&o.out).map_err(|e| match e {
        e if e.is_refusal() => McError::Options(OptionError::Conflict(e.to_string())),
        e => McError::Io {
            path: o.out.clone(),
            source: e.into(),
        },
    })?;
    let started = Instant::now();
    let results = run_pool(&base, o, staging.path(), interrupt)?;
    let wall_seconds = started.elapsed().as_secs_f64();
    let summary = report::summarise(head(&base, o), &results);
    let files = Files {
        header: report::trials_header(&base.dispersion),
        initial: initial_csv(&base, &results),
        planned: o.range().end - o.range().start,
    };
    files.write(staging.path(), &summary, &results)?;
    staging.commit().map_err(io_at(&o.out))?;
    if let Some(signal) = interrupt.signal() {
        return Err(McError::Interrupted(signal));
    }
    Ok(McRun {
        summary,
        results,
        wall_seconds,
    })
}

/// `mc.json` before the trials' figures.
fn head(base: &Base, o: &McOptions) -> McSummary {
    let net = &base.loaded.resolved.network;
    McSummary {
        attsync_version: env!("CARGO_PKG_VERSION").into(),
        scenario: base.loaded.name(),
        engine: o.engine.name().into(),
        seed: o.seed,
        trials: o.trials,
        trials_run: 0,
        complete: false,
        shard: o.shard.map(|s| s.of(o.trials)),
        duration: net.steps as f64 * net.dt,
        tolerance: o.judging.tolerance,
        until: match o.judging.until {
            crate::until::Until::Horizon => None,
            crate::until::Until::Settled { max_duration } => Some(max_duration),
        },
        criterion: format!(
            "the verdict on the largest |R_i R_0^T|_I over agents over the whole run \
             (docs/verdicts.md): converged = below {:e} and staying there; a failure = \
             neither converged nor converging",
            o.judging.tolerance
        ),
        dispersion: base.dispersion.clone(),
        counts: report::Counts::default(),
        failures: 0,
        failure_rate: 0.0,
        failure_rate_upper_95: 1.0,
        failure_rate_interval_95: [0.0, 1.0],
        failed_trials: Vec::new(),
        slowest: Vec::new(),
    }
}

/// Runs trial `k` with `o`'s engine (process logs under `dir/logs/trial-<k>`,
/// kept only if the trial failed).
fn one(
    base: &Base,
    o: &McOptions,
    k: u64,
    dir: &Path,
    interrupt: &Interrupt,
) -> Result<Ran, McError> {
    let p = base.prepare(k)?;
    match o.engine {
        Engine::InProcess => Ok(run_in_process(&p, (&o.judging, o.law.as_ref()), interrupt)),
        Engine::Processes => {
            let logs = layout::McLayout::new(dir).trial_logs(k);
            let ran = run_processes(&p, &o.processes, &logs, &o.judging, interrupt)
                .map_err(|source| McError::Processes { trial: k, source })?;
            let failed = matches!(&ran, Ran::Done(r) if r.outcome == super::Outcome::Failed);
            if !failed {
                let _ = std::fs::remove_dir_all(&logs);
            }
            Ok(ran)
        }
    }
}

/// Trials `o.range()` on `o.jobs` workers; the results by index (those
/// an interrupt prevented are missing). The first failed trial (by index)
/// stops the pool and is the error.
fn run_pool(
    base: &Base,
    o: &McOptions,
    dir: &Path,
    interrupt: &Interrupt,
) -> Result<Vec<TrialResult>, McError> {
    let trials = o.range();
    let bar = crate::progress::of_jobs(o.progress, trials.end - trials.start, "trials");
    let ran = crate::pool::run(
        (trials.end - trials.start) as usize,
        o.jobs,
        || interrupt.is_set(),
        |k| match one(base, o, trials.start + k as u64, dir, interrupt) {
            Ok(Ran::Done(r)) => {
                bar.inc(1);
                Flow::Next(Ok(r))
            }
            Ok(Ran::Interrupted) => Flow::Stop(None),
            Err(e) => Flow::Stop(Some(Err(e))),
        },
    );
    bar.finish_and_clear();
    ran.into_iter().flatten().collect()
}

/// `initial.csv` of `results`: their draws, recomputed from each trial's seed.
fn initial_csv(base: &Base, results: &[TrialResult]) -> String {
    let ids: Vec<u32> = (base.loaded.scenario.agents.iter()).map(|a| a.id).collect();
    let mut initial = format!("{}\n", report::INITIAL_HEADER);
    for r in results {
        let draws = super::draws::draw(&base.dispersion, &mut super::trial_rng(r.seed));
        report::initial_rows(&mut initial, r.trial, &ids, &base.dispersion, &draws);
    }
    initial
}

/// What a Monte Carlo's directory holds besides `mc.json`, made ready
/// (by a run or by [`mod@super::merge`]).
pub(super) struct Files {
    /// `trials.csv`'s header.
    pub header: String,
    /// `initial.csv`, whole.
    pub initial: String,
    /// The trials planned (all, or a shard's): `complete` when all ran.
    pub planned: u64,
}

impl Files {
    /// Writes `trials.csv`, `initial.csv`, `mc.svg`, then `mc.json` into `dir`.
    pub(super) fn write(
        &self,
        dir: &Path,
        s: &McSummary,
        results: &[TrialResult],
    ) -> Result<(), McError> {
        let files = layout::McLayout::new(dir);
        let write = |path: std::path::PathBuf, text: &str| {
            std::fs::write(&path, text).map_err(io_at(&path))
        };
        write(
            files.trials(),
            &report::trials_csv_under(&self.header, results),
        )?;
        write(files.initial(), &self.initial)?;
        let svg = files.svg();
        let title = format!("{}: {} trials, seed {}", s.scenario, s.trials_run, s.seed);
        plot::draw(&svg, &title, results).map_err(|crate::results::plot::PlotError(message)| {
            McError::Plot {
                path: svg.clone(),
                message,
            }
        })?;
        let mut s = s.clone();
        s.complete = s.trials_run == self.planned;
        let json = serde_json::to_string_pretty(&s).expect("json") + "\n";
        write(files.json(), &json)
    }
}

/// One trial run alone as a normal run.
#[derive(Debug, Clone)]
pub struct Alone {
    /// The trial (its draws and overrides).
    pub prepared: Prepared,
    /// The run's `summary.json`.
    pub summary: crate::results::Summary,
    /// The trial's `trials.csv` row, computed from the run's `errors.csv`.
    pub result: TrialResult,
    /// The header of that row ([`report::trials_header`]).
    pub header: String,
    /// The `attsync run …` command line that reproduces it.
    pub command: String,
}

/// Runs trial `k` of `o` alone as a normal run into `out` (`errors.csv`,
/// `summary.json`, … as `attsync run` writes them) and computes its
/// `trials.csv` row from them.
///
/// # Errors
/// See [`McError`]; a run that an interrupt stopped is [`McError::Interrupted`].
pub fn trial_alone(
    o: &McOptions,
    k: u64,
    out: &Path,
    interrupt: &Interrupt,
) -> Result<Alone, McError> {
    let base = load_base(o)?;
    let prepared = base.prepare(k)?;
    let opts = RunOptions {
        engine: o.engine,
        out: out.to_owned(),
        processes: o.processes.clone(),
        progress: o.progress,
        threads: 1,
        view: true,
        hosts: None,
        judging: o.judging,
        law: o.law.clone(),
    };
    let summary = crate::run::run(&prepared.loaded, &opts, interrupt)?;
    if let Some(signal) = interrupt.signal() {
        return Err(McError::Interrupted(signal));
    }
    let trace = trace_of_run(out, &base)?;
    let end = match (&summary.diverged, &summary.incomplete_reason) {
        (Some(d), Some(why)) => End::Diverged(d.t, why.to_string()),
        (_, Some(why)) => End::Failed(why.clone()),
        _ => End::Complete,
    };
    let result = prepared.classify(end, &trace, &o.judging);
    let command = run_command(o, &prepared);
    Ok(Alone {
        prepared,
        summary,
        result,
        header: report::trials_header(&base.dispersion),
        command,
    })
}

/// The trace of a run from its `states.bin` (the numbers a trial records).
fn trace_of_run(out: &Path, base: &Base) -> Result<Trace, McError> {
    let file = crate::results::RunLayout::new(out).states();
    let records = crate::results::states::open(&file)?;
    let net = &base.loaded.resolved.network;
    let mut trace = Trace::new(net, false);
    let mut agents = Vec::with_capacity(net.agents.len());
    for rec in records {
        let rec = rec?;
        agents.clear();
        agents.extend(
            rec.agents
                .iter()
                .map(crate::results::states::AgentRecord::state),
        );
        trace.record(&attitude::engine::Snapshot {
            step: rec.step,
            leader: &rec.leader.state(),
            agents: &agents,
            torques: &rec.torques(),
        });
    }
    Ok(trace)
}

/// `attsync run SCENARIO --engine E [--no-stiffness-check] --set …` (the
/// user's overrides, then the trial's; quoted for a POSIX shell).
#[must_use]
pub fn run_command(o: &McOptions, p: &Prepared) -> String {
    let mut c = format!(
        "attsync run {} --engine {}",
        super::draws::shell_quote(&o.scenario.display().to_string()),
        o.engine.name()
    );
    if o.stiffness == crate::scenario::StiffnessCheck::Warn {
        c += " --no-stiffness-check";
    }
    for s in o.set.iter().chain(&p.overrides) {
        c += " --set ";
        c += &super::draws::shell_quote(s);
    }
    c
}
