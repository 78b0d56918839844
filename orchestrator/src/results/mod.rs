//! Run outputs: `errors.csv`, `summary.json`, `errors.svg`, `states.bin`
//! (`scenario.toml` and `logs/` are written by the run driver), staged and
//! renamed into place atomically.
//!
//! # Layout
//! - [`layout`]: the name of every file and directory of a run and of a
//!   sweep (`RunLayout`, `SweepLayout`, the staging directory's name).
//! - this module: [`Recorder`] (snapshots → `errors.csv` rows and
//!   [`Series`], and `states.bin`; each agent's [`Row`] made where the
//!   engine likes), [`agent_summaries`], [`write_summary`],
//!   [`WriteError`] (naming the file).
//! - [`summary`]: `summary.json` ([`Summary`]) and the end-of-run table.
//! - [`states`]: `states.bin`, its byte layout, reader and CSV export.
//! - [`plot`]: draws `errors.svg`; [`envelope`]: what it draws of many
//!   agents (their band) and of many samples (thinned lines).
//! - [`staging`]: the atomic results directory (`.NAME.partial-PID`), replacing
//!   only a directory marked as attsync's.
//! - [`lock`]: the lock (`.NAME.lock`) serialising runs into one directory.
//! - [`manifest`]: `manifest.json` (versions, seeds, settings, platform, the
//!   SHA-256 of every other file), written last; [`digest`]: SHA-256 of bytes
//!   and files; [`platform`]: the machine it records.

pub mod digest;
pub mod envelope;
pub mod layout;
pub mod lock;
pub mod manifest;
pub mod palette;
pub mod platform;
pub mod plot;
pub mod staging;
pub mod states;
pub mod summary;
pub mod until;

use attitude::engine::Snapshot;
use attitude::metrics::{Errors, errors};
use attitude::network::{AgentState, Network};
use attitude::reference::LeaderState;
pub use layout::{RunLayout, SweepLayout};
use nalgebra::Vector3;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
pub use summary::{AgentSummary, Summary};

/// The exact header of `errors.csv`.
pub const CSV_HEADER: &str = "t,agent,att_err,angvel_err,obs_att_err,obs_angvel_err";

/// Error time series of one agent, as sampled.
#[derive(Debug, Clone, Default)]
pub struct Series {
    /// Agent id.
    pub id: u32,
    /// Sample times, s.
    pub t: Vec<f64>,
    /// `|Rᵢ R₀ᵀ|_I`.
    pub att: Vec<f64>,
    /// `‖ωᵢ − ω₀‖`.
    pub angvel: Vec<f64>,
    /// Observer errors (empty without an observer).
    pub obs_att: Vec<f64>,
    /// Observer angular-velocity errors.
    pub obs_angvel: Vec<f64>,
    /// `‖τᵢ‖` at stage 0 of each sampled step, N·m (NaN at the last step:
    /// no torque follows it; NaN where the agent did not report it).
    pub torque: Vec<f64>,
}

/// A results file could not be written (a full disk, a read-only directory).
#[derive(Debug, thiserror::Error)]
#[error("writing {}: {source}", path.display())]
pub struct WriteError {
    /// The file.
    pub path: PathBuf,
    /// The OS error.
    pub source: io::Error,
}

/// Maps an I/O error writing `path` to a [`WriteError`].
fn writing(path: &Path) -> impl FnOnce(io::Error) -> WriteError + '_ {
    move |source| WriteError {
        path: path.to_owned(),
        source,
    }
}

/// Turns snapshots into `errors.csv` rows (streamed) and in-memory series.
#[derive(Debug)]
pub struct Recorder {
    files: RunLayout,
    csv: BufWriter<File>,
    states: states::StatesWriter,
    dt: f64,
    has_observer: bool,
    series: Vec<Series>,
}

/// One agent's part of a sample's record: its errors and the end of its
/// `errors.csv` row after the time (`,id,att,angvel,obs_att,obs_angvel`,
/// the observer's two empty without an observer).
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    errors: Errors,
    tail: String,
}

impl Row {
    /// The row of agent `id` with errors `e`.
    fn of(id: u32, e: &Errors) -> Self {
        let tail = match e.observer {
            Some((oa, ow)) => format!(",{id},{},{},{oa},{ow}", e.att, e.angvel),
            None => format!(",{id},{},{},,", e.att, e.angvel),
        };
        Self { errors: *e, tail }
    }
}

/// Every agent's row of `snap` in order, made by `row` ([`Recorder::row_maker`]) here.
pub fn rows_of(
    row: &impl Fn(usize, &AgentState, &LeaderState) -> Row,
    snap: &Snapshot<'_>,
) -> Vec<Row> {
    let agents = snap.agents.iter().enumerate();
    agents.map(|(k, x)| row(k, x, snap.leader)).collect()
}

/// Formats a sample time `step · dt` without binary noise (9 decimals, trimmed).
#[must_use]
pub fn fmt_time(step: u64, dt: f64) -> String {
    let s = format!("{:.9}", step as f64 * dt);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s.is_empty() {
        "0".into()
    } else {
        s.to_string()
    }
}

/// A printed sample time ([`fmt_time`]) read back.
fn read_time(printed: &str) -> f64 {
    printed.parse().expect("fmt_time prints a number")
}

/// The sample time `step · dt` as `errors.csv` prints it, read back: the
/// series, plots, frames and verdicts hold exactly the printed values.
#[must_use]
pub fn sample_time(step: u64, dt: f64) -> f64 {
    read_time(&fmt_time(step, dt))
}

