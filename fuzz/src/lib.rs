//! What the fuzz targets share: a run directory laid out as `attsync run`
//! leaves it (the fixture of a 0.05 s run of `paper/constant-observer`),
//! in a temporary directory of its own.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A run directory with the fixture's files, and a copy of its
/// `states.bin` outside it (what `verify` compares a re-run with).
pub struct RunDir {
    dir: tempfile::TempDir,
    /// The fixture's `states.bin`, outside the run directory.
    pub reference: PathBuf,
}

impl RunDir {
    /// The run directory.
    pub fn path(&self) -> &Path {
        self.dir.path()
    }
}

const FILES: [(&str, &[u8]); 4] = [
    (
        "scenario.toml",
        include_bytes!("../fixtures/run/scenario.toml"),
    ),
    (
        "summary.json",
        include_bytes!("../fixtures/run/summary.json"),
    ),
    ("states.bin", include_bytes!("../fixtures/run/states.bin")),
    ("errors.csv", include_bytes!("../fixtures/run/errors.csv")),
];

/// A fresh run directory (one per process and `name`).
pub fn run_dir(cell: &'static OnceLock<RunDir>) -> &'static RunDir {
    cell.get_or_init(|| {
        let dir = tempfile::tempdir().expect("a temp dir");
        for (name, bytes) in FILES {
            std::fs::write(dir.path().join(name), bytes).expect("a fixture file");
        }
        let reference = dir.path().with_extension("reference.bin");
        std::fs::write(&reference, FILES[2].1).expect("the reference states");
        RunDir { dir, reference }
    })
}

/// The fixture run's files, by name.
pub fn fixture(name: &str) -> &'static [u8] {
    FILES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, b)| *b)
        .expect("a fixture file")
}

/// The largest single allocation a target may make: 256 MiB. Inputs are
/// at most a few tens of KiB (`tools/fuzz.sh`'s `-max_len`), so a request
/// past this is an allocation sized by a hostile field, not by the input.
/// Without a sanitizer libFuzzer's `-malloc_limit_mb` sees no allocation:
/// this allocator makes such a request a crash (an abort) that libFuzzer
/// reports and saves, rather than an allocation that merely succeeds
/// (overcommit) or an out-of-memory kill elsewhere.
pub const MAX_ALLOCATION: usize = 256 << 20;

/// The system allocator, aborting on a request over [`MAX_ALLOCATION`].
struct Bounded;

// SAFETY: every call is forwarded unchanged to the system allocator.
#[allow(unsafe_code)]
unsafe impl std::alloc::GlobalAlloc for Bounded {
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        check(layout.size());
        // SAFETY: the caller's contract, forwarded.
        unsafe { std::alloc::System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        check(layout.size());
        // SAFETY: the caller's contract, forwarded.
        unsafe { std::alloc::System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        // SAFETY: the caller's contract, forwarded.
        unsafe { std::alloc::System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new: usize) -> *mut u8 {
        check(new);
        // SAFETY: the caller's contract, forwarded.
        unsafe { std::alloc::System.realloc(ptr, layout, new) }
    }
}

/// Aborts (a crash libFuzzer saves) on a request over [`MAX_ALLOCATION`].
fn check(size: usize) {
    if size > MAX_ALLOCATION {
        // No allocation here: write the message by hand.
        let msg = b"attsync-fuzz: an allocation over MAX_ALLOCATION (256 MiB)\n";
        let _ = std::io::Write::write_all(&mut std::io::stderr(), msg);
        std::process::abort();
    }
}

#[global_allocator]
static ALLOCATOR: Bounded = Bounded;
