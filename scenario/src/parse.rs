//! Text → effective document (after `--set`) → typed [`Scenario`], with
//! every problem of the overrides and of the schema found in one pass.
//! The document is `stream`'s tree; toml's own parser reads only a text
//! that tree refuses (to word its syntax error), and toml's spans are
//! looked up only for a schema problem.

use super::deserialize::{self, DocPath, Kind, Problem, Seg};
use super::input::{MAX_QUOTE_CHARS, clip, locate};
use super::overrides;
use super::resolve::Issue;
use super::schema::Scenario;
use super::stream;
use serde::de::DeserializeOwned;
use std::time::Instant;
use toml::Table;
use toml::de::{DeArray, DeTable};
use tracing::debug;

/// Most characters of a reason (serde's messages list the expected keys).
const MAX_REASON_CHARS: usize = 600;

/// Why a text and its overrides do not make a scenario.
pub(super) enum Failure {
    /// The text is not TOML (nothing else can be checked).
    Syntax(Issue),
    /// `--set` overrides that could not be applied, and the problems of the
    /// document (with the other overrides applied) against the schema.
    Schema {
        /// One per bad override, in command-line order.
        overrides: Vec<Issue>,
        /// Unknown keys, wrong types, missing fields.
        schema: Vec<Issue>,
    },
}

/// The typed form of the effective document.
pub(super) fn parse(text: &str, sets: &[String]) -> Result<Scenario, Failure> {
    let (document, bad, applied) = effective(text, sets)?;
    let start = Instant::now();
    let typed = deserialize::deserialize_tree(&document);
    drop(document);
    debug!(
        elapsed = ?start.elapsed(),
        ok = typed.is_ok(),
        "scenario: schema read"
    );
    match typed {
        Ok(s) if bad.is_empty() => Ok(s),
        Ok(_) => Err(Failure::Schema {
            overrides: bad,
            schema: Vec::new(),
        }),
        Err(problems) => Err(Failure::Schema {
            overrides: bad,
            schema: located(text, &applied, &problems),
        }),
    }
}

/// `text` (TOML, without overrides) as a `T` — another of attsync's files,
/// e.g. a hosts file — or its syntax error, or every schema problem, each
/// located in the text as a scenario's are.
pub fn typed<T: DeserializeOwned>(text: &str) -> Result<T, Vec<Issue>> {
    let table: Table = text
        .parse()
        .map_err(|e: toml::de::Error| vec![syntax(text, &e)])?;
    deserialize::collect_as(&table).map_err(|problems| located(text, &[], &problems))
}

/// Each schema problem as an issue, located in `text` unless an override
/// (of `applied`) set its field.
fn located(text: &str, applied: &[&str], problems: &[Problem]) -> Vec<Issue> {
    let spans = DeTable::parse(text).ok();
    problems
        .iter()
        .map(|p| issue(text, spans.as_ref().map(|s| s.get_ref()), applied, p))
        .collect()
}

/// The effective document (read by [`stream`], else by toml's parser, which
/// words a syntax error), with every override of `sets` that applies; the
/// ones that do not as issues, in order; the paths of the ones that do.
pub(super) fn effective<'a, 's>(
    text: &'a str,
    sets: &'s [String],
) -> Result<(stream::Table<'a>, Vec<Issue>, Vec<&'s str>), Failure> {
    let start = Instant::now();
    let mut document = match stream::read(text) {
        Some(tree) => tree,
        None => {
            let table: Table = text
                .parse()
                .map_err(|e: toml::de::Error| Failure::Syntax(syntax(text, &e)))?;
            table.into()
        }
    };
    debug!(bytes = text.len(), elapsed = ?start.elapsed(), "scenario: TOML parsed");
    let mut bad = Vec::new();
    let mut applied = Vec::new();
    for o in sets {
        // A failed override leaves the document as it was.
        match overrides::apply(&mut document, o) {
            Ok(()) => applied.extend(overrides::path_of(o)),
            Err(e) => bad.push(Issue {
                field: format!("--set {}", clip(o, MAX_QUOTE_CHARS)),
                reason: e.to_string(),
            }),
        }
    }
    Ok((document, bad, applied))
}

/// A TOML syntax error as `line L, column C: reason: `the line``.
fn syntax(text: &str, e: &toml::de::Error) -> Issue {
    let reason = clip(e.message().trim(), MAX_REASON_CHARS);
    match e.span() {
        Some(span) => {
            let (line, col, quote) = locate(text, span.start);
            Issue {
                field: format!("line {line}, column {col}"),
                reason: format!("{reason}: `{quote}`"),
            }
        }
        None => Issue {
            field: "TOML".into(),
            reason,
        },
    }
}

/// A schema problem as an issue on its field, with its place in the text
/// when the field is as written there (not set by an override).
fn issue(text: &str, spans: Option<&DeTable>, applied: &[&str], p: &Problem) -> Issue {
    let field = p.path.to_string();
    let overridden = applied.iter().any(|a| {
        field == *a
            || field
                .strip_prefix(a)
                .is_some_and(|rest| rest.starts_with(['.', '[']))
    });
    let at = match p.kind {
        Kind::Missing => DocPath(p.path.0[..p.path.0.len() - 1].to_vec()),
        _ => p.path.clone(),
    };
    let place = spans
        .filter(|_| !overridden)
        .and_then(|s| offset(s, &at.0, p.kind == Kind::UnknownKey))
        .map(|o| {
            let (line, col, _) = locate(text, o);
            format!(" (line {line}, column {col})")
        })
        .unwrap_or_default();
    Issue {
        field: clip(&field, MAX_QUOTE_CHARS),
        reason: format!("{}{place}", clip(&p.message, MAX_REASON_CHARS)),
    }
}

/// Byte offset in the text of the value at `path` (of its key, if `at_key`).
fn offset(root: &DeTable, path: &[Seg], at_key: bool) -> Option<usize> {
    let (mut table, mut array) = (Some(root), None);
    let mut at = None;
    for (i, s) in path.iter().enumerate() {
        let last = i + 1 == path.len();
        let v = match s {
            Seg::Key(name) => {
                let (k, v) = table?
                    .iter()
                    .find(|(k, _)| k.get_ref().as_ref() == name.as_str())?;
                at = Some(if at_key && last { k.span() } else { v.span() }.start);
                v
            }
            Seg::Index(n) => {
                let v = array.and_then(|a: &DeArray| a.get(*n))?;
                at = Some(v.span().start);
                v
            }
        };
        table = v.get_ref().as_table();
        array = v.get_ref().as_array();
    }
    at
}
