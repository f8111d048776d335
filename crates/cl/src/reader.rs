//! The streaming CL reader.

use std::io::BufRead;

use kinpost_diag::{Diagnostic, Severity};

use crate::number::{PLAIN_CHUNK, parse_number, plain_number, scan_number};
use crate::words::suggest;
use crate::{ClEvent, FeedUnit, Motion, Move, Next, SpindleDir, Statement, Units, Vec3};

/// A byte range in the logical statement text.
type Span = (usize, usize);

/// One physical line of the current logical statement.
#[derive(Debug, Clone, Copy)]
struct Segment {
    /// 1-based line number.
    line: usize,
    /// The line's text in `raw` (no line end, no byte-order mark).
    raw_start: usize,
    raw_end: usize,
    /// The part of the line that went into `text` (always a prefix of the
    /// line: only the line end, a `$$` comment, trailing blanks and the
    /// continuation `$` are cut off).
    text_start: usize,
    text_end: usize,
}

/// What [`ClReader::begin_statement`] found.
enum Begin {
    /// A plain `GOTO` line, read and parsed: `count` values, `end` the
    /// length of its text (in `raw`).
    PlainGoto { count: usize, end: usize },
    /// A plain line, now in `raw`.
    PlainLine,
    /// Nothing yet: `read_lines` reads the statement.
    Lines,
}

/// What [`ClReader::read_lines`] found.
enum Read {
    /// End of input.
    Eof,
    /// A `$$` comment line.
    Comment(usize, String),
    /// A logical statement, now in `text` / `segments`.
    Statement,
}

/// Streaming reader of NX CLSF / APT text: one [`Statement`] at a time.
///
/// The reader keeps the modal state of the CL file: the current tool axis and
/// reference direction (a three-value `GOTO` repeats them), the one-shot
/// `RAPID`, and the units (for `FEDRAT` without a unit). It allocates nothing
/// per `GOTO` line: lines are read into a reused buffer and numbers are parsed
/// in place.
///
/// **Errors** ([`Severity::Error`]) are returned by
/// [`next_statement`](Self::next_statement) and mean the input cannot be
/// posted as it is. The failed statement has no effect; the reader stays
/// usable and the next call goes on with the following line (so a checker can
/// list every error), except after an I/O error, after which it reports end
/// of input.
///
/// **Warnings** (unknown statements, a cut-short `MSYS`, ignored cutter
/// compensation, …) are collected in order and handed out, drained, by
/// [`take_warnings`](Self::take_warnings).
///
/// The reader is also an [`Iterator`] over `Result<Statement, Diagnostic>`.
pub struct ClReader<R> {
    input: R,
    file: String,
    /// Physical lines of the current statement, back to back.
    raw: Vec<u8>,
    /// The logical statement: continuation lines joined, comments removed;
    /// unused (empty) when `text_in_raw` is set.
    text: String,
    /// `Some(len)` if the logical statement is `raw[..len]` (a plain line,
    /// read by the fast path, which is ASCII): then it is not copied to
    /// `text`. See [`text_bytes`](Self::text_bytes).
    text_in_raw: Option<usize>,
    segments: Vec<Segment>,
    /// Comma-separated fields of the current statement's arguments.
    fields: Vec<Span>,
    /// Physical lines read so far.
    line: usize,
    /// Set after an I/O error.
    finished: bool,
    warnings: Vec<Diagnostic>,
    axis: Option<Vec3>,
    reference: Option<Vec3>,
    /// A tool axis far from unit length was reported.
    axis_length_noted: bool,
    /// The point of the last `GOTO` (CL units), for `GODLTA`.
    last_point: Option<Vec3>,
    /// The first `MSYS` (origin and axes as given) and its line: a later
    /// one must not change it.
    msys: Option<([f64; 9], usize, usize)>,
    rapid: bool,
    units: Units,
    spindle: Option<(f64, SpindleDir)>,
}

impl<R: BufRead> ClReader<R> {
    /// A reader of `input`; `file_name` is used in diagnostics (`-` or
    /// `<stdin>` for standard input).
    pub fn new(input: R, file_name: impl Into<String>) -> Self {
        ClReader {
            input,
            file: file_name.into(),
            raw: Vec::with_capacity(256),
            text: String::with_capacity(256),
            text_in_raw: None,
            segments: Vec::with_capacity(4),
            fields: Vec::with_capacity(16),
            line: 0,
            finished: false,
            warnings: Vec::new(),
            axis: None,
            reference: None,
            axis_length_noted: false,
            last_point: None,
            msys: None,
            rapid: false,
            units: Units::Mm,
            spindle: None,
        }
    }

    /// Sets the tool axis used by three-value `GOTO`s until a six- or
    /// nine-value `GOTO` gives one, for 3-axis APT files that never state it
    /// (usually `[0.0, 0.0, 1.0]`). Without it, a `GOTO/x,y,z` before any
    /// tool axis is known is an error. The vector is normalized.
    ///
    /// # Panics
    ///
    /// If `axis` is zero or not finite.
    pub fn with_default_axis(mut self, axis: Vec3) -> Self {
        let axis = normalize(axis).expect("default tool axis must be a finite, non-zero vector");
        self.axis = Some(axis);
        self
    }

    /// The file name given to [`new`](Self::new).
    pub fn file_name(&self) -> &str {
        &self.file
    }

    /// The current tool axis (unit length), if known.
    pub fn tool_axis(&self) -> Option<Vec3> {
        self.axis
    }

    /// The current units (`Mm` until a `UNITS` statement says otherwise).
    pub fn units(&self) -> Units {
        self.units
    }

    /// The number of physical lines read so far.
    pub fn lines_read(&self) -> usize {
        self.line
    }

    /// The warnings found since the last call, in input order; the reader's
    /// list is emptied. Call it after each statement to interleave warnings
    /// with the output, or once at the end.
    pub fn take_warnings(&mut self) -> Vec<Diagnostic> {
        std::mem::take(&mut self.warnings)
    }

    /// A diagnostic about the statement last returned by
    /// [`next_statement`](Self::next_statement), for problems found after
    /// reading (a pose the machine cannot reach, a feed move without a feed
    /// rate): placed on the statement's first line, underlining its text.
    pub fn statement_diagnostic(
        &self,
        severity: Severity,
        message: impl Into<String>,
    ) -> Diagnostic {
        let end = self.segments.last().map_or(0, |s| s.text_end);
        let start = skip_blanks(self.text_bytes(), 0).min(end);
        self.diag(severity, (start, end), message)
    }

    /// The first physical line of the current statement, without its line
    /// ending, and its number: for diagnostics about the statement made after
    /// the reader has moved on (the planner decides a whole path at once).
    pub fn statement_line(&self) -> (usize, &[u8]) {
        match self.segments.first() {
            Some(seg) => {
                let raw = &self.raw[seg.raw_start..seg.raw_end];
                let end = raw
                    .iter()
                    .rposition(|&b| b != b'\n' && b != b'\r')
                    .map_or(0, |i| i + 1);
                (seg.line, &raw[..end])
            }
            None => (self.line, &[]),
        }
    }

