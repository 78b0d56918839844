//! Records the git commit attsync is built from, for every run's
//! `manifest.json` (`orchestrator/src/results/manifest.rs`):
//! `ATTSYNC_GIT_COMMIT` (the full hash of `HEAD`, or `unknown`) and
//! `ATTSYNC_GIT_DIRTY` (`true` if tracked files differ from `HEAD`, `false`,
//! or `unknown`).
//!
//! Never fails the build: outside a git checkout, without `git`, or on any
//! error of it, both are `unknown`. Re-run when `HEAD`, its branch, the
//! packed refs or the index move, and when the orchestrator's sources
//! change (so `dirty` follows edits of this crate; an edit elsewhere in the
//! workspace is seen at the next of these).

use std::path::{Path, PathBuf};
use std::process::Command;

/// `git -C dir args…`'s trimmed stdout, if it ran and succeeded.
fn git(dir: &Path, args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("-C")
        .arg(dir)
        .args(args)
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    String::from_utf8(out.stdout)
        .ok()
        .map(|s| s.trim().to_owned())
}

/// The files whose change moves `HEAD` or the dirty state (those that exist).
fn watched(dir: &Path) -> Vec<PathBuf> {
    let mut names = vec!["HEAD".to_owned(), "index".into(), "packed-refs".into()];
    names.extend(git(dir, &["symbolic-ref", "-q", "HEAD"]));
    names
        .iter()
        .filter_map(|n| git(dir, &["rev-parse", "--git-path", n]))
        .map(|p| dir.join(p))
        .filter(|p| p.exists())
        .collect()
}

fn main() {
    let dir = PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default());
    let commit = git(&dir, &["rev-parse", "--verify", "-q", "HEAD"]).filter(|c| !c.is_empty());
    let dirty = commit.as_ref().and_then(|_| {
        let status = [
            "--no-optional-locks",
            "status",
            "--porcelain",
            "--untracked-files=no",
        ];
        git(&dir, &status).map(|s| !s.is_empty())
    });
    for path in watched(&dir) {
        println!("cargo:rerun-if-changed={}", path.display());
    }
    println!("cargo:rerun-if-changed=src");
    println!("cargo:rerun-if-changed=build.rs");
    let unknown = || "unknown".to_owned();
    println!(
        "cargo:rustc-env=ATTSYNC_GIT_COMMIT={}",
        commit.unwrap_or_else(unknown)
    );
    println!(
        "cargo:rustc-env=ATTSYNC_GIT_DIRTY={}",
        dirty.map_or_else(unknown, |d| d.to_string())
    );
}
