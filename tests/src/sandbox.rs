//! A test's private temporary directory, kept if the test fails.

use std::path::{Path, PathBuf};

/// A test's private temporary directory. Removed when dropped, except while
/// panicking: then it is kept for inspection and its path printed.
#[derive(Debug)]
pub struct Sandbox {
    dir: Option<tempfile::TempDir>,
}

impl Sandbox {
    /// A new empty directory named after `test`.
    #[must_use]
    pub fn new(test: &str) -> Self {
        let dir = tempfile::Builder::new()
            .prefix(&format!("attsync-e2e-{test}-"))
            .tempdir()
            .expect("a temporary directory");
        Self { dir: Some(dir) }
    }

    /// The directory.
    #[must_use]
    pub fn path(&self) -> &Path {
        self.dir.as_ref().expect("present until dropped").path()
    }

    /// `path()/rel`.
    #[must_use]
    pub fn join(&self, rel: impl AsRef<Path>) -> PathBuf {
        self.path().join(rel)
    }
}

impl Drop for Sandbox {
    fn drop(&mut self) {
        if std::thread::panicking() {
            if let Some(dir) = self.dir.take() {
                eprintln!(
                    "test failed; its files are kept in {}",
                    dir.keep().display()
                );
            }
        }
    }
}
