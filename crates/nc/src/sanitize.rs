//! The one cleaning every text from outside goes through before it reaches
//! a program: file names, `PARTNO`, `TOOL PATH`, tool names, `PPRINT`
//! comments, template variables. A CL file, a file name or a machine file
//! must never put code into a program: a line break in a file name would
//! otherwise start a block of its own (`part\nG0 Z-100`), a carriage return
//! ends the line on some controllers, and a `)` ends a Fanuc comment so that
//! the rest of it runs. The CL's `INSERT` is the one deliberate
//! pass-through of code ([`crate::NcWriter::insert`]).

use std::borrow::Cow;
use std::collections::BTreeMap;

use minijinja::Value;
use minijinja::value::ValueKind;

use crate::CommentSyntax;

/// Whether `c` must not reach a program line as it is: an ASCII or Unicode
/// control character (tab, CR, LF, NUL, form feed, vertical tab, escape,
/// DEL, the C1 controls such as NEL) or a Unicode line or paragraph
/// separator.
fn is_line_control(c: char) -> bool {
    c.is_control() || c == '\u{2028}' || c == '\u{2029}'
}

impl CommentSyntax {
    /// `text` made safe to stand inside this dialect's comment (and in any
    /// header line): every control character and line break becomes a
    /// blank, the dialect's `replace` pairs are applied (`(` → `[`), an
    /// ASCII-only dialect gets `?` for anything beyond ASCII, and whatever
    /// is left of the comment's own delimiters (its suffix, and for a
    /// bracketed comment its prefix) becomes a blank, so that the text can
    /// never end the comment it stands in. Idempotent.
    pub fn clean<'a>(&self, text: &'a str) -> Cow<'a, str> {
        let prefix = self.prefix.trim();
        let suffix = self.suffix.trim();
        let plain = !text.chars().any(is_line_control)
            && !self
                .replace
                .iter()
                .any(|(from, _)| text.contains(from.as_str()))
            && (!self.ascii || text.is_ascii())
            && (suffix.is_empty() || !(text.contains(suffix) || text.contains(prefix)));
        if plain {
            return Cow::Borrowed(text);
        }
        let mut body: String = text
            .chars()
            .map(|c| if is_line_control(c) { ' ' } else { c })
            .collect();
        for (from, to) in &self.replace {
            if !from.is_empty() && body.contains(from.as_str()) {
                body = body.replace(from.as_str(), to);
            }
        }
        if self.ascii {
            body = crate::template::ascii(&body);
        }
        if !suffix.is_empty() {
            for delimiter in [suffix, prefix] {
                if !delimiter.is_empty() && body.contains(delimiter) {
                    body = body.replace(delimiter, " ");
                }
            }
        }
        // A replacement may itself bring a control character (a dialect
        // file's own choice): never into the program.
        if body.chars().any(is_line_control) {
            body = body
                .chars()
                .map(|c| if is_line_control(c) { ' ' } else { c })
                .collect();
        }
        Cow::Owned(body)
    }

    /// Every string inside `value` (lists and maps too) cleaned with
    /// [`CommentSyntax::clean`]; numbers, booleans and the rest as they are.
    pub fn clean_value(&self, value: &Value) -> Value {
        match value.kind() {
            ValueKind::String => match value.as_str() {
                Some(s) => match self.clean(s) {
                    Cow::Borrowed(_) => value.clone(),
                    Cow::Owned(s) => Value::from(s),
                },
                None => value.clone(),
            },
            ValueKind::Seq => match value.try_iter() {
                Ok(items) => Value::from(items.map(|v| self.clean_value(&v)).collect::<Vec<_>>()),
                Err(_) => value.clone(),
            },
            ValueKind::Map => match value.try_iter() {
                Ok(keys) => Value::from(
                    keys.filter_map(|k| {
                        let v = value.get_item(&k).ok()?;
                        let key = k
                            .as_str()
                            .map_or_else(|| k.to_string(), |s| self.clean(s).into_owned());
                        Some((key, self.clean_value(&v)))
                    })
                    .collect::<BTreeMap<String, Value>>(),
                ),
                Err(_) => value.clone(),
            },
            _ => value.clone(),
        }
    }

    /// Every variable of `vars` cleaned in place ([`CommentSyntax::clean_value`]).
    pub fn clean_vars(&self, vars: &mut BTreeMap<String, Value>) {
        for v in vars.values_mut() {
            *v = self.clean_value(v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Dialect;
    use proptest::prelude::*;

    fn syntax(name: &str) -> CommentSyntax {
        Dialect::builtin(name).unwrap().comment.clone()
    }

    #[test]
    fn line_breaks_and_controls_become_blanks() {
        let s = syntax("sinumerik");
        assert_eq!(
            s.clean("part\nG0 Z-100\r\u{0}\u{c}\u{b}\u{1b}x\u{85}\u{2028}"),
            "part G0 Z-100     x  "
        );
        assert_eq!(s.clean("plain; text (ok)"), "plain; text (ok)");
    }

    #[test]
    fn fanuc_text_cannot_end_its_comment() {
        let s = syntax("fanuc");
        assert_eq!(s.clean("A) G0 Z-100 (B %"), "A] G0 Z-100 [B PCT");
        assert_eq!(s.clean("Gehäuse"), "Geh?use");
    }

    #[test]
    fn a_dialect_without_replacements_loses_its_delimiters() {
        let s = CommentSyntax {
            enabled: true,
            prefix: "(".into(),
            suffix: ")".into(),
            replace: Vec::new(),
            ascii: false,
        };
        assert_eq!(s.clean("a) G0 (b"), "a  G0  b");
    }

    #[test]
    fn values_are_cleaned_inside_lists_and_maps() {
        let s = syntax("linuxcnc");
        let mut extra = BTreeMap::new();
        extra.insert("k".to_string(), Value::from("x\ny"));
        let v = Value::from(vec![Value::from("a)b"), Value::from(3), Value::from(extra)]);
        let got = s.clean_value(&v);
        assert_eq!(got.get_item(&Value::from(0)).unwrap().as_str(), Some("a]b"));
        assert_eq!(got.get_item(&Value::from(1)).unwrap(), Value::from(3));
        let inner = got.get_item(&Value::from(2)).unwrap();
        assert_eq!(inner.get_attr("k").unwrap().as_str(), Some("x y"));
    }

    proptest! {
        /// Whatever the text, a cleaned one has no control character or
        /// line break, never holds the end of a bracketed comment, and
        /// cleaning it again changes nothing.
        #[test]
        fn cleaned_text_is_one_safe_line(text in "\\PC*|[\\x00-\\x7f()%;\n\r]*") {
            for name in Dialect::builtin_names() {
                let s = syntax(name);
                let once = s.clean(&text).into_owned();
                prop_assert!(!once.chars().any(is_line_control), "{name}: {once:?}");
                if !s.suffix.trim().is_empty() {
                    prop_assert!(!once.contains(s.suffix.trim()), "{name}: {once:?}");
                }
                prop_assert_eq!(s.clean(&once).into_owned(), once.clone());
            }
        }
    }
}
