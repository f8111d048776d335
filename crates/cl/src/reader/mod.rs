//! The streaming CL reader.
//!
//! This module reads lines into logical statements (the fast paths for plain
//! lines, `$` continuations, comments) and dispatches each statement to the
//! module of its family: [`motion`] (`GOTO`, `CIRCLE`, `NURBS`, `FROM`, …),
//! [`cycle`] (`CYCLE`), [`tool`] (tools, spindle, coolant, cutter
//! compensation) and [`setup`] (units, frames and the rest).

mod cycle;
mod motion;
mod setup;
mod tool;

use std::io::BufRead;

use kinpost_diag::{Diagnostic, Severity};

use crate::number::{PLAIN_CHUNK, parse_number, plain_number, scan_number};
use crate::vector::{cross, normalize};
use crate::words::suggest;
use crate::{
    Circle, ClEvent, MM_PER_INCH, Motion, Move, Next, SpindleDir, SpindleSpeed, Statement, Units,
    Vec3,
};

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
    /// A `$$` comment (joined over `$` continuation lines) and its first line.
    Comment(usize, String),
    /// A logical statement, now in `text` / `segments`.
    Statement,
}

/// A `CIRCLE` waiting for the `GOTO` that ends it.
#[derive(Debug, Clone)]
struct PendingCircle {
    circle: Circle,
    /// The line of the `CIRCLE` statement.
    line: usize,
    /// Its first physical line, for an error about it made later.
    source: String,
}

