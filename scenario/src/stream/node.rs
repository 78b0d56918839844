//! The tree the fast path builds: the same data model as `toml::Value`
//! (strings, 64-bit integers, floats, booleans, datetimes, arrays, tables
//! with sorted keys), in 32 bytes a node, with keys and strings borrowed
//! from the text where they need no decoding.

use crate::overrides::{Tree, TreeValue};
use serde::ser::{Serialize, SerializeMap, Serializer};
use std::borrow::Cow;
use toml::Value;
use toml::value::Datetime;

/// One value of the document.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Node<'a> {
    /// A string, decoded.
    String(Cow<'a, str>),
    /// An integer (toml's range: `i64`).
    Integer(i64),
    /// A float.
    Float(f64),
    /// A boolean.
    Boolean(bool),
    /// A datetime (boxed: rare, and it would double the node).
    Datetime(Box<Datetime>),
    /// An array; `true` if made by `[[header]]`s (an array of tables).
    Array(bool, Vec<Node<'a>>),
    /// A table.
    Table(Table<'a>),
}

/// How a table was made, which decides how it may be extended (TOML's
/// rules, as toml 0.9's `de/parser/document.rs` applies them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Made {
    /// Made on the way to a key or header (not defined by its own header).
    pub(crate) implicit: bool,
    /// Made by a dotted key.
    pub(crate) dotted: bool,
    /// Written `{ … }` (closed to any later key).
    pub(crate) inline: bool,
}

/// A table: its entries sorted by key (as in `toml::Table`, a `BTreeMap`).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Table<'a> {
    /// How it was made.
    pub(crate) made: Made,
    entries: Vec<(Cow<'a, str>, Node<'a>)>,
}

impl<'a> Table<'a> {
    /// An empty table made as `made`.
    pub(crate) fn new(made: Made) -> Self {
        Self {
            made,
            entries: Vec::new(),
        }
    }

    /// The entries, sorted by key.
    pub(crate) fn iter(&self) -> std::slice::Iter<'_, (Cow<'a, str>, Node<'a>)> {
        self.entries.iter()
    }

    /// How many entries.
    pub(crate) fn len(&self) -> usize {
        self.entries.len()
    }

    fn find(&self, key: &str) -> Result<usize, usize> {
        self.entries.binary_search_by(|(k, _)| k.as_ref().cmp(key))
    }

    /// The value at `key`.
    pub(crate) fn get(&self, key: &str) -> Option<&Node<'a>> {
        self.find(key).ok().map(|i| &self.entries[i].1)
    }

    /// The value at `key`, to change.
    pub(crate) fn get_mut(&mut self, key: &str) -> Option<&mut Node<'a>> {
        self.find(key).ok().map(|i| &mut self.entries[i].1)
    }

    /// The value at `key`, `make()` inserted first if there is none.
    pub(crate) fn get_or_insert(
        &mut self,
        key: Cow<'a, str>,
        make: impl FnOnce() -> Node<'a>,
    ) -> &mut Node<'a> {
        let i = match self.find(&key) {
            Ok(i) => i,
            Err(i) => {
                self.entries.insert(i, (key, make()));
                i
            }
        };
        &mut self.entries[i].1
    }

    /// Inserts `value` at `key`; `false` (and no change) if `key` is taken.
    #[must_use]
    pub(crate) fn insert_new(&mut self, key: Cow<'a, str>, value: Node<'a>) -> bool {
        match self.find(&key) {
            Ok(_) => false,
            Err(i) => {
                self.entries.insert(i, (key, value));
                true
            }
        }
    }

    /// Sets `key` to `value`, replacing what was there.
    pub(crate) fn set(&mut self, key: Cow<'a, str>, value: Node<'a>) {
        match self.find(&key) {
            Ok(i) => self.entries[i].1 = value,
            Err(i) => self.entries.insert(i, (key, value)),
        }
    }

    /// Removes `key`'s value.
    pub(crate) fn remove(&mut self, key: &str) -> Option<Node<'a>> {
        self.find(key).ok().map(|i| self.entries.remove(i).1)
    }

    /// `t` as a tree, borrowing its keys and strings.
    pub(crate) fn of(t: &'a toml::Table) -> Self {
        Self {
            made: Made::default(),
            entries: t
                .iter()
                .map(|(k, v)| (Cow::Borrowed(k.as_str()), Node::of(v)))
                .collect(),
        }
    }

    /// As a `toml::Table` (a copy, for the collecting pass).
    pub(crate) fn to_toml(&self) -> toml::Table {
        self.iter()
            .map(|(k, v)| (k.clone().into_owned(), v.to_toml()))
            .collect()
    }
}

