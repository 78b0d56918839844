//! `--set key.path=value`: overrides of any scenario field, applied to the
//! parsed TOML before it is checked.
//!
//! Paths use TOML keys separated by dots; array elements are selected with a
//! 0-based index in brackets: `agent[2].omega=[0, 0, 1]`,
//! `simulation.duration=10`, `scheme.kind="observerless"`. The value is read
//! as a TOML value; if that fails it is taken as a string (`scheme.kind=observerless`).

use thiserror::Error;
use toml::{Table, Value};

/// Why one `--set` override could not be applied.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum OverrideError {
    /// There is no `=` between the key path and the value.
    #[error("expected key.path=value")]
    NoEquals,
    /// The key path is empty.
    #[error("empty key path")]
    EmptyPath,
    /// A segment of the path is neither `key` nor `key[index]`.
    #[error("bad path segment `{0}`")]
    BadSegment(String),
    /// The path goes through a value that is not a table.
    #[error("`{0}` is not a table")]
    NotATable(String),
    /// An index is applied to a value that is not an array.
    #[error("`{0}` is not an array")]
    NotAnArray(String),
    /// The indexed array does not exist.
    #[error("no array `{0}`")]
    NoArray(String),
    /// The index is past the end of the array.
    #[error("`{key}[{index}]`: index out of range (it has {len} elements)")]
    OutOfRange {
        /// The array's key.
        key: String,
        /// The index asked for.
        index: usize,
        /// The array's length.
        len: usize,
    },
}

/// The key path of an override (`agent[2].omega` of `agent[2].omega=[0, 0, 1]`).
#[must_use]
pub fn path_of(spec: &str) -> Option<&str> {
    spec.split_once('=').map(|(path, _)| path.trim())
}

/// A document `--set` edits: toml's [`Table`], or the tree the fast path
/// reads (`scenario::stream`).
pub trait Tree: Sized {
    /// Its values.
    type Value: TreeValue<Tree = Self>;
    /// The value at `key`.
    fn get(&self, key: &str) -> Option<&Self::Value>;
    /// The value at `key`, to change.
    fn get_mut(&mut self, key: &str) -> Option<&mut Self::Value>;
    /// The value at `key`, an empty table inserted first if there is none.
    fn get_or_table(&mut self, key: &str) -> &mut Self::Value;
    /// Sets `key` to `value`.
    fn set(&mut self, key: &str, value: Self::Value);
}

/// A value of a [`Tree`].
pub trait TreeValue: Sized {
    /// The tree's tables.
    type Tree;
    /// `value` (an override's) as a value of the tree.
    fn from_toml(value: Value) -> Self;
    /// The table, if it is one.
    fn as_table(&self) -> Option<&Self::Tree>;
    /// The table, to change, if it is one.
    fn as_table_mut(&mut self) -> Option<&mut Self::Tree>;
    /// The elements, if it is an array.
    fn as_array(&self) -> Option<&[Self]>;
    /// The elements, to change, if it is an array.
    fn as_array_mut(&mut self) -> Option<&mut [Self]>;
}

impl Tree for Table {
    type Value = Value;
    fn get(&self, key: &str) -> Option<&Value> {
        Table::get(self, key)
    }
    fn get_mut(&mut self, key: &str) -> Option<&mut Value> {
        Table::get_mut(self, key)
    }
    fn get_or_table(&mut self, key: &str) -> &mut Value {
        self.entry(key)
            .or_insert_with(|| Value::Table(Table::new()))
    }
    fn set(&mut self, key: &str, value: Value) {
        self.insert(key.to_owned(), value);
    }
}

impl TreeValue for Value {
    type Tree = Table;
    fn from_toml(value: Value) -> Self {
        value
    }
    fn as_table(&self) -> Option<&Table> {
        Value::as_table(self)
    }
    fn as_table_mut(&mut self) -> Option<&mut Table> {
        Value::as_table_mut(self)
    }
    fn as_array(&self) -> Option<&[Value]> {
        Value::as_array(self).map(Vec::as_slice)
    }
    fn as_array_mut(&mut self) -> Option<&mut [Value]> {
        Value::as_array_mut(self).map(Vec::as_mut_slice)
    }
}

/// Applies one `key.path=value` override to `doc`; on an error `doc` is
/// left as it was (the path is walked read-only first, so that a large
/// document need not be copied to keep a half-applied override out).
pub fn apply<T: Tree>(doc: &mut T, spec: &str) -> Result<(), OverrideError> {
    let (path, raw) = spec.split_once('=').ok_or(OverrideError::NoEquals)?;
    let value = T::Value::from_toml(parse_value(raw.trim()));
    let segments = parse_path(path.trim())?;
    check(doc, &segments)?;
    set(doc, &segments, value)
}

/// The value at `path` (`agent[2].omega`) in `doc`, if there is one: what
/// an override of `path` set, read back.
#[must_use]
pub fn get<'a>(doc: &'a Table, path: &str) -> Option<&'a Value> {
    let segments = parse_path(path.trim()).ok()?;
    let (last, parents) = segments.split_last()?;
    let mut table = doc;
    for (key, index) in parents {
        let mut v = table.get(key)?;
        if let Some(k) = index {
            v = index_ref(v, key, *k).ok()?;
        }
        table = v.as_table()?;
    }
    let (key, index) = last;
    let v = table.get(key)?;
    match index {
        Some(k) => index_ref(v, key, *k).ok(),
        None => Some(v),
    }
}

/// A path of `(key, index)` segments.
type Segments = [(String, Option<usize>)];

