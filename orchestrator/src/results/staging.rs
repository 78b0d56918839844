//! Atomic results directories: everything is written into a hidden staging
//! directory beside the destination, which is renamed into place only when
//! complete. An interrupted process leaves at most a `.NAME.partial-PID`
//! directory, never something that looks like finished results.

use super::layout;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// A staging directory that becomes `dest` on [`Staging::commit`] and is
/// removed if dropped before.
#[derive(Debug)]
pub struct Staging {
    tmp: PathBuf,
    dest: PathBuf,
    committed: bool,
}

/// The file that marks a directory as attsync results (so that only such a
/// directory is ever replaced).
pub const MARKER: &str = layout::SUMMARY;

impl Staging {
    /// Prepares a staging directory for `dest`. Fails if `dest` exists and is
    /// neither empty nor an earlier attsync results directory.
    pub fn new(dest: &Path) -> io::Result<Self> {
        if dest.exists() && !replaceable(dest)? {
            return Err(io::Error::new(
                io::ErrorKind::AlreadyExists,
                format!(
                    "{} exists and is not an attsync results directory (no {MARKER}); refusing to replace it",
                    dest.display()
                ),
            ));
        }
        let tmp = layout::staging_dir(dest, std::process::id()).ok_or_else(|| {
            io::Error::new(io::ErrorKind::InvalidInput, "output path has no name")
        })?;
        fs::create_dir_all(tmp.parent().expect("beside dest"))?;
        if tmp.exists() {
            fs::remove_dir_all(&tmp)?;
        }
        fs::create_dir_all(&tmp)?;
        Ok(Self {
            tmp,
            dest: dest.to_owned(),
            committed: false,
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

fn replaceable(dest: &Path) -> io::Result<bool> {
    if !dest.is_dir() {
        return Ok(false);
    }
    Ok(dest.join(MARKER).is_file() || fs::read_dir(dest)?.next().is_none())
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
}
