//! The attsync scenario file format, a crate of its own below the
//! orchestrator (as cargo keeps `cargo-util-schemas` apart): nothing here
//! starts a process or knows about runs.
//!
//! Scenario files: format ([`schema`]), `--set` overrides ([`overrides`]),
//! validation and resolution into the model's network ([`resolve`]).
//!
//! [`load`] reads the file ([`input`]: size limit, bounded read), parses it
//! and applies the overrides, deserialises it collecting every schema problem
//! ([`deserialize`]), then checks what the paper assumes ([`resolve`],
//! [`plugin`]). Every problem of a stage is reported at once
//! ([`ScenarioError`]).
//!
//! # Layout
//! - [`schema`] — the file format as serde types;
//! - [`input`] — reading a file within [`input::MAX_FILE_BYTES`]; quotes of
//!   the input clipped;
//! - [`overrides`] — `--set key.path=value`;
//! - `parse` — text + overrides → document and [`Scenario`], every problem at once;
//! - `stream` — its fast path from text to document: `toml_parser`'s events
//!   into a compact tree, a chunk of tokens at a time;
//! - [`deserialize`] — the document → [`Scenario`], every schema problem;
//!   `borrowed` — its fast path: the document read in place, without a copy;
//! - `document` — [`Document`], the effective TOML a run writes;
//! - [`resolve`] — validation and resolution into the network, one phase per table;
//! - [`monte_carlo`] — the `[monte_carlo]` table and its resolution;
//! - [`plugin`] — plug-in agents (`[[agent]] command`);
//! - [`report`] — the text `attsync check` prints;
//! - `error` — [`ScenarioError`].

pub mod body;
mod borrowed;
pub mod deserialize;
mod document;
mod error;
pub mod event;
pub mod input;
pub mod monte_carlo;
pub mod overrides;
pub mod parse;
pub mod plugin;
pub mod report;
pub mod resolve;
pub mod schema;
mod stream;

pub use document::Document;
pub use error::ScenarioError;
pub use error::fmt_issues;
pub use resolve::{Issue, Resolved, StiffnessCheck};
pub use schema::Scenario;

use std::path::{Path, PathBuf};

/// A scenario as loaded: the effective document (after overrides), its
/// typed form and its resolved network.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The file it came from.
    pub file: PathBuf,
    /// The effective TOML (after `--set`), as written to the results.
    pub document: Document,
    /// Typed form.
    pub scenario: Scenario,
    /// Validated network and diagnostics.
    pub resolved: Resolved,
}

impl Loaded {
    /// The scenario's name: its `name` field, else the file stem.
    #[must_use]
    pub fn name(&self) -> String {
        self.scenario.name.clone().unwrap_or_else(|| {
            self.file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "scenario".into())
        })
    }
}

/// Reads (at most [`input::MAX_FILE_BYTES`]), overrides, parses and
/// validates a scenario file (a `simulation.dt` clearly beyond the largest
/// stable step is refused).
pub fn load(file: &Path, overrides: &[String]) -> Result<Loaded, ScenarioError> {
    load_with(file, overrides, StiffnessCheck::Refuse)
}

/// As [`load`], with the stiffness verdict `check` (`--no-stiffness-check`).
pub fn load_with(
    file: &Path,
    overrides: &[String],
    check: StiffnessCheck,
) -> Result<Loaded, ScenarioError> {
    let text = input::read_bounded(file).map_err(|error| ScenarioError::Io {
        file: file.to_owned(),
        error,
    })?;
    load_text(file, text, overrides, check)
}

/// As [`load`], from text already read (`file` is used in messages).
pub fn load_str(file: &Path, text: &str, overrides: &[String]) -> Result<Loaded, ScenarioError> {
    load_str_with(file, text, overrides, StiffnessCheck::Refuse)
}

/// As [`load_str`], with the stiffness verdict `check`.
pub fn load_str_with(
    file: &Path,
    text: &str,
    overrides: &[String],
    check: StiffnessCheck,
) -> Result<Loaded, ScenarioError> {
    load_text(file, text.to_owned(), overrides, check)
}

/// As [`load_str_with`], keeping `text` as the document.
fn load_text(
    file: &Path,
    text: String,
    overrides: &[String],
    check: StiffnessCheck,
) -> Result<Loaded, ScenarioError> {
    let file_buf = file.to_owned();
    let scenario = parse::parse(&text, overrides).map_err(|f| match f {
        parse::Failure::Syntax(issue) => ScenarioError::Parse {
            file: file_buf.clone(),
            issues: vec![issue],
        },
        parse::Failure::Schema { overrides, schema } if overrides.is_empty() => {
            ScenarioError::Parse {
                file: file_buf.clone(),
                issues: schema,
            }
        }
        parse::Failure::Schema {
            mut overrides,
            schema,
        } => {
            overrides.extend(schema);
            ScenarioError::Override {
                file: file_buf.clone(),
                issues: overrides,
            }
        }
    })?;
    let dir = match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    };
    let dir = std::path::absolute(&dir).unwrap_or(dir);
    let start = std::time::Instant::now();
    let resolved = match (
        resolve::resolve_with(&scenario, check),
        plugin::resolve(&scenario, &dir),
    ) {
        (Ok(r), Ok(plugins)) => Ok(resolve::Resolved { plugins, ..r }),
        (Err(mut a), Err(b)) => {
            a.extend(b);
            Err(a)
        }
        (Err(a), Ok(_)) | (Ok(_), Err(a)) => Err(a),
    }
    .map_err(|issues| ScenarioError::Invalid {
        file: file.to_owned(),
        issues,
    })?;
    tracing::debug!(elapsed = ?start.elapsed(), "scenario: resolved");
    Ok(Loaded {
        file: file.to_owned(),
        document: Document::new(text, overrides),
        scenario,
        resolved,
    })
}
