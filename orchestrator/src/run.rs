//! `attsync run`: a loaded scenario through an engine into a results
//! directory.

use crate::failure::Failure;
use crate::hosts::{Hosts, HostsError, Placement};
use crate::interrupt::Interrupt;
use crate::options::{self, OptionError};
use crate::outcome::Outcome;
use crate::processes::capacity::{self, CapacityError, Host, Need};
use crate::processes::{self, ProcessError, ProcessOptions};
use crate::results::layout::RunLayout;
use crate::results::manifest::{Manifest, Seeds};
use crate::results::summary::{Diverged, LinkSummary, NodeSummary};
use crate::results::{self, Recorder, Series, Summary, WriteError, plot, staging::Staging};
use crate::scenario::Loaded;
pub use crate::until::Judging;
use crate::until::{self, Stopped, Until, UntilSummary};
use crate::view;
use attitude::engine::InProcess;
use indicatif::ProgressBar;
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};
use thiserror::Error;

/// Which engine runs the network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Engine {
    /// One OS process per node (leader and agents), iceoryx2 in lockstep.
    Processes,
    /// Every node in the orchestrator's process, in lockstep.
    InProcess,
}

impl Engine {
    /// Name as written on the command line and in `summary.json`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Engine::Processes => "processes",
            Engine::InProcess => "in-process",
        }
    }
}

/// Options of one run.
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Engine.
    pub engine: Engine,
    /// Results directory.
    pub out: PathBuf,
    /// Process-engine options.
    pub processes: ProcessOptions,
    /// Draw a progress bar on stderr (it also hides itself when stderr is not a terminal).
    pub progress: bool,
    /// In-process engine: threads to step the agents on (≥ 1; a small
    /// network uses fewer, see [`InProcess::with_threads`]; [`default_threads`]).
    pub threads: usize,
    /// Write `view.html` (`attsync run`, unless `--no-view`; not in a
    /// sweep's runs: one page per value would be most of the sweep's size).
    pub view: bool,
    /// `--hosts`: the machines the nodes are spread over (`None`: all on
    /// this one). Placed on the scenario before anything starts.
    pub hosts: Option<Hosts>,
    /// `--tolerance` and `--until`: what the run is judged by and how long it goes.
    pub judging: Judging,
    /// A control law from outside in place of the scheme's (the Python
    /// package's `law=`; [`attitude::law`]): in-process, on one thread.
    pub law: Option<attitude::law::SharedLaw>,
}

/// The default `--threads`: the number of cores (1 if unknown).
#[must_use]
pub fn default_threads() -> usize {
    std::thread::available_parallelism().map_or(1, std::num::NonZero::get)
}

impl RunOptions {
    /// Checks the options that do not depend on the scenario
    /// (`--stage-timeout`, `--realtime`, `--threads`; limits in [`crate::options`]).
    ///
    /// # Errors
    /// The first option out of its range.
    pub fn validate(&self) -> Result<(), OptionError> {
        options::seconds("--stage-timeout", self.processes.stage_timeout)?;
        options::seconds("--start-timeout", self.processes.start_timeout)?;
        options::threads(self.threads)?;
        self.judging.validate()?;
        if let Some(f) = self.processes.realtime {
            options::realtime(f)?;
        }
        if self.hosts.is_some() && self.engine == Engine::InProcess {
            return Err(OptionError::Conflict(
                "--hosts needs --engine processes (the in-process engine runs every node in this process)"
                    .into(),
            ));
        }
        Ok(())
    }
}

/// The default results directory: `results/<scenario name>`.
#[must_use]
pub fn default_out(loaded: &Loaded) -> PathBuf {
    crate::results::layout::default_run_dir(&loaded.name())
}

