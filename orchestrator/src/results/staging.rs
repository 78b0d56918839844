//! Atomic results directories: everything is written into a hidden staging
//! directory beside the destination, which is renamed into place only when
//! complete. An interrupted process leaves at most a `.NAME.partial-PID`
//! directory, never something that looks like finished results.

use super::layout;
use super::lock::{LockError, OutLock};
use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// A staging directory that becomes `dest` on [`Staging::commit`] and is
/// removed if dropped before. It holds `dest`'s lock ([`OutLock`]) until then.
#[derive(Debug)]
pub struct Staging {
    tmp: PathBuf,
    dest: PathBuf,
    committed: bool,
    _lock: OutLock,
}

/// The file that marks a directory as attsync results (so that only such a
/// directory is ever replaced).
pub const MARKER: &str = layout::MARKER;

/// Why a results directory cannot be prepared.
#[derive(Debug, Error)]
pub enum StagingError {
    /// `dest` exists and is not attsync's to replace (nothing was started).
    #[error(
        "{} exists and is not an attsync results directory ({reason}); refusing to replace it",
        dir.display()
    )]
    Foreign {
        /// The directory (or file) in the way.
        dir: PathBuf,
        /// What makes it foreign: no marker, or the foreign files.
        reason: String,
    },
    /// Another attsync process is writing `dest` (nothing was started).
    #[error("another attsync run (pid {}) is writing {} (lock {})",
        pid.map_or("?".into(), |p| p.to_string()), dir.display(), lock.display())]
    Busy {
        /// The results directory.
        dir: PathBuf,
        /// The other run's pid, if known.
        pid: Option<u32>,
        /// The lock file.
        lock: PathBuf,
    },
    /// A file system operation failed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or directory.
        path: PathBuf,
        /// The OS error.
        source: io::Error,
    },
}

impl StagingError {
    /// Whether the run was refused before anything started (foreign or busy
    /// `--out`), as opposed to a failing file system.
    #[must_use]
    pub fn is_refusal(&self) -> bool {
        !matches!(self, StagingError::Io { .. })
    }
}

impl From<StagingError> for io::Error {
    fn from(e: StagingError) -> Self {
        let kind = match &e {
            StagingError::Foreign { .. } => io::ErrorKind::AlreadyExists,
            StagingError::Busy { .. } => io::ErrorKind::ResourceBusy,
            StagingError::Io { source, .. } => source.kind(),
        };
        io::Error::new(kind, e.to_string())
    }
}

fn at(path: &Path) -> impl FnOnce(io::Error) -> StagingError + '_ {
    move |source| StagingError::Io {
        path: path.to_owned(),
        source,
    }
}

impl Staging {
    /// [`Staging::claim`] with the error as an [`io::Error`].
    pub fn new(dest: &Path) -> io::Result<Self> {
        Self::claim(dest).map_err(io::Error::from)
    }

    /// Takes `dest`'s lock, removes staging directories of dead runs beside
    /// it, and prepares a staging directory holding the marker. Fails if
    /// another run holds the lock, or if `dest` exists and is neither empty
    /// nor an attsync results directory holding only what attsync writes.
    ///
    /// # Errors
    /// See [`StagingError`].
    pub fn claim(dest: &Path) -> Result<Self, StagingError> {
        let (parent, name) = layout::beside(dest).ok_or_else(|| {
            at(dest)(io::Error::new(
                io::ErrorKind::InvalidInput,
                "output path has no name",
            ))
        })?;
        fs::create_dir_all(parent).map_err(at(parent))?;
        let lock_path = OutLock::path_for(dest).expect("named");
        let lock = OutLock::acquire(&lock_path).map_err(|e| match e {
            LockError::Held(pid) => StagingError::Busy {
                dir: dest.to_owned(),
                pid,
                lock: lock_path.clone(),
            },
            LockError::Io(source) => at(&lock_path)(source),
        })?;
        remove_dead_staging(parent, &name);
        if dest.exists() {
            if let Some(reason) = foreign(dest).map_err(at(dest))? {
                return Err(StagingError::Foreign {
                    dir: dest.to_owned(),
                    reason,
                });
            }
        }
        let tmp = layout::staging_dir(dest, std::process::id()).expect("named");
        if tmp.exists() {
            fs::remove_dir_all(&tmp).map_err(at(&tmp))?;
        }
        fs::create_dir_all(&tmp).map_err(at(&tmp))?;
        let id = format!(
            "{}\n",
            tmp.file_name()
                .expect("named")
                .to_string_lossy()
                .trim_start_matches('.')
        );
        fs::write(tmp.join(MARKER), id).map_err(at(&tmp))?;
        Ok(Self {
            tmp,
            dest: dest.to_owned(),
            committed: false,
            _lock: lock,
        })
    }

    /// Where to write files now.
    #[must_use]
    pub fn path(&self) -> &Path {
        &self.tmp
    }

    /// The final location.
    #[must_use]
    pub fn dest(&self) -> &Path {
        &self.dest
    }

    /// Moves the staging directory into place, replacing an earlier result.
    pub fn commit(mut self) -> io::Result<PathBuf> {
        if self.dest.exists() {
            let old = self.tmp.with_file_name(layout::replaced_name(
                &self.tmp.file_name().expect("named").to_string_lossy(),
            ));
            fs::rename(&self.dest, &old)?;
            fs::rename(&self.tmp, &self.dest)?;
            fs::remove_dir_all(&old)?;
        } else {
            fs::rename(&self.tmp, &self.dest)?;
        }
        self.committed = true;
        Ok(self.dest.clone())
    }
}

