//! Reading programs back: the reader of every dialect.

use kinpost_diag::Diagnostic;

use crate::dialect::{Dialect, DialectKind};
use crate::{ArcMotion, ArcPlane, AxisSpec, Block, Motion};

/// A program read back, with the lines that were not motion blocks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ReadProgram {
    /// The motion blocks, each with its program `line` and, from a CSV
    /// table, its `cl_line`. Axis values are in machine order, with modal
    /// values carried over; `None` for an axis not programmed so far (e.g.
    /// a fixed axis). The pressure word ([`AxisSpec::pressure`]) is read
    /// like a modal axis word, also from a line of its own. `feed` is the
    /// feed in force (the last feed word), `None` before the first. A
    /// circular block (`G2`/`G3` with the dialect's `[arc]` words) has its
    /// arc: the plane in force, the sense, and the centre words of the
    /// block (a centre word not written is 0).
    pub blocks: Vec<Block<Vec<Option<f64>>>>,
    /// 1-based numbers of non-empty lines that were not (only) words of this
    /// dialect: header/footer text, inserts, commands. Comment-only lines and
    /// lines that only set modal words (`G01`, `F250`) are not listed.
    pub other_lines: Vec<usize>,
}

/// Reads a program written in `dialect` for a machine with `axes` back into
/// motion blocks. See [`read_program_full`].
pub fn read_program(
    dialect: &Dialect,
    axes: &[AxisSpec],
    file_name: &str,
    text: &str,
) -> Result<Vec<Block<Vec<Option<f64>>>>, Diagnostic> {
    read_program_full(dialect, axes, file_name, text).map(|p| p.blocks)
}

