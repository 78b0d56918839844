//! A serde `Deserializer` over a *borrowed* tree (`stream`'s), for
//! the fast path of [`super::deserialize`]: toml's own deserializer of a
//! `toml::Value` (0.9, `value.rs`) takes the value by value, so reading a
//! document that must be kept would first copy the whole table — hundreds
//! of MiB at 10⁵ agents.
//!
//! It mirrors toml's semantics (integers as `i64`, a present value as
//! `Some`, arrays and tables read to their end, enums from strings) with one
//! exception: an enum written as a table (`kind = { observerless = [] }`) is
//! refused here. So it accepts a subset of what toml's accepts, with the same
//! result; whatever it refuses goes to the collecting pass, whose messages
//! come from toml's own deserializer.

use super::stream::{Node, Table};
use serde::de::value::BorrowedStrDeserializer;
use serde::de::{self, DeserializeSeed, IntoDeserializer, MapAccess, SeqAccess, Visitor};
use std::borrow::Cow;
use toml::de::Error;

/// `v`, to be deserialised in place.
#[derive(Clone, Copy)]
pub(super) struct ValueRef<'a, 'i>(pub(super) &'a Node<'i>);

/// A whole document, to be deserialised in place.
#[derive(Clone, Copy)]
pub(super) struct TableRef<'a, 'i>(pub(super) &'a Table<'i>);

impl<'de> de::Deserializer<'de> for TableRef<'de, '_> {
    type Error = Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visit_table(self.0, visitor)
    }

    serde::forward_to_deserialize_any! {
        bool u8 u16 u32 u64 i8 i16 i32 i64 f32 f64 char str string unit seq
        bytes byte_buf map unit_struct tuple_struct struct newtype_struct
        tuple ignored_any identifier option enum
    }
}

impl<'de> de::Deserializer<'de> for ValueRef<'de, '_> {
    type Error = Error;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        match self.0 {
            Node::Boolean(v) => visitor.visit_bool(*v),
            Node::Integer(n) => visitor.visit_i64(*n),
            Node::Float(x) => visitor.visit_f64(*x),
            Node::String(s) => visitor.visit_borrowed_str(s),
            Node::Datetime(d) => visitor.visit_string(d.to_string()),
            Node::Array(_, a) => {
                let mut seq = Seq(a.iter());
                let out = visitor.visit_seq(&mut seq)?;
                match seq.0.len() {
                    0 => Ok(out),
                    _ => Err(de::Error::invalid_length(
                        a.len(),
                        &"fewer elements in array",
                    )),
                }
            }
            Node::Table(t) => visit_table(t, visitor),
        }
    }

    // `None` is a missing field: a present value is `Some`, as in toml.
    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Error> {
        visitor.visit_some(self)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value, Error> {
        visitor.visit_newtype_struct(self)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Error> {
        match self.0 {
            Node::String(s) => visitor.visit_enum(s.as_ref().into_deserializer()),
            _ => Err(de::Error::invalid_type(
                de::Unexpected::UnitVariant,
                &"string only",
            )),
        }
    }

    serde::forward_to_deserialize_any! {
        bool u8 u16 u32 u64 i8 i16 i32 i64 f32 f64 char str string unit seq
        bytes byte_buf map unit_struct tuple_struct struct
        tuple ignored_any identifier
    }
}

/// A table as a map, read to its end.
fn visit_table<'de, V: Visitor<'de>>(t: &'de Table<'_>, visitor: V) -> Result<V::Value, Error> {
    let mut map = Map {
        iter: t.iter(),
        value: None,
    };
    let out = visitor.visit_map(&mut map)?;
    match map.iter.len() {
        0 => Ok(out),
        _ => Err(de::Error::invalid_length(t.len(), &"fewer elements in map")),
    }
}

/// The elements of an array.
struct Seq<'a, 'i>(std::slice::Iter<'a, Node<'i>>);

impl<'de> SeqAccess<'de> for Seq<'de, '_> {
    type Error = Error;

    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Error> {
        self.0
            .next()
            .map(|v| seed.deserialize(ValueRef(v)))
            .transpose()
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.0.len())
    }
}

/// The entries of a table, each key before its value.
struct Map<'a, 'i> {
    iter: std::slice::Iter<'a, (Cow<'i, str>, Node<'i>)>,
    value: Option<&'a Node<'i>>,
}

impl<'de> MapAccess<'de> for Map<'de, '_> {
    type Error = Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, Error> {
        let Some((k, v)) = self.iter.next() else {
            return Ok(None);
        };
        self.value = Some(v);
        seed.deserialize(BorrowedStrDeserializer::new(k)).map(Some)
    }

    fn next_value_seed<T: DeserializeSeed<'de>>(&mut self, seed: T) -> Result<T::Value, Error> {
        match self.value.take() {
            Some(v) => seed.deserialize(ValueRef(v)),
            None => Err(de::Error::custom("value is missing")),
        }
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.iter.len())
    }
}