/// Why a run produced no results.
#[derive(Debug, Error)]
pub enum RunError {
    /// Writing results failed.
    #[error("{path}: {source}")]
    Io {
        /// File or directory concerned.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// The process engine could not start.
    #[error(transparent)]
    Processes(#[from] ProcessError),
    /// The options are out of range or do not fit the scenario.
    #[error(transparent)]
    Options(#[from] OptionError),
    /// This machine cannot run the scenario with the chosen engine (nothing started).
    #[error(transparent)]
    Capacity(Box<CapacityError>),
    /// Writing `view.html` failed.
    #[error(transparent)]
    View(#[from] crate::view::ViewError),
    /// The hosts file does not fit the scenario (nothing started).
    #[error(transparent)]
    Hosts(#[from] HostsError),
    /// Drawing the plot failed.
    #[error("{path}: cannot draw plot: {message}")]
    Plot {
        /// The plot file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

impl RunError {
    /// The process exit code ([`crate::error`]'s table): 2 for options,
    /// hosts or a capacity refused before anything started, else 1.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            RunError::Options(_) | RunError::Capacity(_) | RunError::Hosts(_) => {
                crate::exit::INVALID
            }
            _ => crate::exit::FAILED,
        }
    }
}

impl From<CapacityError> for RunError {
    fn from(e: CapacityError) -> Self {
        RunError::Capacity(Box::new(e))
    }
}

fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_owned(),
        source,
    }
}

/// Runs `loaded` and writes its results to `opts.out` (atomically). Stops
/// early, keeping the results so far marked incomplete (the reason names
/// the signal, [`crate::interrupt::reason`]), when `interrupt` is raised.
pub fn run(loaded: &Loaded, opts: &RunOptions, interrupt: &Interrupt) -> Result<Summary, RunError> {
    let started_at = SystemTime::now();
    opts.validate()?;
    check_options(loaded, opts)?;
    plan(loaded, opts)?;
    check_capacity(loaded, opts)?;
    interrupt.arm();
    let staging = Staging::claim(&opts.out).map_err(|e| match e {
        // A foreign or busy --out: refused before anything started (exit 2).
        e if e.is_refusal() => RunError::Options(OptionError::Conflict(e.to_string())),
        e => io_at(&opts.out)(e.into()),
    })?;
    tracing::debug!(staging = %staging.path().display(), engine = opts.engine.name(), "run: staged");
    let layout = RunLayout::new(staging.path());
    let text = toml::to_string(&loaded.document).expect("a TOML table serialises");
    std::fs::write(layout.scenario(), &text).map_err(io_at(&layout.scenario()))?;
    let started = Instant::now();
    let driven = drive(loaded, opts, &layout, interrupt)?;
    let wall_seconds = started.elapsed().as_secs_f64();
    let text = final_scenario(loaded, &layout, &driven.judged)?.unwrap_or(text);
    let Driven {
        outcome,
        series,
        threads,
        frames,
        judged,
    } = driven;
    let mut summary = summarise(loaded, opts, outcome, &series, judged, wall_seconds);
    summary.threads = threads;
    if let Some(frames) = frames {
        let data = view::view_data(&loaded.resolved.network, view::run_info(&summary), frames);
        view::write(&layout.view(), &data)?;
    }
    let torque_plot = loaded.scenario.output.torque_plot;
    write_results(&layout, &summary, (&series, torque_plot))?;
    (manifest(loaded, opts, &summary, &text, started_at).write(&layout)).map_err(written)?;
    staging.commit().map_err(io_at(&opts.out))?;
    tracing::debug!(out = %opts.out.display(), complete = summary.complete, "run: committed");
    Ok(summary)
}

/// The results of a run `--until settled` extended are those of its
/// scenario run to the final horizon: `scenario.toml` (what `verify`
/// re-runs) says so. Its new text, if it changed.
fn final_scenario(
    loaded: &Loaded,
    layout: &RunLayout,
    judged: &Judged,
) -> Result<Option<String>, RunError> {
    let net = &loaded.resolved.network;
    if judged.until.is_none() || judged.horizon == net.steps {
        return Ok(None);
    }
    let t = crate::results::fmt_time(judged.horizon, net.dt);
    let document = loaded.document.with_set(format!("simulation.duration={t}"));
    let text = toml::to_string(&document).expect("a TOML table serialises");
    std::fs::write(layout.scenario(), &text).map_err(io_at(&layout.scenario()))?;
    tracing::debug!(duration = %t, "run: scenario.toml at the final horizon");
    Ok(Some(text))
}

/// What [`drive`] recorded: how the run ended, the series, the in-process
/// engine's thread count, the frames of `view.html` (if asked for), and
/// how it was judged.
struct Driven {
    outcome: Outcome,
    series: Vec<Series>,
    threads: Option<usize>,
    frames: Option<view::Frames>,
    judged: Judged,
}

/// The verdict on a run and the horizon it ended with.
struct Judged {
    verdict: attsync_verdict::Verdict,
    /// The horizon, steps (the scenario's unless `--until settled` extended it).
    horizon: u64,
    /// `--until settled`: how it went.
    until: Option<UntilSummary>,
}

/// `--hosts` placed on the scenario's network (checked before anything
/// starts): the hosts and their nodes, or `None` for a run on this machine.
fn plan(loaded: &Loaded, opts: &RunOptions) -> Result<Option<crate::remote::Plan>, RunError> {
    let Some(hosts) = &opts.hosts else {
        return Ok(None);
    };
    let placement = Placement::of(hosts, &loaded.resolved.network)?;
    tracing::debug!(cut_edges = placement.cut_edges().len(), "run: placed");
    let security = hosts.settled(None)?;
    Ok(Some(crate::remote::Plan::of(&placement, security)))
}

/// Where the snapshots of one attempt go: `errors.csv`, `states.bin`, the
/// series, the view's frames and the progress bar.
struct Recording<'a> {
    recorder: Recorder,
    frames: Option<view::Collector>,
    bar: &'a ProgressBar,
    write_error: Option<WriteError>,
}

impl<'a> Recording<'a> {
    /// Starts the files of a run of `net` in `layout` (again: truncated).
    fn start(
        loaded: &Loaded,
        opts: &RunOptions,
        layout: &RunLayout,
        bar: &'a ProgressBar,
    ) -> Result<Self, RunError> {
        let net = &loaded.resolved.network;
        let recorder = Recorder::new(layout.root(), &loaded.name(), net).map_err(written)?;
        Ok(Self {
            recorder,
            frames: opts.view.then(|| view::Collector::new(net)),
            bar,
            write_error: None,
        })
    }

