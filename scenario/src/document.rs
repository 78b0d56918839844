//! [`Document`]: the effective TOML of a loaded scenario (its text with the
//! `--set` overrides applied), as written to a run's `scenario.toml`.

use super::parse;
use serde::ser::{Error as _, Serialize, Serializer};
use std::fmt;

/// The effective document, kept as the text and the overrides it came from
/// and read again (fast: `stream`) when written out, instead of as a tree
/// (at 10⁵ agents a `toml::Table` is several times the text). It
/// serialises exactly as the `toml::Table` toml would read and `--set`
/// would edit.
#[derive(Clone)]
pub struct Document {
    text: String,
    sets: Vec<String>,
}

impl Document {
    /// `text` with the overrides `sets` (every one of which applies).
    pub(super) fn new(text: String, sets: &[String]) -> Self {
        Self {
            text,
            sets: sets.to_vec(),
        }
    }

    /// The overrides (`--set key.path=value`), in the order given.
    #[must_use]
    pub fn sets(&self) -> &[String] {
        &self.sets
    }

    /// This document with one more override `set` (`key.path=value`),
    /// which must apply (a field the scenario already validated).
    #[must_use]
    pub fn with_set(&self, set: String) -> Self {
        let mut sets = self.sets.clone();
        sets.push(set);
        Self {
            text: self.text.clone(),
            sets,
        }
    }
}

impl Serialize for Document {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match parse::effective(&self.text, &self.sets) {
            Ok((tree, bad, _)) if bad.is_empty() => tree.serialize(serializer),
            _ => Err(S::Error::custom("the scenario no longer reads")),
        }
    }
}

impl fmt::Debug for Document {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Document")
            .field("bytes", &self.text.len())
            .field("sets", &self.sets)
            .finish()
    }
}