    /// The next statement that means something; `Ok(None)` at the end of the
    /// input. Blank lines and silently ignored statements (`RAPID`, which only
    /// marks the next `GOTO`, `PAINT/…`, unknown statements, …) are skipped.
    ///
    /// An `Err` is an error diagnostic (never a warning): the input cannot be
    /// posted as it is. See the type's documentation for what happens after.
    pub fn next_statement(&mut self) -> Result<Option<Statement>, Diagnostic> {
        let mut goto = Move::default();
        Ok(match self.next_move(&mut goto)? {
            Next::Move => Some(goto.into()),
            Next::Statement(statement) => Some(statement),
            Next::End => None,
        })
    }

    /// [`next_statement`](Self::next_statement) for a caller that reads
    /// mostly moves: the `GOTO` of a plain line (the bulk of a CL file) is
    /// written into `goto`, field by field, and only said to be there
    /// ([`Next::Move`]); every other statement, and a `GOTO` of any other
    /// shape, comes as a [`Statement`]. (A move returned inside the
    /// statement enum was copied from place to place on its way.)
    #[inline(always)]
    pub fn next_move(&mut self, goto: &mut Move) -> Result<Next, Diagnostic> {
        if self.finished {
            return Ok(Next::End);
        }
        // Everything but a plain `GOTO` line is left to
        // `next_statement_general`, out of line, so that this stays small.
        let mut values = [0.0; 9];
        match self.begin_statement(&mut values)? {
            Begin::PlainGoto { count, end } => {
                self.plain_move(goto, values, count, end)?;
                Ok(Next::Move)
            }
            begun => Ok(match self.next_statement_general(begun, values)? {
                Some(statement) => Next::Statement(statement),
                None => Next::End,
            }),
        }
    }

    /// [`next_statement`](Self::next_statement) after `begin_statement`
    /// found something else than a plain `GOTO` line.
    #[inline(never)]
    fn next_statement_general(
        &mut self,
        mut begun: Begin,
        mut values: [f64; 9],
    ) -> Result<Option<Statement>, Diagnostic> {
        loop {
            let read = match begun {
                Begin::PlainGoto { count, end } => {
                    let mut goto = Move::default();
                    self.plain_move(&mut goto, values, count, end)?;
                    return Ok(Some(goto.into()));
                }
                Begin::PlainLine => Read::Statement,
                Begin::Lines => self.read_lines()?,
            };
            match read {
                Read::Eof => return Ok(None),
                Read::Comment(line, text) => {
                    return Ok(Some(Statement {
                        line,
                        event: ClEvent::Comment(text),
                    }));
                }
                Read::Statement => {
                    if let Some(event) = self.interpret()? {
                        let line = self.segments[0].line;
                        return Ok(Some(Statement { line, event }));
                    }
                }
            }
            if self.finished {
                return Ok(None);
            }
            begun = self.begin_statement(&mut values)?;
        }
    }

    /// The move of a plain `GOTO` line read by `begin_statement` (its
    /// `count` values and the length of its text), written into `goto`
    /// field by field.
    #[inline(always)]
    fn plain_move(
        &mut self,
        goto: &mut Move,
        values: [f64; 9],
        count: usize,
        end: usize,
    ) -> Result<(), Diagnostic> {
        let (point, axis, motion) = self.goto_move((5, end), values, count)?;
        goto.line = self.line;
        goto.point = point;
        goto.axis = axis;
        goto.reference = self.reference;
        goto.motion = motion;
        Ok(())
    }

    // ----- lines -----

    /// The logical statement text.
    #[inline(always)]
    fn text_bytes(&self) -> &[u8] {
        match self.text_in_raw {
            Some(len) => &self.raw[..len],
            None => self.text.as_bytes(),
        }
    }

    /// The logical statement text as a `str` (for the slower paths: it is
    /// validated again when it is a line of `raw`).
    fn text(&self) -> &str {
        match self.text_in_raw {
            Some(len) => std::str::from_utf8(&self.raw[..len]).expect("statement text is UTF-8"),
            None => &self.text,
        }
    }

    /// Starts the next statement: the fast paths, on the input buffer as it
    /// is. A whole line in the buffer that is ASCII without `$` (no comment,
    /// no continuation, no UTF-8 to check) is a statement on its own; a plain
    /// `GOTO` line is also parsed, its values into `values`. Anything else is
    /// left to [`read_lines`](Self::read_lines), which handles it exactly as
    /// before.
    #[inline(always)]
    fn begin_statement(&mut self, values: &mut [f64; 9]) -> Result<Begin, Diagnostic> {
        self.raw.clear();
        self.text.clear();
        self.segments.clear();
        self.text_in_raw = None;
        match self.input.fill_buf() {
            Ok(buf) => {
                if let Some(PlainGoto { count, end, next }) = plain_goto(buf, values) {
                    self.raw.extend_from_slice(&buf[..end]);
                    self.input.consume(next);
                    self.line += 1;
                    self.segments.push(Segment {
                        line: self.line,
                        raw_start: 0,
                        raw_end: end,
                        text_start: 0,
                        text_end: end,
                    });
                    self.text_in_raw = Some(end);
                    return Ok(Begin::PlainGoto { count, end });
                }
                if let Some(n) = plain_line(buf) {
                    let line = &buf[..n];
                    let mut end = n;
                    if end > 0 && line[end - 1] == b'\r' {
                        end -= 1;
                    }
                    let text_end = trim_end_ascii(&line[..end]);
                    self.raw.extend_from_slice(line);
                    self.input.consume(n + 1);
                    self.line += 1;
                    self.segments.push(Segment {
                        line: self.line,
                        raw_start: 0,
                        raw_end: end,
                        text_start: 0,
                        text_end,
                    });
                    self.text_in_raw = Some(text_end);
                    return Ok(Begin::PlainLine);
                }
            }
            // `read_until` in `read_lines` retries.
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(self.read_error(e)),
        }
        Ok(Begin::Lines)
    }

    /// Reads physical lines until a logical statement is complete (the
    /// general path, after `begin_statement`).
    fn read_lines(&mut self) -> Result<Read, Diagnostic> {
        loop {
            let mut start = self.raw.len();
            if self.segments.len() >= MAX_STATEMENT_LINES {
                // (At the line that would be one too many.)
                self.line += 1;
                return Err(self.too_long(format!(
                    "the statement that starts on line {} goes on over more than {MAX_STATEMENT_LINES} \
                     lines (`$` continuations): a CL statement is a line or a few",
                    self.segments[0].line
                )));
            }
            match read_line_bounded(&mut self.input, &mut self.raw, MAX_STATEMENT_BYTES) {
                Ok(None) => {
                    self.line += 1;
                    return Err(self.too_long(format!(
                        "the statement on line {} is longer than {MAX_STATEMENT_BYTES} bytes \
                         (its lines and `$` continuations): a CL statement is a line or a few; \
                         is this a CL file?",
                        self.segments.first().map_or(self.line, |s| s.line)
                    )));
                }
                Ok(Some(0)) => {
                    let Some(last) = self.segments.last() else {
                        return Ok(Read::Eof);
                    };
                    // Point at the `$` that promised a continuation.
                    let at = last.text_end;
                    return Err(self.diag(
                        Severity::Error,
                        (at, at + 1),
                        "the statement continues (`$`) past the end of the file",
                    ));
                }
                Ok(Some(_)) => {}
                Err(e) => return Err(self.read_error(e)),
            }
            self.line += 1;
            let mut end = self.raw.len();
            if self.raw[end - 1] == b'\n' {
                end -= 1;
            }
            if end > start && self.raw[end - 1] == b'\r' {
                end -= 1;
            }
            self.raw.truncate(end);
            if self.line == 1 && self.raw.starts_with(b"\xEF\xBB\xBF") {
                start += 3;
            }
            // (Trailing CRs are blanks at the end of a line, as on the fast
            // path.)
            let content = trim_end_ascii(&self.raw[start..end]);
            if let Some(at) = self.raw[start..start + content]
                .iter()
                .position(|&b| b == b'\r')
            {
                return Err(self.carriage_return(start, end, at));
            }
            let line = match std::str::from_utf8(&self.raw[start..end]) {
                Ok(line) => line,
                Err(e) => return Err(self.invalid_utf8(start, end, e)),
            };
            let mut body = line;
            if line.as_bytes().contains(&b'$')
                && let Some(p) = line.find("$$")
            {
                if line[..p].trim().is_empty() {
                    if self.segments.is_empty() {
                        let comment = line[p + 2..].trim().to_string();
                        return Ok(Read::Comment(self.line, comment));
                    }
                    // A comment line inside a continued statement.
                    self.raw.truncate(start);
                    continue;
                }
                body = &line[..p];
            }
            let body = body.trim_end();
            let (body, continued) = match body.strip_suffix('$') {
                Some(body) => (body, true),
                None => (body, false),
            };
            let text_start = self.text.len();
            self.text.push_str(body);
            self.segments.push(Segment {
                line: self.line,
                raw_start: start,
                raw_end: end,
                text_start,
                text_end: self.text.len(),
            });
            if !continued {
                return Ok(Read::Statement);
            }
        }
    }

