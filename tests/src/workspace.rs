//! Where the workspace's binaries and scenario files are, and copying an
//! executable safely while other threads start processes.

use std::fs;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The directory of the workspace binaries: the parent of the directory
/// holding the test executable (`target/<profile>/deps/`).
#[must_use]
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test executable has a path");
    exe.parent()
        .and_then(Path::parent)
        .unwrap_or_else(|| panic!("{} is not in target/<profile>/deps/", exe.display()))
        .to_owned()
}

/// The path of workspace binary `name`; panics, saying how to build it, if
/// it is missing.
#[must_use]
pub fn bin(name: &str) -> PathBuf {
    let path = bin_dir().join(name);
    assert!(
        path.is_file(),
        "{} not found: build the workspace binaries first with `cargo build --release --workspace` \
         (into the same target directory and profile as the tests; `cargo test --workspace --release` does it)",
        path.display()
    );
    path
}

/// A scenario file of the repository, e.g. `scenario("paper/timevarying.toml")`.
#[must_use]
pub fn scenario(rel: &str) -> PathBuf {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../scenarios")
        .join(rel);
    path.canonicalize()
        .unwrap_or_else(|e| panic!("scenario {}: {e}", path.display()))
}

/// One of the paper's scenarios: `timevarying`, `constant-observer`,
/// `constant-observerless`.
#[must_use]
pub fn paper(name: &str) -> PathBuf {
    scenario(&format!("paper/{name}.toml"))
}

/// Serialises writing executables with starting processes in this test
/// binary: a process forked while another thread holds a freshly copied
/// executable open for writing inherits that descriptor, and executing the
/// copy then fails with `ETXTBSY` ("Text file busy").
pub(crate) fn exec_lock() -> std::sync::MutexGuard<'static, ()> {
    static LOCK: Mutex<()> = Mutex::new(());
    LOCK.lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// Copies executable `from` to `to` (safe against concurrent
/// [`Attsync::spawn`](crate::Attsync::spawn)s of this test binary, see `ETXTBSY`).
pub fn copy_executable(from: &Path, to: &Path) {
    let _no_fork = exec_lock();
    fs::copy(from, to)
        .unwrap_or_else(|e| panic!("copy {} to {}: {e}", from.display(), to.display()));
}