/// Reads a program back. NC dialects: a line is a motion block when, after
/// its block number and comments are removed, it consists only of words of
/// the dialect (motion words and their aliases, axis words of any machine
/// axis, the feed word, the rapid-feed literal, the `after_axes` words) and
/// has at least one axis word; a line of such words without an axis word
/// only updates the modal motion and feed; any other line is skipped (and
/// listed in `other_lines`). Missing modal words keep their previous value.
/// CSV: every row after the header row is a block; errors are reported.
pub fn read_program_full(
    dialect: &Dialect,
    axes: &[AxisSpec],
    file_name: &str,
    text: &str,
) -> Result<ReadProgram, Diagnostic> {
    match dialect.kind {
        DialectKind::Words => Ok(WordsReader::new(dialect, axes).read(text)),
        DialectKind::Csv => read_csv(dialect, axes, file_name, text),
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Token {
    Axis(usize),
    /// The pressure word: modal, not a motion by itself.
    Pressure(usize),
    Feed,
    Motion(Motion),
    /// Rapid-feed literal (`FMAX`): this block is rapid.
    RapidLiteral,
    /// `after_axes` words (`R0`): ignored.
    Ignored,
    /// The straight motion word shared by rapids and feeds (Heidenhain
    /// `L`): ends a circular motion, the rapid-feed literal tells which.
    Straight,
    /// The circular motion word, clockwise (`G2`) or not (`G3`), or
    /// either (Heidenhain `C`: the sense word tells): modal.
    Arc(Option<bool>),
    /// A sense word after the axis words, clockwise (`DR-`) or not.
    Sense(bool),
    /// The word of a centre line (`CC`): its axis words are the centre's
    /// absolute coordinates.
    CentreBlock,
    /// A plane selection word (`G17`): modal.
    Plane(ArcPlane),
    /// A centre word on program axis 0, 1, 2 (`I`, `J`, `K`).
    Centre(usize),
}

struct Candidate {
    text: String,
    suffix: String,
    /// Followed by a number (and `suffix`), else a literal word.
    numeric: bool,
    token: Token,
}

struct WordsReader {
    candidates: Vec<Candidate>,
    number_prefix: String,
    bare_numbers: bool,
    comment_start: String,
    comment_end: String,
    line_end_extra: String,
    separator: String,
    n_axes: usize,
    /// The program axis (X, Y, Z: 0, 1, 2) of each machine axis, if any.
    program_axis: Vec<Option<usize>>,
    /// The number format of the centre words: an absolute centre (`CC`)
    /// minus the start is the offset as a relative centre word writes it.
    centre_format: kinpost_number::NumberFormat,
    initial_motion: Motion,
}

impl WordsReader {
    fn new(dialect: &Dialect, axes: &[AxisSpec]) -> WordsReader {
        let mut candidates = Vec::new();
        for (i, a) in axes.iter().enumerate() {
            if a.pressure && !dialect.writes_pressure() {
                continue;
            }
            let wf = dialect.word_format(a);
            candidates.push(Candidate {
                text: wf.prefix,
                suffix: wf.suffix,
                numeric: true,
                token: if a.pressure {
                    Token::Pressure(i)
                } else {
                    Token::Axis(i)
                },
            });
        }
        let feed = &dialect.feed;
        candidates.push(Candidate {
            text: feed.word.prefix.clone(),
            suffix: feed.word.suffix.clone(),
            numeric: true,
            token: Token::Feed,
        });
        let literal = |text: &str, token| Candidate {
            text: text.to_string(),
            suffix: String::new(),
            numeric: false,
            token,
        };
        if !feed.rapid.is_empty() {
            candidates.push(literal(&feed.rapid, Token::RapidLiteral));
        }
        let m = &dialect.motion;
        // The same word for both (Heidenhain `L`): the motion then comes from
        // the rapid-feed literal.
        let same = m.rapid == m.feed;
        if !m.rapid.is_empty() && !same {
            candidates.push(literal(&m.rapid, Token::Motion(Motion::Rapid)));
        }
        if !m.feed.is_empty() {
            let t = if same {
                Token::Straight
            } else {
                Token::Motion(Motion::Feed)
            };
            candidates.push(literal(&m.feed, t));
        }
        for a in &m.rapid_aliases {
            candidates.push(literal(a, Token::Motion(Motion::Rapid)));
        }
        for a in &m.feed_aliases {
            candidates.push(literal(a, Token::Motion(Motion::Feed)));
        }
        for w in dialect.block.after_axes.split_whitespace().chain(
            dialect
                .block
                .compensated
                .iter()
                .flat_map(|c| c.split_whitespace()),
        ) {
            candidates.push(literal(w, Token::Ignored));
        }
        if let Some(arc) = dialect.arc_words() {
            if arc.clockwise == arc.counter_clockwise {
                candidates.push(literal(&arc.clockwise, Token::Arc(None)));
            } else {
                candidates.push(literal(&arc.clockwise, Token::Arc(Some(true))));
                candidates.push(literal(&arc.counter_clockwise, Token::Arc(Some(false))));
            }
            for (word, clockwise) in arc.sense.iter().zip([true, false]) {
                candidates.push(literal(word, Token::Sense(clockwise)));
            }
            candidates.push(literal(&arc.centre_block, Token::CentreBlock));
            for (plane, word) in [ArcPlane::Xy, ArcPlane::Zx, ArcPlane::Yz]
                .into_iter()
                .zip(&arc.planes)
            {
                candidates.push(literal(word, Token::Plane(plane)));
            }
            for (k, prefix) in arc.centre.iter().enumerate() {
                candidates.push(Candidate {
                    text: prefix.clone(),
                    suffix: String::new(),
                    numeric: true,
                    token: Token::Centre(k),
                });
            }
        }
        candidates.retain(|c| !c.text.is_empty() || c.numeric);
        // Longest first, so that `X=` wins over `X` and `FMAX` over `F`.
        candidates.sort_by_key(|c| std::cmp::Reverse(c.text.len()));
        let initial_motion = match m.initial {
            Some(i) => i,
            None if same => Motion::Feed,
            None => Motion::Rapid,
        };
        WordsReader {
            candidates,
            number_prefix: dialect.numbering.prefix.clone(),
            bare_numbers: dialect.numbering.enabled && dialect.numbering.prefix.is_empty(),
            comment_start: dialect.comment.prefix.trim().to_string(),
            comment_end: dialect.comment.suffix.trim().to_string(),
            line_end_extra: dialect
                .block
                .line_end
                .trim_end_matches(['\r', '\n'])
                .to_string(),
            separator: dialect.block.separator.trim().to_string(),
            n_axes: axes.len(),
            centre_format: dialect.word_format(&AxisSpec::linear("X")).number,
            program_axis: axes
                .iter()
                .map(|a| {
                    ["X", "Y", "Z"]
                        .iter()
                        .position(|n| !a.rotary && a.name.eq_ignore_ascii_case(n))
                })
                .collect(),
            initial_motion,
        }
    }

    fn read(&self, text: &str) -> ReadProgram {
        let mut program = ReadProgram::default();
        let mut state: Vec<Option<f64>> = vec![None; self.n_axes];
        let mut motion = self.initial_motion;
        let mut feed: Option<f64> = None;
        // The circular motion in force (clockwise or not) and the plane.
        let mut circle: Option<bool> = None;
        let mut plane = ArcPlane::Xy;
        // The absolute centre of a centre line (`CC`), for the arc after it.
        let mut centre_point: [Option<f64>; 3] = [None; 3];
        let mut words: Vec<(Token, f64)> = Vec::new();
        for (index, raw_line) in text.lines().enumerate() {
            let line_no = index + 1;
            let mut line = raw_line.trim_end_matches('\r');
            if !self.line_end_extra.is_empty() {
                line = line
                    .trim_end()
                    .trim_end_matches(self.line_end_extra.as_str());
            }
            let mut rest = line.trim();
            if rest.is_empty() {
                continue;
            }
            let mut number = None;
            if let Some((n, r)) = self.block_number(rest) {
                number = Some(n);
                rest = r.trim_start();
            }
            words.clear();
            if !self.words(rest, &mut words) {
                program.other_lines.push(line_no);
                continue;
            }
            if words.iter().any(|(t, _)| *t == Token::CentreBlock) {
                for &(t, v) in &words {
                    if let Token::Axis(i) = t
                        && let Some(k) = self.program_axis[i]
                    {
                        centre_point[k] = Some(v);
                    }
                }
                continue;
            }
            // Where the block starts, on the program's X, Y, Z (for an
            // absolute centre).
            let mut start = [None; 3];
            for (i, k) in self.program_axis.iter().enumerate() {
                if let Some(k) = *k {
                    start[k] = state[i];
                }
            }
            let mut block_motion = None;
            let mut has_axis = false;
            let mut centre = [0.0; 3];
            let mut sense = None;
            for &(t, v) in &words {
                match t {
                    Token::Axis(i) => {
                        state[i] = Some(v);
                        has_axis = true;
                    }
                    Token::Pressure(i) => state[i] = Some(v),
                    Token::Feed => feed = Some(v),
                    Token::Motion(m) => {
                        motion = m;
                        circle = None;
                    }
                    Token::RapidLiteral => block_motion = Some(Motion::Rapid),
                    Token::Ignored | Token::CentreBlock => {}
                    Token::Straight => {
                        motion = Motion::Feed;
                        circle = None;
                    }
                    Token::Arc(clockwise) => {
                        motion = Motion::Feed;
                        circle = Some(clockwise.unwrap_or(true));
                    }
                    Token::Sense(clockwise) => sense = Some(clockwise),
                    Token::Plane(p) => plane = p,
                    Token::Centre(k) => centre[k] = v,
                }
            }
            if let Some(c) = circle.as_mut()
                && let Some(s) = sense
            {
                *c = s;
            }
            // An absolute centre (`CC`) is the centre's offset from the
            // arc's start, as the arc block has it.
            if circle.is_some() {
                for ((offset, c), s) in centre.iter_mut().zip(centre_point).zip(start) {
                    if let (Some(c), Some(s)) = (c, s) {
                        *offset = self.centre_format.quantize(c - s);
                    }
                }
            }
            if has_axis {
                let motion = block_motion.unwrap_or(motion);
                program.blocks.push(Block {
                    line: Some(line_no),
                    number,
                    cl_line: None,
                    motion,
                    axes: state.clone(),
                    feed,
                    arc: circle
                        .filter(|_| motion == Motion::Feed)
                        .map(|clockwise| ArcMotion {
                            plane,
                            clockwise,
                            centre_offset: centre,
                        }),
                });
            }
        }
        program
    }

    /// `N120` (or a bare `120` for Heidenhain-style numbering) at the start.
    fn block_number<'a>(&self, s: &'a str) -> Option<(u64, &'a str)> {
        let digits_from = if !self.number_prefix.is_empty() {
            s.strip_prefix(self.number_prefix.as_str())?
        } else if self.bare_numbers {
            s
        } else {
            return None;
        };
        let end = digits_from
            .bytes()
            .position(|b| !b.is_ascii_digit())
            .unwrap_or(digits_from.len());
        if end == 0 {
            return None;
        }
        let rest = &digits_from[end..];
        // A bare number must be followed by a space (else `459` of a word).
        if self.number_prefix.is_empty() && !(rest.is_empty() || rest.starts_with([' ', '\t'])) {
            return None;
        }
        // `N` of a word like `NEXT` is not a block number: digits required (checked).
        let n = digits_from[..end].parse().ok()?;
        Some((n, rest))
    }

    /// Splits `s` into known words; false when something is not a word of
    /// this dialect.
    fn words(&self, mut s: &str, out: &mut Vec<(Token, f64)>) -> bool {
        loop {
            s = s.trim_start();
            if !self.separator.is_empty() {
                while let Some(r) = s.strip_prefix(self.separator.as_str()) {
                    s = r.trim_start();
                }
            }
            if s.is_empty() {
                return true;
            }
            if let Some((t, v, r)) = self.word(s) {
                out.push((t, v));
                s = r;
            } else if let Some(r) = self.comment(s) {
                s = r;
            } else {
                return false;
            }
        }
    }

    /// Skips a comment at the start of `s` (to its end marker, or to the end
    /// of the line). Words are tried first, so a comment marker inside a word
    /// (`A=DC(` with `(` comments) is not taken for a comment.
    fn comment<'a>(&self, s: &'a str) -> Option<&'a str> {
        if self.comment_start.is_empty() {
            return None;
        }
        let after = s.strip_prefix(self.comment_start.as_str())?;
        if self.comment_end.is_empty() {
            return Some("");
        }
        Some(match after.find(self.comment_end.as_str()) {
            Some(e) => &after[e + self.comment_end.len()..],
            None => "",
        })
    }

    fn word<'a>(&self, s: &'a str) -> Option<(Token, f64, &'a str)> {
        for c in &self.candidates {
            let Some(after) = s.strip_prefix(c.text.as_str()) else {
                continue;
            };
            if c.numeric {
                let Some((v, r)) = parse_number(after) else {
                    continue;
                };
                let Some(r) = r.strip_prefix(c.suffix.as_str()) else {
                    continue;
                };
                return Some((c.token, v, r));
            }
            let boundary = after.bytes().next().is_none_or(|b| {
                !(b.is_ascii_digit()
                    || b == b'.'
                    || b.is_ascii_alphabetic()
                        && c.text
                            .bytes()
                            .last()
                            .is_some_and(|l| l.is_ascii_alphabetic()))
            });
            if boundary {
                return Some((c.token, 0.0, after));
            }
        }
        None
    }
}