    /// Records one snapshot; `false` (stop) once a file cannot be written.
    fn record(&mut self, snap: &attitude::engine::Snapshot<'_>, rows: &[results::Row]) -> bool {
        if let Err(e) = self.recorder.record_rows(snap, rows) {
            self.write_error = Some(e);
            return false;
        }
        if let Some(f) = self.frames.as_mut() {
            f.push(snap);
        }
        self.bar.set_position(snap.step);
        true
    }

    /// Flushes the files: the series and the frames.
    fn finish(self) -> Result<(Vec<Series>, Option<view::Frames>), RunError> {
        if let Some(e) = self.write_error {
            return Err(written(e));
        }
        let series = self.recorder.finish().map_err(written)?;
        Ok((series, self.frames.map(view::Collector::finish)))
    }
}

/// Runs the engine, recording every snapshot into `layout` (and the view's
/// frames), for as long as `opts.judging` says: how it ended (its failure
/// naming the signal if interrupted), the recorded series, the in-process
/// engine's thread count and the verdict.
fn drive(
    loaded: &Loaded,
    opts: &RunOptions,
    layout: &RunLayout,
    interrupt: &Interrupt,
) -> Result<Driven, RunError> {
    let net = &loaded.resolved.network;
    let bar = crate::progress::of_steps(opts.progress, net.steps, net.dt);
    let driven = match opts.engine {
        Engine::InProcess => drive_in_process(loaded, opts, layout, interrupt, &bar)?,
        Engine::Processes => drive_processes(loaded, opts, layout, interrupt, &bar)?,
    };
    bar.finish_and_clear();
    // A diverged run says where, whichever engine ran it. An engine
    // stopped by the interrupt says "interrupted": say which signal.
    let outcome = driven.outcome;
    let failure = match &outcome.diverged {
        Some(d) => Some(Failure::Diverged(Some(
            d.message(net, loaded.resolved.stiffness.as_ref()),
        ))),
        None if interrupt.is_set() => {
            (outcome.failure).map(|f| f.with_signal(interrupted_signal(interrupt)))
        }
        None => outcome.failure,
    };
    let outcome = Outcome { failure, ..outcome };
    Ok(Driven { outcome, ..driven })
}

/// The in-process engine, its horizon extended in chunks while
/// `--until settled` asks for it ([`InProcess::extend_to`]).
fn drive_in_process(
    loaded: &Loaded,
    opts: &RunOptions,
    layout: &RunLayout,
    interrupt: &Interrupt,
    bar: &ProgressBar,
) -> Result<Driven, RunError> {
    let net = &loaded.resolved.network;
    let mut rec = Recording::start(loaded, opts, layout, bar)?;
    let row = rec.recorder.row_maker();
    let mut engine = InProcess::new(net).with_threads(opts.threads);
    if let Some(law) = &opts.law {
        engine = engine.with_law(law.clone());
    }
    let max = opts.judging.max_steps(net.steps, net.dt);
    let (mut chunks, mut interrupted) = (0, false);
    let (diverged, verdict) = loop {
        chunks += 1;
        // Each agent's row is made by the thread that steps it; the
        // interrupt is asked every step (samples may be far apart).
        let diverged = engine.run_until(
            &row,
            |snap, rows| {
                interrupted = interrupt.is_set();
                !interrupted && rec.record(snap, rows)
            },
            || interrupt.is_set(),
        );
        let verdict = opts.judging.verdict(rec.recorder.series());
        let stopped = diverged.is_some() || engine.step_index() < engine.horizon();
        if stopped || !until::goes_on(verdict.kind) || engine.horizon() >= max {
            break (diverged, verdict);
        }
        engine.extend_to(until::next_horizon(engine.horizon(), max, net.sample_every));
        // The former last sample had no torques (no step followed it): now one does.
        let step = engine.step_index();
        if let Some(torques) = engine.begin_step() {
            rec.recorder.amend_torques(step, torques);
        }
        bar.set_length(engine.horizon());
    };
    let stopped = diverged.is_none() && engine.step_index() < engine.horizon();
    let interrupted = interrupted || (stopped && interrupt.is_set());
    let ended = diverged.is_some() || interrupted;
    let outcome = Outcome::in_process(&engine, interrupted, diverged);
    let horizon = engine.horizon();
    let (series, frames) = rec.finish()?;
    let judged = judged(loaded, opts, verdict, horizon, chunks, ended, &outcome);
    Ok(Driven {
        outcome,
        series,
        threads: Some(engine.threads()),
        frames,
        judged,
    })
}

/// The processes engine: its nodes are started for a fixed horizon, so
/// `--until settled` first finds the final horizon in-process
/// ([`until::settled_horizon`]), or, with plug-ins, runs again from t = 0
/// with the next horizon while the verdict is not final.
fn drive_processes(
    loaded: &Loaded,
    opts: &RunOptions,
    layout: &RunLayout,
    interrupt: &Interrupt,
    bar: &ProgressBar,
) -> Result<Driven, RunError> {
    let mut net = loaded.resolved.network.clone();
    let max = opts.judging.max_steps(net.steps, net.dt);
    let mut process_opts = opts.processes.clone();
    process_opts.plugins = loaded.resolved.plugins.clone();
    process_opts.hosts = plan(loaded, opts)?.map(|p| std::sync::Arc::new(p) as _);
    let mut chunks = 0;
    // Without plug-ins the in-process engine finds the final horizon
    // (bit-identical lockstep): the processes run once, to it.
    let probe = matches!(opts.judging.until, Until::Settled { .. })
        && loaded.resolved.plugins.is_empty()
        && opts.processes.realtime.is_none();
    if probe && let Some((horizon, probed)) = until::settled_horizon(&net, &opts.judging, interrupt)
    {
        net.steps = horizon;
        bar.set_length(horizon);
        chunks = probed - 1;
    }
    loop {
        chunks += 1;
        let mut rec = Recording::start(loaded, opts, layout, bar)?;
        let row = rec.recorder.row_maker();
        let record =
            |snap: &attitude::engine::Snapshot<'_>| rec.record(snap, &results::rows_of(&row, snap));
        let outcome = processes::run(
            &net,
            &process_opts,
            &layout.logs(),
            interrupt.flag(),
            record,
        )?;
        let (series, frames) = rec.finish()?;
        let verdict = opts.judging.verdict(&series);
        let ended = outcome.diverged.is_some() || outcome.failure.is_some();
        if ended || !until::goes_on(verdict.kind) || net.steps >= max {
            let judged = judged(loaded, opts, verdict, net.steps, chunks, ended, &outcome);
            return Ok(Driven {
                outcome,
                series,
                threads: None,
                frames,
                judged,
            });
        }
        net.steps = until::next_horizon(net.steps, max, net.sample_every);
        bar.set_length(net.steps);
        bar.set_position(0);
    }
}

/// The verdict of a run that ended at `horizon` after `chunks` chunks
/// (`ended`: diverged, failed or interrupted), and the `until` record of
/// an `--until settled` run.
fn judged(
    loaded: &Loaded,
    opts: &RunOptions,
    verdict: attsync_verdict::Verdict,
    horizon: u64,
    chunks: u32,
    ended: bool,
    outcome: &Outcome,
) -> Judged {
    let net = &loaded.resolved.network;
    let verdict = match &outcome.diverged {
        Some(d) => attsync_verdict::diverged(d.step as f64 * net.dt, opts.judging.tolerance),
        None => verdict,
    };
    let until = match opts.judging.until {
        Until::Horizon => None,
        Until::Settled { max_duration } => Some(UntilSummary {
            rule: "settled".into(),
            scenario_duration: net.steps as f64 * net.dt,
            max_duration,
            duration: horizon as f64 * net.dt,
            chunks,
            stopped: if ended {
                Stopped::RunEnded
            } else if until::goes_on(verdict.kind) {
                Stopped::MaxDuration
            } else {
                Stopped::VerdictFinal
            },
        }),
    };
    Judged {
        verdict,
        horizon,
        until,
    }
}

/// `summary.json` of a run that ended as `outcome` with `series` recorded.
fn summarise(
    loaded: &Loaded,
    opts: &RunOptions,
    outcome: Outcome,
    series: &[Series],
    judged: Judged,
    wall_seconds: f64,
) -> Summary {
    let net = &loaded.resolved.network;
    let horizon = judged.horizon;
    let mut agents = results::agent_summaries(series, &outcome.peak_torques);
    for (a, p) in agents.iter_mut().zip(&outcome.pacing) {
        if opts.processes.realtime.is_some() {
            (a.late_stages, a.max_lateness) = (Some(p.0), Some(p.1));
        }
    }
    for a in &mut agents {
        let plugins = &loaded.resolved.plugins;
        a.plugin = plugins
            .iter()
            .find(|p| p.agent == a.id)
            .map(|p| p.display());
    }
    let steps = outcome.steps;
    Summary {
        attsync_version: env!("CARGO_PKG_VERSION").into(),
        scenario: loaded.name(),
        overrides: loaded.document.sets().to_vec(),
        engine: opts.engine.name().into(),
        law: loaded.scenario.scheme.law,
        complete: outcome.failure.is_none() && outcome.diverged.is_none() && steps == horizon,
        incomplete_reason: outcome.failure,
        diverged: outcome.diverged.map(|d| Diverged::of(&d, net.dt)),
        dt: net.dt,
        duration: horizon as f64 * net.dt,
        t_end: steps as f64 * net.dt,
        steps,
        wall_seconds,
        max_final_att_err: agents.iter().map(|a| a.final_att_err).fold(0.0, f64::max),
        agents,
        links: (outcome.links.iter())
            .map(|(from, to, st)| LinkSummary::of(*from, *to, st))
            .collect(),
        realtime: opts.processes.realtime,
        nodes: (outcome.nodes.iter())
            .map(|(name, id, d)| NodeSummary::of(*id, name, d))
            .collect(),
        restarts: outcome.restarts.clone(),
        threads: None,
        verdict: Some(judged.verdict),
        until: judged.until,
        hosts: opts.hosts.as_ref().and_then(hosts_summary),
        outside_theory: (loaded.resolved.outside_theory.iter())
            .map(ToString::to_string)
            .collect(),
        events: loaded.resolved.events.clone(),
        unreachable: loaded.resolved.isolated.clone(),
    }
}

/// `summary.json`'s `hosts` of a run across `hosts` (its security settled).
fn hosts_summary(hosts: &Hosts) -> Option<results::summary::HostsSummary> {
    let names = hosts.hosts.iter().map(|h| h.name.clone()).collect();
    let security = hosts.settled(None).ok()?;
    Some(results::summary::HostsSummary::of(names, &security))
}

/// Writes the plot (with the torque panel if `torque_plot`: the scenario's
/// `[output] torque_plot`), then `summary.json` (last: it marks the
/// directory as complete results).
fn write_results(
    layout: &RunLayout,
    summary: &Summary,
    (series, torque_plot): (&[Series], bool),
) -> Result<(), RunError> {
    let svg = layout.errors_svg();
    let title = plot::title(summary);
    // Real-time runs measure every link's age of information; lockstep
    // links are ideal (or impaired by design, which summary.json lists).
    let aoi = if summary.realtime.is_some() {
        &summary.links[..]
    } else {
        &[]
    };
    let marks: Vec<plot::Mark> = (summary.events.iter())
        .map(|e| plot::Mark {
            t: e.t,
            label: e.what.to_string(),
        })
        .collect();
    let drawn = plot::draw(&svg, &title, series, aoi, &marks, torque_plot);
    drawn.map_err(|plot::PlotError(message)| RunError::Plot {
        path: svg.clone(),
        message,
    })?;
    results::write_summary(layout.root(), summary).map_err(written)
}

/// `manifest.json` of a run of `loaded` with `opts` that wrote `summary`
/// (`scenario_text`: its `scenario.toml`; files listed when it is written).
fn manifest(
    loaded: &Loaded,
    opts: &RunOptions,
    summary: &Summary,
    scenario_text: &str,
    started: SystemTime,
) -> Manifest {
    use clap::ValueEnum;
    let p = &opts.processes;
    let processes = opts.engine == Engine::Processes;
    let placement = p.placement.to_possible_value();
    Manifest {
        scenario: summary.scenario.clone(),
        scenario_file: std::path::absolute(&loaded.file).unwrap_or_else(|_| loaded.file.clone()),
        scenario_sha256: results::digest::sha256_hex(scenario_text.as_bytes()),
        seeds: Seeds::of(loaded.scenario.network.seed, &loaded.resolved.network),
        engine: opts.engine.name().into(),
        wait: processes.then_some(p.wait),
        placement: placement.filter(|_| processes).map(|v| v.get_name().into()),
        threads: summary.threads,
        stage_timeout: p.stage_timeout,
        realtime: p.realtime,
        complete: summary.complete,
        incomplete_reason: (summary.incomplete_reason.as_ref()).map(ToString::to_string),
        diverged: summary.diverged.is_some(),
        outside_theory: summary.outside_theory.clone(),
        ..Manifest::now(started)
    }
}

/// A results file that could not be written, as a [`RunError::Io`] naming it.
fn written(e: WriteError) -> RunError {
    RunError::Io {
        path: e.path,
        source: e.source,
    }
}

/// The signal named in `incomplete_reason` of an interrupted run.
fn interrupted_signal(interrupt: &Interrupt) -> i32 {
    interrupt.signal().unwrap_or(signal_hook::consts::SIGINT)
}

/// How a run that produced results ended, as an error if it did not
/// complete: the signal that interrupted it, or why it failed.
///
/// # Errors
/// [`RunEnd::Interrupted`] or [`RunEnd::Failed`].
pub fn verdict(summary: &Summary, interrupt: &Interrupt) -> Result<(), RunEnd> {
    match (&summary.incomplete_reason, interrupt.signal()) {
        (None, _) => Ok(()),
        (Some(f), _) if summary.diverged.is_some() => Err(RunEnd::Diverged(f.clone())),
        (Some(_), Some(signal)) => Err(RunEnd::Interrupted(signal)),
        (Some(f), None) => Err(RunEnd::Failed(f.clone())),
    }
}

/// A run that wrote its results but did not complete.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RunEnd {
    /// A signal stopped it (the number).
    #[error("{}", crate::interrupt::reason(*.0))]
    Interrupted(i32),
    /// It failed: a node died, stalled or broke the protocol (the reason
    /// in `summary.json`).
    #[error("the run failed: {0}")]
    Failed(Failure),
    /// A state left the envelope (`summary.json` `diverged`; the message
    /// names the time, the node, the quantity and its value).
    #[error("the run {0}")]
    Diverged(Failure),
}

