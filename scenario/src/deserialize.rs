//! The effective document → [`Scenario`], collecting every schema problem
//! (unknown key, wrong type, missing field) instead of stopping at the first.
//!
//! A valid document is read once, in place (`borrowed`: no copy of the
//! tree `stream` read). Only when that fails does the collecting pass
//! ([`collect`]) run, on a `toml::Table`.
//! serde stops at the first error; so after each one the offending value is
//! removed from a copy of the document and the copy deserialised again, until
//! it fits (or [`MAX_PROBLEMS`] are found). A missing field that is missing
//! only because it was removed is not reported again. Paths are reported in
//! the coordinates of the document as written (array indices count removed
//! elements).

use super::borrowed::TableRef;
use super::schema::Scenario;
use super::stream;
use serde::Deserialize;
use serde_path_to_error::Segment;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use toml::{Table, Value};

/// Most schema problems reported for one document.
pub const MAX_PROBLEMS: usize = 100;

/// One step of a path into the document.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Seg {
    /// A table key.
    Key(String),
    /// An array index (0-based).
    Index(usize),
}

/// A path into the document, displayed as `agent[1].observer.omega`.
#[derive(Debug, Clone, Default, PartialEq, Eq, PartialOrd, Ord)]
pub struct DocPath(pub Vec<Seg>);

impl fmt::Display for DocPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, s) in self.0.iter().enumerate() {
            match s {
                Seg::Key(k) if i == 0 => write!(f, "{k}")?,
                Seg::Key(k) => write!(f, ".{k}")?,
                Seg::Index(n) => write!(f, "[{n}]")?,
            }
        }
        Ok(())
    }
}

/// What kind of schema problem, which says where it is in the text.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A key the schema does not know (located at the key).
    UnknownKey,
    /// A required field is absent (located at the table that lacks it).
    Missing,
    /// A value of the wrong type or shape (located at the value).
    Value,
}

/// One schema problem.
#[derive(Debug, Clone)]
pub struct Problem {
    /// Where, in the document as written.
    pub path: DocPath,
    /// What kind.
    pub kind: Kind,
    /// serde's message (e.g. ``unknown field `colour`, expected …``).
    pub message: String,
}

/// The values removed so far, in written coordinates.
#[derive(Default)]
struct Removed {
    paths: BTreeSet<DocPath>,
    /// Array path → indices of the elements removed from it.
    elements: BTreeMap<DocPath, BTreeSet<usize>>,
}

impl Removed {
    /// `here` (a path into the edited copy) as a path into the document as written.
    fn written(&self, here: &[Seg]) -> DocPath {
        let mut out = DocPath::default();
        for s in here {
            let s = match s {
                Seg::Index(i) => {
                    let mut j = *i;
                    for &r in self.elements.get(&out).into_iter().flatten() {
                        if r <= j {
                            j += 1;
                        }
                    }
                    Seg::Index(j)
                }
                key => key.clone(),
            };
            out.0.push(s);
        }
        out
    }
}

/// `doc` as a [`Scenario`], or every problem found (at most [`MAX_PROBLEMS`]):
/// read in place first (through a tree that borrows its strings), and only
/// if that fails by [`collect`].
pub fn deserialize(doc: &Table) -> Result<Scenario, Vec<Problem>> {
    match Scenario::deserialize(TableRef(&stream::Table::of(doc))) {
        Ok(s) => Ok(s),
        Err(_) => collect(doc),
    }
}

/// As [`deserialize`], of the tree the fast path read (a copy as a
/// `toml::Table` is made only for the collecting pass).
pub(super) fn deserialize_tree(tree: &stream::Table<'_>) -> Result<Scenario, Vec<Problem>> {
    match Scenario::deserialize(TableRef(tree)) {
        Ok(s) => Ok(s),
        Err(_) => collect(&tree.to_toml()),
    }
}

/// `doc` as a [`Scenario`], or every problem found (at most
/// [`MAX_PROBLEMS`]), by the collecting pass alone (toml's own
/// deserializer, on a copy). [`deserialize`] gives the same result, faster
/// on a valid document.
pub fn collect(doc: &Table) -> Result<Scenario, Vec<Problem>> {
    collect_as(doc)
}

