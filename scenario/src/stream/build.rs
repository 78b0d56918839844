//! `toml_parser`'s events → the tree, as they come (no event vector).
//!
//! The rules for where a key or a header's table goes, and when it may not
//! go there, are toml 0.9's (`de/parser/document.rs`: `capture_key_value`,
//! `finish_table`, `start_table`, `descend_path`; `inline_table.rs`), so a
//! document read here is the `toml::Table` toml reads. Wherever toml would
//! report an error, or an event comes that a valid document does not have,
//! the builder gives up (`refused`) and the text goes to toml's own parser,
//! which says what is wrong in its own words.

use super::node::{Made, Node, Table};
use super::scalar;
use std::borrow::Cow;
use toml_parser::decoder::Encoding;
use toml_parser::parser::{Event, EventKind, EventReceiver};
use toml_parser::{ErrorSink, Source, Span};

/// toml's limit on nesting and on the keys of a dotted key (`LIMIT` of
/// `de/parser/mod.rs`).
pub(super) const LIMIT: u32 = 80;

/// A dotted key, one decoded part each.
type Keys<'a> = Vec<Cow<'a, str>>;

/// A value being read: an array (its elements so far are
/// `Builder::items[start..]`), or an inline table with the key of its next
/// value.
enum Open<'a> {
    Array { start: usize },
    Inline(Table<'a>, Keys<'a>),
}

/// A `[header]` or `[[header]]`.
struct Header<'a> {
    keys: Keys<'a>,
    array: bool,
}

/// The tree so far, and what is being read.
pub(super) struct Builder<'a> {
    source: Source<'a>,
    root: Table<'a>,
    /// The keys since the last header (toml's `current_table`).
    current: Table<'a>,
    /// The header `current` goes under (`None`: the root's own keys).
    header: Option<Header<'a>>,
    /// The key being read: of a header, or of a key/value outside `{ … }`.
    keys: Keys<'a>,
    /// While a header's keys are read: whether it is `[[…]]`.
    in_header: Option<bool>,
    open: Vec<Open<'a>>,
    /// The elements of the open arrays, innermost last (each array is then
    /// allocated once, at its length).
    items: Vec<Node<'a>>,
    /// Not a document this path reads (toml's parser will say why).
    pub(super) refused: bool,
}

impl<'a> Builder<'a> {
    pub(super) fn new(source: Source<'a>) -> Self {
        Self {
            source,
            root: Table::default(),
            current: Table::default(),
            header: None,
            keys: Vec::new(),
            in_header: None,
            open: Vec::new(),
            items: Vec::new(),
            refused: false,
        }
    }

    /// The document, once every event is in; `None` if refused.
    pub(super) fn finish(mut self) -> Option<Table<'a>> {
        self.finish_table();
        let done = self.open.is_empty() && self.keys.is_empty() && self.in_header.is_none();
        (done && !self.refused).then_some(self.root)
    }

    /// `ok`, or refused from now on.
    fn check(&mut self, ok: bool) {
        self.refused |= !ok;
    }

    /// A complete value: into its array, its inline table, or the current table.
    fn value(&mut self, node: Node<'a>) {
        let ok = match self.open.last_mut() {
            Some(Open::Array { .. }) => {
                self.items.push(node);
                true
            }
            Some(Open::Inline(table, keys)) => insert(table, keys, node, true),
            None if self.in_header.is_none() => {
                insert(&mut self.current, &mut self.keys, node, false)
            }
            None => false,
        };
        self.check(ok);
    }

    /// toml's `finish_table`: the current table into the root, under its header.
    fn finish_table(&mut self) {
        let table = std::mem::take(&mut self.current);
        let Some(Header { mut keys, array }) = self.header.take() else {
            self.root = table;
            return;
        };
        let Some(key) = keys.pop() else {
            return self.check(false);
        };
        let Some(parent) = descend(&mut self.root, keys, false, false) else {
            return self.check(false);
        };
        let ok = if array {
            match parent.get_or_insert(key, || Node::Array(true, Vec::new())) {
                Node::Array(true, tables) => {
                    tables.push(Node::Table(table));
                    true
                }
                _ => false,
            }
        } else {
            parent.insert_new(key, Node::Table(table))
        };
        self.check(ok);
    }

    /// toml's `start_table`: a `[header]` may take over a table made on the
    /// way to an earlier header, nothing else that exists.
    fn start_table(&mut self, header: Header<'a>) {
        if !header.array {
            let Some((key, path)) = header.keys.split_last() else {
                return self.check(false);
            };
            let Some(parent) = descend(&mut self.root, path.iter().cloned(), false, false) else {
                return self.check(false);
            };
            match parent.remove(key) {
                None => {}
                Some(Node::Table(t)) if t.made.implicit && !t.made.dotted => self.current = t,
                Some(_) => return self.check(false),
            }
        }
        self.current.made.implicit = false;
        self.current.made.dotted = false;
        self.header = Some(header);
    }

    fn open_header(&mut self, array: bool) {
        self.finish_table();
        self.check(self.in_header.is_none() && self.keys.is_empty() && self.open.is_empty());
        self.in_header = Some(array);
    }

    fn close_header(&mut self, array: bool) {
        let keys = std::mem::take(&mut self.keys);
        self.check(self.in_header == Some(array) && !keys.is_empty() && short(&keys));
        self.in_header = None;
        if !self.refused {
            self.start_table(Header { keys, array });
        }
    }
}

