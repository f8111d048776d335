//! The program text: lines by position, forward and backward jumps, and
//! located errors.

use kinpost_diag::Diagnostic;

/// A position in the program: the byte offset where a line starts and its
/// 1-based number.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Pos {
    pub offset: usize,
    pub line: usize,
}

/// One line of the program.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Line<'a> {
    /// 1-based line number.
    pub no: usize,
    /// Where it starts.
    pub pos: Pos,
    /// Its text without the line end.
    pub text: &'a str,
}

/// The program text with a cursor on the next line.
pub(crate) struct Source<'a> {
    pub text: &'a str,
    next: Pos,
}

impl<'a> Source<'a> {
    pub fn new(text: &'a str) -> Source<'a> {
        Source {
            text,
            next: Pos { offset: 0, line: 1 },
        }
    }

    /// The next line, or `None` at the end of the text.
    #[inline]
    pub fn next_line(&mut self) -> Option<Line<'a>> {
        let start = self.next.offset;
        if start >= self.text.len() {
            return None;
        }
        let rest = &self.text[start..];
        let (len, advance) = match rest.as_bytes().iter().position(|&b| b == b'\n') {
            Some(i) => (i, i + 1),
            None => (rest.len(), rest.len()),
        };
        let mut text = &rest[..len];
        if let Some(t) = text.strip_suffix('\r') {
            text = t;
        }
        let line = Line {
            no: self.next.line,
            pos: self.next,
            text,
        };
        self.next = Pos {
            offset: start + advance,
            line: self.next.line + 1,
        };
        Some(line)
    }

    /// Where the next line starts.
    pub fn position(&self) -> Pos {
        self.next
    }

    /// Continues at `pos` (a position this source handed out).
    pub fn seek(&mut self, pos: Pos) {
        self.next = pos;
    }

    /// The line at `pos` (without moving the cursor).
    pub fn line_at(&self, pos: Pos) -> Option<Line<'a>> {
        let mut s = Source {
            text: self.text,
            next: pos,
        };
        s.next_line()
    }
}

/// An error inside one line: a byte range and a message; the caller adds
/// the file and line.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fail {
    /// Byte offset in the line where the problem starts.
    pub at: usize,
    /// Bytes it spans (at least 1 is shown).
    pub len: usize,
    pub message: String,
}

/// A located error in a line.
pub(crate) fn fail<T>(at: usize, len: usize, message: impl Into<String>) -> Result<T, Fail> {
    Err(Fail {
        at,
        len,
        message: message.into(),
    })
}

/// The diagnostic of `f` in `line` of `file`, with character columns.
pub(crate) fn diagnostic(file: &str, line: &Line<'_>, f: Fail, warning: bool) -> Diagnostic {
    let text = line.text;
    let at = floor(text, f.at.min(text.len()));
    let end = floor(text, (f.at + f.len).min(text.len()).max(at));
    let column = text[..at].chars().count() + 1;
    let width = text[at..end].chars().count().max(1);
    if warning {
        Diagnostic::warning(file, line.no, column, width, text, f.message)
    } else {
        Diagnostic::error(file, line.no, column, width, text, f.message)
    }
}

fn floor(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}
