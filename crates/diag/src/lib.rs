//! Diagnostics shared by every kinpost reader (CL files, machine files, dialect
//! files, NC programs).
//!
//! A [`Diagnostic`] always names the file, the 1-based line and column, and
//! carries the text of the offending source line so that it can be shown
//! without re-reading the input (inputs may be streams).
//!
//! ```text
//! error: malformed number `1.2.3`
//!   --> part.cls:12:6
//!    |
//! 12 | GOTO/1.2.3,4,5
//!    |      ^^^^^
//! ```

#![deny(missing_docs)]

use std::fmt;

mod site;
pub mod toml_names;

pub use site::{Located, Site};

/// How bad a diagnostic is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Severity {
    /// Harmless: the input is still used (an unknown statement, a cut-short record).
    Warning,
    /// The input cannot be used as it is.
    Error,
}

impl fmt::Display for Severity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Severity::Warning => "warning",
            Severity::Error => "error",
        })
    }
}

/// One message about one place in one input file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// Error or warning.
    pub severity: Severity,
    /// File name as the user gave it (`-` or `<stdin>` for standard input).
    pub file: String,
    /// 1-based line number; 0 when the message concerns the whole file.
    pub line: usize,
    /// 1-based column, counted in characters; 0 when not known.
    pub column: usize,
    /// Number of characters to underline, at least 1 when `column > 0`.
    pub width: usize,
    /// The message, without the severity prefix.
    pub message: String,
    /// The text of line `line`, without its line ending.
    pub source_line: String,
}

impl Diagnostic {
    /// An error at a character position of a source line.
    pub fn error(
        file: impl Into<String>,
        line: usize,
        column: usize,
        width: usize,
        source_line: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self::new(
            Severity::Error,
            file,
            line,
            column,
            width,
            source_line,
            message,
        )
    }

    /// A warning at a character position of a source line.
    pub fn warning(
        file: impl Into<String>,
        line: usize,
        column: usize,
        width: usize,
        source_line: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        Self::new(
            Severity::Warning,
            file,
            line,
            column,
            width,
            source_line,
            message,
        )
    }

    fn new(
        severity: Severity,
        file: impl Into<String>,
        line: usize,
        column: usize,
        width: usize,
        source_line: impl Into<String>,
        message: impl Into<String>,
    ) -> Self {
        // (A message that quotes a huge token is cut here too, so that
        // what reaches a JSON summary is as short as what is shown.)
        let message = message.into();
        let message = match cut(&message, MESSAGE_CHARS) {
            std::borrow::Cow::Borrowed(_) => message,
            std::borrow::Cow::Owned(short) => short,
        };
        Diagnostic {
            severity,
            file: file.into(),
            line,
            column,
            width: width.max(1),
            message,
            source_line: source_line.into(),
        }
    }

    /// Builds a diagnostic from a byte range of a whole in-memory source text
    /// (as TOML parsers report them): finds the line, the character column and
    /// the width.
    pub fn at_byte_span(
        severity: Severity,
        file: impl Into<String>,
        source: &str,
        span: std::ops::Range<usize>,
        message: impl Into<String>,
    ) -> Self {
        let start = floor_char_boundary(source, span.start.min(source.len()));
        let end = floor_char_boundary(source, span.end.clamp(start, source.len()));
        let line_start = source[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = source[start..]
            .find('\n')
            .map_or(source.len(), |i| start + i);
        let line = source[..start].matches('\n').count() + 1;
        let column = source[line_start..start].chars().count() + 1;
        let width = source[start..end.min(line_end).max(start)].chars().count();
        let text = source[line_start..line_end].trim_end_matches('\r');
        Self::new(severity, file, line, column, width, text, message)
    }

    /// The `file:line:column` location, as editors understand it.
    pub fn location(&self) -> String {
        match (self.line, self.column) {
            (0, _) => self.file.clone(),
            (l, 0) => format!("{}:{}", self.file, l),
            (l, c) => format!("{}:{}:{}", self.file, l, c),
        }
    }

    /// Whether it is an error (not a warning).
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// The most characters of a source line a diagnostic shows.
const SHOWN_CHARS: usize = 160;

/// The most characters of a message a diagnostic shows: a message that
/// quotes a token of 100 MB (a CL line without breaks) shows its start and
/// end.
pub const MESSAGE_CHARS: usize = 400;

/// The most characters of a piece of input a message quotes
/// ([`excerpt`]).
pub const EXCERPT_CHARS: usize = 60;

/// The error for a settings file (`kind`: "machine", "dialect") of more
/// than `max_bytes`, or `None`: such files are a few kilobytes, so a larger
/// one is refused before it is parsed (it is not one, and parsing it would
/// only cost time). Shown at line 1 with the file's first line.
pub fn oversized_file(
    file: &str,
    source: &str,
    kind: &str,
    max_bytes: usize,
) -> Option<Diagnostic> {
    (source.len() > max_bytes).then(|| {
        Diagnostic::error(
            file,
            1,
            1,
            1,
            source.lines().next().unwrap_or(""),
            format!(
                "the {kind} file has {} bytes, more than {max_bytes}: a {kind} file is a few \
                 kilobytes (is this a {kind} file?)",
                source.len()
            ),
        )
    })
}

/// `text` to quote in a message: whole when it has at most
/// [`EXCERPT_CHARS`] characters, else its start, `…` and how long it is.
/// The one place that decides how much of an input a message echoes.
pub fn excerpt(text: &str) -> std::borrow::Cow<'_, str> {
    cut(text, EXCERPT_CHARS)
}

/// `text` cut to about `max` characters: its start and end around a `…`
/// that says how many bytes it has.
fn cut(text: &str, max: usize) -> std::borrow::Cow<'_, str> {
    if text.len() <= max || text.chars().nth(max).is_none() {
        return std::borrow::Cow::Borrowed(text);
    }
    let head_chars = max * 2 / 3;
    let tail_chars = max / 6;
    let head_end = text
        .char_indices()
        .nth(head_chars)
        .map_or(text.len(), |(i, _)| i);
    let tail_start = text
        .char_indices()
        .rev()
        .nth(tail_chars.saturating_sub(1))
        .map_or(head_end, |(i, _)| i.max(head_end));
    std::borrow::Cow::Owned(format!(
        "{}…[{} bytes]…{}",
        &text[..head_end],
        text.len(),
        &text[tail_start..]
    ))
}

