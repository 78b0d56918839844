//! The programs a daemon starts for plug-in nodes: only those it was told
//! to allow (`attsync host --allow-plugin PATH…`; the built-in nodes
//! always). A plug-in's program is resolved as the spawn would resolve it
//! (a path with `/` from the plug-in's directory, a bare name on the
//! daemon's `PATH`), then compared, canonical, with the allowed ones; the
//! daemon then starts the canonical path it checked. Its directory must
//! exist, and its environment may not touch the dynamic loader (`LD_*`)
//! nor `PATH`: either would let a caller run other code through an
//! allowed program.
//!
//! Allowing an interpreter (`python3`, `sh`) allows whatever it is told
//! to run: allow a script (executable, with a `#!` line) instead.

use super::TrustError;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The programs allowed, canonical.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Allowlist {
    programs: Vec<PathBuf>,
}

/// A plug-in's command as asked for over the network.
#[derive(Debug, Clone, Copy)]
pub struct Asked<'a> {
    /// Program and arguments.
    pub command: &'a [String],
    /// Extra environment variables.
    pub env: &'a BTreeMap<String, String>,
    /// Working directory.
    pub dir: &'a Path,
}

/// The program to start, once admitted: canonical.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Admitted {
    /// The canonical path of the program checked.
    pub program: PathBuf,
    /// The canonical working directory.
    pub dir: PathBuf,
}

impl Allowlist {
    /// Allows `paths` (from `--allow-plugin`): each must be an executable file.
    pub fn new(paths: &[PathBuf]) -> Result<Self, TrustError> {
        let programs = (paths.iter())
            .map(|p| executable(p).map_err(|reason| file_error(p, &reason)))
            .collect::<Result<_, _>>()?;
        Ok(Self { programs })
    }

    /// The allowed programs, canonical.
    #[must_use]
    pub fn programs(&self) -> &[PathBuf] {
        &self.programs
    }

    /// Admits `asked`, or says why not (for a message naming the host and
    /// the node).
    ///
    /// # Errors
    /// [`AdmitError`]: the first reason to refuse it.
    pub fn admit(&self, asked: &Asked<'_>) -> Result<Admitted, AdmitError> {
        let Some(first) = asked.command.first() else {
            return Err(AdmitError::EmptyCommand);
        };
        if let Some(k) = asked.env.keys().find(|k| forbidden_env(k)) {
            return Err(AdmitError::ForbiddenEnv(k.clone()));
        }
        let dir = std::fs::canonicalize(asked.dir).map_err(|source| AdmitError::Dir {
            dir: asked.dir.to_owned(),
            source,
        })?;
        let found = resolve(first, &dir).ok_or_else(|| AdmitError::NotFound(first.clone()))?;
        let program = executable(&found).map_err(|source| AdmitError::NotExecutable {
            program: first.clone(),
            source,
        })?;
        if !self.programs.contains(&program) {
            let allowed = self.describe();
            return Err(AdmitError::NotAllowed { program, allowed });
        }
        Ok(Admitted { program, dir })
    }

    /// The allowed programs, for messages.
    fn describe(&self) -> String {
        if self.programs.is_empty() {
            return "no plug-in, only the built-in nodes".into();
        }
        let list: Vec<String> = (self.programs.iter())
            .map(|p| p.display().to_string())
            .collect();
        list.join(", ")
    }
}

/// Variables never taken from the network: the dynamic loader's, and the
/// program search path.
fn forbidden_env(name: &str) -> bool {
    name.starts_with("LD_") || name == "PATH"
}

/// Where the spawn finds `program` run from `dir`: a path with `/` from
/// `dir`, a bare name on this process's `PATH`.
fn resolve(program: &str, dir: &Path) -> Option<PathBuf> {
    if program.contains('/') {
        return Some(dir.join(program));
    }
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|d| d.join(program))
        .find(|p| executable(p).is_ok())
}

/// `path`, canonical, if it is an executable regular file.
fn executable(path: &Path) -> Result<PathBuf, NotExecutable> {
    use std::os::unix::fs::PermissionsExt;
    let canonical = std::fs::canonicalize(path)?;
    let meta = std::fs::metadata(&canonical)?;
    if !meta.is_file() || meta.permissions().mode() & 0o111 == 0 {
        return Err(NotExecutable::NotAFile);
    }
    Ok(canonical)
}

