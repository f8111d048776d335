//! Unknown keys and values of a TOML file, checked against the serde types
//! that read it, all at once: serde stops at the first. The names come from
//! the types themselves (a deserializer that only listens), so the lists
//! cannot drift from them.

use std::ops::Range;

use serde::de::{DeserializeOwned, Error, Visitor, value};
use toml::de::{DeTable, DeValue};

use crate::{Diagnostic, Severity};

/// The unknown keys and values found so far: where, and what to say.
#[derive(Debug, Default)]
pub struct Unknown(Vec<(Range<usize>, String)>);

impl Unknown {
    /// Checks the keys of `table` against `fields`, and the string values
    /// of the keys in `words` against their allowed values.
    pub fn check(&mut self, table: &DeTable, fields: &[&str], words: &[(&str, &[&str])]) {
        for (key, value) in table {
            let k = key.get_ref().as_ref();
            if !fields.contains(&k) {
                self.0.push((
                    key.span(),
                    format!("unknown key `{k}`, {}", expected(fields)),
                ));
                continue;
            }
            if let (Some((_, allowed)), DeValue::String(w)) =
                (words.iter().find(|(name, _)| *name == k), value.get_ref())
                && !allowed.contains(&w.as_ref())
            {
                self.0.push((
                    value.span(),
                    format!("unknown value `{w}`, {}", expected(allowed)),
                ));
            }
        }
    }

    /// The diagnostics, in file order.
    pub fn into_diagnostics(mut self, file: &str, source: &str) -> Vec<Diagnostic> {
        self.0.sort_by_key(|(span, _)| span.start);
        self.0
            .into_iter()
            .map(|(span, message)| {
                Diagnostic::at_byte_span(Severity::Error, file, source, span, message)
            })
            .collect()
    }
}

/// What to report when serde refuses the file after `unknown` was found:
/// the unknown names, and serde's own error unless it is one of them (its
/// first unknown value) at the same place.
pub fn with_serde_error(mut unknown: Vec<Diagnostic>, serde: Diagnostic) -> Vec<Diagnostic> {
    if !unknown
        .iter()
        .any(|d| (d.line, d.column) == (serde.line, serde.column))
    {
        unknown.push(serde);
    }
    unknown
}

/// The table `name` of `table`, if it is one.
pub fn table<'a, 'i>(table: &'a DeTable<'i>, name: &str) -> Option<&'a DeTable<'i>> {
    match table.get(name).map(|v| v.get_ref()) {
        Some(DeValue::Table(t)) => Some(t),
        _ => None,
    }
}

/// serde's wording of the names a key or value may take.
pub fn expected(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.as_slice() {
        [] => "there are none".to_string(),
        [one] => format!("expected {one}"),
        [a, b] => format!("expected {a} or {b}"),
        all => format!("expected one of {}", all.join(", ")),
    }
}

/// The field names serde's derive gives a struct, or the variant names of an
/// enum (as written in the file), asked of `T` through a deserializer that
/// only listens.
pub fn names<T: DeserializeOwned>() -> &'static [&'static str] {
    struct Listen<'a>(&'a mut &'static [&'static str]);
    impl Listen<'_> {
        /// Keeps the names the type asked for, and stops it there.
        fn heard<T>(self, names: &'static [&'static str]) -> Result<T, value::Error> {
            *self.0 = names;
            Err(value::Error::custom("listening only"))
        }
    }
    impl<'de> serde::Deserializer<'de> for Listen<'_> {
        type Error = value::Error;
        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, value::Error> {
            self.heard(&[])
        }
        fn deserialize_struct<V: Visitor<'de>>(
            self,
            _: &'static str,
            fields: &'static [&'static str],
            _: V,
        ) -> Result<V::Value, value::Error> {
            self.heard(fields)
        }
        fn deserialize_enum<V: Visitor<'de>>(
            self,
            _: &'static str,
            variants: &'static [&'static str],
            _: V,
        ) -> Result<V::Value, value::Error> {
            self.heard(variants)
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
            bytes byte_buf option unit unit_struct newtype_struct seq tuple
            tuple_struct map identifier ignored_any
        }
    }
    let mut names: &'static [&'static str] = &[];
    let _ = T::deserialize(Listen(&mut names));
    names
}
