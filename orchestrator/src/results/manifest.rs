//! `manifest.json`: what a run was (attsync's version and git commit, the
//! effective scenario's SHA-256, the seeds, the engine and its settings,
//! the platform, the command line, the start time) and the size and
//! SHA-256 of every other file of its results directory. Written last, in
//! the staging directory, after every other file (so it can hash them);
//! every run writes one, an incomplete run too (`complete: false`).
//! `attsync verify` ([`crate::verify`]) reads it, checks the files and
//! re-runs the scenario.
//!
//! # Format (`manifest_version` 1)
//! ```text
//! { manifest_version, attsync_version, git_commit, git_dirty,
//!   command_line: [arg…], started_at: "YYYY-MM-DDTHH:MM:SSZ",
//!   scenario, scenario_file, scenario_sha256,
//!   seeds: { network, links: [{ from, to, seed }…] },
//!   engine, wait, placement, threads, stage_timeout, realtime,
//!   complete, incomplete_reason, diverged,
//!   platform: { os, arch, cpu_model, cores, kernel },
//!   files: [{ path, size, sha256 }…] }
//! ```
//! `files` is sorted by `path` (relative, `/`-separated: `logs/leader.log`);
//! `wait` and `placement` are null in-process, `threads` null for the
//! processes engine, `realtime` null in lockstep.

use super::layout::{MANIFEST, RunLayout};
use super::{WriteError, digest, writing};
use crate::results::platform::Platform;
use attitude::network::Network;
use msgs::config::WaitStrategy;
use serde::{Deserialize, Serialize};
use std::io;
use std::path::{Component, Path, PathBuf};
use std::time::{SystemTime, UNIX_EPOCH};
use thiserror::Error;

/// The layout version of `manifest.json` this attsync writes and reads.
pub const MANIFEST_VERSION: u32 = 1;

/// The git commit attsync was built from (`build.rs`), or `unknown`.
pub const GIT_COMMIT: &str = env!("ATTSYNC_GIT_COMMIT");

/// A run's `manifest.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    /// [`MANIFEST_VERSION`].
    pub manifest_version: u32,
    /// attsync's version (`CARGO_PKG_VERSION`).
    pub attsync_version: String,
    /// The commit attsync was built from ([`GIT_COMMIT`]).
    pub git_commit: String,
    /// Whether tracked files differed from that commit (`None`: unknown).
    pub git_dirty: Option<bool>,
    /// The command line of the `attsync` process that ran it.
    pub command_line: Vec<String>,
    /// Start time, UTC, RFC 3339 to the second.
    pub started_at: String,
    /// The scenario's name (as in `summary.json` and `states.bin`).
    pub scenario: String,
    /// The scenario file it was loaded from (plug-ins are found beside it).
    pub scenario_file: PathBuf,
    /// SHA-256 of the effective `scenario.toml` in the run directory.
    pub scenario_sha256: String,
    /// Every seed of the run.
    pub seeds: Seeds,
    /// `processes` or `in-process`.
    pub engine: String,
    /// The nodes' wait strategy (processes engine).
    pub wait: Option<WaitStrategy>,
    /// The nodes' placement (`auto`, `spread`, `pack`; processes engine).
    pub placement: Option<String>,
    /// Threads stepping the agents (in-process engine).
    pub threads: Option<usize>,
    /// `--stage-timeout`, s.
    pub stage_timeout: f64,
    /// The real-time factor (`None`: lockstep, deterministic).
    pub realtime: Option<f64>,
    /// Whether the run completed (as `summary.json`).
    pub complete: bool,
    /// Why not (as `summary.json`).
    pub incomplete_reason: Option<String>,
    /// Whether it stopped because a state left the envelope.
    pub diverged: bool,
    /// How the scenario leaves the paper's Assumption 1 (as `summary.json`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub outside_theory: Vec<String>,
    /// The machine.
    pub platform: Platform,
    /// Every other file of the directory.
    pub files: Vec<FileEntry>,
}

/// The seeds of a run. attsync draws random numbers nowhere else: the
/// model, the schedule and both engines are deterministic.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Seeds {
    /// `network.seed`, of the loss and jitter streams.
    pub network: u64,
    /// The stream seed of each impaired link (mixed from `network` and the
    /// link's ends, `attitude::link::link_seed`), by (from, to).
    pub links: Vec<LinkSeed>,
}

