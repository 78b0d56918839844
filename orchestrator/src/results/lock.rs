//! The lock that serialises runs into one results directory: `flock` on
//! `<parent>/.<name>.lock` (see [`layout::lock_name`]), taken without
//! waiting (a second run into the same `--out` fails at once), holding the
//! owner's pid, and removed when released.

use super::layout;
use nix::fcntl::{Flock, FlockArg};
use std::fs::{self, File, OpenOptions};
use std::io::{self, Read, Seek, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};

/// A held lock on a results directory; unlocked and removed on drop.
#[derive(Debug)]
pub struct OutLock {
    path: PathBuf,
    file: Option<Flock<File>>,
}

/// Why the lock could not be taken.
#[derive(Debug)]
pub enum LockError {
    /// Another process holds it (its pid, if it wrote one).
    Held(Option<u32>),
    /// The lock file could not be opened or locked.
    Io(io::Error),
}

impl OutLock {
    /// The lock file of `dest`.
    #[must_use]
    pub fn path_for(dest: &Path) -> Option<PathBuf> {
        let (parent, name) = layout::beside(dest)?;
        Some(parent.join(layout::lock_name(&name)))
    }

    /// Takes the lock at `path` without waiting.
    ///
    /// # Errors
    /// [`LockError::Held`] if another process holds it.
    pub fn acquire(path: &Path) -> Result<Self, LockError> {
        // The holder removes the file on release: retry if the file we
        // locked is no longer the one at `path`.
        for _ in 0..16 {
            let file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(path)
                .map_err(LockError::Io)?;
            let mut locked = match Flock::lock(file, FlockArg::LockExclusiveNonblock) {
                Ok(l) => l,
                Err((mut file, nix::errno::Errno::EWOULDBLOCK)) => {
                    let mut text = String::new();
                    let _ = file.read_to_string(&mut text);
                    return Err(LockError::Held(text.trim().parse().ok()));
                }
                Err((_, e)) => return Err(LockError::Io(e.into())),
            };
            let same = match (locked.metadata(), fs::metadata(path)) {
                (Ok(a), Ok(b)) => a.ino() == b.ino() && a.dev() == b.dev(),
                _ => false,
            };
            if !same {
                continue;
            }
            locked.set_len(0).map_err(LockError::Io)?;
            locked.rewind().map_err(LockError::Io)?;
            write!(locked, "{}", std::process::id()).map_err(LockError::Io)?;
            return Ok(Self {
                path: path.to_owned(),
                file: Some(locked),
            });
        }
        Err(LockError::Io(io::Error::other(
            "the lock file keeps changing",
        )))
    }
}

impl Drop for OutLock {
    fn drop(&mut self) {
        // Remove while still holding it, then unlock (on close).
        let _ = fs::remove_file(&self.path);
        drop(self.file.take());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_second_lock_fails_at_once_and_the_file_goes_with_the_lock() {
        let root = tempfile::tempdir().unwrap();
        let path = OutLock::path_for(&root.path().join("out")).unwrap();
        let held = OutLock::acquire(&path).unwrap();
        match OutLock::acquire(&path) {
            Err(LockError::Held(pid)) => assert_eq!(pid, Some(std::process::id())),
            other => panic!("{other:?}"),
        }
        drop(held);
        assert!(!path.exists());
        drop(OutLock::acquire(&path).unwrap());
    }
}