/// Whether a dotted key is within toml's limit.
fn short(keys: &[Cow<'_, str>]) -> bool {
    keys.len() <= LIMIT as usize
}

/// `value` at the dotted key `keys` (emptied) under `table` (toml's
/// `capture_key_value`, or `finish_value` in `{ … }` if `inline`).
#[must_use]
fn insert<'a>(table: &mut Table<'a>, keys: &mut Keys<'a>, value: Node<'a>, inline: bool) -> bool {
    if !short(keys) {
        return false;
    }
    let Some(key) = keys.pop() else { return false };
    let dotted = !keys.is_empty();
    let Some(parent) = descend(table, keys.drain(..), true, inline) else {
        return false;
    };
    // "using dotted keys to redefine tables already defined in [table] form is not allowed"
    parent.made.dotted == dotted && parent.insert_new(key, value)
}

/// The table at `path` under `table`, tables made on the way (toml's
/// `descend_path`; in `{ … }` if `inline`); `None` where toml reports an error.
fn descend<'t, 'a>(
    mut table: &'t mut Table<'a>,
    path: impl IntoIterator<Item = Cow<'a, str>>,
    dotted: bool,
    inline: bool,
) -> Option<&'t mut Table<'a>> {
    for key in path {
        let made = Made {
            implicit: true,
            dotted,
            inline,
        };
        table = match table.get_or_insert(key, || Node::Table(Table::new(made))) {
            Node::Array(true, tables) if !inline => match tables.last_mut() {
                Some(Node::Table(t)) => t,
                _ => return None,
            },
            Node::Table(t) if t.made.inline && !inline => return None,
            Node::Table(t) if dotted && !t.made.implicit => return None,
            Node::Table(t) => t,
            _ => return None,
        };
    }
    Some(table)
}

impl EventReceiver for Builder<'_> {
    fn std_table_open(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        self.open_header(false);
    }
    fn std_table_close(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        self.close_header(false);
    }
    fn array_table_open(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        self.open_header(true);
    }
    fn array_table_close(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        self.close_header(true);
    }
    fn inline_table_open(&mut self, _span: Span, _error: &mut dyn ErrorSink) -> bool {
        let made = Made {
            inline: true,
            ..Made::default()
        };
        self.open.push(Open::Inline(Table::new(made), Vec::new()));
        true
    }
    fn inline_table_close(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        match self.open.pop() {
            Some(Open::Inline(table, keys)) if keys.is_empty() => self.value(Node::Table(table)),
            _ => self.check(false),
        }
    }
    fn array_open(&mut self, _span: Span, _error: &mut dyn ErrorSink) -> bool {
        self.open.push(Open::Array {
            start: self.items.len(),
        });
        true
    }
    fn array_close(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        match self.open.pop() {
            Some(Open::Array { start }) => {
                let items = self.items.drain(start..).collect();
                self.value(Node::Array(false, items));
            }
            _ => self.check(false),
        }
    }
    fn simple_key(&mut self, span: Span, encoding: Option<Encoding>, error: &mut dyn ErrorSink) {
        let event = Event::new_unchecked(EventKind::SimpleKey, encoding, span);
        let Some(raw) = self.source.get(event) else {
            return self.check(false);
        };
        let mut key = Cow::Borrowed("");
        raw.decode_key(&mut key, error);
        match self.open.last_mut() {
            Some(Open::Inline(_, keys)) => keys.push(key),
            Some(Open::Array { .. }) => self.check(false),
            None => self.keys.push(key),
        }
    }
    fn scalar(&mut self, span: Span, encoding: Option<Encoding>, error: &mut dyn ErrorSink) {
        let event = Event::new_unchecked(EventKind::Scalar, encoding, span);
        match self
            .source
            .get(event)
            .and_then(|raw| scalar::decode(raw, error))
        {
            Some(node) => self.value(node),
            None => self.check(false),
        }
    }
    fn error(&mut self, _span: Span, _error: &mut dyn ErrorSink) {
        self.check(false);
    }
}
