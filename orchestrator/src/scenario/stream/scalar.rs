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