/// Streaming reader of NX CLSF / APT text: one [`Statement`] at a time.
///
/// The reader keeps the modal state of the CL file: the current tool axis and
/// reference direction (a three-value `GOTO` repeats them), the one-shot
/// `RAPID`, the units (every length of every event is in mm), a `CIRCLE`
/// waiting for its end point. It allocates nothing per plain `GOTO` line:
/// lines are read into a reused buffer and numbers are parsed in place.
///
/// **Errors** ([`Severity::Error`]) are returned by
/// [`next_statement`](Self::next_statement) and mean the input cannot be
/// posted as it is. The failed statement has no effect; the reader stays
/// usable and the next call goes on with the following line (so a checker can
/// list every error), except after an I/O error, after which it reports end
/// of input.
///
/// **Warnings** (unknown statements, a cut-short `MSYS`, …) are collected in
/// order and handed out, drained, by [`take_warnings`](Self::take_warnings).
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
    /// The hot path must step aside: `finished`, a held statement or a line
    /// read ahead (kept equal to their disjunction by `update_slow`).
    slow: bool,
    /// A statement to hand out before reading on (the `GOTO` of a Creo
    /// continuation point after its repeated `CIRCLE`).
    held: Option<Box<Statement>>,
    /// A physical line read ahead (after `NURBS` records) and its number:
    /// the next statement starts with it.
    pending_line: Option<(Vec<u8>, usize)>,
    warnings: Vec<Diagnostic>,
    axis: Option<Vec3>,
    reference: Option<Vec3>,
    /// A tool axis far from unit length was reported.
    axis_length_noted: bool,
    /// The current point (mm): the last `GOTO`, `FROM`, `GOHOME` or the end
    /// of a `NURBS`; the start of a `CIRCLE`, `NURBS` or `GODLTA`.
    last_point: Option<Vec3>,
    /// The last `FROM` point (mm), for a bare `GOHOME`.
    from: Option<Vec3>,
    rapid: bool,
    /// The file's length units (as declared, given, or assumed mm).
    units: Units,
    /// The units were declared by a `UNITS` statement or given by the caller.
    units_known: bool,
    /// The units the caller gave (`--units`), if any.
    units_given: Option<Units>,
    /// mm per length unit of the file: 1 or 25.4.
    scale: f64,
    spindle: Option<(SpindleSpeed, SpindleDir)>,
    /// A `GOTO` needs more than the plain case: inch lengths or a circle to
    /// end (kept equal to `scale != 1 || circle.is_some()`).
    goto_special: bool,
    /// A `CIRCLE` waiting for its end point.
    circle: Option<Box<PendingCircle>>,
    /// The circle of the `GOTO` statement just read, if it ended an arc: a
    /// Creo continuation point (a bare `x, y, z` line) follows it too.
    arc_goto: Option<Box<PendingCircle>>,
    /// The number of values of the last statement if it was a `GOTO` (a
    /// Creo continuation line takes the same shape), else 0.
    goto_count: usize,
    /// Inside the header NX writes before a CLSF saved from its Information
    /// window.
    listing_header: bool,
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
            slow: false,
            held: None,
            pending_line: None,
            warnings: Vec::new(),
            axis: None,
            reference: None,
            axis_length_noted: false,
            last_point: None,
            from: None,
            rapid: false,
            units: Units::Mm,
            units_known: false,
            units_given: None,
            scale: 1.0,
            spindle: None,
            goto_special: false,
            circle: None,
            arc_goto: None,
            goto_count: 0,
            listing_header: false,
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

    /// Sets the length units of a file that does not declare them (the
    /// `--units` option): `None` (the default) takes an undeclared file as
    /// mm but refuses inch feeds (`FEDRAT/IPM`, `IPR`) in it. A `UNITS`
    /// statement that contradicts the given units is an error.
    pub fn with_units(mut self, units: Option<Units>) -> Self {
        self.units_given = units;
        if let Some(units) = units {
            self.set_units(units);
            self.units_known = true;
        }
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

    /// The file's length units so far (`Mm` until a `UNITS` statement or
    /// [`with_units`](Self::with_units) says otherwise). Events carry mm
    /// whatever the file's units.
    pub fn units(&self) -> Units {
        self.units
    }

    /// The current point (mm), if any.
    pub fn current_point(&self) -> Option<Vec3> {
        self.last_point
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
    ///
    /// (Out of line, with [`next_move`](Self::next_move)'s body inlined in
    /// it, for the same reason as `next_move`.)
    #[inline(never)]
    pub fn next_statement(&mut self) -> Result<Option<Statement>, Diagnostic> {
        let mut goto = Move::default();
        Ok(match self.next_move_inline(&mut goto)? {
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
    ///
    /// (Out of line on purpose: inlined into its caller's loop, the parser's
    /// state competed with the caller's for registers and the bench
    /// `next_move_100k_lines` read 7 % slower; a call per line costs less.)
    #[inline(never)]
    pub fn next_move(&mut self, goto: &mut Move) -> Result<Next, Diagnostic> {
        self.next_move_inline(goto)
    }

    /// The body of [`next_move`](Self::next_move), inlined into
    /// [`next_statement`](Self::next_statement) (which turns its result into
    /// a statement at once).
    #[inline(always)]
    fn next_move_inline(&mut self, goto: &mut Move) -> Result<Next, Diagnostic> {
        if self.slow {
            return self.next_slow();
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

    /// `next_move` when the hot path steps aside: at the end, with a held
    /// statement, or with a line read ahead.
    #[cold]
    #[inline(never)]
    fn next_slow(&mut self) -> Result<Next, Diagnostic> {
        if self.finished {
            return Ok(Next::End);
        }
        if let Some(statement) = self.held.take() {
            self.update_slow();
            return Ok(Next::Statement(*statement));
        }
        // A line read ahead: the general path takes it first.
        self.clear_statement();
        Ok(match self.next_statement_general(Begin::Lines, [0.0; 9])? {
            Some(statement) => Next::Statement(statement),
            None => Next::End,
        })
    }

    fn update_slow(&mut self) {
        self.slow = self.finished || self.held.is_some() || self.pending_line.is_some();
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
                Read::Eof => return self.end_of_input(),
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
            if self.slow {
                // A statement held or a line read ahead by `interpret`.
                if let Some(statement) = self.held.take() {
                    self.update_slow();
                    return Ok(Some(*statement));
                }
                if self.finished {
                    return Ok(None);
                }
                self.clear_statement();
                begun = Begin::Lines;
                continue;
            }
            begun = self.begin_statement(&mut values)?;
        }
    }

    /// The end of the input: an arc still waiting for its end is an error.
    #[cold]
    fn end_of_input(&mut self) -> Result<Option<Statement>, Diagnostic> {
        if let Some(pending) = self.circle.take() {
            self.update_goto_special();
            let width = pending.source.trim_end().chars().count().max(1);
            return Err(Diagnostic::error(
                &self.file,
                pending.line,
                1,
                width,
                pending.source,
                format!(
                    "the CIRCLE at line {} has no end point: the file ends before the GOTO that ends the arc",
                    pending.line
                ),
            ));
        }
        Ok(None)
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

    /// Sets the length units (and the scale to mm).
    fn set_units(&mut self, units: Units) {
        self.units = units;
        self.scale = match units {
            Units::Mm => 1.0,
            Units::Inch => MM_PER_INCH,
        };
        self.update_goto_special();
    }

    fn update_goto_special(&mut self) {
        self.goto_special = self.scale != 1.0 || self.circle.is_some();
    }

    /// A length of the file in mm.
    fn mm(&self, v: f64) -> f64 {
        v * self.scale
    }

    /// A point of the file in mm.
    fn mm3(&self, p: Vec3) -> Vec3 {
        [p[0] * self.scale, p[1] * self.scale, p[2] * self.scale]
    }

    // ----- lines -----

    /// Forgets the current statement.
    #[inline(always)]
    fn clear_statement(&mut self) {
        self.raw.clear();
        self.text.clear();
        self.segments.clear();
        self.text_in_raw = None;
    }

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
        self.clear_statement();
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

    /// Appends the next physical line to `raw` (the line read ahead first),
    /// without its line end and, on line 1, a byte-order mark: its number and
    /// its range in `raw`. `None` at the end of the input.
    fn read_physical(&mut self) -> Result<Option<(usize, usize, usize)>, Diagnostic> {
        let mut start = self.raw.len();
        if let Some((bytes, line)) = self.pending_line.take() {
            self.update_slow();
            self.raw.extend_from_slice(&bytes);
            return Ok(Some((line, start, self.raw.len())));
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
            Ok(Some(0)) => return Ok(None),
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
        if self.line == 1 && self.raw[start..].starts_with(b"\xEF\xBB\xBF") {
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
        Ok(Some((self.line, start, end)))
    }

    /// Reads physical lines until a logical statement is complete (the
    /// general path, after `begin_statement`).
    fn read_lines(&mut self) -> Result<Read, Diagnostic> {
        // The lines of a `$$` comment continued with `$` (Creo `$$->`).
        let mut comment: Option<(usize, String)> = None;
        let mut comment_lines = 0usize;
        loop {
            // (Lines of a continued comment count as the statement's.)
            let lines = self.segments.len() + comment.as_ref().map_or(0, |_| comment_lines);
            if lines >= MAX_STATEMENT_LINES {
                // (At the line that would be one too many.)
                self.line += 1;
                let first = self
                    .segments
                    .first()
                    .map_or_else(|| comment.as_ref().map_or(self.line, |c| c.0), |s| s.line);
                return Err(self.too_long(format!(
                    "the statement that starts on line {first} goes on over more than {MAX_STATEMENT_LINES} \
                     lines (`$` continuations): a CL statement is a line or a few"
                )));
            }
            let Some((line_no, start, end)) = self.read_physical()? else {
                if let Some((line, text)) = comment {
                    return Ok(Read::Comment(line, text));
                }
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
            };
            if comment.is_some() {
                comment_lines += 1;
            }
            let line = match std::str::from_utf8(&self.raw[start..end]) {
                Ok(line) => line,
                Err(e) => return Err(self.invalid_utf8(line_no, start, end, e)),
            };
            if let Some((first, mut text)) = comment.take() {
                // A line of a continued comment.
                let (body, continued) = comment_continues(line.trim());
                if !text.is_empty() && !body.is_empty() {
                    text.push(' ');
                }
                text.push_str(body);
                if !continued {
                    return Ok(Read::Comment(first, text));
                }
                comment = Some((first, text));
                self.raw.truncate(start);
                continue;
            }
            let mut body = line;
            if line.as_bytes().contains(&b'$')
                && let Some(p) = line.find("$$")
            {
                if line[..p].trim().is_empty() {
                    if self.segments.is_empty() {
                        let (text, continued) = comment_continues(line[p + 2..].trim());
                        if !continued {
                            return Ok(Read::Comment(line_no, text.to_string()));
                        }
                        comment = Some((line_no, text.to_string()));
                        self.raw.truncate(start);
                        continue;
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
                line: line_no,
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

    /// Reads the next physical line as a further line of the current
    /// statement if `belongs` says so (its text, trimmed at a `$$` comment
    /// and at the end): true if it was taken. Otherwise the line is kept
    /// for the next statement. (The records of `NURBS`.)
    fn take_line_if(&mut self, belongs: impl Fn(&str) -> bool) -> Result<bool, Diagnostic> {
        let Some((line_no, start, end)) = self.read_physical()? else {
            return Ok(false);
        };
        let taken = match std::str::from_utf8(&self.raw[start..end]) {
            Ok(line) => {
                let body = line.find("$$").map_or(line, |p| &line[..p]).trim_end();
                if belongs(body.trim_start()) {
                    let text_start = self.text.len() + 1;
                    // (Each record its own line of `text`, for the spans.)
                    self.text.push('\n');
                    self.text.push_str(body);
                    self.segments.push(Segment {
                        line: line_no,
                        raw_start: start,
                        raw_end: end,
                        text_start,
                        text_end: self.text.len(),
                    });
                    true
                } else {
                    false
                }
            }
            Err(_) => false,
        };
        if !taken {
            let bytes = self.raw[start..end].to_vec();
            self.raw.truncate(start);
            self.pending_line = Some((bytes, line_no));
            self.update_slow();
        }
        Ok(taken)
    }

    /// The error for a failed read; the reader then reports end of input.
    #[cold]
    fn read_error(&mut self, e: std::io::Error) -> Diagnostic {
        self.finished = true;
        self.update_slow();
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

    fn invalid_utf8(
        &self,
        line: usize,
        start: usize,
        end: usize,
        e: std::str::Utf8Error,
    ) -> Diagnostic {
        let bytes = &self.raw[start..end];
        let valid = e.valid_up_to();
        let column = String::from_utf8_lossy(&bytes[..valid]).chars().count() + 1;
        Diagnostic::error(
            &self.file,
            line,
            column,
            1,
            String::from_utf8_lossy(bytes),
            format!(
                "invalid UTF-8 (byte 0x{:02X}); CL files are read as UTF-8 text: for the ISO 8859-1 accented comments CATIA V5 writes give `--encoding latin1`; convert other encodings (e.g. `iconv -f GBK -t UTF-8`)",
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
        if matches!(b[start], b'0'..=b'9' | b'-' | b'+' | b'.') {
            // A line of numbers: a further point of the GOTO before (Creo).
            return self.continuation_point(start);
        }
        let mut word_end = start;
        while word_end < b.len() && is_word_byte(b[word_end]) {
            word_end += 1;
        }
        if word_end - start >= 4 && b[start..start + 4].eq_ignore_ascii_case(b"CSI_") {
            self.goto_count = 0;
            return Ok(None); // CAMWorks display / tool-library records
        }
        let (key, key_len) = statement_key(&b[start..word_end]);
        let key: &[u8] = &key[..key_len];
        let path_end = if key == b"TOOL" {
            tool_path_end(b, word_end)
        } else {
            None
        };
        let tool_path = path_end.is_some();
        let word: Span = (start, path_end.unwrap_or(word_end));
        let after = skip_blanks(b, word.1);
        let slash = after < b.len() && b[after] == b'/';
        let args: Span = (if slash { after + 1 } else { after }, b.len());
        let has_args = skip_blanks(b, args.0) < args.1;

        // Any statement but a GOTO ends a multi-point GOTO.
        if key != b"GOTO" {
            self.goto_count = 0;
            self.arc_goto = None;
        }
        if self.listing_header && !matches!(key, b"DATE" | b"CURRENT" | b"NODE") {
            self.listing_header = false;
        }
        if tool_path {
            if !slash && nx_listing_footer(&self.text()[args.0..]) {
                return Ok(None);
            }
            self.no_pending_circle(word)?;
            return self.tool_path(args).map(Some);
        }
        if takes_slash_arguments(key) && !slash && has_args {
            let name = self.text()[word.0..word.1].to_ascii_uppercase();
            return Err(self.error((after, after + 1), format!("expected `/` after `{name}`")));
        }
        self.statement(key, start, word, args)
    }

    /// Acts on one statement, named by its upper-case `key` (its `word` in
    /// the text, which starts at `start`); `args` are its arguments, after
    /// the slash if it has one.
    #[inline(always)]
    fn statement(
        &mut self,
        key: &[u8],
        start: usize,
        word: Span,
        args: Span,
    ) -> Result<Option<ClEvent>, Diagnostic> {
        match key {
            b"GOTO" => self.goto(args).map(Some),
            b"RAPID" => {
                self.rapid = true;
                Ok(None)
            }
            b"FEDRAT" => self.fedrat(word, args).map(Some),
            b"CIRCLE" => self.circle(word, args).map(Some),
            b"NURBS" => self.nurbs(word, args).map(Some),
            b"KNOT" | b"CNTRL" => Err(self.error(
                word,
                format!(
                    "`{}` outside a NURBS: KNOT and CNTRL records follow a NURBS/ statement",
                    self.text()[word.0..word.1].to_ascii_uppercase()
                ),
            )),
            b"FROM" => self.from(word, args).map(Some),
            b"GOHOME" => self.gohome(word, args).map(Some),
            b"TLAXIS" => self.tlaxis(word, args),
            b"GODLTA" => self.godlta(word, args).map(Some),
            b"CYCLE" => self.cycle(word, args),
            b"LOADTL" => self.loadtl(word, args).map(Some),
            b"TLDATA" => self.tool_data(args, false).map(Some),
            b"CUTTER" => self.tool_data(args, true).map(Some),
            b"MSYS" => self.msys(args).map(Some),
            b"CSYS" => self.csys(word, args).map(Some),
            b"LOAD" => self.load(word, args).map(Some),
            b"SELECT" => self.select(word, args).map(Some),
            b"SPINDL" => self.spindle(args).map(Some),
            b"COOLNT" => self.coolant(args).map(Some),
            b"CUTCOM" => self.cutcom(word, args).map(Some),
            b"INSERT" => Ok(Some(ClEvent::Insert(
                self.text()[args.0..].trim_end().to_string(),
            ))),
            // CATIA V5's tool print (the tool's description, "TPRINT/T1
            // PointeurD10") is an operator message like PPRINT.
            b"PPRINT" | b"TPRINT" => Ok(Some(ClEvent::Comment(
                self.text()[args.0..].trim().to_string(),
            ))),
            b"TOOLNO" => self.toolno(word, args),
            // CATIA V5 writes `REWIND/0` before `END`: rewind the tape. The
            // program's end (the dialect's footer, M2 or M30) does that.
            b"REWIND" => Ok(None),
            b"END-OF-PATH" => {
                self.no_pending_circle(word)?;
                Ok(Some(ClEvent::EndOfPath))
            }
            b"PARTNO" => Ok(Some(ClEvent::PartNo(
                unquote(self.text()[args.0..].trim()).to_string(),
            ))),
            b"UNITS" | b"UNIT" => self.units_statement(word, args).map(Some),
            b"MULTAX" => self.multax(args).map(Some),
            b"PRESSURE" => self.pressure(word, args).map(Some),
            b"FINI" => {
                self.no_pending_circle(word)?;
                self.bare(word, args, ClEvent::Fini)
            }
            b"STOP" | b"OPSTOP" => self.stop(key == b"OPSTOP", args),
            b"END" => self.bare(word, args, ClEvent::End),
            b"TMARK" => Ok(Some(ClEvent::TapeMark)),
            b"DELAY" | b"DWELL" => self.delay(word, args).map(Some),
            b"MACHIN" => self.machin(word, args).map(Some),
            b"OPNAME" => Ok(Some(ClEvent::OperationName(
                unquote(self.text()[args.0..].trim()).to_string(),
            ))),
            b"CLAMP" => self.clamp(args).map(Some),
            b"ORIGIN" => self.origin(word, args).map(Some),
            b"SETUP" => self.setup(word, args).map(Some),
            // Display records of NX and the transformation type of
            // SOLIDWORKS CAM (see the crate documentation).
            b"PAINT" | b"TRNTYP" => Ok(None),
            b"INFORMATION"
                if self.text()[start..].starts_with("Information listing created by") =>
            {
                self.listing_header = true;
                Ok(None)
            }
            b"DATE" | b"CURRENT" | b"NODE"
                if self.listing_header && nx_listing_line(&self.text()[start..]) =>
            {
                Ok(None)
            }
            _ => {
                self.unknown(word);
                Ok(None)
            }
        }
    }

    /// `STOP` or `OPSTOP`, bare or with the operator's instruction (CATIA
    /// V5: `STOP/(INSTALL TEST STRIP LARGE END UP)`): the instruction comes
    /// first as a comment, the stop next.
    fn stop(&mut self, optional: bool, args: Span) -> Result<Option<ClEvent>, Diagnostic> {
        let event = if optional {
            ClEvent::OptionalStop
        } else {
            ClEvent::Stop
        };
        let text = self.text()[args.0..args.1].trim();
        if text.is_empty() {
            return Ok(Some(event));
        }
        let message = text
            .strip_prefix('(')
            .and_then(|t| t.strip_suffix(')'))
            .unwrap_or(text)
            .trim()
            .to_string();
        let line = self.segments[0].line;
        self.held = Some(Box::new(Statement { line, event }));
        self.update_slow();
        Ok(Some(ClEvent::Comment(message)))
    }

    /// A statement that takes no arguments.
    fn bare(
        &mut self,
        word: Span,
        args: Span,
        event: ClEvent,
    ) -> Result<Option<ClEvent>, Diagnostic> {
        if skip_blanks(self.text_bytes(), args.0) < args.1 {
            let name = self.text()[word.0..word.1].to_ascii_uppercase();
            return Err(self.error(args, format!("`{name}` takes no arguments")));
        }
        Ok(Some(event))
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

    /// A `GOTO` with `count` values (the first 9 in `v`, in the file's
    /// units): its point (mm), tool axis and motion, the new modal state set
    /// (the reference direction is then `self.reference`).
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
        let mut point = [v[0], v[1], v[2]];
        if self.goto_special {
            point = self.special_point(args, point)?;
        }
        self.finish_move(args, point, v, count)
    }

    /// The rest of [`goto_move`](Self::goto_move), from the point in mm
    /// (checked against a waiting arc): the tool axis and reference
    /// direction of `v` (`count` values), then the new modal state.
    #[inline(always)]
    fn finish_move(
        &mut self,
        args: Span,
        point: Vec3,
        v: [f64; 9],
        count: usize,
    ) -> Result<(Vec3, Vec3, Motion), Diagnostic> {
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
        self.goto_count = count;
        if self.circle.is_some() || self.arc_goto.is_some() {
            self.arc_transition();
        }
        let motion = if std::mem::take(&mut self.rapid) {
            Motion::Rapid
        } else {
            Motion::Feed
        };
        Ok((point, axis, motion))
    }

    /// After a `GOTO`: the arc it ended (if any) is the one a Creo further
    /// point continues; an earlier one is over (out of line: the plain case
    /// has neither).
    #[cold]
    #[inline(never)]
    fn arc_transition(&mut self) {
        self.arc_goto = self.circle.take();
        self.update_goto_special();
    }

    /// The point of a `GOTO` in mm, and the check of the arc it ends (out
    /// of line: the plain case is mm without an arc).
    #[cold]
    #[inline(never)]
    fn special_point(&mut self, args: Span, point: Vec3) -> Result<Vec3, Diagnostic> {
        let point = self.mm3(point);
        if let Some(pending) = &self.circle {
            let start = self
                .last_point
                .expect("a CIRCLE is only read after a point");
            if self.rapid {
                return Err(self.error(
                    args,
                    format!(
                        "RAPID before the GOTO that ends the CIRCLE of line {}: an arc is a feed move",
                        pending.line
                    ),
                ));
            }
            if let Err(e) = pending.circle.arc(start, point) {
                let line = pending.line;
                return Err(self.error(
                    args,
                    format!("this GOTO cannot end the CIRCLE of line {line}: {e}"),
                ));
            }
        }
        Ok(point)
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

    fn tool_path(&mut self, args: Span) -> Result<ClEvent, Diagnostic> {
        self.split(args);
        let mut fields = self.fields.iter().map(|&f| self.field(f).to_string());
        let name = fields.next().unwrap_or_default();
        let words = fields.collect();
        Ok(ClEvent::ToolPath { name, words })
    }

    // ----- fields -----

    /// Makes `text` hold the statement (a plain line is only in `raw`), so
    /// that further lines can be appended.
    fn own_text(&mut self) {
        if let Some(len) = self.text_in_raw.take() {
            self.text.clear();
            self.text
                .push_str(std::str::from_utf8(&self.raw[..len]).expect("statement text is UTF-8"));
        }
    }

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

    /// Field `f` as an upper-case word.
    fn word(&self, f: Span) -> String {
        self.field(f).to_ascii_uppercase()
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

    /// The numbers of fields `range` (split already).
    fn numbers(&self, range: std::ops::Range<usize>) -> Result<Vec<f64>, Diagnostic> {
        range.map(|k| self.number(self.fields[k])).collect()
    }

    /// Field `k` (split already) as a whole number from 0 to `u32::MAX`;
    /// `what` names it in the error.
    fn whole(&self, k: usize, what: &str) -> Result<u32, Diagnostic> {
        let f = self.fields[k];
        let n = self.number(f)?;
        if !(n >= 0.0 && n <= f64::from(u32::MAX) && n.fract() == 0.0) {
            return Err(self.error(
                f,
                format!(
                    "the {what} must be a whole number from 0 to {}, got `{}`",
                    u32::MAX,
                    self.field(f)
                ),
            ));
        }
        Ok(n as u32)
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

/// Whether a comment's text continues on the next line (Creo ends a long
/// `$$->` comment with `,  $`): the text without the `$`, and whether it
/// does. A `$` right after other text (`$$ 5$`) is text.
fn comment_continues(text: &str) -> (&str, bool) {
    match text.strip_suffix('$') {
        Some(body)
            if body.is_empty() || body.ends_with(|c: char| c == ',' || c.is_whitespace()) =>
        {
            (body.trim_end(), true)
        }
        _ => (text, false),
    }
}

/// Whether `rest` (after `TOOL PATH`) is the footer NX writes after a CLSF
/// listed in its Information window: `Listing has 11294 lines.`
fn nx_listing_footer(rest: &str) -> bool {
    rest.trim()
        .strip_prefix("Listing has ")
        .and_then(|r| r.strip_suffix(" lines."))
        .is_some_and(|n| !n.is_empty() && n.bytes().all(|c| c.is_ascii_digit()))
}

/// Whether `line` is one of the lines of the header NX writes above a CLSF
/// listed in its Information window (after `Information listing created
/// by`): `Date`, `Current work part`, `Node name`, each followed by a tab
/// or blanks.
fn nx_listing_line(line: &str) -> bool {
    ["Date", "Current work part", "Node name"].iter().any(|k| {
        line.strip_prefix(k)
            .is_some_and(|rest| rest.starts_with(['\t', ' ']))
    })
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

/// The statement key of a major word: the word in upper case, in a fixed
/// buffer with its length (no allocation per statement); length 0 for a
/// word longer than any statement's (it is then unknown).
#[inline(always)]
fn statement_key(word: &[u8]) -> ([u8; 12], usize) {
    let mut key = [0u8; 12];
    if word.len() > key.len() {
        return (key, 0);
    }
    for (k, &c) in key.iter_mut().zip(word) {
        *k = c.to_ascii_uppercase();
    }
    (key, word.len())
}

/// Where `PATH` ends when the `TOOL` word ending at `word_end` is followed
/// by blanks and a whole word `PATH` (the two-word `TOOL PATH` statement of
/// NX), else `None`.
#[inline(always)]
fn tool_path_end(b: &[u8], word_end: usize) -> Option<usize> {
    let p = skip_blanks(b, word_end);
    (p > word_end
        && b.len() >= p + 4
        && b[p..p + 4].eq_ignore_ascii_case(b"PATH")
        && b.get(p + 4).is_none_or(|&c| !is_word_byte(c)))
    .then_some(p + 4)
}

/// Whether the statement named by `key` takes its arguments after a slash
/// (`GOTO/…`): one without the slash but with arguments is an error, not a
/// statement read some other way.
#[inline(always)]
fn takes_slash_arguments(key: &[u8]) -> bool {
    matches!(
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
            | b"CIRCLE"
            | b"CYCLE"
            | b"FROM"
            | b"GOHOME"
            | b"CUTCOM"
            | b"DELAY"
            | b"DWELL"
            | b"MACHIN"
            | b"CLAMP"
            | b"ORIGIN"
            | b"SETUP"
            | b"KNOT"
            | b"CNTRL"
            | b"TLAXIS"
            | b"GODLTA"
            | b"LOADTL"
            | b"OPNAME"
            | b"TOOLNO"
    )
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
