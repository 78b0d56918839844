//! Reading a scenario file safely: a size limit checked before parsing (and
//! enforced while reading, for pipes and devices that have no size), and
//! quotes of the input clipped so that a huge line is never echoed whole.

use std::io::Read;
use std::path::Path;
use thiserror::Error;

/// The largest scenario file accepted: 256 MiB.
pub const MAX_FILE_BYTES: u64 = 256 << 20;

/// Most characters of the input quoted in a message.
pub const MAX_QUOTE_CHARS: usize = 200;

/// Why a scenario file could not be read.
#[derive(Debug, Error)]
pub enum ReadError {
    /// The OS refused to open or read it.
    #[error("cannot read: {0}")]
    Io(std::io::Error),
    /// It is over its limit ([`MAX_FILE_BYTES`] for a scenario); `size` is
    /// `None` when the file has no size (a pipe or a device) and more than
    /// the limit was read.
    #[error("{} is over the limit of {} bytes ({} MiB) for {}", match size {
        Some(n) => format!("its size, {n} bytes,"),
        None => format!("its content, more than {} bytes,", limit.bytes),
    }, limit.bytes, limit.bytes >> 20, limit.what)]
    TooLarge {
        /// The size from the file's metadata, if it has one.
        size: Option<u64>,
        /// The limit it is over.
        limit: Limit,
    },
    /// It is not UTF-8 text.
    #[error("not UTF-8 text (invalid byte at offset {offset})")]
    NotUtf8 {
        /// Byte offset of the first invalid byte.
        offset: usize,
    },
}

/// A size limit on a file read, and what kind of file it is for messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limit {
    /// The most bytes accepted.
    pub bytes: u64,
    /// The kind of file, e.g. "a scenario file".
    pub what: &'static str,
}

/// The limit of a scenario file: [`MAX_FILE_BYTES`].
pub const SCENARIO: Limit = Limit {
    bytes: MAX_FILE_BYTES,
    what: "a scenario file",
};

/// The text of `file`, refused without reading when its metadata says it
/// is over [`MAX_FILE_BYTES`], and never reading more than that plus one byte.
pub fn read_bounded(file: &Path) -> Result<String, ReadError> {
    read_limited(file, SCENARIO)
}

/// As [`read_bounded`], within `limit`.
pub fn read_limited(file: &Path, limit: Limit) -> Result<String, ReadError> {
    let f = std::fs::File::open(file).map_err(ReadError::Io)?;
    let meta = f.metadata().map_err(ReadError::Io)?;
    let hint = if meta.is_file() {
        if meta.len() > limit.bytes {
            return Err(ReadError::TooLarge {
                size: Some(meta.len()),
                limit,
            });
        }
        meta.len()
    } else {
        0
    };
    let mut bytes = Vec::with_capacity(usize::try_from(hint).unwrap_or(0) + 1);
    f.take(limit.bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(ReadError::Io)?;
    if bytes.len() as u64 > limit.bytes {
        return Err(ReadError::TooLarge {
            size: meta.is_file().then_some(bytes.len() as u64),
            limit,
        });
    }
    String::from_utf8(bytes).map_err(|e| ReadError::NotUtf8 {
        offset: e.utf8_error().valid_up_to(),
    })
}

/// `s`, cut to at most `max` characters (an ellipsis marks the cut).
#[must_use]
pub fn clip(s: &str, max: usize) -> String {
    match s.char_indices().nth(max) {
        None => s.to_owned(),
        Some((end, _)) => format!("{}…", &s[..end]),
    }
}

/// Line and column (1-based, the column in characters) of byte `offset`
/// of `text`, and the line around it, clipped to [`MAX_QUOTE_CHARS`]
/// characters centred on the column.
#[must_use]
pub fn locate(text: &str, offset: usize) -> (usize, usize, String) {
    let offset = (0..=offset.min(text.len()))
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0);
    let start = text[..offset].rfind('\n').map_or(0, |i| i + 1);
    let end = text[offset..].find('\n').map_or(text.len(), |i| offset + i);
    let line_no = text[..start].bytes().filter(|&b| b == b'\n').count() + 1;
    let line = text[start..end].trim_end_matches('\r');
    let col = text[start..offset].chars().count();
    let skip = col.saturating_sub(MAX_QUOTE_CHARS / 2);
    let mut quote: String = line.chars().skip(skip).take(MAX_QUOTE_CHARS).collect();
    if skip > 0 {
        quote.insert(0, '…');
    }
    if line.chars().count() > skip + MAX_QUOTE_CHARS {
        quote.push('…');
    }
    (line_no, col + 1, quote)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quotes_are_clipped_around_the_column() {
        let long = format!("a = {}", "x".repeat(10_000));
        let (line, col, quote) = locate(&format!("\n{long}\n"), 5_001);
        assert_eq!((line, col), (2, 5_001));
        assert!(quote.chars().count() <= MAX_QUOTE_CHARS + 2, "{quote}");
        assert!(quote.starts_with('…') && quote.ends_with('…'));
        assert_eq!(locate("a = 1", 4), (1, 5, "a = 1".to_owned()));
        assert_eq!(clip("abcdef", 3), "abc…");
        assert_eq!(clip("abc", 3), "abc");
    }
}