    /// The error for a failed read; the reader then reports end of input.
    #[cold]
    fn read_error(&mut self, e: std::io::Error) -> Diagnostic {
        self.finished = true;
        Diagnostic::error(
            &self.file,
            self.line + 1,
            0,
            0,
            "",
            format!("cannot read the file: {e}"),
        )
    }

    /// A statement or line past the reader's limits: the error, at the
    /// current line (its start shown); the reader then reports the end of
    /// the input (the rest of the line is not read).
    #[cold]
    fn too_long(&mut self, message: String) -> Diagnostic {
        self.finished = true;
        let start = self.segments.last().map_or(0, |s| s.raw_end);
        let shown = &self.raw[start.min(self.raw.len())..];
        let shown = &shown[..shown.len().min(200)];
        Diagnostic::error(
            &self.file,
            self.line,
            1,
            1,
            String::from_utf8_lossy(shown),
            message,
        )
    }

    /// A carriage return inside a line (byte `at` of the line in
    /// `raw[start..end]`): ends lines on some systems (classic Mac OS, some
    /// controllers), is a stray byte on others; the reader does not guess
    /// which statements were meant.
    #[cold]
    fn carriage_return(&mut self, start: usize, end: usize, at: usize) -> Diagnostic {
        let bytes = &self.raw[start..end];
        let column = String::from_utf8_lossy(&bytes[..at]).chars().count() + 1;
        // (The whole line, as the fast path's diagnostic has it: the
        // display shows the part around the column.)
        Diagnostic::error(
            &self.file,
            self.line,
            column,
            1,
            String::from_utf8_lossy(bytes),
            CR_INSIDE_A_LINE,
        )
    }

    fn invalid_utf8(&self, start: usize, end: usize, e: std::str::Utf8Error) -> Diagnostic {
        let bytes = &self.raw[start..end];
        let valid = e.valid_up_to();
        let column = String::from_utf8_lossy(&bytes[..valid]).chars().count() + 1;
        Diagnostic::error(
            &self.file,
            self.line,
            column,
            1,
            String::from_utf8_lossy(bytes),
            format!(
                "invalid UTF-8 (byte 0x{:02X}); CL files must be UTF-8 text (convert it, e.g. with `iconv -f GBK -t UTF-8`)",
                bytes[valid]
            ),
        )
    }

    // ----- diagnostics -----

    /// A diagnostic about `span` of the logical text, placed on the physical
    /// line that holds the start of the span.
    fn diag(&self, severity: Severity, span: Span, message: impl Into<String>) -> Diagnostic {
        let index = self
            .segments
            .iter()
            .position(|s| span.0 < s.text_end)
            .unwrap_or(self.segments.len().saturating_sub(1));
        let Some(seg) = self.segments.get(index) else {
            return make(severity, &self.file, self.line, 0, 0, "", message);
        };
        // Spans end at the statement's end.
        let end = self.segments.last().map_or(0, |s| s.text_end);
        let span = (span.0.min(end), span.1.min(end));
        let raw = String::from_utf8_lossy(&self.raw[seg.raw_start..seg.raw_end]);
        let from = floor_char_boundary(&raw, span.0.saturating_sub(seg.text_start));
        let to = span.1.min(seg.text_end).saturating_sub(seg.text_start);
        let to = floor_char_boundary(&raw, to.max(from));
        let column = raw[..from].chars().count() + 1;
        let width = raw[from..to].chars().count();
        make(severity, &self.file, seg.line, column, width, raw, message)
    }

    fn error(&self, span: Span, message: impl Into<String>) -> Diagnostic {
        self.diag(Severity::Error, span, message)
    }

    fn warn(&mut self, span: Span, message: impl Into<String>) {
        let d = self.diag(Severity::Warning, span, message);
        self.warnings.push(d);
    }

    // ----- statements -----