impl Drop for Staging {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.tmp);
        }
    }
}

/// Why `dest` is not attsync's to replace (`None`: it is, or it is empty).
fn foreign(dest: &Path) -> io::Result<Option<String>> {
    if !dest.is_dir() {
        return Ok(Some("not a directory".into()));
    }
    let names: Vec<String> = fs::read_dir(dest)?
        .map(|e| e.map(|e| e.file_name().to_string_lossy().into_owned()))
        .collect::<io::Result<_>>()?;
    if names.is_empty() {
        return Ok(None);
    }
    let mut alien: Vec<String> = Vec::new();
    for n in &names {
        let path = dest.join(n);
        if !layout::OWNED.contains(&n.as_str()) {
            alien.push(n.clone());
        } else if n == layout::LOGS && path.is_dir() {
            for e in fs::read_dir(&path)? {
                let f = e?.file_name().to_string_lossy().into_owned();
                if !f.ends_with(".log") {
                    alien.push(format!("{n}/{f}"));
                }
            }
        } else if n == layout::RUNS && path.is_dir() {
            for e in fs::read_dir(&path)? {
                let run = e?.path();
                if let Some(why) = foreign(&run)? {
                    alien.push(format!(
                        "{n}/{} ({why})",
                        run.file_name().unwrap_or_default().to_string_lossy()
                    ));
                }
            }
        }
    }
    alien.sort();
    let list = format!("foreign file(s): {}", alien.join(", "));
    Ok(
        match (names.iter().any(|n| n == MARKER), alien.is_empty()) {
            (true, true) => None,
            (true, false) => Some(list),
            (false, true) => Some(format!("no {MARKER}")),
            (false, false) => Some(format!("no {MARKER}; {list}")),
        },
    )
}

/// Removes `.<name>.partial-<pid>` (and `.old`) directories in `parent`
/// whose process is no longer alive.
fn remove_dead_staging(parent: &Path, name: &str) {
    let Ok(rd) = fs::read_dir(parent) else {
        return;
    };
    for e in rd.filter_map(Result::ok) {
        let entry = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = layout::staging_pid(name, &entry) else {
            continue;
        };
        if !attsync_sched::process::exists(pid) {
            let _ = fs::remove_dir_all(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropped_staging_leaves_nothing_and_commit_replaces_results() {
        let root = tempfile::tempdir().unwrap();
        let dest = root.path().join("out");
        {
            let s = Staging::new(&dest).unwrap();
            fs::write(s.path().join(layout::ERRORS_CSV), "x").unwrap();
        }
        assert_eq!(fs::read_dir(root.path()).unwrap().count(), 0);
        let s = Staging::new(&dest).unwrap();
        fs::write(s.path().join(MARKER), "{}").unwrap();
        s.commit().unwrap();
        let s = Staging::new(&dest).unwrap();
        fs::write(s.path().join(MARKER), "{\"v\":2}").unwrap();
        s.commit().unwrap();
        assert_eq!(fs::read_to_string(dest.join(MARKER)).unwrap(), "{\"v\":2}");
        assert_eq!(fs::read_dir(root.path()).unwrap().count(), 1);
    }

    #[test]
    fn refuses_to_replace_a_foreign_directory() {
        let root = tempfile::tempdir().unwrap();
        fs::write(root.path().join("thesis.tex"), "precious").unwrap();
        let err = Staging::new(root.path()).unwrap_err();
        assert!(err.to_string().contains("not an attsync results directory"));
    }

    #[test]
    fn replaces_only_a_marked_directory_of_attsync_files() {
        let root = tempfile::tempdir().unwrap();
        let dest = root.path().join("out");
        fs::create_dir_all(dest.join(layout::LOGS)).unwrap();
        fs::write(dest.join(layout::SUMMARY), "{}").unwrap();
        let err = Staging::claim(&dest).unwrap_err();
        assert!(
            err.is_refusal() && err.to_string().contains(MARKER),
            "{err}"
        );
        fs::write(dest.join(MARKER), "old\n").unwrap();
        fs::write(dest.join("analysis.py"), "x").unwrap();
        fs::write(dest.join(layout::LOGS).join("notes.txt"), "x").unwrap();
        let err = Staging::claim(&dest).unwrap_err().to_string();
        assert!(
            err.contains("foreign file(s): analysis.py, logs/notes.txt"),
            "{err}"
        );
        fs::remove_file(dest.join("analysis.py")).unwrap();
        fs::remove_file(dest.join(layout::LOGS).join("notes.txt")).unwrap();
        fs::write(dest.join(layout::LOGS).join("leader.log"), "x").unwrap();
        Staging::claim(&dest).unwrap().commit().unwrap();
        assert!(!dest.join(layout::SUMMARY).exists());
        let id = fs::read_to_string(dest.join(MARKER)).unwrap();
        assert!(id.starts_with("out.partial-"), "{id}");
    }

    #[test]
    fn a_second_claim_is_refused_and_dead_staging_is_removed() {
        let root = tempfile::tempdir().unwrap();
        let dest = root.path().join("out");
        let stale = root.path().join(".out.partial-999999");
        fs::create_dir_all(&stale).unwrap();
        let first = Staging::claim(&dest).unwrap();
        assert!(!stale.exists());
        let err = Staging::claim(&dest).unwrap_err().to_string();
        assert!(
            err.contains("another attsync run") && err.contains(".out.lock"),
            "{err}"
        );
        first.commit().unwrap();
        assert_eq!(fs::read_dir(root.path()).unwrap().count(), 1);
    }
}