/// One impaired link's seed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct LinkSeed {
    /// Sender id (0: the leader).
    pub from: u32,
    /// Receiver id.
    pub to: u32,
    /// The link's stream seed.
    pub seed: u64,
}

impl Seeds {
    /// The seeds of `net`, resolved from a scenario with `network.seed = network`.
    #[must_use]
    pub fn of(network: u64, net: &Network) -> Self {
        let mut links: Vec<LinkSeed> = (net.agents.iter())
            .flat_map(|a| {
                let to = a.model.id;
                let from_neighbours =
                    (a.model.neighbours.iter()).filter_map(move |n| n.link.map(|l| (n.id, l)));
                from_neighbours
                    .chain(a.model.leader_link.map(|l| (0, l)))
                    .map(move |(from, l)| LinkSeed {
                        from,
                        to,
                        seed: l.seed,
                    })
            })
            .collect();
        links.sort_by_key(|l| (l.from, l.to));
        Self { network, links }
    }
}

/// One file of a results directory.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct FileEntry {
    /// Path relative to the directory, `/`-separated.
    pub path: String,
    /// Size, bytes.
    pub size: u64,
    /// SHA-256, lower-case hex.
    pub sha256: String,
}

impl FileEntry {
    /// The file in `dir`, if `path` is relative and stays inside it.
    #[must_use]
    pub fn within(&self, dir: &Path) -> Option<PathBuf> {
        let rel = Path::new(&self.path);
        let inside = rel.components().all(|c| matches!(c, Component::Normal(_)));
        (inside && !self.path.is_empty()).then(|| dir.join(rel))
    }
}

/// Why `manifest.json` cannot be read.
#[derive(Debug, Error)]
pub enum ManifestError {
    /// The file is missing or unreadable (not a run of this attsync, or of one before manifests).
    #[error("{}: {source}", path.display())]
    Io {
        /// The manifest.
        path: PathBuf,
        /// The OS error.
        source: io::Error,
    },
    /// The file is not a manifest: bad JSON, a missing field or a bad value.
    #[error("{}: not an attsync manifest: {reason}", path.display())]
    Parse {
        /// The manifest.
        path: PathBuf,
        /// What is wrong (serde's message, with line and column).
        reason: String,
    },
    /// A layout version this attsync does not read.
    #[error("{}: manifest_version {found} (this attsync reads {})", path.display(), MANIFEST_VERSION)]
    Version {
        /// The manifest.
        path: PathBuf,
        /// The version in the file.
        found: u32,
    },
    /// A listed file path that is absolute or leaves the directory.
    #[error("{}: files: {file:?} is not a path inside the results directory", path.display())]
    Path {
        /// The manifest.
        path: PathBuf,
        /// The listed path.
        file: String,
    },
}

impl Manifest {
    /// The fields that describe the build, the process and the machine
    /// (version, git commit, command line, start time `started`, platform);
    /// the caller fills in the run's.
    #[must_use]
    pub fn now(started: SystemTime) -> Self {
        Self {
            manifest_version: MANIFEST_VERSION,
            attsync_version: env!("CARGO_PKG_VERSION").into(),
            git_commit: GIT_COMMIT.into(),
            git_dirty: env!("ATTSYNC_GIT_DIRTY").parse().ok(),
            command_line: std::env::args_os()
                .map(|a| a.to_string_lossy().into_owned())
                .collect(),
            started_at: rfc3339(started),
            scenario: String::new(),
            scenario_file: PathBuf::new(),
            scenario_sha256: String::new(),
            seeds: Seeds {
                network: 0,
                links: Vec::new(),
            },
            engine: String::new(),
            wait: None,
            placement: None,
            threads: None,
            stage_timeout: 0.0,
            realtime: None,
            complete: false,
            incomplete_reason: None,
            diverged: false,
            outside_theory: Vec::new(),
            platform: Platform::read(),
            files: Vec::new(),
        }
    }

    /// Lists every file now in `layout`'s directory into `files` and writes
    /// `manifest.json` there.
    ///
    /// # Errors
    /// A file cannot be read, or the manifest cannot be written.
    pub fn write(mut self, layout: &RunLayout) -> Result<(), WriteError> {
        let file = layout.manifest();
        self.files = list_files(layout.root()).map_err(writing(&file))?;
        let text = serde_json::to_string_pretty(&self).map_err(io::Error::other);
        text.and_then(|t| std::fs::write(&file, t + "\n"))
            .map_err(writing(&file))
    }