/// `doc` as a `T` (any file format of attsync's, e.g. a hosts file), or
/// every problem found (at most [`MAX_PROBLEMS`]), as [`collect`] does.
pub fn collect_as<T: serde::de::DeserializeOwned>(doc: &Table) -> Result<T, Vec<Problem>> {
    let mut copy = doc.clone();
    let mut removed = Removed::default();
    let mut problems = Vec::new();
    while problems.len() < MAX_PROBLEMS {
        let e = match serde_path_to_error::deserialize::<_, T>(Value::Table(copy.clone())) {
            Ok(s) if problems.is_empty() => return Ok(s),
            Ok(_) => break,
            Err(e) => e,
        };
        let here: Vec<Seg> = e
            .path()
            .iter()
            .map_while(|s| match s {
                Segment::Seq { index } => Some(Seg::Index(*index)),
                Segment::Map { key } => Some(Seg::Key(key.clone())),
                Segment::Enum { .. } | Segment::Unknown => None,
            })
            .collect();
        let message = e.inner().message().to_owned();
        let (kind, path) = match missing_field(&message) {
            Some(name) => {
                let mut p = removed.written(&here);
                p.0.push(Seg::Key(name.to_owned()));
                (Kind::Missing, p)
            }
            None if message.starts_with("unknown field `") => {
                (Kind::UnknownKey, removed.written(&here))
            }
            None => (Kind::Value, removed.written(&here)),
        };
        if !(kind == Kind::Missing && removed.paths.contains(&path)) {
            problems.push(Problem {
                path,
                kind,
                message,
            });
        }
        if !remove(&mut copy, &mut removed, here) {
            break;
        }
    }
    Err(problems)
}

/// The field's name of serde's ``missing field `x` `` message.
fn missing_field(message: &str) -> Option<&str> {
    message.strip_prefix("missing field `")?.split('`').next()
}

/// Removes the value at `here` from `copy` (a scalar inside an array takes
/// its whole array with it, so that fixed-length arrays are not reported
/// again as too short); `false` if there is nothing left to remove.
fn remove(copy: &mut Table, removed: &mut Removed, mut here: Vec<Seg>) -> bool {
    while matches!(here.last(), Some(Seg::Index(_)))
        && !get(copy, &here).is_some_and(Value::is_table)
    {
        here.pop();
    }
    let Some((last, parent)) = here.split_last() else {
        return false;
    };
    let written = removed.written(&here);
    let done = match (last, get_mut(copy, parent)) {
        (Seg::Key(k), None) if parent.is_empty() => copy.remove(k).is_some(),
        (Seg::Key(k), Some(Value::Table(t))) => t.remove(k).is_some(),
        (Seg::Index(i), Some(Value::Array(a))) if *i < a.len() => {
            a.remove(*i);
            if let Some(Seg::Index(w)) = written.0.last() {
                let array = DocPath(written.0[..written.0.len() - 1].to_vec());
                removed.elements.entry(array).or_default().insert(*w);
            }
            true
        }
        _ => false,
    };
    removed.paths.insert(written);
    done
}

fn get<'a>(copy: &'a Table, path: &[Seg]) -> Option<&'a Value> {
    let (first, rest) = path.split_first()?;
    let Seg::Key(k) = first else { return None };
    rest.iter().try_fold(copy.get(k)?, |v, s| match s {
        Seg::Key(k) => v.as_table()?.get(k),
        Seg::Index(i) => v.as_array()?.get(*i),
    })
}

fn get_mut<'a>(copy: &'a mut Table, path: &[Seg]) -> Option<&'a mut Value> {
    let (first, rest) = path.split_first()?;
    let Seg::Key(k) = first else { return None };
    rest.iter().try_fold(copy.get_mut(k)?, |v, s| match s {
        Seg::Key(k) => v.as_table_mut()?.get_mut(k),
        Seg::Index(i) => v.as_array_mut()?.get_mut(*i),
    })
}
