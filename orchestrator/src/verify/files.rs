//! The files `manifest.json` lists, checked against their recorded size
//! and SHA-256: a changed, missing or unreadable file is named.

use crate::results::digest::sha256_file;
use crate::results::manifest::FileEntry;
use std::fmt;
use std::path::Path;

/// A listed file that is not as recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Changed {
    /// What the manifest says.
    pub recorded: FileEntry,
    /// What is there now.
    pub now: Now,
}

/// The state of a listed file that is not as recorded.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Now {
    /// It is gone.
    Missing,
    /// It cannot be read (the OS error).
    Unreadable(String),
    /// Its contents differ.
    Differs {
        /// Size, bytes.
        size: u64,
        /// SHA-256.
        sha256: String,
    },
}

impl fmt::Display for Changed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let r = &self.recorded;
        let was = format!("recorded {} bytes, SHA-256 {}", r.size, r.sha256);
        match &self.now {
            Now::Missing => write!(f, "{}: missing ({was})", r.path),
            Now::Unreadable(e) => write!(f, "{}: cannot be read: {e} ({was})", r.path),
            Now::Differs { size, sha256 } => write!(
                f,
                "{}: SHA-256 mismatch: {was}; now {size} bytes, SHA-256 {sha256}",
                r.path
            ),
        }
    }
}

/// The files of `listed` (inside `dir`) that are not as recorded, in
/// manifest order.
#[must_use]
pub fn check(dir: &Path, listed: &[FileEntry]) -> Vec<Changed> {
    let mut changed = Vec::new();
    for entry in listed {
        // `Manifest::read` has refused paths that leave the directory.
        let Some(path) = entry.within(dir) else {
            continue;
        };
        let now = match sha256_file(&path) {
            Ok((size, sha256)) if size == entry.size && sha256 == entry.sha256 => continue,
            Ok((size, sha256)) => Now::Differs { size, sha256 },
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => Now::Missing,
            Err(e) => Now::Unreadable(e.to_string()),
        };
        changed.push(Changed {
            recorded: entry.clone(),
            now,
        });
    }
    changed
}
