//! Plug-in agents: `[[agent]] command = [...]`, `env = {...}`.

use super::resolve::Issue;
use super::schema::Scenario;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// An agent run by a program of the user's instead of `attsync-agent`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plugin {
    /// The agent's id.
    pub agent: u32,
    /// Program and arguments (`--config FILE` is appended).
    pub command: Vec<String>,
    /// Extra environment variables.
    pub env: BTreeMap<String, String>,
    /// Working directory: the scenario file's directory.
    pub dir: PathBuf,
}

impl Plugin {
    /// The command as a user would type it, for messages.
    #[must_use]
    pub fn display(&self) -> String {
        self.command.join(" ")
    }
}

/// The plug-ins of `s`, whose file lives in `dir`. A program named with a
/// `/` is looked up relative to `dir`, a bare name on `PATH`; either must
/// exist.
pub fn resolve(s: &Scenario, dir: &Path) -> Result<Vec<Plugin>, Vec<Issue>> {
    let mut out = Vec::new();
    let mut issues = Vec::new();
    let mut err = |field: String, reason: String| issues.push(Issue { field, reason });
    for (k, a) in s.agents.iter().enumerate() {
        if a.command.is_none() {
            if a.env.is_some() {
                err(
                    format!("agent[{k}].env"),
                    "is only used with `command` (a plug-in agent)".into(),
                );
            }
            continue;
        }
        let command = a.command.clone().unwrap_or_default();
        let f = format!("agent[{k}].command");
        match command.first() {
            None => err(f, "is empty: give the program and its arguments".into()),
            Some(p) if p.trim().is_empty() => err(format!("{f}[0]"), "the program is empty".into()),
            Some(p) => {
                if let Err(reason) = find_program(p, dir) {
                    err(format!("{f}[0]"), reason.to_string());
                }
            }
        }
        let env = a.env.clone().unwrap_or_default();
        for key in env.keys() {
            if key.is_empty() || key.contains('=') || key.contains('\0') {
                err(
                    format!("agent[{k}].env"),
                    format!("{key:?} is not a valid variable name"),
                );
            }
        }
        out.push(Plugin {
            agent: a.id,
            command,
            env,
            dir: dir.to_owned(),
        });
    }
    if issues.is_empty() {
        Ok(out)
    } else {
        Err(issues)
    }
}

/// Why a plug-in's program cannot be found.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum FindProgramError {
    /// A program named with a `/` is not a file under the scenario's directory.
    #[error("{program}: no such file (relative paths are taken from the scenario's directory {})", dir.display())]
    NoSuchFile {
        /// The program as written.
        program: String,
        /// The scenario's directory.
        dir: PathBuf,
    },
    /// A bare program name is not on `PATH`.
    #[error("{0}: not found on PATH")]
    NotOnPath(String),
}

/// Where `program` would be found.
fn find_program(program: &str, dir: &Path) -> Result<PathBuf, FindProgramError> {
    if program.contains('/') {
        let p = dir.join(program);
        return if p.is_file() {
            Ok(p)
        } else {
            Err(FindProgramError::NoSuchFile {
                program: program.to_owned(),
                dir: dir.to_owned(),
            })
        };
    }
    std::env::var_os("PATH")
        .iter()
        .flat_map(std::env::split_paths)
        .map(|d| d.join(program))
        .find(|p| p.is_file())
        .ok_or_else(|| FindProgramError::NotOnPath(program.to_owned()))
}