impl<'a> Node<'a> {
    /// `v` as a tree, borrowing its keys and strings.
    pub(crate) fn of(v: &'a Value) -> Self {
        match v {
            Value::String(s) => Self::String(Cow::Borrowed(s)),
            Value::Integer(n) => Self::Integer(*n),
            Value::Float(x) => Self::Float(*x),
            Value::Boolean(b) => Self::Boolean(*b),
            Value::Datetime(d) => Self::Datetime(Box::new(*d)),
            Value::Array(a) => Self::Array(false, a.iter().map(Self::of).collect()),
            Value::Table(t) => Self::Table(Table::of(t)),
        }
    }

    /// As a `toml::Value` (a copy).
    pub(crate) fn to_toml(&self) -> Value {
        match self {
            Self::String(s) => Value::String(s.clone().into_owned()),
            Self::Integer(n) => Value::Integer(*n),
            Self::Float(x) => Value::Float(*x),
            Self::Boolean(b) => Value::Boolean(*b),
            Self::Datetime(d) => Value::Datetime(**d),
            Self::Array(_, a) => Value::Array(a.iter().map(Self::to_toml).collect()),
            Self::Table(t) => Value::Table(t.to_toml()),
        }
    }
}

/// Serialised exactly as the `toml::Value` it stands for (so
/// `toml::to_string` writes the same bytes).
impl Serialize for Node<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Self::String(s) => serializer.serialize_str(s),
            Self::Integer(n) => serializer.serialize_i64(*n),
            Self::Float(x) => serializer.serialize_f64(*x),
            Self::Boolean(b) => serializer.serialize_bool(*b),
            Self::Datetime(d) => d.serialize(serializer),
            Self::Array(_, a) => serializer.collect_seq(a),
            Self::Table(t) => t.serialize(serializer),
        }
    }
}

/// Serialised exactly as the `toml::Table` it stands for.
impl Serialize for Table<'_> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(Some(self.len()))?;
        for (k, v) in self.iter() {
            map.serialize_key(k)?;
            map.serialize_value(v)?;
        }
        map.end()
    }
}

/// `v` as a tree that owns its strings (an override's value).
impl From<Value> for Node<'static> {
    fn from(v: Value) -> Self {
        match v {
            Value::String(s) => Self::String(Cow::Owned(s)),
            Value::Integer(n) => Self::Integer(n),
            Value::Float(x) => Self::Float(x),
            Value::Boolean(b) => Self::Boolean(b),
            Value::Datetime(d) => Self::Datetime(Box::new(d)),
            Value::Array(a) => Self::Array(false, a.into_iter().map(Self::from).collect()),
            Value::Table(t) => Self::Table(t.into()),
        }
    }
}

/// `t` as a tree that owns its strings (a document toml's parser read).
impl From<toml::Table> for Table<'static> {
    fn from(t: toml::Table) -> Self {
        Self {
            made: Made::default(),
            entries: t
                .into_iter()
                .map(|(k, v)| (Cow::Owned(k), Node::from(v)))
                .collect(),
        }
    }
}

impl<'a> Tree for Table<'a> {
    type Value = Node<'a>;
    fn get(&self, key: &str) -> Option<&Node<'a>> {
        Table::get(self, key)
    }
    fn get_mut(&mut self, key: &str) -> Option<&mut Node<'a>> {
        Table::get_mut(self, key)
    }
    fn get_or_table(&mut self, key: &str) -> &mut Node<'a> {
        self.get_or_insert(Cow::Owned(key.to_owned()), || Node::Table(Table::default()))
    }
    fn set(&mut self, key: &str, value: Node<'a>) {
        Table::set(self, Cow::Owned(key.to_owned()), value);
    }
}

impl<'a> TreeValue for Node<'a> {
    type Tree = Table<'a>;
    fn from_toml(value: Value) -> Self {
        Node::from(value)
    }
    fn as_table(&self) -> Option<&Table<'a>> {
        match self {
            Self::Table(t) => Some(t),
            _ => None,
        }
    }
    fn as_table_mut(&mut self) -> Option<&mut Table<'a>> {
        match self {
            Self::Table(t) => Some(t),
            _ => None,
        }
    }
    fn as_array(&self) -> Option<&[Self]> {
        match self {
            Self::Array(_, a) => Some(a),
            _ => None,
        }
    }
    fn as_array_mut(&mut self) -> Option<&mut [Self]> {
        match self {
            Self::Array(_, a) => Some(a),
            _ => None,
        }
    }
}