    /// Interprets the logical statement in `text`.
    #[inline(always)]
    fn interpret(&mut self) -> Result<Option<ClEvent>, Diagnostic> {
        // (A line read on the fast path: its CR is checked here, the
        // general path checked it already.)
        if let Some(at) = self.text_bytes().iter().position(|&b| b == b'\r') {
            return Err(self.error((at, at + 1), CR_INSIDE_A_LINE));
        }
        let b = self.text_bytes();
        let start = skip_blanks(b, 0);
        if start == b.len() {
            return Ok(None);
        }
        let mut word_end = start;
        while word_end < b.len() && is_word_byte(b[word_end]) {
            word_end += 1;
        }
        if word_end - start >= 4 && b[start..start + 4].eq_ignore_ascii_case(b"CSI_") {
            return Ok(None); // CAMWorks display / tool-library records
        }
        let mut key = [0u8; 12];
        let n = word_end - start;
        let key: &[u8] = if n <= key.len() {
            for (k, &c) in key.iter_mut().zip(&b[start..word_end]) {
                *k = c.to_ascii_uppercase();
            }
            &key[..n]
        } else {
            b""
        };
        let mut word: Span = (start, word_end);
        let mut tool_path = false;
        if key == b"TOOL" {
            let p = skip_blanks(b, word_end);
            if p > word_end
                && b.len() >= p + 4
                && b[p..p + 4].eq_ignore_ascii_case(b"PATH")
                && b.get(p + 4).is_none_or(|&c| !is_word_byte(c))
            {
                word.1 = p + 4;
                tool_path = true;
            }
        }
        let after = skip_blanks(b, word.1);
        let slash = after < b.len() && b[after] == b'/';
        let args: Span = (if slash { after + 1 } else { after }, b.len());
        let has_args = skip_blanks(b, args.0) < args.1;

        if tool_path {
            return self.tool_path(args).map(Some);
        }
        // Statements that take arguments after a slash.
        let needs_slash = matches!(
            key,
            b"GOTO"
                | b"FEDRAT"
                | b"TLDATA"
                | b"CUTTER"
                | b"MSYS"
                | b"LOAD"
                | b"SELECT"
                | b"SPINDL"
                | b"COOLNT"
                | b"UNITS"
                | b"UNIT"
                | b"PRESSURE"
                | b"CSYS"
                | b"MULTAX"
        );
        if needs_slash && !slash && has_args {
            let name = self.text()[word.0..word.1].to_ascii_uppercase();
            return Err(self.error((after, after + 1), format!("expected `/` after `{name}`")));
        }
        match key {
            b"GOTO" => self.goto(args).map(Some),
            b"RAPID" => {
                self.rapid = true;
                Ok(None)
            }
            b"FEDRAT" => {
                let feed = self.fedrat(args)?;
                // APT: a feed rate cancels a RAPID that no move has used.
                if std::mem::take(&mut self.rapid) {
                    self.warn(
                        (word.0, args.1),
                        "FEDRAT after RAPID: the next move is at this feed, not rapid",
                    );
                }
                Ok(Some(feed))
            }
            b"TLAXIS" => self.tlaxis(word, args),
            b"GODLTA" => self.godlta(word, args).map(Some),
            b"LOADTL" => Ok(Some(ClEvent::LoadTool {
                number: self.loadtl(word, args)?,
            })),
            b"TLDATA" => self.tool_data(args, false).map(Some),
            b"CUTTER" => self.tool_data(args, true).map(Some),
            b"MSYS" => self.msys(args),
            b"LOAD" => Ok(Some(ClEvent::LoadTool {
                number: self.tool_number("LOAD", word, args)?,
            })),
            b"SELECT" => Ok(Some(ClEvent::SelectTool {
                number: self.tool_number("SELECT", word, args)?,
            })),
            b"SPINDL" => self.spindle(args).map(Some),
            b"COOLNT" => self.coolant(args).map(Some),
            b"INSERT" => Ok(Some(ClEvent::Insert(
                self.text()[args.0..].trim_end().to_string(),
            ))),
            b"PPRINT" => Ok(Some(ClEvent::Comment(
                self.text()[args.0..].trim().to_string(),
            ))),
            b"END-OF-PATH" => Ok(Some(ClEvent::EndOfPath)),
            b"PARTNO" => Ok(Some(ClEvent::PartNo(
                unquote(self.text()[args.0..].trim()).to_string(),
            ))),
            b"UNITS" | b"UNIT" => self.units_statement(word, args).map(Some),
            b"MULTAX" => self.multax(args).map(Some),
            b"PRESSURE" => self.pressure(word, args).map(Some),
            b"FINI" => Ok(Some(ClEvent::Fini)),
            b"PAINT" | b"TRNTYP" => Ok(None),
            b"CSYS" => self.csys(word, args),
            b"CUTCOM" => {
                self.split(args);
                let off = self.fields.first().is_some_and(|&f| self.is(f, "OFF"));
                if !off {
                    self.warn(
                        (word.0, args.1),
                        "cutter compensation ignored: the GOTO points are used as tool positions",
                    );
                }
                Ok(None)
            }
            b"CIRCLE" => Err(self.error(
                word,
                "CIRCLE is not supported yet; have the CAM system output arcs as GOTO points (linearized)",
            )),
            b"NURBS" => Err(self.error(
                word,
                "NURBS is not supported yet; have the CAM system output GOTO points instead",
            )),
            b"CYCLE" => {
                self.split(args);
                if self.fields.len() == 1 && self.is(self.fields[0], "OFF") {
                    return Ok(None);
                }
                Err(self.error(
                    word,
                    "CYCLE is not supported yet; have the CAM system output canned cycles as GOTO moves",
                ))
            }
            _ => {
                self.unknown(word);
                Ok(None)
            }
        }
    }

    fn unknown(&mut self, word: Span) {
        let mut word = word;
        if word.0 == word.1 {
            // Not a word at all: show the token up to a blank or a slash.
            let b = self.text_bytes();
            let mut end = word.0;
            while end < b.len() && !b[end].is_ascii_whitespace() && b[end] != b'/' {
                end += 1;
            }
            if end == word.0 {
                end += 1;
            }
            word.1 = floor_char_boundary(self.text(), end.min(b.len()));
            if word.1 == word.0 {
                word.1 = self.text()[word.0..]
                    .chars()
                    .next()
                    .map_or(word.0, |c| word.0 + c.len_utf8());
            }
        }
        let text = &self.text()[word.0..word.1];
        let message = match suggest(text) {
            Some(known) => format!("unknown statement `{text}` (did you mean `{known}`?) ignored"),
            None => format!("unknown statement `{text}` ignored"),
        };
        self.warn(word, message);
    }

    /// Parses the values of a `GOTO` in one pass, without splitting into
    /// fields first. `None` if a field is not a plain number: the caller then
    /// takes the slow path, which finds the field and reports it.
    #[inline(always)]
    fn goto_values(&self, args: Span, v: &mut [f64; 9]) -> Option<usize> {
        let b = &self.text_bytes()[..args.1];
        let mut i = skip_blanks(b, args.0);
        if i == b.len() {
            return Some(0);
        }
        let mut count = 0;
        loop {
            let (x, end) = scan_number(b, i)?;
            if let Some(slot) = v.get_mut(count) {
                *slot = x;
            }
            count += 1;
            let k = match b.get(end) {
                Some(b',') => end,
                _ => skip_blanks(b, end),
            };
            match b.get(k) {
                None => return Some(count),
                Some(b',') => i = skip_blanks(b, k + 1),
                Some(_) => return None,
            }
            if i == b.len() {
                return None; // trailing empty field
            }
        }
    }

    #[inline(always)]
    fn goto(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        let mut v = [0.0; 9];
        let count = match self.goto_values(args, &mut v) {
            Some(count) => count,
            None => {
                self.split(args);
                for (value, &field) in v.iter_mut().zip(&self.fields) {
                    *value = self.number(field)?;
                }
                self.fields.len()
            }
        };
        let (point, axis, motion) = self.goto_move(args, v, count)?;
        Ok(ClEvent::Goto {
            point,
            axis,
            reference: self.reference,
            motion,
        })
    }