fn file_error(p: &Path, reason: &NotExecutable) -> TrustError {
    TrustError::File {
        field: "--allow-plugin".into(),
        path: p.to_owned(),
        reason: reason.to_string(),
    }
}

/// Why a path is not a program to start.
#[derive(Debug, thiserror::Error)]
pub enum NotExecutable {
    /// It cannot be resolved or read.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// It is not a regular file with an execute bit.
    #[error("not an executable file")]
    NotAFile,
}

/// Why a daemon refuses a plug-in's command ([`Allowlist::admit`]).
#[derive(Debug, thiserror::Error)]
pub enum AdmitError {
    /// The command has no program.
    #[error("an empty command")]
    EmptyCommand,
    /// Its environment sets a variable no daemon takes from the network.
    #[error("its environment sets `{0}`, which no daemon takes from the network")]
    ForbiddenEnv(String),
    /// Its working directory cannot be resolved.
    #[error("its directory {}: {source}", dir.display())]
    Dir {
        /// The directory asked for.
        dir: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Its program is not found from its directory or on `PATH`.
    #[error("`{0}` is not found here")]
    NotFound(String),
    /// Its program is not an executable file.
    #[error("`{program}`: {source}")]
    NotExecutable {
        /// The program asked for.
        program: String,
        /// Why not.
        source: NotExecutable,
    },
    /// Its program is not on the daemon's allowlist.
    #[error(
        "`{}` is not allowed here (the daemon allows {allowed}; start it with --allow-plugin {} to allow it)",
        program.display(),
        program.display()
    )]
    NotAllowed {
        /// The program, canonical.
        program: PathBuf,
        /// The programs allowed, for the message.
        allowed: String,
    },
}

#[cfg(test)]
mod tests {
    use super::*;

    fn asked<'a>(command: &'a [String], env: &'a BTreeMap<String, String>) -> Asked<'a> {
        Asked {
            command,
            env,
            dir: Path::new("/"),
        }
    }

    #[test]
    fn only_allowed_programs_are_admitted_by_their_canonical_path() {
        let sh = executable(Path::new("/bin/sh")).expect("a shell");
        let list = Allowlist::new(&["/bin/sh".into()]).unwrap();
        let env = BTreeMap::new();
        let cmd = vec!["sh".to_string(), "-c".into(), "true".into()];
        let a = list.admit(&asked(&cmd, &env)).expect("sh is allowed");
        assert_eq!(a.program, sh);
        let cmd = vec!["/bin/../bin/sh".to_string()];
        assert_eq!(list.admit(&asked(&cmd, &env)).unwrap().program, sh);
        let none = Allowlist::default();
        let e = none.admit(&asked(&cmd, &env)).unwrap_err().to_string();
        assert!(e.contains("is not allowed here"), "{e}");
        assert!(e.contains("only the built-in nodes"), "{e}");
    }

    #[test]
    fn the_loader_and_path_are_never_taken_from_the_network() {
        let list = Allowlist::new(&["/bin/sh".into()]).unwrap();
        let cmd = vec!["/bin/sh".to_string()];
        for k in ["LD_PRELOAD", "LD_LIBRARY_PATH", "PATH"] {
            let env = BTreeMap::from([(k.to_string(), "/tmp".to_string())]);
            let e = list.admit(&asked(&cmd, &env)).unwrap_err().to_string();
            assert!(e.contains(k), "{e}");
        }
        let env = BTreeMap::new();
        let e = list.admit(&asked(&[], &env)).unwrap_err().to_string();
        assert!(e.contains("empty"), "{e}");
    }

    #[test]
    fn an_allowed_path_must_be_an_executable_file() {
        let e = Allowlist::new(&["/nonexistent/plugin".into()]).unwrap_err();
        assert!(
            e.to_string()
                .starts_with("--allow-plugin: /nonexistent/plugin: "),
            "{e}"
        );
        assert!(Allowlist::new(&["/etc/hostname".into(), "/bin".into()]).is_err());
    }
}
