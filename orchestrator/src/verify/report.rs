//! [`Report`]: what `attsync verify` found, printed as it is.

use super::compare::{RowDifference, StatesDifference};
use super::files::Changed;
use crate::results::layout::{ERRORS_CSV, STATES};
use crate::run::Engine;
use std::fmt;
use std::path::PathBuf;

/// What `attsync verify` found.
#[derive(Debug, Clone)]
pub struct Report {
    /// The results directory.
    pub dir: PathBuf,
    /// Who recorded it: attsync's version, git commit and engine.
    pub recorded_by: String,
    /// Files the manifest lists.
    pub listed: usize,
    /// The listed files that are not as recorded.
    pub changed: Vec<Changed>,
    /// The engine of the re-run.
    pub engine: Engine,
    /// Steps the re-run took, and its end time as `errors.csv` writes it.
    pub steps: (u64, String),
    /// The first difference of `states.bin`, if any.
    pub states: Option<StatesDifference>,
    /// The first difference of `errors.csv`, if any.
    pub errors: Option<RowDifference>,
}

impl Report {
    /// Whether every listed file is as recorded and the re-run wrote the
    /// same `states.bin` and `errors.csv`.
    #[must_use]
    pub fn is_identical(&self) -> bool {
        self.changed.is_empty() && self.states.is_none() && self.errors.is_none()
    }

    /// The last line: `bit-identical`, or `different: …` naming what differs.
    #[must_use]
    pub fn verdict(&self) -> String {
        if self.is_identical() {
            return "bit-identical".into();
        }
        let mut what = Vec::new();
        if !self.changed.is_empty() {
            what.push(format!(
                "{} of {} files not as recorded",
                self.changed.len(),
                self.listed
            ));
        }
        if self.states.is_some() {
            what.push(format!("the re-run's {STATES} differs"));
        }
        if self.errors.is_some() {
            what.push(format!("the re-run's {ERRORS_CSV} differs"));
        }
        format!("different: {}", what.join("; "))
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}: recorded by {}",
            self.dir.display(),
            self.recorded_by
        )?;
        match self.changed.len() {
            0 => writeln!(f, "files: {} listed, all as recorded", self.listed)?,
            n => {
                writeln!(f, "files: {} listed, {n} not as recorded:", self.listed)?;
                for c in &self.changed {
                    writeln!(f, "  {c}")?;
                }
            }
        }
        let (steps, t) = &self.steps;
        let engine = self.engine.name();
        writeln!(f, "re-run: {steps} steps to t = {t} s, {engine} engine")?;
        let same = "the same as recorded".to_owned();
        let states = self
            .states
            .as_ref()
            .map_or(same.clone(), ToString::to_string);
        writeln!(f, "{STATES}: {states}")?;
        let errors = self.errors.as_ref().map_or(same, ToString::to_string);
        writeln!(f, "{ERRORS_CSV}: {errors}")?;
        writeln!(f, "{}", self.verdict())
    }
}
