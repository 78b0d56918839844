//! `attsync mc merge DIR… --out DIR`: joins the directories of a Monte
//! Carlo's shards (`--shard K/N`, [`super::shard`]) into the files one run
//! of every trial writes, byte for byte.
//!
//! Nothing is run again. `trials.csv` rows are read back exactly (every
//! number was written in its shortest round-trip form,
//! [`report::parse_row`]); `initial.csv` rows are taken as written; the
//! summary (counts, bounds, failed and slowest trials) is recomputed from
//! the rows, and the reasons of the slowest trials come from the shards'
//! own `slowest` lists (the ten slowest of the whole are each among the
//! ten slowest of their shard). The shards must be of one Monte Carlo
//! (same scenario, engine, seed, trials, tolerance, dispersion, attsync),
//! each slice exactly once, each complete; otherwise nothing is written
//! and the error names the directory and what differs or is missing.

use super::driver::{Files, McRun};
use super::error::{McError, io_at};
use super::outcome::TrialResult;
use super::report::{self, McSummary};
use super::shard::ShardRange;
use crate::results::layout::McLayout;
use crate::results::staging::Staging;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Why shards cannot be merged.
#[derive(Debug, Error)]
pub enum MergeError {
    /// A directory holds a whole Monte Carlo, not a shard.
    #[error("{}: mc.json has no `shard`: not a run of `attsync mc --shard K/N`", dir.display())]
    NotAShard {
        /// The directory.
        dir: PathBuf,
    },
    /// A file is not what `attsync mc` writes.
    #[error("{}: {reason}", path.display())]
    Unreadable {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// Two directories are shards of different Monte Carlos.
    #[error("{}: {field} is {here} but {there} in {}: shards of different Monte Carlos", dir.display(), first.display())]
    Different {
        /// The directory that differs.
        dir: PathBuf,
        /// The first directory.
        first: PathBuf,
        /// The `mc.json` field (or `trials.csv header`).
        field: &'static str,
        /// Its value in `dir`.
        here: String,
        /// Its value in `first`.
        there: String,
    },
    /// A slice given twice.
    #[error("shard {index}/{count} given twice: {} and {}", a.display(), b.display())]
    Twice {
        /// `K`.
        index: u64,
        /// `N`.
        count: u64,
        /// One directory.
        a: PathBuf,
        /// The other.
        b: PathBuf,
    },
    /// Slices not given.
    #[error("shards {} of {count} missing (trials {trials}): give every shard's directory", missing.iter().map(u64::to_string).collect::<Vec<_>>().join(", "))]
    Missing {
        /// The missing `K`s.
        missing: Vec<u64>,
        /// `N`.
        count: u64,
        /// Their trials, as ranges.
        trials: String,
    },
    /// A shard stopped before its last trial.
    #[error("{}: shard {index}/{count} is incomplete ({ran} of {planned} trials ran): run it again", dir.display())]
    Incomplete {
        /// The directory.
        dir: PathBuf,
        /// `K`.
        index: u64,
        /// `N`.
        count: u64,
        /// Trials that ran.
        ran: u64,
        /// Trials of its slice.
        planned: u64,
    },
}

/// One shard's directory, read.
struct Part {
    dir: PathBuf,
    summary: McSummary,
    shard: ShardRange,
    header: String,
    results: Vec<TrialResult>,
    /// `initial.csv` without its header.
    initial: String,
}

/// Merges the shard directories `dirs` into `out` (atomically: all files
/// or none).
///
/// # Errors
/// [`McError::Merge`] for shards that do not make one whole Monte Carlo;
/// [`McError::Io`] for a file that cannot be read or written.
pub fn merge(dirs: &[PathBuf], out: &Path) -> Result<McRun, McError> {
    let mut parts = dirs
        .iter()
        .map(|d| read(d))
        .collect::<Result<Vec<_>, _>>()?;
    parts.sort_by_key(|p| p.shard.index);
    check(&parts)?;
    let first = &parts[0];
    let mut results: Vec<TrialResult> = parts.iter().flat_map(|p| p.results.clone()).collect();
    for p in &parts {
        for slow in &p.summary.slowest {
            if let Some(r) = results.iter_mut().find(|r| r.trial == slow.trial) {
                r.reason.clone_from(&slow.reason);
            }
        }
    }
    let head = McSummary {
        shard: None,
        ..first.summary.clone()
    };
    let summary = report::summarise(head, &results);
    let files = Files {
        header: first.header.clone(),
        initial: parts
            .iter()
            .fold(format!("{}\n", report::INITIAL_HEADER), |s, p| {
                s + &p.initial
            }),
        planned: summary.trials,
    };
    let staging = Staging::claim(out).map_err(|e| match e {
        e if e.is_refusal() => {
            McError::Options(crate::options::OptionError::Conflict(e.to_string()))
        }
        e => McError::Io {
            path: out.to_owned(),
            source: e.into(),
        },
    })?;
    files.write(staging.path(), &summary, &results)?;
    staging.commit().map_err(io_at(out))?;
    Ok(McRun {
        summary,
        results,
        wall_seconds: 0.0,
    })
}

/// Reads the shard in `dir`.
fn read(dir: &Path) -> Result<Part, McError> {
    let files = McLayout::new(dir);
    let text = |path: PathBuf| std::fs::read_to_string(&path).map_err(io_at(&path));
    let unreadable =
        |path: PathBuf, reason: String| McError::Merge(MergeError::Unreadable { path, reason });
    let summary: McSummary = serde_json::from_str(&text(files.json())?)
        .map_err(|e| unreadable(files.json(), e.to_string()))?;
    let shard = (summary.shard).ok_or_else(|| MergeError::NotAShard {
        dir: dir.to_owned(),
    })?;
    let trials = text(files.trials())?;
    let mut lines = trials.lines();
    let header = lines.next().unwrap_or_default().to_string();
    let results = (lines.enumerate())
        .map(|(k, row)| {
            report::parse_row(&header, row)
                .map_err(|e| unreadable(files.trials(), format!("line {}: {e}", k + 2)))
        })
        .collect::<Result<Vec<_>, _>>()?;
    let initial = text(files.initial())?;
    let initial = match initial.split_once('\n') {
        Some((h, rest)) if h == report::INITIAL_HEADER => rest.to_string(),
        _ => {
            return Err(unreadable(
                files.initial(),
                "not the header of initial.csv".into(),
            ));
        }
    };
    Ok(Part {
        dir: dir.to_owned(),
        summary,
        shard,
        header,
        results,
        initial,
    })
}

/// The parts (sorted by shard) are one Monte Carlo's every slice, each
/// complete.
fn check(parts: &[Part]) -> Result<(), MergeError> {
    let Some(first) = parts.first() else {
        return Err(MergeError::Missing {
            missing: Vec::new(),
            count: 0,
            trials: "all".into(),
        });
    };
    for p in parts {
        same(first, p)?;
        let planned = p.shard.end - p.shard.first;
        if !p.summary.complete || p.results.len() as u64 != planned {
            return Err(MergeError::Incomplete {
                dir: p.dir.clone(),
                index: p.shard.index,
                count: p.shard.count,
                ran: p.results.len() as u64,
                planned,
            });
        }
        let slice = super::shard::Shard {
            index: p.shard.index,
            count: p.shard.count,
        }
        .range(p.summary.trials);
        let trials: Vec<u64> = p.results.iter().map(|r| r.trial).collect();
        if slice != (p.shard.first..p.shard.end) || !trials.iter().copied().eq(slice) {
            return Err(MergeError::Unreadable {
                path: McLayout::new(&p.dir).trials(),
                reason: format!(
                    "its trials are not those of shard {}/{} of {}",
                    p.shard.index, p.shard.count, p.summary.trials
                ),
            });
        }
    }
    for w in parts.windows(2) {
        if w[0].shard.index == w[1].shard.index {
            return Err(MergeError::Twice {
                index: w[0].shard.index,
                count: w[0].shard.count,
                a: w[0].dir.clone(),
                b: w[1].dir.clone(),
            });
        }
    }
    let count = first.shard.count;
    let given: Vec<u64> = parts.iter().map(|p| p.shard.index).collect();
    let missing: Vec<u64> = (1..=count).filter(|k| !given.contains(k)).collect();
    if !missing.is_empty() {
        let trials = (missing.iter())
            .map(|&index| {
                let r = super::shard::Shard { index, count }.range(first.summary.trials);
                format!("{}..{}", r.start, r.end)
            })
            .collect::<Vec<_>>()
            .join(", ");
        return Err(MergeError::Missing {
            missing,
            count,
            trials,
        });
    }
    Ok(())
}

/// `p` is a shard of the same Monte Carlo as `first`.
fn same(first: &Part, p: &Part) -> Result<(), MergeError> {
    let (a, b) = (&first.summary, &p.summary);
    let differ = |field: &'static str, there: String, here: String| {
        (here != there).then(|| MergeError::Different {
            dir: p.dir.clone(),
            first: first.dir.clone(),
            field,
            here,
            there,
        })
    };
    let json = |d: &super::Dispersion| serde_json::to_string(d).unwrap_or_default();
    let checks = [
        differ(
            "attsync_version",
            a.attsync_version.clone(),
            b.attsync_version.clone(),
        ),
        differ("scenario", a.scenario.clone(), b.scenario.clone()),
        differ("engine", a.engine.clone(), b.engine.clone()),
        differ("seed", a.seed.to_string(), b.seed.to_string()),
        differ("trials", a.trials.to_string(), b.trials.to_string()),
        differ(
            "shard.count",
            first.shard.count.to_string(),
            p.shard.count.to_string(),
        ),
        differ("duration", a.duration.to_string(), b.duration.to_string()),
        differ(
            "tolerance",
            a.tolerance.to_string(),
            b.tolerance.to_string(),
        ),
        differ("until", format!("{:?}", a.until), format!("{:?}", b.until)),
        differ("criterion", a.criterion.clone(), b.criterion.clone()),
        differ("dispersion", json(&a.dispersion), json(&b.dispersion)),
        differ("trials.csv header", first.header.clone(), p.header.clone()),
    ];
    checks.into_iter().flatten().next().map_or(Ok(()), Err)
}
