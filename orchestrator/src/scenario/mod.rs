//! Scenario files: format ([`schema`]), `--set` overrides ([`overrides`]),
//! validation and resolution into the model's network ([`resolve`]).

pub mod overrides;
pub mod plugin;
pub mod report;
pub mod resolve;
pub mod schema;

pub use resolve::{Issue, Resolved};
pub use schema::Scenario;

use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why a scenario could not be loaded.
#[derive(Debug, Error)]
pub enum ScenarioError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The scenario file.
        file: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Not valid TOML, or a field of the wrong type, or an unknown key.
    #[error("{file}: {message}")]
    Parse {
        /// The scenario file.
        file: PathBuf,
        /// The parser's message (with line, column and key).
        message: String,
    },
    /// A `--set` override could not be applied.
    #[error("{file}: --set {message}")]
    Override {
        /// The scenario file.
        file: PathBuf,
        /// What is wrong with the override.
        message: String,
    },
    /// The scenario parsed but breaks the model's assumptions.
    #[error("{}", fmt_issues(file, issues))]
    Invalid {
        /// The scenario file.
        file: PathBuf,
        /// Every problem found.
        issues: Vec<Issue>,
    },
}

fn fmt_issues(file: &Path, issues: &[Issue]) -> String {
    issues
        .iter()
        .map(|i| format!("{}: {i}", file.display()))
        .collect::<Vec<_>>()
        .join("\n")
}

/// A scenario as loaded: the effective document (after overrides), its
/// typed form and its resolved network.
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The file it came from.
    pub file: PathBuf,
    /// The effective TOML (after `--set`), as written to the results.
    pub document: toml::Table,
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

/// Reads, overrides, parses and validates a scenario file.
pub fn load(file: &Path, overrides: &[String]) -> Result<Loaded, ScenarioError> {
    let text = std::fs::read_to_string(file).map_err(|source| ScenarioError::Io {
        file: file.to_owned(),
        source,
    })?;
    load_str(file, &text, overrides)
}

/// As [`load`], from text already read (`file` is used in messages).
pub fn load_str(file: &Path, text: &str, overrides: &[String]) -> Result<Loaded, ScenarioError> {
    let parse = |message: String| ScenarioError::Parse {
        file: file.to_owned(),
        message,
    };
    let mut document: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| parse(e.to_string()))?;
    for o in overrides {
        overrides::apply(&mut document, o).map_err(|message| ScenarioError::Override {
            file: file.to_owned(),
            message,
        })?;
    }
    // Without overrides, parse the text itself so messages carry line and
    // column; with them, parse the edited document and name the field path.
    let scenario = if overrides.is_empty() {
        toml::from_str::<Scenario>(text).map_err(|e| parse(e.to_string()))?
    } else {
        serde_path_to_error::deserialize(toml::Value::Table(document.clone()))
            .map_err(|e| parse(format!("{}: {}", e.path(), e.inner())))?
    };
    let dir = match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    };
    let dir = std::path::absolute(&dir).unwrap_or(dir);
    let resolved = match (
        resolve::resolve(&scenario),
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
    Ok(Loaded {
        file: file.to_owned(),
        document,
        scenario,
        resolved,
    })
}
