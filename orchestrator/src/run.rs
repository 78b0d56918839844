//! `attsync run`: a loaded scenario through an engine into a results
//! directory.

use crate::outcome::Outcome;
use crate::processes::{self, ProcessError, ProcessOptions};
use crate::results::{self, Recorder, Summary, plot, staging::Staging};
use crate::scenario::Loaded;
use attitude::engine::InProcess;
use indicatif::{ProgressBar, ProgressState, ProgressStyle};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;
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
    /// The options do not fit the scenario.
    #[error("{0}")]
    Options(String),
    /// Drawing the plot failed.
    #[error("{path}: cannot draw plot: {message}")]
    Plot {
        /// The plot file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

fn io_at(path: &Path) -> impl FnOnce(std::io::Error) -> RunError + '_ {
    move |source| RunError::Io {
        path: path.to_owned(),
        source,
    }
}

/// Runs `loaded` and writes its results to `opts.out` (atomically). Stops
/// early, keeping the results so far marked incomplete, when `interrupt`
/// becomes true.
pub fn run(
    loaded: &Loaded,
    opts: &RunOptions,
    interrupt: &AtomicBool,
) -> Result<Summary, RunError> {
    let net = &loaded.resolved.network;
    check_options(loaded, opts)?;
    let mut process_opts = opts.processes.clone();
    process_opts.plugins = loaded.resolved.plugins.clone();
    let staging = Staging::new(&opts.out).map_err(io_at(&opts.out))?;
    let dir = staging.path().to_owned();
    let text = toml::to_string(&loaded.document).expect("a TOML table serialises");
    std::fs::write(dir.join("scenario.toml"), text).map_err(io_at(&dir))?;
    let mut recorder = Recorder::new(&dir, &loaded.name(), net).map_err(io_at(&dir))?;

    let bar = progress_bar(opts.progress, net.steps, net.dt);
    let started = Instant::now();
    let mut write_error = None;
    let mut record = |snap: &attitude::engine::Snapshot<'_>| {
        if let Err(e) = recorder.record(snap) {
            write_error = Some(e);
            return false;
        }
        bar.set_position(snap.step);
        true
    };
    let outcome = match opts.engine {
        Engine::InProcess => {
            let mut engine = InProcess::new(net);
            let mut interrupted = false;
            engine.run(|snap| {
                if interrupt.load(Ordering::Relaxed) {
                    interrupted = true;
                    return false;
                }
                record(snap)
            });
            Outcome::in_process(&engine, interrupted)
        }
        Engine::Processes => {
            processes::run(net, &process_opts, &dir.join("logs"), interrupt, record)?
        }
    };
    let Outcome {
        peak_torques: peaks,
        steps,
        failure,
        links,
        pacing,
        nodes,
    } = outcome;
    let wall_seconds = started.elapsed().as_secs_f64();
    bar.finish_and_clear();
    if let Some(e) = write_error {
        return Err(io_at(&dir)(e));
    }
    let series = recorder.finish().map_err(io_at(&dir))?;
    let mut agents = results::agent_summaries(&series, &peaks);
    for (a, p) in agents.iter_mut().zip(&pacing) {
        if opts.processes.realtime.is_some() {
            (a.late_stages, a.max_lateness) = (Some(p.0), Some(p.1));
        }
    }
    for a in &mut agents {
        a.plugin = loaded
            .resolved
            .plugins
            .iter()
            .find(|p| p.agent == a.id)
            .map(|p| p.display());
    }
    let summary = Summary {
        attsync_version: env!("CARGO_PKG_VERSION").into(),
        scenario: loaded.name(),
        engine: opts.engine.name().into(),
        complete: failure.is_none() && steps == net.steps,
        incomplete_reason: failure,
        dt: net.dt,
        duration: net.steps as f64 * net.dt,
        t_end: steps as f64 * net.dt,
        steps,
        wall_seconds,
        max_final_att_err: agents.iter().map(|a| a.final_att_err).fold(0.0, f64::max),
        agents,
        links: links
            .iter()
            .map(|(from, to, st)| results::summary::LinkSummary {
                from: *from,
                to: *to,
                sent: st.sent,
                delivered: st.delivered,
                lost: st.lost,
                aoi_mean: if st.evaluations > 0 {
                    st.age_sum / st.evaluations as f64
                } else {
                    0.0
                },
                aoi_max: st.age_max,
                rejected: st.rejected,
            })
            .collect(),
        realtime: opts.processes.realtime,
        nodes: nodes
            .into_iter()
            .map(|(name, id, d)| results::summary::NodeSummary {
                id,
                name,
                peak_rss_kb: d.peak_rss_kb,
                started_unix_ns: d.started_unix_ns,
                done_unix_ns: d.done_unix_ns,
            })
            .collect(),
    };
    let svg = dir.join("errors.svg");
    plot::draw(
        &svg,
        &format!("{} ({})", summary.scenario, summary.engine),
        &series,
    )
    .map_err(|message| RunError::Plot {
        path: svg.clone(),
        message,
    })?;
    // summary.json last: it marks the directory as complete results.
    results::write_summary(&dir, &summary).map_err(io_at(&dir))?;
    staging.commit().map_err(io_at(&opts.out))?;
    Ok(summary)
}

/// Options that the scenario cannot run with.
fn check_options(loaded: &Loaded, opts: &RunOptions) -> Result<(), RunError> {
    let plugins = &loaded.resolved.plugins;
    if opts.engine == Engine::InProcess {
        if let Some(p) = plugins.first() {
            return Err(RunError::Options(format!(
                "agent {} is a plug-in (`{}`): plug-ins need --engine processes",
                p.agent,
                p.display()
            )));
        }
        if opts.processes.realtime.is_some() {
            return Err(RunError::Options(
                "--realtime needs --engine processes (the in-process engine is lockstep only)"
                    .into(),
            ));
        }
    }
    if let Some(f) = opts.processes.realtime {
        if !(f.is_finite() && f > 0.0) {
            return Err(RunError::Options(format!(
                "--realtime {f}: the factor must be a positive number (simulated s per wall s)"
            )));
        }
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
            return Err(RunError::Options(
                "--realtime cannot be combined with [network] impairments: they are defined in \
                 simulated lockstep time; in real-time mode the transport's own latency is measured"
                    .into(),
            ));
        }
    }
    Ok(())
}

fn progress_bar(enabled: bool, steps: u64, dt: f64) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    let total = steps as f64 * dt;
    let style = ProgressStyle::with_template(&format!(
        "{{bar:40}} t = {{simt}} / {total} s  {{rtf}}× real time  eta {{eta}}"
    ))
    .expect("valid template")
    .with_key(
        "simt",
        move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{:.2}", s.pos() as f64 * dt);
        },
    )
    .with_key(
        "rtf",
        move |s: &ProgressState, w: &mut dyn std::fmt::Write| {
            let _ = write!(w, "{:.1}", s.per_sec() * dt);
        },
    );
    ProgressBar::new(steps).with_style(style)
}