impl RunEnd {
    /// The process exit code ([`crate::error`]'s table): 128 + N for
    /// signal N, 3 diverged, 1 failed.
    #[must_use]
    pub fn exit_code(&self) -> u8 {
        match self {
            RunEnd::Interrupted(signal) => crate::interrupt::exit_code(*signal),
            RunEnd::Diverged(_) => crate::exit::DIVERGED,
            RunEnd::Failed(f) => f.exit_code(),
        }
    }
}

/// Options that the scenario cannot run with.
fn check_options(loaded: &Loaded, opts: &RunOptions) -> Result<(), OptionError> {
    let plugins = &loaded.resolved.plugins;
    let crashes = (loaded.resolved.network.agents.iter())
        .any(|a| (a.model.timeline.as_deref()).is_some_and(|t| !t.crashes.is_empty()));
    if opts.law.is_some() && opts.engine != Engine::InProcess {
        return Err(OptionError::Conflict(
            "a control law given from outside (law=) runs in-process only".into(),
        ));
    }
    if crashes && (opts.processes.realtime.is_some() || opts.hosts.is_some()) {
        return Err(OptionError::Conflict(
            "a crash ([[event]] action = \"crash\") cannot run with --realtime or --hosts: \
             the orchestrator replaces a crashed process at a lockstep step on this machine"
                .into(),
        ));
    }
    if opts.engine == Engine::InProcess {
        if let Some(p) = plugins.first() {
            return Err(OptionError::Conflict(format!(
                "agent {} is a plug-in (`{}`): plug-ins need --engine processes",
                p.agent,
                p.display()
            )));
        }
        if opts.processes.realtime.is_some() {
            return Err(OptionError::Conflict(
                "--realtime needs --engine processes (the in-process engine is lockstep only)"
                    .into(),
            ));
        }
    }
    if opts.processes.realtime.is_some() {
        let net = &loaded.resolved.network;
        let impaired = net.agents.iter().any(|a| {
            a.model
                .neighbours
                .iter()
                .filter_map(|n| n.link)
                .chain(a.model.leader_link)
                .any(|l| l.is_impaired())
        });
        if impaired {
            return Err(OptionError::Conflict(
                "--realtime cannot be combined with [network] impairments: they are defined in \
                 simulated lockstep time; in real-time mode the transport's own latency is measured"
                    .into(),
            ));
        }
    }
    Ok(())
}