    /// A `GOTO` with `count` values (the first 9 in `v`): its point, tool
    /// axis and motion, the new modal state set (the reference direction is
    /// then `self.reference`).
    #[inline(always)]
    fn goto_move(
        &mut self,
        args: Span,
        v: [f64; 9],
        count: usize,
    ) -> Result<(Vec3, Vec3, Motion), Diagnostic> {
        if !matches!(count, 3 | 6 | 9) {
            return Err(self.goto_count_error(args, count));
        }
        let point = [v[0], v[1], v[2]];
        let axis = if count >= 6 {
            let n2 = v[3] * v[3] + v[4] * v[4] + v[5] * v[5];
            if !(AXIS_LENGTH2.0..=AXIS_LENGTH2.1).contains(&n2) && !self.axis_length_noted {
                self.axis_length(args, n2);
            }
            match normalize([v[3], v[4], v[5]]) {
                Some(axis) => axis,
                None => {
                    return Err(self.goto_error(
                        args,
                        3,
                        "the tool axis (i,j,k) is zero or not finite",
                    ));
                }
            }
        } else {
            match self.axis {
                Some(axis) => axis,
                None => {
                    return Err(self.goto_error(
                        args,
                        0,
                        "GOTO/x,y,z before any tool axis is known: give the first GOTO as x,y,z,i,j,k (or set a default tool axis for a 3-axis file)",
                    ));
                }
            }
        };
        if count == 9 {
            let r = normalize([v[6], v[7], v[8]]);
            let problem = match r {
                None => Some("the reference direction (u,v,w) is zero or not finite"),
                Some(r) => {
                    let c = cross(axis, r);
                    ((c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() < 1e-9)
                        .then_some("the reference direction (u,v,w) is parallel to the tool axis")
                }
            };
            if let Some(message) = problem {
                return Err(self.goto_error(args, 6, message));
            }
            self.reference = r;
        }
        // Only now, when nothing can fail: a failed statement has no effect.
        // (The reference direction is kept as it is unless given.)
        self.axis = Some(axis);
        self.last_point = Some(point);
        let motion = if std::mem::take(&mut self.rapid) {
            Motion::Rapid
        } else {
            Motion::Feed
        };
        Ok((point, axis, motion))
    }

    /// The error for a `GOTO` with `count` values, not 3, 6 or 9 (out of
    /// line: `goto_move` is on the hot path).
    #[cold]
    #[inline(never)]
    fn goto_count_error(&mut self, args: Span, count: usize) -> Diagnostic {
        self.split(args);
        let extra = match count {
            0..=2 => args,
            4 | 5 => (self.fields[3].0, args.1),
            7 | 8 => (self.fields[6].0, args.1),
            _ => (self.fields[9].0, args.1),
        };
        self.error(
            extra,
            format!(
                "GOTO has {count} value{}, expected 3 (x,y,z), 6 (x,y,z,i,j,k) or 9 (x,y,z,i,j,k,u,v,w)",
                if count == 1 { "" } else { "s" }
            ),
        )
    }

    /// The warning for a tool axis given far from unit length (once a
    /// file; a zero or non-finite one is an error of its own).
    #[cold]
    #[inline(never)]
    fn axis_length(&mut self, args: Span, n2: f64) {
        if !(n2.is_finite() && n2 > 0.0) {
            return;
        }
        self.axis_length_noted = true;
        self.split(args);
        let span = (self.fields[3].0, self.fields[5].1);
        self.warn(
            span,
            format!(
                "the tool axis (i,j,k) has length {:.6}, not 1: it is scaled to unit length \
                 (further ones are not reported)",
                n2.sqrt()
            ),
        );
    }

    /// The error about the values `first..first + 3` of a `GOTO`.
    #[cold]
    #[inline(never)]
    fn goto_error(&mut self, args: Span, first: usize, message: &str) -> Diagnostic {
        self.split(args);
        self.error((self.fields[first].0, self.fields[first + 2].1), message)
    }

    fn fedrat(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut value: Option<(f64, Span)> = None;
        let mut unit: Option<FeedUnit> = None;
        for k in 0..self.fields.len() {
            let f = self.fields[k];
            if self.is_word(f) {
                let u = match self.field(f).to_ascii_uppercase().as_str() {
                    "MMPM" => FeedUnit::Mmpm,
                    "IPM" => FeedUnit::Ipm,
                    "MMPR" => FeedUnit::Mmpr,
                    "IPR" => FeedUnit::Ipr,
                    other => {
                        return Err(self.error(
                            f,
                            format!("unknown feed unit `{other}`; expected MMPM, IPM, MMPR or IPR"),
                        ));
                    }
                };
                if unit.is_some() {
                    return Err(self.error(f, "FEDRAT has two units"));
                }
                unit = Some(u);
            } else {
                if value.is_some() {
                    return Err(self.error(f, "FEDRAT has two feed values"));
                }
                value = Some((self.number(f)?, f));
            }
        }
        let Some((value, span)) = value else {
            return Err(self.error(args, "FEDRAT without a feed value"));
        };
        if value <= 0.0 {
            return Err(self.error(
                span,
                format!("the feed rate must be positive, got `{}`", self.field(span)),
            ));
        }
        let unit = unit.unwrap_or(match self.units {
            Units::Mm => FeedUnit::Mmpm,
            Units::Inch => FeedUnit::Ipm,
        });
        Ok(ClEvent::Feedrate { value, unit })
    }

    fn tool_path(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut fields = self.fields.iter().map(|&f| self.field(f).to_string());
        let name = fields.next().unwrap_or_default();
        let words = fields.collect();
        Ok(ClEvent::ToolPath { name, words })
    }

    fn tool_data(&mut self, args: Span, cutter: bool) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut first = 0;
        let kind = if cutter {
            "CUTTER".to_string()
        } else if let Some(&f) = self.fields.first().filter(|&&f| self.is_word(f)) {
            first = 1;
            self.field(f).to_string()
        } else {
            String::new()
        };
        let mut values = Vec::with_capacity(self.fields.len());
        for k in first..self.fields.len() {
            values.push(self.number(self.fields[k])?);
        }
        Ok(ClEvent::ToolData { kind, values })
    }

    fn msys(&mut self, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        self.split(args);
        let mut count = self.fields.len();
        // A record cut short often keeps its trailing comma.
        if count > 1 && self.fields[count - 1].0 == self.fields[count - 1].1 {
            count -= 1;
        }
        let mut v = [0.0; 9];
        for (k, value) in v.iter_mut().enumerate().take(count) {
            *value = self.number(self.fields[k])?;
        }
        if count < 3 {
            return Err(self.error(args, "MSYS needs at least the origin x,y,z"));
        }
        // Every GOTO is posted in the machine file's part frame: a second
        // coordinate system would put the points after it elsewhere.
        let line = self.statement_line().0;
        match self.msys {
            None => self.msys = Some((v, count, line)),
            Some((first, first_count, first_line)) => {
                let n = count.min(first_count).min(v.len());
                if (0..n).any(|k| (v[k] - first[k]).abs() > 1e-6) {
                    return Err(self.error(
                        args,
                        format!(
                            "MSYS changes the machine coordinate system of line {first_line}: kinpost posts every point in the part frame of the machine file; post the operations of each coordinate system as a program of their own"
                        ),
                    ));
                }
            }
        }
        let origin = [v[0], v[1], v[2]];
        let x = (count >= 6).then_some([v[3], v[4], v[5]]);
        let y = (count >= 9).then_some([v[6], v[7], v[8]]);
        if count != 3 && count != 9 {
            let detail = match count {
                4 | 5 => "only the origin is used",
                6..=8 => {
                    "the line looks cut short: the origin and the X axis are used, the Y axis is missing"
                }
                _ => "the values after the ninth are ignored",
            };
            self.warn(
                args,
                format!("MSYS has {count} values, expected 3 or 9; {detail}"),
            );
        }
        Ok(Some(ClEvent::MachineSystem { origin, x, y }))
    }

    /// `TLAXIS/i,j,k`: the tool axis of the three-value `GOTO`s that follow.
    fn tlaxis(&mut self, word: Span, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        self.split(args);
        if self.fields.len() != 3 || self.fields.iter().any(|&f| self.is_word(f)) {
            return Err(self.error(
                (word.0, args.1),
                "only `TLAXIS/i,j,k` is supported (a fixed tool axis); have the CAM system output the tool axis in each GOTO",
            ));
        }
        let mut v = [0.0; 3];
        for (value, &f) in v.iter_mut().zip(&self.fields) {
            *value = self.number(f)?;
        }
        match normalize(v) {
            Some(axis) => {
                self.axis = Some(axis);
                Ok(None)
            }
            None => Err(self.error(args, "the tool axis (i,j,k) is zero or not finite")),
        }
    }