/// `[+-]digits[.digits]` at the start of `s`.
fn parse_number(s: &str) -> Option<(f64, &str)> {
    let b = s.as_bytes();
    let mut i = 0;
    if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
        i += 1;
    }
    let int_start = i;
    while i < b.len() && b[i].is_ascii_digit() {
        i += 1;
    }
    let mut digits = i - int_start;
    if i < b.len() && b[i] == b'.' {
        i += 1;
        let f = i;
        while i < b.len() && b[i].is_ascii_digit() {
            i += 1;
        }
        digits += i - f;
    }
    if digits == 0 {
        return None;
    }
    let v: f64 = s[..i].parse().ok()?;
    v.is_finite().then_some((v, &s[i..]))
}

fn read_csv(
    dialect: &Dialect,
    axes: &[AxisSpec],
    file: &str,
    text: &str,
) -> Result<ReadProgram, Diagnostic> {
    let sep = dialect.block.separator.as_str();
    let mut program = ReadProgram::default();
    #[derive(Clone, Copy)]
    enum Col {
        Line,
        Motion,
        Axis(usize),
        Feed,
        /// What the feed is (`per-minute`, `inverse-time`); read for its
        /// syntax only.
        FeedMode,
    }
    let mut columns: Option<Vec<Col>> = None;
    let column_of = |line: &str, field_index: usize| -> usize {
        line.split(sep)
            .take(field_index)
            .map(|f| f.chars().count() + sep.chars().count())
            .sum::<usize>()
            + 1
    };
    for (index, raw) in text.lines().enumerate() {
        let line_no = index + 1;
        let line = raw.trim_end_matches('\r');
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(sep).collect();
        let Some(cols) = &columns else {
            let mut cols = Vec::new();
            for (k, f) in fields.iter().enumerate() {
                let name = f.trim();
                let col = match name {
                    "line" => Col::Line,
                    "motion" => Col::Motion,
                    "feed" => Col::Feed,
                    "feed_mode" => Col::FeedMode,
                    _ => match axes.iter().position(|a| a.name == name) {
                        Some(i) => Col::Axis(i),
                        None => {
                            return Err(Diagnostic::error(
                                file,
                                line_no,
                                column_of(line, k),
                                name.chars().count(),
                                line,
                                format!("unknown column `{name}` (not an axis of the machine)"),
                            ));
                        }
                    },
                };
                cols.push(col);
            }
            columns = Some(cols);
            continue;
        };
        if fields.len() != cols.len() {
            return Err(Diagnostic::error(
                file,
                line_no,
                1,
                line.chars().count(),
                line,
                format!(
                    "row has {} fields, the header has {}",
                    fields.len(),
                    cols.len()
                ),
            ));
        }
        let mut block = Block {
            cl_line: None,
            line: Some(line_no),
            number: None,
            motion: Motion::Feed,
            axes: vec![None; axes.len()],
            feed: None,
            arc: None,
        };
        for (k, (f, col)) in fields.iter().zip(cols).enumerate() {
            let v = f.trim();
            let bad = |what: &str| {
                Diagnostic::error(
                    file,
                    line_no,
                    column_of(line, k),
                    f.chars().count(),
                    line,
                    format!("malformed {what} `{v}`"),
                )
            };
            match *col {
                Col::Line => {
                    if !v.is_empty() {
                        block.cl_line = Some(v.parse().map_err(|_| bad("line number"))?);
                    }
                }
                Col::Motion => {
                    block.motion = match v {
                        "rapid" => Motion::Rapid,
                        "feed" => Motion::Feed,
                        _ => return Err(bad("motion (expected `rapid` or `feed`)")),
                    }
                }
                Col::Axis(i) => {
                    if !v.is_empty() {
                        block.axes[i] = Some(csv_number(v).ok_or_else(|| bad("number"))?);
                    }
                }
                Col::Feed => {
                    if !v.is_empty() {
                        block.feed = Some(csv_number(v).ok_or_else(|| bad("feed"))?);
                    }
                }
                Col::FeedMode => {
                    if !matches!(v, "" | "per-minute" | "inverse-time") {
                        return Err(bad(
                            "feed mode (expected `per-minute`, `inverse-time` or nothing)",
                        ));
                    }
                }
            }
        }
        program.blocks.push(block);
    }
    Ok(program)
}

fn csv_number(v: &str) -> Option<f64> {
    match parse_number(v) {
        Some((x, "")) => Some(x),
        _ => None,
    }
}
