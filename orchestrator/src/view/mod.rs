//! `view.html`: a run in 3D in the browser, one self-contained file (no
//! network, no third-party code): every body as the box of its inertia on
//! the follower graph, the leader's frame, the observers' estimates as
//! ghosts, a timeline, and the error curves with a cursor.
//!
//! # Layout
//! - [`graph`]: where the bodies stand (a radial tree around the leader).
//! - [`shape`]: a body's box from its inertia.
//! - [`frames`]: the decimated trajectory ([`Collector`] of snapshots →
//!   [`Frames`]).
//! - [`data`]: everything the page shows ([`ViewData`]), its JSON.
//! - this module: the page assembled from `view.html`, `view.css` and
//!   `view.js` (the page's own code, beside this file) with the data
//!   ([`html`], [`write()`]); a run directory's page made again from its
//!   files ([`regenerate`]); [`ViewError`].
//!
//! The page reads the fragment `#t=12.5` (start time, s) and `&paused`, and
//! sets `data-rendered` on `<html>` to the time it last drew (3 decimals):
//! `tests/browser/cdp_check.py` waits on it.

pub mod data;
pub mod frames;
pub mod graph;
pub mod shape;

pub use data::{RunInfo, ViewData, view_data};
pub use frames::{Collector, Frames};

use crate::results::layout::RunLayout;
use crate::results::{Summary, states};
use attitude::engine::Snapshot;
use attitude::network::{AgentState, Network};
use std::io;
use std::path::{Path, PathBuf};
use thiserror::Error;

const PAGE: &str = include_str!("view.html");
const STYLE: &str = include_str!("view.css");
const SCRIPT: &str = include_str!("view.js");

/// A run directory's `view.html` cannot be made.
#[derive(Debug, Error)]
pub enum ViewError {
    /// Its `scenario.toml` cannot be read, or does not resolve into a network.
    #[error("{}: {reason}", file.display())]
    Scenario {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Its `summary.json` cannot be read (a run that never finished).
    #[error("{}: {reason}", file.display())]
    Summary {
        /// The file.
        file: PathBuf,
        /// What is wrong.
        reason: String,
    },
    /// Its `states.bin` cannot be read (the message names the file).
    #[error(transparent)]
    States(#[from] crate::results::states::StatesError),
    /// Its `states.bin` is not of its scenario's network.
    #[error("{}: {reason}", file.display())]
    Mismatch {
        /// `states.bin`.
        file: PathBuf,
        /// What differs.
        reason: String,
    },
    /// `view.html` cannot be written.
    #[error("writing {}: {source}", file.display())]
    Write {
        /// The file.
        file: PathBuf,
        /// The OS error.
        source: io::Error,
    },
}

/// The page showing `data`.
#[must_use]
pub fn html(data: &ViewData) -> String {
    let json = serde_json::to_string(data).expect("view data serialises");
    // Inside <script type="application/json"> nothing may read as a tag:
    // `<` only occurs in strings, where `\u003c` means the same.
    let json = json.replace('<', "\\u003c");
    let title = escape(&format!("{} ({})", data.run.scenario, data.run.engine));
    PAGE.replace("{{style}}", STYLE)
        .replace("{{script}}", SCRIPT)
        .replace("{{title}}", &title)
        .replace("{{data}}", &json)
}

/// Text as HTML (also `{` and `}`, so a name never reads as a placeholder).
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '{' => out.push_str("&#123;"),
            '}' => out.push_str("&#125;"),
            c => out.push(c),
        }
    }
    out
}

/// Writes the page of `data` to `file`.
///
/// # Errors
/// [`ViewError::Write`].
pub fn write(file: &Path, data: &ViewData) -> Result<(), ViewError> {
    std::fs::write(file, html(data)).map_err(|source| ViewError::Write {
        file: file.to_owned(),
        source,
    })
}

/// The run's facts the page shows, from its summary.
#[must_use]
pub fn run_info(s: &Summary) -> RunInfo {
    RunInfo {
        scenario: s.scenario.clone(),
        engine: s.engine.clone(),
        complete: s.complete,
        incomplete_reason: (s.incomplete_reason.as_ref()).map(ToString::to_string),
        realtime: s.realtime,
        events: (s.events.iter())
            .map(|e| data::EventMark {
                t: e.t,
                label: e.what.to_string(),
            })
            .collect(),
    }
}

/// `attsync view DIR`: writes `DIR/view.html` from the run's
/// `scenario.toml`, `summary.json` and `states.bin` — the same page the
/// run wrote. Returns the file written.
///
/// # Errors
/// See [`ViewError`].
pub fn regenerate(dir: &Path) -> Result<PathBuf, ViewError> {
    let files = RunLayout::new(dir);
    let net = network_of(&files.scenario())?;
    let summary_file = files.summary();
    let summary_error = |reason: String| ViewError::Summary {
        file: summary_file.clone(),
        reason,
    };
    let text = std::fs::read_to_string(&summary_file).map_err(|e| summary_error(e.to_string()))?;
    let summary: Summary = serde_json::from_str(&text).map_err(|e| summary_error(e.to_string()))?;
    let frames = replay(&files.states(), &net)?;
    let file = files.view();
    write(&file, &view_data(&net, run_info(&summary), frames))?;
    Ok(file)
}

/// The network of a run's `scenario.toml` (plug-in programs are not looked
/// up: the page only needs the network).
fn network_of(file: &Path) -> Result<Network, ViewError> {
    let err = |reason: String| ViewError::Scenario {
        file: file.to_owned(),
        reason,
    };
    let text = std::fs::read_to_string(file).map_err(|e| err(e.to_string()))?;
    let scenario: crate::scenario::Scenario =
        toml::from_str(&text).map_err(|e| err(e.to_string()))?;
    let check = crate::scenario::StiffnessCheck::Warn;
    match crate::scenario::resolve::resolve_with(&scenario, check) {
        Ok(r) => Ok(r.network),
        Err(issues) => Err(err(issues
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("; "))),
    }
}

/// The frames of `states.bin` of a run of `net`, as the run collected them
/// (read a record at a time: memory does not grow with the run's length).
fn replay(file: &Path, net: &Network) -> Result<Frames, ViewError> {
    let records = states::open(file).map_err(ViewError::States)?;
    let header = &records.header;
    let ids: Vec<u32> = net.agents.iter().map(|a| a.model.id).collect();
    if header.agent_ids != ids || header.sample_every != net.sample_every {
        return Err(ViewError::Mismatch {
            file: file.to_owned(),
            reason: format!(
                "agents {:?} sampled every {} steps, but its scenario.toml has agents {ids:?} every {}",
                header.agent_ids, header.sample_every, net.sample_every
            ),
        });
    }
    let mut collector = Collector::new(net);
    let mut agents: Vec<AgentState> = Vec::with_capacity(ids.len());
    for rec in records {
        let rec = rec.map_err(ViewError::States)?;
        agents.clear();
        agents.extend(rec.agents.iter().map(states::AgentRecord::state));
        collector.push(&Snapshot {
            step: rec.step,
            leader: &rec.leader.state(),
            agents: &agents,
            torques: &rec.torques(),
        });
    }
    Ok(collector.finish())
}