    /// `GODLTA/dx,dy,dz` (a move by that much) or `GODLTA/d` (along the
    /// tool axis): a `GOTO` relative to the last point, tool axis kept.
    fn godlta(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let (Some(last), Some(axis)) = (self.last_point, self.axis) else {
            return Err(self.error(
                (word.0, args.1),
                "GODLTA before any GOTO: a relative move needs a point to start from",
            ));
        };
        let mut d = [0.0; 3];
        match self.fields.len() {
            1 => {
                let t = self.number(self.fields[0])?;
                d = axis.map(|a| a * t);
            }
            3 => {
                for (value, &f) in d.iter_mut().zip(&self.fields) {
                    *value = self.number(f)?;
                }
            }
            n => {
                return Err(self.error(
                    args,
                    format!(
                        "GODLTA has {n} values, expected 1 (along the tool axis) or 3 (dx,dy,dz)"
                    ),
                ));
            }
        }
        // A three-value GOTO to the moved point.
        let mut v = [0.0; 9];
        for k in 0..3 {
            v[k] = last[k] + d[k];
        }
        let (point, axis, motion) = self.goto_move(args, v, 3)?;
        Ok(ClEvent::Goto {
            point,
            axis,
            reference: self.reference,
            motion,
        })
    }

    /// `LOADTL/n[,…]` (CATIA, Fusion, Mastercam APT): `LOAD/TOOL,n`.
    fn loadtl(&mut self, word: Span, args: Span) -> Result<u32, Diagnostic> {
        self.split(args);
        if self.fields.is_empty() {
            return Err(self.error(word, "expected `LOADTL/n`"));
        }
        self.tool_number_field(0, args)
    }

    /// Field `k` (split already) as a tool number; the fields after it are
    /// ignored with a warning.
    fn tool_number_field(&mut self, k: usize, args: Span) -> Result<u32, Diagnostic> {
        let f = self.fields[k];
        let n = self.number(f)?;
        if !(n >= 0.0 && n <= f64::from(u32::MAX) && n.fract() == 0.0) {
            return Err(self.error(
                f,
                format!(
                    "the tool number must be a whole number from 0 to {}, got `{}`",
                    u32::MAX,
                    self.field(f)
                ),
            ));
        }
        if let Some(next) = self.fields.get(k + 1) {
            let rest = (next.0, args.1);
            let text = self.text()[rest.0..rest.1].trim().to_string();
            self.warn(rest, format!("`{text}` after the tool number ignored"));
        }
        Ok(n as u32)
    }

    fn tool_number(&mut self, name: &str, word: Span, args: Span) -> Result<u32, Diagnostic> {
        self.split(args);
        let usage = format!("expected `{name}/TOOL,n`");
        let Some(&first) = self.fields.first() else {
            return Err(self.error(word, usage));
        };
        if !self.is(first, "TOOL") {
            return Err(self.error(first, usage));
        }
        if self.fields.len() < 2 {
            return Err(self.error(
                (first.1, first.1),
                format!("{usage}: the tool number is missing"),
            ));
        }
        self.tool_number_field(1, args)
    }

    fn spindle(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut rpm: Option<(f64, Span)> = None;
        let mut dir: Option<SpindleDir> = None;
        for k in 0..self.fields.len() {
            let f = self.fields[k];
            if self.is_word(f) {
                match self.field(f).to_ascii_uppercase().as_str() {
                    "OFF" => return Ok(ClEvent::SpindleOff),
                    "ON" | "RPM" => {}
                    "CLW" => dir = Some(SpindleDir::Clockwise),
                    "CCLW" => dir = Some(SpindleDir::CounterClockwise),
                    "SFM" | "SMM" => {
                        return Err(self.error(
                            f,
                            "constant surface speed (SFM/SMM) is not supported; give the speed in RPM",
                        ));
                    }
                    _ => {
                        let text = self.field(f).to_string();
                        self.warn(f, format!("`{text}` in SPINDL ignored"));
                    }
                }
            } else if rpm.is_none() {
                rpm = Some((self.number(f)?, f));
            } else {
                let text = self.field(f).to_string();
                self.warn(f, format!("`{text}` in SPINDL ignored"));
            }
        }
        let (rpm, dir) = match rpm {
            Some((value, span)) => {
                if value <= 0.0 {
                    return Err(self.error(
                        span,
                        format!(
                            "the spindle speed must be positive, got `{}` (use SPINDL/OFF to stop it)",
                            self.field(span)
                        ),
                    ));
                }
                (value, dir.unwrap_or(SpindleDir::Clockwise))
            }
            None => match self.spindle {
                Some((value, last)) => (value, dir.unwrap_or(last)),
                None => {
                    return Err(self.error(
                        args,
                        "SPINDL without a speed, and no earlier speed to restart",
                    ));
                }
            },
        };
        self.spindle = Some((rpm, dir));
        Ok(ClEvent::Spindle { rpm, dir })
    }

    fn coolant(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let Some(&first) = self.fields.first() else {
            return Ok(ClEvent::Coolant {
                on: true,
                mode: "ON".to_string(),
            });
        };
        let on = !self.fields.iter().any(|&f| self.is(f, "OFF"));
        // The mode is the first word that is not ON: `COOLNT/ON,MIST` is
        // mist, as `COOLNT/MIST` is.
        let mode = self
            .fields
            .iter()
            .find(|&&f| !self.is(f, "ON") && !self.is(f, "OFF"))
            .map_or(first, |&f| f);
        Ok(ClEvent::Coolant {
            on,
            mode: self.field(mode).to_ascii_uppercase(),
        })
    }

    fn units_statement(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let units = match self.fields.as_slice() {
            [f] => match self.field(*f).to_ascii_uppercase().as_str() {
                "MM" | "MILLIMETERS" | "MILLIMETRES" => Units::Mm,
                "IN" | "INCH" | "INCHES" => Units::Inch,
                _ => {
                    return Err(self.error(
                        *f,
                        format!("unknown units `{}`; expected MM or INCHES", self.field(*f)),
                    ));
                }
            },
            [] => return Err(self.error(word, "expected `UNITS/MM` or `UNITS/INCHES`")),
            [_, second, ..] => {
                return Err(self.error((second.0, args.1), "expected `UNITS/MM` or `UNITS/INCHES`"));
            }
        };
        // The last point (for `GODLTA`) is kept in the units it was
        // written in: into the new ones, as the deltas that follow are.
        if let Some(p) = &mut self.last_point {
            match (self.units, units) {
                (Units::Inch, Units::Mm) => *p = p.map(|v| v * 25.4),
                (Units::Mm, Units::Inch) => *p = p.map(|v| v / 25.4),
                _ => {}
            }
        }
        self.units = units;
        Ok(ClEvent::Units(units))
    }

    fn multax(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        match self.fields.as_slice() {
            [] => Ok(ClEvent::Multax(true)),
            [f] if self.is(*f, "ON") => Ok(ClEvent::Multax(true)),
            [f] if self.is(*f, "OFF") => Ok(ClEvent::Multax(false)),
            _ => Err(self.error(args, "expected `MULTAX`, `MULTAX/ON` or `MULTAX/OFF`")),
        }
    }