/// `bytes` as UTF-8 text, or an error at the line and column of the first
/// byte that is not UTF-8 (the line shown with that byte as U+FFFD).
pub fn decode_utf8(bytes: Vec<u8>, file: &str) -> Result<String, Diagnostic> {
    match String::from_utf8(bytes) {
        Ok(s) => Ok(s),
        Err(e) => {
            let bytes = e.as_bytes();
            let at = e.utf8_error().valid_up_to();
            let line_start = bytes[..at]
                .iter()
                .rposition(|&b| b == b'\n')
                .map_or(0, |i| i + 1);
            let line_end = bytes[at..]
                .iter()
                .position(|&b| b == b'\n')
                .map_or(bytes.len(), |i| at + i);
            let line = bytes[..at].iter().filter(|&&b| b == b'\n').count() + 1;
            // (Valid up to `at`: the characters before it count exactly.)
            let before = std::str::from_utf8(&bytes[line_start..at]).unwrap_or("");
            let column = before.chars().count() + 1;
            let text = String::from_utf8_lossy(&bytes[line_start..line_end]);
            Err(Diagnostic::error(
                file,
                line,
                column,
                1,
                text.trim_end_matches('\r'),
                format!(
                    "invalid UTF-8: byte 0x{:02X} is not part of a UTF-8 character (the file must be UTF-8 text)",
                    bytes[at]
                ),
            ))
        }
    }
}

