//! Why a file of `/proc` could not be read ([`ProcError`]).

use std::path::{Path, PathBuf};
use thiserror::Error;

/// A file of `/proc` that could not be read or understood.
#[derive(Debug, Error)]
pub enum ProcError {
    /// The file could not be read (most often: the process is gone).
    #[error("reading {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The system's reason.
        source: std::io::Error,
    },
    /// The file's text is not what the kernel writes there.
    #[error("{}: no {field} where the kernel writes it", path.display())]
    Malformed {
        /// The file.
        path: PathBuf,
        /// The field that is missing or not a number.
        field: &'static str,
    },
}

/// The text of `path`.
pub(crate) fn read(path: impl AsRef<Path>) -> Result<String, ProcError> {
    let path = path.as_ref();
    std::fs::read_to_string(path).map_err(|source| ProcError::Read {
        path: path.to_owned(),
        source,
    })
}

/// The directory of process `pid` in `/proc`.
#[must_use]
pub(crate) fn dir(pid: u32) -> PathBuf {
    PathBuf::from(format!("/proc/{pid}"))
}