    fn pressure(&mut self, word: Span, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let (name, f) = match self.fields.as_slice() {
            [f] => (None, *f),
            [w, f] if self.is_word(*w) => (Some(self.field(*w).to_string()), *f),
            [] => return Err(self.error(word, "expected `PRESSURE/[word,]value`")),
            _ => return Err(self.error(args, "expected `PRESSURE/[word,]value`")),
        };
        let value = self.number(f)?;
        if value < 0.0 {
            return Err(self.error(
                f,
                format!("the pressure must not be negative, got `{}`", self.field(f)),
            ));
        }
        Ok(ClEvent::Pressure { word: name, value })
    }

    /// `CSYS/` with the identity matrix is a no-op; any other matrix would
    /// have to transform the following GOTOs, which is not supported.
    fn csys(&mut self, word: Span, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        self.split(args);
        if self.fields.len() != 12 {
            return Err(self.error(
                if self.fields.is_empty() { word } else { args },
                format!(
                    "CSYS has {} values, expected 12 (a 3x4 matrix)",
                    self.fields.len()
                ),
            ));
        }
        const IDENTITY: [f64; 12] = [1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0.];
        for (k, expected) in IDENTITY.iter().enumerate() {
            if (self.number(self.fields[k])? - expected).abs() > 1e-9 {
                return Err(self.error(
                    args,
                    "CSYS with a non-identity matrix is not supported yet (the following GOTOs would have to be transformed); output the tool path in one coordinate system",
                ));
            }
        }
        Ok(None)
    }

    // ----- fields -----

    /// Splits `args` at commas into trimmed fields (`self.fields`). Blank
    /// arguments give no field; an empty field between commas is a
    /// zero-width span at its comma (or at the end).
    fn split(&mut self, args: Span) {
        self.fields.clear();
        // `self.text_bytes()`, borrowing only `raw` and `text`.
        let b = match self.text_in_raw {
            Some(len) => &self.raw[..len],
            None => self.text.as_bytes(),
        };
        let (mut s, end) = args;
        if skip_blanks(b, s) >= end {
            return;
        }
        loop {
            let e = b[s..end]
                .iter()
                .position(|&c| c == b',')
                .map_or(end, |p| s + p);
            let mut ts = s;
            let mut te = e;
            while ts < te && b[ts].is_ascii_whitespace() {
                ts += 1;
            }
            while te > ts && b[te - 1].is_ascii_whitespace() {
                te -= 1;
            }
            self.fields.push((ts, te));
            if e == end {
                break;
            }
            s = e + 1;
        }
    }

    fn field(&self, f: Span) -> &str {
        match self.text_in_raw {
            // A field of an ASCII line.
            Some(_) => std::str::from_utf8(&self.raw[f.0..f.1]).expect("statement text is UTF-8"),
            None => &self.text[f.0..f.1],
        }
    }

    /// Whether field `f` is `keyword` (case-insensitive).
    fn is(&self, f: Span, keyword: &str) -> bool {
        self.field(f).eq_ignore_ascii_case(keyword)
    }

    /// Whether field `f` is a word rather than a number.
    fn is_word(&self, f: Span) -> bool {
        self.text_bytes()[f.0..f.1]
            .first()
            .is_some_and(|c| c.is_ascii_alphabetic())
    }

    fn number(&self, f: Span) -> Result<f64, Diagnostic> {
        let text = self.field(f);
        if let Some(v) = parse_number(text) {
            return Ok(v);
        }
        let message = if text.is_empty() {
            "empty field: expected a number".to_string()
        } else if text
            .bytes()
            .all(|c| c.is_ascii_digit() || matches!(c, b'.' | b'+' | b'-' | b'e' | b'E'))
            && text.parse::<f64>().is_ok_and(f64::is_infinite)
        {
            format!("number `{text}` is out of range")
        } else {
            format!("malformed number `{text}`")
        };
        Err(self.error(f, message))
    }
}

impl<R: BufRead> Iterator for ClReader<R> {
    type Item = Result<Statement, Diagnostic>;

    /// Same as [`ClReader::next_statement`], transposed.
    fn next(&mut self) -> Option<Self::Item> {
        self.next_statement().transpose()
    }
}

impl<R> std::fmt::Debug for ClReader<R> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ClReader")
            .field("file", &self.file)
            .field("line", &self.line)
            .field("axis", &self.axis)
            .field("reference", &self.reference)
            .field("rapid", &self.rapid)
            .field("units", &self.units)
            .finish_non_exhaustive()
    }
}

fn make(
    severity: Severity,
    file: &str,
    line: usize,
    column: usize,
    width: usize,
    source_line: impl Into<String>,
    message: impl Into<String>,
) -> Diagnostic {
    match severity {
        Severity::Error => Diagnostic::error(file, line, column, width, source_line, message),
        Severity::Warning => Diagnostic::warning(file, line, column, width, source_line, message),
    }
}

/// The most bytes a logical statement may have, its physical lines and
/// `$` continuations (and comment lines between them) together: 1 MiB, a
/// thousand times a long CL line. Past it the input is an error (a binary
/// file, a line without end), not memory without bound.
pub const MAX_STATEMENT_BYTES: usize = 1 << 20;

/// The most physical lines a logical statement may span (`$`
/// continuations): fifty million `$` lines would otherwise be one
/// statement held in memory.
pub const MAX_STATEMENT_LINES: usize = 10_000;

const CR_INSIDE_A_LINE: &str = "a carriage return (CR) inside a line: lines must end with LF or \
     CR LF; a file whose lines end with CR alone (classic Mac OS) must be converted \
     (e.g. `tr '\\r' '\\n'`)";

/// `read_until(b'\n')` that stops once `buf` would hold more than `limit`
/// bytes: `Ok(None)` then (what was read stays in `buf`), else the bytes
/// read (0 at the end of the input).
fn read_line_bounded<R: BufRead>(
    input: &mut R,
    buf: &mut Vec<u8>,
    limit: usize,
) -> std::io::Result<Option<usize>> {
    let mut read = 0;
    loop {
        let available = match input.fill_buf() {
            Ok(b) => b,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        };
        if available.is_empty() {
            return Ok(Some(read));
        }
        let (take, done) = match available.iter().position(|&b| b == b'\n') {
            Some(i) => (i + 1, true),
            None => (available.len(), false),
        };
        if buf.len() + take > limit {
            let room = limit.saturating_sub(buf.len());
            buf.extend_from_slice(&available[..room.min(take)]);
            input.consume(room.min(take));
            return Ok(None);
        }
        buf.extend_from_slice(&available[..take]);
        input.consume(take);
        read += take;
        if done {
            return Ok(Some(read));
        }
    }
}

const ONES: u64 = 0x0101_0101_0101_0101;
const HIGH_BITS: u64 = 0x8080_8080_8080_8080;

/// The high bit of each zero byte of `v`, and maybe of bytes above a zero
/// byte (so the lowest one is exact).
#[inline(always)]
fn zero_bytes(v: u64) -> u64 {
    v.wrapping_sub(ONES) & !v & HIGH_BITS
}