/// Refuses a run this machine cannot take with the chosen engine (before
/// the results directory is claimed, so nothing is left behind); logs the
/// process engine's warnings.
fn check_capacity(loaded: &Loaded, opts: &RunOptions) -> Result<(), CapacityError> {
    let need = Need::of(&loaded.resolved.network, opts.processes.wait);
    let host = Host::read(&crate::launch::namespace::base_dir());
    match opts.engine {
        Engine::Processes => {
            for warning in capacity::processes(&host, &need)? {
                tracing::warn!("{warning}");
            }
            Ok(())
        }
        Engine::InProcess => capacity::in_process(&host, &need),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn options(out: PathBuf) -> RunOptions {
        RunOptions {
            engine: Engine::InProcess,
            out,
            processes: ProcessOptions::default(),
            progress: false,
            threads: 1,
            view: false,
            hosts: None,
            judging: Judging::default(),
            law: None,
        }
    }

    #[test]
    fn stage_timeout_and_realtime_are_checked() {
        assert_eq!(options(PathBuf::new()).validate(), Ok(()));
        for t in [f64::NAN, f64::INFINITY, -1.0, 0.0, 1e300] {
            let mut o = options(PathBuf::new());
            o.processes.stage_timeout = t;
            let e = o.validate().unwrap_err();
            assert!(e.to_string().starts_with("--stage-timeout"), "{e}");
        }
        for f in [f64::NAN, f64::INFINITY, -1.0, 0.0, 1e300] {
            let mut o = options(PathBuf::new());
            o.processes.realtime = Some(f);
            let e = o.validate().unwrap_err();
            assert!(e.to_string().starts_with("--realtime"), "{e}");
        }
        let mut o = options(PathBuf::new());
        o.threads = 0;
        let e = o.validate().unwrap_err();
        assert_eq!(e.to_string(), "--threads 0: must be at least 1");
    }

    #[test]
    fn an_interrupted_run_keeps_its_results_and_names_the_signal() {
        let file =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenarios/paper/timevarying.toml");
        let loaded =
            crate::scenario::load(&file, &["simulation.duration=0.1".into()]).expect("valid");
        let tmp = tempfile::tempdir().expect("tempdir");
        let interrupt = Interrupt::new();
        interrupt.trigger(signal_hook::consts::SIGHUP);
        let out = tmp.path().join("out");
        let s = run(&loaded, &options(out.clone()), &interrupt).expect("results");
        assert!(!s.complete);
        assert_eq!(
            s.incomplete_reason
                .as_ref()
                .map(ToString::to_string)
                .as_deref(),
            Some("interrupted by SIGHUP")
        );
        assert_eq!(verdict(&s, &interrupt), Err(RunEnd::Interrupted(1)));
        assert!(out.join("summary.json").is_file() && out.join("errors.csv").is_file());
        let done = run(&loaded, &options(out), &Interrupt::new()).expect("results");
        assert_eq!(verdict(&done, &Interrupt::new()), Ok(()));
    }
}
