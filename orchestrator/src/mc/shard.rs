//! `--shard K/N`: one of `N` slices of a Monte Carlo's trials, so that a
//! job array (Slurm, GNU parallel, a Dask cluster) spreads one Monte Carlo
//! over many machines; `attsync mc merge` joins the slices' directories
//! into the files one run would have written ([`mod@super::merge`]).
//!
//! Shard `K` of `N` runs the trials `⌊(K−1)·T/N⌋ .. ⌊K·T/N⌋` of `T`: the
//! slices are contiguous, disjoint, cover every trial and differ in size
//! by at most one. Trial `k` draws from its own seed whatever the slice
//! ([`super::trial_seed`]), so each trial is the one a single run makes.

use crate::options::OptionError;
use serde::{Deserialize, Serialize};
use std::ops::Range;
use std::str::FromStr;

/// `--shard K/N`: slice `index` (1-based) of `count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// `K`, 1 ≤ K ≤ N.
    pub index: u64,
    /// `N` ≥ 1.
    pub count: u64,
}

impl FromStr for Shard {
    type Err = OptionError;

    fn from_str(s: &str) -> Result<Self, OptionError> {
        let bad = || OptionError::OutOfRange {
            option: "--shard",
            value: s.to_string(),
            expected: "K/N with 1 ≤ K ≤ N (for example 2/8)".into(),
        };
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            k.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if !(1..=count).contains(&index) {
            return Err(bad());
        }
        Ok(Self { index, count })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// The trials of this slice of `trials`.
    #[must_use]
    pub fn range(self, trials: u64) -> Range<u64> {
        let at = |k: u64| (u128::from(k) * u128::from(trials) / u128::from(self.count)) as u64;
        at(self.index - 1)..at(self.index)
    }

    /// Refuses `K` outside `1..=N`, and more slices than trials (a slice
    /// would be empty).
    ///
    /// # Errors
    /// Either.
    pub fn check(self, trials: u64) -> Result<(), OptionError> {
        if !(1..=self.count).contains(&self.index) {
            return Err(OptionError::OutOfRange {
                option: "--shard",
                value: self.to_string(),
                expected: "K/N with 1 ≤ K ≤ N (for example 2/8)".into(),
            });
        }
        if self.count > trials {
            return Err(OptionError::Conflict(format!(
                "--shard {self}: {} slices of {trials} trials (at most one slice per trial)",
                self.count
            )));
        }
        Ok(())
    }

    /// What `mc.json` records of this slice of `trials`.
    #[must_use]
    pub fn of(self, trials: u64) -> ShardRange {
        let r = self.range(trials);
        ShardRange {
            index: self.index,
            count: self.count,
            first: r.start,
            end: r.end,
        }
    }
}

/// `mc.json` `shard`: which slice a directory holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ShardRange {
    /// `K` of `--shard K/N`.
    pub index: u64,
    /// `N`.
    pub count: u64,
    /// Its first trial.
    pub first: u64,
    /// One past its last trial.
    pub end: u64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slices_are_contiguous_disjoint_and_cover_every_trial() {
        for trials in 1..40u64 {
            for count in 1..=trials {
                let mut next = 0;
                for index in 1..=count {
                    let r = Shard { index, count }.range(trials);
                    assert_eq!(r.start, next);
                    let len = r.end - r.start;
                    assert!(len == trials / count || len == trials / count + 1);
                    next = r.end;
                }
                assert_eq!(next, trials);
            }
        }
        assert_eq!(Shard { index: 3, count: 3 }.range(u64::MAX).end, u64::MAX);
    }

    #[test]
    fn k_over_n_is_parsed_and_checked() {
        assert_eq!("2/3".parse(), Ok(Shard { index: 2, count: 3 }));
        for bad in ["0/3", "4/3", "3", "a/b", "1/0", "-1/2", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        assert!(Shard { index: 1, count: 5 }.check(4).is_err());
        assert!(Shard { index: 1, count: 4 }.check(4).is_ok());
        assert!(Shard { index: 0, count: 4 }.check(4).is_err());
        assert!(Shard { index: 5, count: 4 }.check(9).is_err());
    }
}
