//! A scalar's text → its value: `toml_parser`'s decoder, then the
//! conversions toml 0.9 applies (`de/parser/value.rs` `on_scalar`,
//! `de/parser/devalue.rs` `DeInteger::to_i64`, `DeFloat::to_f64`).

use super::node::Node;
use std::borrow::Cow;
use toml_parser::decoder::ScalarKind;
use toml_parser::{ErrorSink, Raw};

/// The value `raw` stands for; `None` for what toml would refuse or not
/// read as a `toml::Value` (an integer beyond `i64`, a float that
/// overflows, a malformed datetime). Decoding errors go to `error`.
pub(super) fn decode<'a>(raw: Raw<'a>, error: &mut dyn ErrorSink) -> Option<Node<'a>> {
    if let Some(node) = plain_number(raw.as_str()) {
        return Some(node);
    }
    let mut decoded = Cow::Borrowed("");
    Some(match raw.decode_scalar(&mut decoded, error) {
        ScalarKind::String => Node::String(decoded),
        ScalarKind::Boolean(b) => Node::Boolean(b),
        ScalarKind::DateTime => Node::Datetime(Box::new(decoded.parse().ok()?)),
        ScalarKind::Float => Node::Float(float(&decoded)?),
        ScalarKind::Integer(radix) => {
            Node::Integer(i64::from_str_radix(&decoded, radix.value()).ok()?)
        }
    })
}

/// toml's `DeFloat::to_f64`: an infinity only when written as one.
fn float(s: &str) -> Option<f64> {
    let f: f64 = s.parse().ok()?;
    (!f.is_infinite() || s.contains("inf")).then_some(f)
}

/// The fast path for the numbers a scenario is mostly made of: a decimal
/// written the plainest way TOML allows (`-?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?`,
/// no `+`, no `_`), read by the standard library's correctly rounded
/// parser — the same value `toml_parser`'s decoder and toml's conversion
/// give, at a fraction of the cost (the decoder took ~900 instructions per
/// float). Anything else (other forms, an integer beyond `i64`) is `None`
/// and goes the decoder's way.
fn plain_number(text: &str) -> Option<Node<'static>> {
    let b = text.as_bytes();
    let digits = |from: usize| from + b[from..].iter().take_while(|c| c.is_ascii_digit()).count();
    let mut i = usize::from(b.first() == Some(&b'-'));
    let int_end = digits(i);
    if int_end == i || (b[i] == b'0' && int_end > i + 1) {
        return None;
    }
    i = int_end;
    let mut is_float = false;
    if b.get(i) == Some(&b'.') {
        let end = digits(i + 1);
        if end == i + 1 {
            return None;
        }
        (i, is_float) = (end, true);
    }
    if matches!(b.get(i), Some(b'e' | b'E')) {
        let sign = usize::from(matches!(b.get(i + 1), Some(b'+' | b'-')));
        let end = digits(i + 1 + sign);
        if end == i + 1 + sign {
            return None;
        }
        (i, is_float) = (end, true);
    }
    if i != b.len() {
        return None;
    }
    if is_float {
        float(text).map(Node::Float)
    } else {
        text.parse().ok().map(Node::Integer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast path gives exactly the decoder's node, and stays out of
    /// every form it does not handle.
    #[test]
    fn plain_numbers_read_as_the_decoder_reads_them() {
        let slow = |t: &str| {
            let mut d = Cow::Borrowed("");
            let raw = Raw::new_unchecked(t, None, toml_parser::Span::new_unchecked(0, t.len()));
            let mut errors = Vec::new();
            match raw.decode_scalar(&mut d, &mut errors) {
                ScalarKind::Float => float(&d).map(Node::Float),
                ScalarKind::Integer(r) => {
                    i64::from_str_radix(&d, r.value()).ok().map(Node::Integer)
                }
                _ => None,
            }
        };
        for t in [
            "0",
            "-0",
            "7",
            "-42",
            "9223372036854775807",
            "0.0",
            "-0.0",
            "1.5",
            "0.46223709729836315",
            "-0.6946946071879747",
            "1e3",
            "1E-3",
            "2.5e+10",
            "-1.0e-300",
            "4.9e-324",
            "12.41628578168751",
            "123456789012345678901234567890.5",
        ] {
            let fast = plain_number(t).unwrap_or_else(|| panic!("{t}: not on the fast path"));
            let want = slow(t).unwrap_or_else(|| panic!("{t}: the decoder refuses it"));
            assert_eq!(format!("{fast:?}"), format!("{want:?}"), "{t}");
            if let (Node::Float(a), Node::Float(b)) = (&fast, &want) {
                assert_eq!(a.to_bits(), b.to_bits(), "{t}");
            }
        }
        for t in [
            "",
            "-",
            "+1",
            "1_000",
            "01",
            "-01.5",
            "1.",
            ".5",
            "1e",
            "1e+",
            "inf",
            "nan",
            "-inf",
            "0x1f",
            "0o7",
            "0b1",
            "1.5.2",
            "9223372036854775808",
            "1979-05-27",
            "true",
            "1.0x",
        ] {
            assert!(
                plain_number(t).is_none(),
                "{t}: must take the decoder's way"
            );
        }
        // An overflow is refused on both paths, as toml refuses it.
        assert!(plain_number("1e400").is_none() && slow("1e400").is_none());
    }
}
