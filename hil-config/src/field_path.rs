//! The field path of a deserialisation error, found by deserialising the
//! document again through a deserializer that tracks where it is.
//!
//! toml reports an error with the span of the value it was deserialising,
//! but a component table (`[policy]`) is deserialised by typetag, which
//! buffers a table whose `type` key is not its first, so an error inside it
//! carries only the table's span. This second pass walks the parsed
//! document itself: every table hands out its `type` key first (so typetag
//! never buffers), every error is tagged with the keys it passed through on
//! its way out, and serde's structured constructors (`missing_field`) say
//! which field was missing. Nothing is read from message text.

use std::fmt;

use serde::de::value::StrDeserializer;
use serde::de::{self, DeserializeOwned, DeserializeSeed, IntoDeserializer, MapAccess, Visitor};

/// Where deserialising a document failed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fault {
    /// The keys (and array indices) from the top of the document to the
    /// value at fault.
    pub(crate) keys: Vec<String>,
    /// A field the table at `keys` lacks.
    pub(crate) missing: Option<&'static str>,
    message: String,
}

impl Fault {
    fn under(mut self, key: &str) -> Self {
        self.keys.insert(0, key.to_string());
        self
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Fault {}

impl de::Error for Fault {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Self {
            keys: Vec::new(),
            missing: None,
            message: msg.to_string(),
        }
    }

    fn missing_field(field: &'static str) -> Self {
        Self {
            keys: Vec::new(),
            missing: Some(field),
            message: format!("missing field `{field}`"),
        }
    }
}

/// Deserialises `T` from `doc` and returns where it fails, or `None` if it
/// does not.
pub(crate) fn fault<T: DeserializeOwned>(doc: &toml::Table) -> Option<Fault> {
    T::deserialize(TableDe(doc)).err()
}

/// A table, as a deserializer.
struct TableDe<'a>(&'a toml::Table);

/// A value, as a deserializer.
struct ValueDe<'a>(&'a toml::Value);

/// A table's entries, `type` first.
struct Entries<'a> {
    entries: Vec<(&'a str, &'a toml::Value)>,
    next: usize,
}

impl<'a> Entries<'a> {
    fn new(table: &'a toml::Table) -> Self {
        let mut entries: Vec<(&str, &toml::Value)> =
            table.iter().map(|(k, v)| (k.as_str(), v)).collect();
        // Stable: every other key keeps its place.
        entries.sort_by_key(|(k, _)| *k != "type");
        Self { entries, next: 0 }
    }
}

impl<'de> MapAccess<'de> for Entries<'_> {
    type Error = Fault;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, Fault> {
        let Some(&(key, _)) = self.entries.get(self.next) else {
            return Ok(None);
        };
        let de: StrDeserializer<'_, Fault> = key.into_deserializer();
        seed.deserialize(de).map(Some).map_err(|e| e.under(key))
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, Fault> {
        let Some(&(key, value)) = self.entries.get(self.next) else {
            return Err(de::Error::custom(
                "a value was asked for after the last key",
            ));
        };
        self.next += 1;
        seed.deserialize(ValueDe(value)).map_err(|e| e.under(key))
    }
}

/// An array's items; an error is tagged with the item's index.
struct Items<'a> {
    items: std::slice::Iter<'a, toml::Value>,
    next: usize,
}

impl<'de> de::SeqAccess<'de> for Items<'_> {
    type Error = Fault;

    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Fault> {
        let Some(item) = self.items.next() else {
            return Ok(None);
        };
        let index = self.next;
        self.next += 1;
        seed.deserialize(ValueDe(item))
            .map(Some)
            .map_err(|e| e.under(&index.to_string()))
    }
}

impl<'de> de::Deserializer<'de> for TableDe<'_> {
    type Error = Fault;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Fault> {
        visitor.visit_map(Entries::new(self.0))
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

impl<'de> de::Deserializer<'de> for ValueDe<'_> {
    type Error = Fault;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Fault> {
        match self.0 {
            toml::Value::String(s) => visitor.visit_str(s),
            toml::Value::Integer(i) => visitor.visit_i64(*i),
            toml::Value::Float(f) => visitor.visit_f64(*f),
            toml::Value::Boolean(b) => visitor.visit_bool(*b),
            toml::Value::Datetime(d) => visitor.visit_string(d.to_string()),
            toml::Value::Array(items) => visitor.visit_seq(Items {
                items: items.iter(),
                next: 0,
            }),
            toml::Value::Table(t) => visitor.visit_map(Entries::new(t)),
        }
    }

    // TOML has no null: a present value is `Some`.
    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Fault> {
        visitor.visit_some(self)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value, Fault> {
        visitor.visit_newtype_struct(self)
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Fault> {
        match self.0 {
            // A unit variant written as a string, as toml reads it.
            toml::Value::String(s) => {
                let de: StrDeserializer<'_, Fault> = s.as_str().into_deserializer();
                visitor.visit_enum(de)
            }
            toml::Value::Table(t) => {
                visitor.visit_enum(de::value::MapAccessDeserializer::new(Entries::new(t)))
            }
            _ => self.deserialize_any(visitor),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf unit unit_struct seq tuple
        tuple_struct map struct identifier ignored_any
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Inner {
        alpha: f64,
        names: Vec<String>,
    }

    #[derive(Debug, serde::Deserialize)]
    #[serde(deny_unknown_fields)]
    #[allow(dead_code)]
    struct Outer {
        seed: u64,
        inner: Inner,
    }

    fn fault_of(text: &str) -> Fault {
        let doc: toml::Table = toml::from_str(text).unwrap();
        fault::<Outer>(&doc).expect("a fault")
    }

    #[test]
    fn faults_name_the_path_to_the_value() {
        let f = fault_of("seed = 1\n[inner]\nalpha = \"x\"\nnames = []\n");
        assert_eq!(
            (f.keys, f.missing),
            (vec!["inner".into(), "alpha".into()], None)
        );
        let f = fault_of("seed = 1\n[inner]\nalpha = 1.0\nnames = [\"a\", 2]\n");
        assert_eq!(f.keys, ["inner", "names", "1"]);
        let f = fault_of("seed = 1\n[inner]\nalpah = 1.0\nnames = []\n");
        assert_eq!(f.keys, ["inner", "alpah"]);
        let f = fault_of("seed = 1\n[inner]\nnames = []\n");
        assert_eq!((f.keys.len(), f.missing), (1, Some("alpha")));
        let f = fault_of("seed = -1\n[inner]\nalpha = 1.0\nnames = []\n");
        assert_eq!(f.keys, ["seed"]);
    }

    #[test]
    fn a_good_document_has_no_fault() {
        let doc: toml::Table =
            toml::from_str("seed = 1\n[inner]\nalpha = 1\nnames = []\n").unwrap();
        assert_eq!(fault::<Outer>(&doc), None);
    }
}