/// The length of the first line of `buf` if `buf` holds its `\n` and it is
/// plain: ASCII without `$`. One pass, eight bytes at a time.
#[inline(always)]
fn plain_line(buf: &[u8]) -> Option<usize> {
    let mut i = 0;
    loop {
        let word = match buf.get(i..).and_then(|b| b.first_chunk::<8>()) {
            Some(word) => u64::from_le_bytes(*word),
            None => {
                let rest = buf.get(i..)?;
                if rest.is_empty() {
                    return None;
                }
                // Zero bytes are neither `\n` nor `$` nor non-ASCII.
                let mut word = [0; 8];
                word[..rest.len()].copy_from_slice(rest);
                u64::from_le_bytes(word)
            }
        };
        let newline = zero_bytes(word ^ (ONES * u64::from(b'\n')));
        let special = zero_bytes(word ^ (ONES * u64::from(b'$'))) | (word & HIGH_BITS);
        if newline != 0 {
            // The bits below the line end's byte.
            let before = (newline & newline.wrapping_neg()) - 1;
            return (special & before == 0).then_some(i + (newline.trailing_zeros() / 8) as usize);
        }
        if special != 0 {
            return None;
        }
        i += 8;
    }
}

/// The length of `line` without trailing whitespace, as `str::trim_end`
/// has it for ASCII (which, unlike `u8::is_ascii_whitespace`, includes the
/// vertical tab).
#[inline(always)]
fn trim_end_ascii(line: &[u8]) -> usize {
    let mut end = line.len();
    while end > 0 && matches!(line[end - 1], b'\t'..=b'\r' | b' ') {
        end -= 1;
    }
    end
}

/// A plain `GOTO` line at the start of `buf`, the common case: `GOTO/`,
/// then numbers [`plain_number`] takes, separated by commas, then the line
/// end (`\n` or `\r\n`), nothing else (no blanks), all within
/// [`GOTO_WINDOW`] bytes after `GOTO/`. Returns the number of values (at
/// most 9, in `v`) and the length of the line without and with its line
/// end; `None` for anything else, which the general path reads.
///
/// As the numbers are read, the line is checked on the way: it is ASCII
/// without `$` (the bytes taken are digits, signs, points and commas).
#[inline(always)]
fn plain_goto(buf: &[u8], v: &mut [f64; 9]) -> Option<PlainGoto> {
    let rest = buf.strip_prefix(b"GOTO/")?;
    let line = match rest.first_chunk::<{ GOTO_WINDOW + PLAIN_CHUNK }>() {
        Some(window) => plain_goto_window(window, v),
        // The end of the input (or of the reader's buffer): zeros are
        // neither separators nor digits.
        None => {
            let mut window = [0; GOTO_WINDOW + PLAIN_CHUNK];
            window[..rest.len()].copy_from_slice(rest);
            plain_goto_window(&window, v)
        }
    }?;
    Some(PlainGoto {
        count: line.count,
        end: line.end + 5,
        next: line.next + 5,
    })
}

/// The bytes after `GOTO/` in which [`plain_goto`] looks for the line end.
const GOTO_WINDOW: usize = 64;

/// [`plain_goto`] on the bytes after `GOTO/` (lengths counted from there).
///
/// The separators are found first, for the whole window at once, and
/// every number is then read from where they say it starts: the numbers
/// do not wait for each other (reading one to find where the next starts
/// made the line one long chain of dependent operations). Each number must
/// end exactly at its separator.
#[inline(always)]
fn plain_goto_window(
    window: &[u8; GOTO_WINDOW + PLAIN_CHUNK],
    v: &mut [f64; 9],
) -> Option<PlainGoto> {
    let mut separators = 0u64;
    for (k, word) in window.chunks_exact(8).take(GOTO_WINDOW / 8).enumerate() {
        let word = u64::from_le_bytes(word.try_into().expect("eight bytes"));
        // The high bit of byte i moved to bit i (the products of distinct
        // bits land on distinct bits: nothing carries).
        let bits = (below_minus(word) >> 7).wrapping_mul(0x0102_0408_1020_4080) >> 56;
        separators |= bits << (8 * k);
    }
    let mut start = 0;
    for (count, slot) in v.iter_mut().enumerate() {
        if separators == 0 {
            return None; // no line end in the window
        }
        let at = separators.trailing_zeros() as usize;
        separators &= separators - 1;
        // The length of the separator: a comma, or the line end.
        let (line_end, width) = match window[at] {
            b',' => (false, 1),
            b'\n' => (true, 1),
            b'\r' if window[at + 1] == b'\n' => (true, 2),
            _ => return None, // a blank, `$`, `+`, …: the general path reads it
        };
        let chunk = window[start..].first_chunk::<PLAIN_CHUNK>()?;
        // (Each number divided by its power of ten at once: quotients
        // stored to be divided two at a time later were loaded in other
        // pieces than they were stored in, which stalls the loads.)
        let (x, len) = plain_number(chunk)?;
        if start + len != at {
            return None;
        }
        *slot = x;
        if line_end {
            return Some(PlainGoto {
                count: count + 1,
                end: at,
                next: at + width,
            });
        }
        start = at + 1;
    }
    None // more than 9 values
}

/// The high bit of each ASCII byte of `word` below `-` (0x2D): the
/// separators `,` and `\n`, but also `\r`, blanks, `$` and `+`, which the
/// caller tells apart. Exact for every byte: `(b | 0x80) − 0x2D` never
/// borrows from the next byte, and keeps its high bit iff `b ≥ 0x2D`.
#[inline(always)]
fn below_minus(word: u64) -> u64 {
    !(((word | HIGH_BITS) - ONES * u64::from(b'-')) | word) & HIGH_BITS
}

/// A plain `GOTO` line found by [`plain_goto`].
struct PlainGoto {
    /// The number of values.
    count: usize,
    /// The length of the line without its line end.
    end: usize,
    /// The length of the line with its line end.
    next: usize,
}

fn is_word_byte(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_' || c == b'-'
}

#[inline(always)]
fn skip_blanks(b: &[u8], mut i: usize) -> usize {
    while let Some(&c) = b.get(i) {
        // One comparison for the common case of a printable byte.
        if c > b' ' || !c.is_ascii_whitespace() {
            break;
        }
        i += 1;
    }
    i
}

fn floor_char_boundary(s: &str, i: usize) -> usize {
    let mut i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

/// `text` without one pair of enclosing quotes (`'1001'`, `"A B"`), as
/// APT writers quote names.
fn unquote(text: &str) -> &str {
    for q in ['\'', '"'] {
        if let Some(inner) = text.strip_prefix(q).and_then(|t| t.strip_suffix(q)) {
            return inner;
        }
    }
    text
}

/// Squared lengths of a tool axis taken as unit length without a remark:
/// CAM systems write seven or more decimals (lengths within 1e-6 of 1); a
/// length off by more than 0.1 % is a hand-made or garbled vector.
const AXIS_LENGTH2: (f64, f64) = (0.998, 1.002);

/// `v` scaled to unit length; `None` if it is (nearly) zero or not finite.
fn normalize(v: Vec3) -> Option<Vec3> {
    let n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
    if n2 == 1.0 {
        return Some(v); // already unit length, e.g. 0,0,1
    }
    // The usual case: no overflow or underflow in the squares (also false
    // for NaN and infinity); one square root, three correctly rounded
    // divisions.
    if n2 > 1e-200 && n2 < 1e200 {
        let n = n2.sqrt();
        return Some([v[0] / n, v[1] / n, v[2] / n]);
    }
    // Scale first so that huge or tiny components neither overflow nor vanish.
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if !(m.is_finite() && m > 1e-300) {
        return None;
    }
    let s = [v[0] / m, v[1] / m, v[2] / m];
    let n = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    Some([s[0] / n, s[1] / n, s[2] / n])
}

fn cross(a: Vec3, b: Vec3) -> Vec3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