/// `c`, or U+FFFD for a control character other than a line break: bytes
/// of a binary file must not reach the terminal as escape sequences. (One
/// character for one: the caret stays under its column.)
fn printable(c: char) -> char {
    if c.is_control() && c != '\n' {
        '\u{FFFD}'
    } else {
        c
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// Renders the diagnostic the way rustc does: severity and message, the
/// location, the source line and a caret under the offending text.
impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let message: String = cut(&self.message, MESSAGE_CHARS)
            .chars()
            .map(printable)
            .collect();
        writeln!(f, "{}: {message}", self.severity)?;
        if self.line == 0 {
            return write!(f, "  --> {}", self.file);
        }
        let number = self.line.to_string();
        let pad = " ".repeat(number.len());
        writeln!(f, "{pad}--> {}", self.location())?;
        writeln!(f, "{pad} |")?;
        // Tabs would shift the caret; show them as single spaces.
        let chars: Vec<char> = self
            .source_line
            .chars()
            .map(|c| if c == '\t' { ' ' } else { printable(c) })
            .collect();
        // A long line (a binary file, a CL line without breaks) is shown
        // around the column only.
        let (mut start, mut end) = (0, chars.len());
        if end > SHOWN_CHARS {
            start = self
                .column
                .saturating_sub(SHOWN_CHARS / 3)
                .min(end - SHOWN_CHARS);
            end = start + SHOWN_CHARS;
        }
        let shown: String = chars[start..end].iter().collect();
        let (before, after) = (
            if start > 0 { "…" } else { "" },
            if end < chars.len() { "…" } else { "" },
        );
        write!(f, "{number} | {before}{shown}{after}")?;
        if self.column > start {
            let width = self.width.min(end + 1 - self.column.min(end));
            write!(
                f,
                "\n{pad} | {}{}",
                " ".repeat(self.column - 1 - start + before.chars().count()),
                "^".repeat(width.max(1))
            )?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostic {}

/// Several diagnostics, e.g. every mistake found in one machine file.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl fmt::Display for Diagnostics {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.0.iter().enumerate() {
            if i > 0 {
                f.write_str("\n\n")?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for Diagnostics {}

impl From<Diagnostic> for Diagnostics {
    fn from(d: Diagnostic) -> Self {
        Diagnostics(vec![d])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_oversized_settings_file_is_refused_at_line_1() {
        assert!(oversized_file("m.toml", "abc", "machine", 3).is_none());
        let d = oversized_file("m.toml", "first line\nsecond", "machine", 3).unwrap();
        assert!(d.is_error());
        assert_eq!(
            (d.line, d.column, d.source_line.as_str()),
            (1, 1, "first line")
        );
        assert_eq!(
            d.message,
            "the machine file has 17 bytes, more than 3: a machine file is a few kilobytes \
             (is this a machine file?)"
        );
    }

    #[test]
    fn control_characters_are_not_echoed() {
        let d = Diagnostic::error("bin.cls", 3, 2, 1, "G\u{1b}[2J\tX", "bad `\u{1b}[2J`");
        assert_eq!(
            d.to_string(),
            "error: bad `\u{FFFD}[2J`\n --> bin.cls:3:2\n  |\n3 | G\u{FFFD}[2J X\n  |  ^"
        );
    }

    #[test]
    fn a_long_line_is_shown_around_its_column() {
        let line = format!("{}X{}", "a".repeat(300), "b".repeat(300));
        let d = Diagnostic::error("long.cls", 1, 301, 1, line, "here");
        let shown = d.to_string();
        let lines: Vec<&str> = shown.lines().collect();
        let want = format!("1 | …{}X{}…", "a".repeat(52), "b".repeat(107));
        assert_eq!(lines[3], want);
        // The caret stands under the X.
        let caret = lines[4].find('^').unwrap();
        assert_eq!(lines[3].chars().nth(caret), Some('X'));
    }

    #[test]
    fn invalid_utf8_is_located_at_its_first_bad_byte() {
        let bytes = b"name = \"m\"\nd = \"\xc3\xa4x\xff\"\n".to_vec();
        let d = decode_utf8(bytes, "m.toml").unwrap_err();
        assert_eq!(d.location(), "m.toml:2:8");
        assert!(d.message.contains("0xFF"), "{d}");
        assert_eq!(d.source_line, "d = \"äx\u{FFFD}\"");
        assert_eq!(decode_utf8(b"ok".to_vec(), "x").unwrap(), "ok");
    }

    #[test]
    fn long_tokens_are_not_echoed_whole() {
        let token = "9".repeat(1_000_000);
        let d = Diagnostic::error("a.cls", 1, 1, 1, "", format!("bad `{token}`"));
        let shown = d.to_string();
        assert!(shown.len() < 1000, "{}", shown.len());
        assert!(shown.contains("[1000006 bytes]"), "{shown}");
        assert!(excerpt(&token).len() < 100);
        assert_eq!(excerpt("short"), "short");
    }

    #[test]
    fn renders_location_source_and_caret() {
        let d = Diagnostic::error(
            "part.cls",
            12,
            6,
            5,
            "GOTO/1.2.3,4,5",
            "malformed number `1.2.3`",
        );
        assert_eq!(
            d.to_string(),
            "error: malformed number `1.2.3`\n  --> part.cls:12:6\n   |\n12 | GOTO/1.2.3,4,5\n   |      ^^^^^"
        );
    }

    #[test]
    fn byte_span_finds_line_and_character_column() {
        let src = "a = 1\nname = \"平板\" x\n";
        // byte offset of the `x` on line 2
        let at = src.find(" x").unwrap() + 1;
        let d = Diagnostic::at_byte_span(Severity::Error, "m.toml", src, at..at + 1, "bad");
        assert_eq!((d.line, d.column, d.width), (2, 13, 1));
        assert_eq!(d.source_line, "name = \"平板\" x");
    }

    #[test]
    fn byte_span_past_the_end_is_clamped() {
        let d = Diagnostic::at_byte_span(Severity::Error, "m.toml", "ab", 10..20, "eof");
        assert_eq!((d.line, d.column), (1, 3));
    }
}
