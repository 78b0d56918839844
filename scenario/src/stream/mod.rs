//! The fast way from text to document: `toml_parser`'s lexer, parser and
//! decoder (the ones toml 0.9 uses), with a receiver of our own that builds
//! a compact tree as the events come.
//!
//! toml's `parse_document` holds every token (a `Vec<Token>`), then every
//! event (a `Vec<Event>` as long), then its `DeTable`, then the
//! `toml::Table` made from it, all at once: ~20 bytes per byte of input.
//! Here the tokens are lexed and parsed a chunk at a time (each chunk ends
//! with a newline outside any bracket, where an expression ends), events
//! are not kept, and the tree borrows its keys and strings from the text.
//!
//! It reads the documents toml reads, to the same table; where toml would
//! report an error (or a value toml takes that `toml::Value` cannot hold,
//! e.g. an integer beyond `i64`), it gives up and returns `None`, so that
//! toml's own parser reads the text and words the error.
//!
//! # Layout
//! - `node` — [`Node`] and [`Table`], the tree (and to/from `toml::Value`);
//! - `build` — the `EventReceiver` that builds it, with toml's rules;
//! - `scalar` — a scalar's text → its value.

mod build;
mod node;
mod scalar;
#[cfg(test)]
mod tests;

pub(crate) use node::{Node, Table};

use build::Builder;
use toml_parser::lexer::TokenKind;
use toml_parser::parser::{RecursionGuard, ValidateWhitespace, parse_document};
use toml_parser::{ErrorSink, ParseError, Source};

/// Tokens lexed before they are parsed (24 bytes each: 1.5 MiB).
const CHUNK_TOKENS: usize = 1 << 16;

/// Whether the parser reported an error.
#[derive(Default)]
struct Failed(bool);

impl ErrorSink for Failed {
    fn report_error(&mut self, _error: ParseError) {
        self.0 = true;
    }
}

/// `text` as a tree, or `None` if it is not TOML, or is TOML this path
/// leaves to toml (see the module's documentation).
pub(crate) fn read(text: &str) -> Option<Table<'_>> {
    let source = Source::new(text);
    let mut builder = Builder::new(source);
    let mut failed = Failed::default();
    let mut tokens = Vec::with_capacity(CHUNK_TOKENS.min(text.len() / 4 + 16));
    let mut depth = 0_i64;
    for token in source.lex() {
        depth += match token.kind() {
            TokenKind::LeftSquareBracket | TokenKind::LeftCurlyBracket => 1,
            TokenKind::RightSquareBracket | TokenKind::RightCurlyBracket => -1,
            _ => 0,
        };
        if depth < 0 {
            return None;
        }
        let end = token.kind() == TokenKind::Newline && depth == 0;
        tokens.push(token);
        if end && tokens.len() >= CHUNK_TOKENS {
            parse(source, &tokens, &mut builder, &mut failed);
            tokens.clear();
            if failed.0 || builder.refused {
                return None;
            }
        }
    }
    parse(source, &tokens, &mut builder, &mut failed);
    if failed.0 {
        return None;
    }
    builder.finish()
}

/// One chunk of whole expressions through toml_parser's parser, with the
/// same checks of whitespace and nesting toml wraps around it.
fn parse(
    source: Source<'_>,
    tokens: &[toml_parser::lexer::Token],
    builder: &mut Builder<'_>,
    failed: &mut Failed,
) {
    let mut whitespace = ValidateWhitespace::new(builder, source);
    let mut guard = RecursionGuard::new(&mut whitespace, build::LIMIT);
    parse_document(tokens, &mut guard, failed);
}