/// The larger of `a` and `b`, NaN if either is: the largest error over
/// agents is NaN once any agent's is.
#[must_use]
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

impl Recorder {
    /// Starts `errors.csv` and `states.bin` in `dir` for `net`.
    pub fn new(dir: &Path, scenario: &str, net: &Network) -> Result<Self, WriteError> {
        let files = RunLayout::new(dir);
        let (states_file, csv_file) = (files.states(), files.errors_csv());
        let states = states::StatesWriter::create(&states_file, scenario, net)
            .map_err(writing(&states_file))?;
        let mut csv = BufWriter::new(File::create(&csv_file).map_err(writing(&csv_file))?);
        writeln!(csv, "{CSV_HEADER}").map_err(writing(&csv_file))?;
        let has_observer = net
            .agents
            .first()
            .is_some_and(|a| a.model.scheme.has_observer());
        let series = net
            .agents
            .iter()
            .map(|a| Series {
                id: a.model.id,
                ..Series::default()
            })
            .collect();
        Ok(Self {
            files,
            csv,
            states,
            dt: net.dt,
            has_observer,
            series,
        })
    }

    /// Writes one row per agent for `snap`. Errors are printed with Rust's
    /// shortest round-trip formatting (full f64 precision).
    pub fn record(&mut self, snap: &Snapshot<'_>) -> Result<(), WriteError> {
        let rows = rows_of(&self.row_maker(), snap);
        self.record_rows(snap, &rows)
    }

    /// The per-agent part of [`Recorder::record`] (agent index, state, the
    /// leader's state → its [`Row`]): pure, so an engine may make each
    /// agent's row on the thread that steps it
    /// ([`attitude::engine::InProcess::run_with`]).
    pub fn row_maker(&self) -> impl Fn(usize, &AgentState, &LeaderState) -> Row + Sync + use<> {
        let ids: Vec<u32> = self.series.iter().map(|s| s.id).collect();
        let has_observer = self.has_observer;
        move |k, x, leader| Row::of(ids[k], &errors(x, leader, has_observer))
    }

    /// [`Recorder::record`] with the rows made already (one per agent, in
    /// network order, by [`Recorder::row_maker`]).
    pub fn record_rows(&mut self, snap: &Snapshot<'_>, rows: &[Row]) -> Result<(), WriteError> {
        (self.states.write(snap)).map_err(writing(&self.files.states()))?;
        self.record_torques(snap.torques);
        self.record_errors(snap.step, rows)
            .map_err(writing(&self.files.errors_csv()))
    }

    /// Every agent's `‖τᵢ‖` of a sample into its series (NaN where missing).
    fn record_torques(&mut self, torques: &[Vector3<f64>]) {
        for (k, s) in self.series.iter_mut().enumerate() {
            s.torque.push(torques.get(k).map_or(f64::NAN, |t| t.norm()));
        }
    }

    /// Sets the torques of the last sample, if it is of step `step` (a run
    /// extended past its horizon: its former last sample had none,
    /// [`attitude::engine::InProcess::begin_step`]).
    pub fn amend_torques(&mut self, step: u64, torques: &[Vector3<f64>]) {
        if self.states.amend_torques(step, torques) {
            for (s, t) in self.series.iter_mut().zip(torques) {
                if let Some(last) = s.torque.last_mut() {
                    *last = t.norm();
                }
            }
        }
    }

    /// The `errors.csv` rows and series samples of step `step`.
    fn record_errors(&mut self, step: u64, rows: &[Row]) -> io::Result<()> {
        let t_str = fmt_time(step, self.dt);
        let t = read_time(&t_str);
        for (row, s) in rows.iter().zip(&mut self.series) {
            let e = &row.errors;
            s.t.push(t);
            s.att.push(e.att);
            s.angvel.push(e.angvel);
            if let Some((oa, ow)) = e.observer {
                s.obs_att.push(oa);
                s.obs_angvel.push(ow);
            }
            writeln!(self.csv, "{t_str}{}", row.tail)?;
        }
        Ok(())
    }

    /// The series recorded so far.
    #[must_use]
    pub fn series(&self) -> &[Series] {
        &self.series
    }

    /// Flushes the CSV and `states.bin` and returns the series.
    pub fn finish(mut self) -> Result<Vec<Series>, WriteError> {
        let (states, csv) = (self.files.states(), self.files.errors_csv());
        self.csv.flush().map_err(writing(&csv))?;
        self.states.finish().map_err(writing(&states))?;
        Ok(self.series)
    }
}

/// Per-agent summaries from the series and peak torques (same order).
#[must_use]
pub fn agent_summaries(series: &[Series], peak_torques: &[f64]) -> Vec<AgentSummary> {
    series
        .iter()
        .zip(peak_torques)
        .map(|(s, &peak_torque)| AgentSummary {
            id: s.id,
            final_att_err: s.att.last().copied().unwrap_or(f64::NAN),
            final_angvel_err: s.angvel.last().copied().unwrap_or(f64::NAN),
            final_obs_att_err: s.obs_att.last().copied(),
            final_obs_angvel_err: s.obs_angvel.last().copied(),
            settle: summary::Settle::of(&s.t, &s.att, &s.angvel),
            peak_torque,
            late_stages: None,
            max_lateness: None,
            plugin: None,
        })
        .collect()
}

/// Writes `summary.json`.
pub fn write_summary(dir: &Path, summary: &Summary) -> Result<(), WriteError> {
    let file = RunLayout::new(dir).summary();
    let text = serde_json::to_string_pretty(summary).map_err(io::Error::other);
    text.and_then(|t| std::fs::write(&file, t + "\n"))
        .map_err(writing(&file))
}