/// The errors [`set`] would meet on `doc`, without changing it: a missing
/// key on the way is a table `set` creates (empty: indexing it fails).
fn check<T: Tree>(doc: &T, segments: &Segments) -> Result<(), OverrideError> {
    let (last, parents) = segments
        .split_last()
        .expect("parse_path returns ≥ 1 segment");
    let mut table = Some(doc);
    for (key, index) in parents {
        let entry = match (table.and_then(|t| t.get(key)), index) {
            (None, Some(_)) => return Err(OverrideError::NotAnArray(key.clone())),
            (None, None) => None,
            (Some(v), Some(k)) => Some(index_ref(v, key, *k)?),
            (Some(v), None) => Some(v),
        };
        table = entry
            .map(|v| {
                v.as_table()
                    .ok_or_else(|| OverrideError::NotATable(key.clone()))
            })
            .transpose()?;
    }
    let (key, index) = last;
    if let Some(k) = index {
        let entry = table
            .and_then(|t| t.get(key))
            .ok_or_else(|| OverrideError::NoArray(key.clone()))?;
        index_ref(entry, key, *k)?;
    }
    Ok(())
}

/// Sets the value at `segments` in `doc`, creating missing tables.
fn set<T: Tree>(doc: &mut T, segments: &Segments, value: T::Value) -> Result<(), OverrideError> {
    let (last, parents) = segments
        .split_last()
        .expect("parse_path returns ≥ 1 segment");
    let mut table = doc;
    for (key, index) in parents {
        let entry = table.get_or_table(key);
        let entry = match index {
            Some(k) => index_into(entry, key, *k)?,
            None => entry,
        };
        table = entry
            .as_table_mut()
            .ok_or_else(|| OverrideError::NotATable(key.clone()))?;
    }
    let (key, index) = last;
    match index {
        Some(k) => {
            let entry = table
                .get_mut(key)
                .ok_or_else(|| OverrideError::NoArray(key.clone()))?;
            *index_into(entry, key, *k)? = value;
        }
        None => table.set(key, value),
    }
    Ok(())
}

fn index_ref<'a, V: TreeValue>(v: &'a V, key: &str, k: usize) -> Result<&'a V, OverrideError> {
    let arr = v
        .as_array()
        .ok_or_else(|| OverrideError::NotAnArray(key.to_owned()))?;
    arr.get(k).ok_or_else(|| OverrideError::OutOfRange {
        key: key.to_owned(),
        index: k,
        len: arr.len(),
    })
}

fn index_into<'a, V: TreeValue>(
    v: &'a mut V,
    key: &str,
    k: usize,
) -> Result<&'a mut V, OverrideError> {
    let arr = v
        .as_array_mut()
        .ok_or_else(|| OverrideError::NotAnArray(key.to_owned()))?;
    let len = arr.len();
    arr.get_mut(k).ok_or_else(|| OverrideError::OutOfRange {
        key: key.to_owned(),
        index: k,
        len,
    })
}

fn parse_value(raw: &str) -> Value {
    format!("v = {raw}")
        .parse::<Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| Value::String(raw.to_string()))
}

fn parse_path(path: &str) -> Result<Vec<(String, Option<usize>)>, OverrideError> {
    if path.is_empty() {
        return Err(OverrideError::EmptyPath);
    }
    path.split('.')
        .map(|seg| {
            let bad = || OverrideError::BadSegment(seg.to_owned());
            match seg.split_once('[') {
                None if !seg.is_empty() => Ok((seg.to_string(), None)),
                None => Err(bad()),
                Some((name, rest)) => {
                    let idx = rest.strip_suffix(']').ok_or_else(bad)?;
                    let idx = idx.parse::<usize>().map_err(|_| bad())?;
                    if name.is_empty() {
                        return Err(bad());
                    }
                    Ok((name.to_string(), Some(idx)))
                }
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_nested_and_indexed_fields() {
        let mut t: Table = "[simulation]\ndt = 0.001\n[[agent]]\nid = 1\n[[agent]]\nid = 2\n"
            .parse()
            .unwrap();
        apply(&mut t, "simulation.duration=10").unwrap();
        apply(&mut t, "agent[1].omega=[0, 0, 1]").unwrap();
        apply(&mut t, "scheme.kind=observerless").unwrap();
        assert_eq!(t["simulation"]["duration"].as_integer(), Some(10));
        assert_eq!(t["agent"][1]["omega"][2].as_integer(), Some(1));
        assert_eq!(t["scheme"]["kind"].as_str(), Some("observerless"));
        assert!(
            apply(&mut t, "agent[5].id=3")
                .unwrap_err()
                .to_string()
                .contains("out of range")
        );
        assert!(apply(&mut t, "no_equals").is_err());
    }

    #[test]
    fn a_failed_override_leaves_the_document_as_it_was() {
        let text = "[simulation]\ndt = 0.001\n[[agent]]\nid = 1\n";
        let mut t: Table = text.parse().unwrap();
        let before = t.clone();
        for (spec, error) in [
            (
                "new.deeper[0].x=1",
                OverrideError::NotAnArray("deeper".into()),
            ),
            (
                "new.deeper.list[0]=1",
                OverrideError::NoArray("list".into()),
            ),
            ("simulation.dt.x=1", OverrideError::NotATable("dt".into())),
            (
                "simulation[0].dt=1",
                OverrideError::NotAnArray("simulation".into()),
            ),
            ("agent[0].id.x=2", OverrideError::NotATable("id".into())),
            (
                "agent[3].id=2",
                OverrideError::OutOfRange {
                    key: "agent".into(),
                    index: 3,
                    len: 1,
                },
            ),
        ] {
            assert_eq!(apply(&mut t, spec), Err(error), "{spec}");
            assert_eq!(t, before, "{spec} left a change behind");
        }
        apply(&mut t, "new.deeper.x=1").unwrap();
        assert_eq!(t["new"]["deeper"]["x"].as_integer(), Some(1));
    }
}