    /// Reads `layout`'s `manifest.json`.
    ///
    /// # Errors
    /// See [`ManifestError`].
    pub fn read(layout: &RunLayout) -> Result<Self, ManifestError> {
        let path = layout.manifest();
        let text = std::fs::read_to_string(&path).map_err(|source| ManifestError::Io {
            path: path.clone(),
            source,
        })?;
        let version = serde_json::from_str::<serde_json::Value>(&text)
            .ok()
            .and_then(|v| v.get("manifest_version")?.as_u64());
        if let Some(found) = version.filter(|&v| v != u64::from(MANIFEST_VERSION)) {
            let found = u32::try_from(found).unwrap_or(u32::MAX);
            return Err(ManifestError::Version { path, found });
        }
        let m: Self = serde_json::from_str(&text).map_err(|e| ManifestError::Parse {
            path: path.clone(),
            reason: e.to_string(),
        })?;
        if let Some(f) = m.files.iter().find(|f| f.within(layout.root()).is_none()) {
            let file = f.path.clone();
            return Err(ManifestError::Path { path, file });
        }
        Ok(m)
    }
}

/// Every file under `dir` except `manifest.json` itself, with its size and
/// SHA-256, sorted by relative path.
///
/// # Errors
/// A directory or file cannot be read.
pub fn list_files(dir: &Path) -> io::Result<Vec<FileEntry>> {
    let mut files = Vec::new();
    let mut todo = vec![PathBuf::new()];
    while let Some(rel) = todo.pop() {
        for e in std::fs::read_dir(dir.join(&rel))? {
            let e = e?;
            let rel = rel.join(e.file_name());
            if e.file_type()?.is_dir() {
                todo.push(rel);
                continue;
            }
            let path = (rel.iter())
                .map(|c| c.to_string_lossy())
                .collect::<Vec<_>>()
                .join("/");
            if path != MANIFEST {
                let (size, sha256) = digest::sha256_file(&dir.join(&rel))?;
                files.push(FileEntry { path, size, sha256 });
            }
        }
    }
    files.sort_by(|a, b| a.path.cmp(&b.path));
    Ok(files)
}

/// `t` as RFC 3339 UTC to the second (`1970-01-01T00:00:00Z` before the epoch).
#[must_use]
pub fn rfc3339(t: SystemTime) -> String {
    let secs = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let (days, s) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        s / 3600,
        s / 60 % 60,
        s % 60
    )
}

/// The proleptic Gregorian date `days` after 1970-01-01 (Hinnant's
/// `civil_from_days`, eras of 400 years).
fn civil_from_days(days: u64) -> (u64, u64, u64) {
    let z = days + 719_468;
    let era = z / 146_097;
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + u64::from(m <= 2);
    (y, m, d)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn start_times_are_rfc3339_utc() {
        let at = |s: u64| rfc3339(UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(at(1_796_169_599), "2026-12-01T23:59:59Z");
        assert_eq!(at(4_107_542_400), "2100-03-01T00:00:00Z");
    }

    #[test]
    fn the_listing_covers_subdirectories_but_not_the_manifest() {
        let dir = tempfile::tempdir().expect("tempdir");
        std::fs::create_dir(dir.path().join("logs")).expect("mkdir");
        std::fs::write(dir.path().join("logs/leader.log"), "abc").expect("write");
        std::fs::write(dir.path().join("errors.csv"), "").expect("write");
        std::fs::write(dir.path().join(MANIFEST), "{}").expect("write");
        let files = list_files(dir.path()).expect("listed");
        let paths: Vec<&str> = files.iter().map(|f| f.path.as_str()).collect();
        assert_eq!(paths, ["errors.csv", "logs/leader.log"]);
        assert_eq!(files[1].size, 3);
        assert_eq!(files[1].sha256, digest::sha256_hex(b"abc"));
    }

    #[test]
    fn listed_paths_stay_inside_the_directory() {
        let entry = |path: &str| FileEntry {
            path: path.into(),
            size: 0,
            sha256: String::new(),
        };
        let dir = Path::new("/r");
        assert_eq!(
            entry("logs/a.log").within(dir),
            Some("/r/logs/a.log".into())
        );
        for bad in ["", "/etc/passwd", "../x", "logs/../../x", "./x"] {
            assert_eq!(entry(bad).within(dir), None, "{bad}");
        }
    }
}
