//! Where a statement of an input file stands, for errors and warnings found
//! after the reader has moved on (the planner decides a whole path at once,
//! the closed-loop check runs on blocks made from points read long before).

use std::fmt;

use crate::{Diagnostic, Severity};

/// A statement's place: its file, its 1-based line and the text of that
/// line (without its line end). What a [`Diagnostic`] about the statement
/// needs, as data that travels with the statement through the stages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Site<'a> {
    /// File name as the user gave it.
    pub file: &'a str,
    /// 1-based line.
    pub line: usize,
    /// The line's text (UTF-8, as the reader checked it).
    pub text: &'a [u8],
}

impl Site<'_> {
    /// A diagnostic about the whole statement: the caret spans its text from
    /// the first character that is not a blank.
    pub fn diagnostic(&self, severity: Severity, message: impl Into<String>) -> Diagnostic {
        let text = String::from_utf8_lossy(self.text);
        let start = text.len() - text.trim_start().len();
        let column = text[..start].chars().count() + 1;
        let width = text.trim().chars().count();
        let d = Diagnostic::error(self.file, self.line, column, width, text, message);
        Diagnostic { severity, ..d }
    }

    /// `error` about this statement.
    pub fn locate<E: fmt::Display>(&self, error: E) -> Located<E> {
        Located {
            diagnostic: Box::new(self.diagnostic(Severity::Error, error.to_string())),
            error,
        }
    }

    /// A warning about this statement (the message of a typed warning).
    pub fn warning(&self, warning: impl fmt::Display) -> Diagnostic {
        self.diagnostic(Severity::Warning, warning.to_string())
    }
}

/// A typed error and the place in an input file it is about: the error for
/// code to match on, the diagnostic (its message is the error's text) for
/// the user.
#[derive(Debug)]
pub struct Located<E> {
    /// What went wrong.
    pub error: E,
    /// Where, rendered for the user.
    pub diagnostic: Box<Diagnostic>,
}

impl<E> fmt::Display for Located<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.diagnostic.fmt(f)
    }
}

impl<E: fmt::Debug> std::error::Error for Located<E> {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_site_underlines_the_statement_without_its_indentation() {
        let site = Site {
            file: "p.cls",
            line: 7,
            text: b"  GOTO/1,2,3  ",
        };
        let d = site.locate("no solution");
        assert_eq!((d.diagnostic.line, d.diagnostic.column), (7, 3));
        assert_eq!(d.diagnostic.width, "GOTO/1,2,3".len());
        assert_eq!(d.diagnostic.message, "no solution");
        assert_eq!(d.error, "no solution");
        assert_eq!(site.warning("careful").severity, Severity::Warning);
    }
}
