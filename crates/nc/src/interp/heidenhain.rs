//! Heidenhain TNC conversational programs (Klartext).
//!
//! Rules followed: TNC 640 user's manual for conversational programming
//! (HEIDENHAIN 892903): "Programming contours" (L, CC, C, CR, CT, LP, CP,
//! radius compensation R0/RL/RR, FMAX, incremental `I` coordinates, polar
//! coordinates PR/PA relative to the pole CC), "Subprograms and program
//! section repeats" (LBL, CALL LBL … REP, LBL 0), "Q parameters" (FN 0 …
//! FN 13, FN 14 ERROR, formulas `Q1 = …`), "Miscellaneous functions" (M91,
//! M126/M127, M128/M129, M89/M99), "FUNCTION TCPM"; and the cycle
//! programming manual (HEIDENHAIN 892905): cycles 7 (datum shift), 9
//! (dwell), 32 (tolerance), 200, 201, 203, 205, 207, 247 (preset).

use std::collections::HashMap;

use kinpost_diag::Diagnostic;

use super::arc::{self, Centre};
use super::cycle::{self, Hole, Op};
use super::expr::{self, Cursor, Lang, Operands, Upper};
use super::machine::{Machine, RotaryMode};
use super::num::{read_number, read_uint};
use super::source::{Fail, Line, Pos, Source, diagnostic, fail};
use super::{
    ArcPlane, CutterComp, CycleRef, Event, FeedMode, MAX_AXES, MotionKind, Options, Report, Sink,
    SpindleDir, StopKind, WorkOffset,
};
use crate::AxisSpec;

mod fast;
mod words;

/// Q parameters of each kind: Q0..Q1999, QL0..QL499, QR0..QR499.
const Q_PARAMS: usize = 2000;
const QL_PARAMS: usize = 500;

/// A defined cycle waiting for its call.
#[derive(Debug, Clone, PartialEq)]
struct CycleDef {
    code: u16,
    line: usize,
}

struct Interp<'a, 's> {
    file: &'a str,
    src: Source<'a>,
    m: Machine<'s>,
    q: Vec<f64>,
    ql: Vec<f64>,
    qr: Vec<f64>,
    /// Circle centre / pole (X, Y, Z), when programmed.
    cc: Option<[f64; 3]>,
    cycle: Option<CycleDef>,
    /// M89: the cycle is called after every positioning block.
    modal_call: bool,
    /// M126: rotary axes take the shortest way.
    shortest: bool,
    /// Subprogram calls: where to return.
    calls: Vec<Pos>,
    /// Program section repeats left, by the CALL line.
    repeats: HashMap<usize, u64>,
    /// Labels found so far: their line.
    labels: HashMap<String, Pos>,
    ended: bool,
    /// Direction of the path at the end of the last move (CT).
    tangent: Option<super::arc::LastElement>,
    /// BLK FORM 0.1 corner, waiting for 0.2.
    blank_min: Option<[f64; 3]>,
    warned: Vec<String>,
    /// CYCL DEF 247 waits for its Q339.
    pending_preset: bool,
    /// The machine axis of each one-letter axis name A..Z, for the hot path.
    letter_axis: [Option<usize>; 26],
}

/// Runs a Heidenhain program.
pub(crate) fn run(
    text: &str,
    axes: &[AxisSpec],
    options: &Options,
    file: &str,
    sink: &mut dyn Sink,
) -> Result<Report, Diagnostic> {
    let mut it = Interp {
        file,
        src: Source::new(text),
        m: Machine::new(axes, options, sink),
        q: vec![0.0; Q_PARAMS],
        ql: vec![0.0; QL_PARAMS],
        qr: vec![0.0; QL_PARAMS],
        cc: None,
        cycle: None,
        modal_call: false,
        shortest: false,
        calls: Vec::new(),
        repeats: HashMap::new(),
        labels: HashMap::new(),
        ended: false,
        tangent: None,
        blank_min: None,
        warned: Vec::new(),
        pending_preset: false,
        letter_axis: [None; 26],
    };
    for (i, a) in axes.iter().enumerate().take(MAX_AXES) {
        let b = a.name.as_bytes();
        if b.len() == 1 && b[0].is_ascii_alphabetic() && !a.pressure {
            it.letter_axis[usize::from(b[0].to_ascii_uppercase() - b'A')] = Some(i);
        }
    }
    while !it.ended {
        let Some(line) = it.src.next_line() else {
            break;
        };
        it.m.at_line(line.no, None);
        if let Err(f) = it.line(&line) {
            return Err(diagnostic(file, &line, f, false));
        }
    }
    if !it.calls.is_empty() && !it.ended {
        return Err(Diagnostic::error(
            file,
            0,
            0,
            0,
            "",
            "the program ends inside a subprogram (no LBL 0)",
        ));
    }
    Ok(std::mem::take(&mut it.m.report))
}

/// The block number and where the block starts.
fn head(b: &[u8]) -> (Option<u64>, usize) {
    let mut c = Cursor::new(b, 0);
    c.skip_ws();
    if c.peek() == Some(b'/') {
        c.i += 1;
        c.skip_ws();
    }
    if let Some((n, len)) = read_uint(&b[c.i..])
        && b.get(c.i + len).is_none_or(|x| *x == b' ' || *x == b'\t')
    {
        return (Some(n), c.i + len);
    }
    (None, c.i)
}

/// The label a line defines (`LBL 5` → "5", `LBL "NAME"` → "NAME").
fn label_of(text: &str) -> Option<String> {
    let b = text.as_bytes();
    let (_, start) = head(b);
    let mut c = Cursor::new(b, start);
    if !c.eat_kw("LBL", true) {
        return None;
    }
    label_name(&mut c)
}

fn label_name(c: &mut Cursor<'_>) -> Option<String> {
    c.skip_ws();
    if c.peek() == Some(b'"') {
        let s = c.i + 1;
        let len = c.b[s..].iter().position(|&x| x == b'"')?;
        c.i = s + len + 1;
        return Some(String::from_utf8_lossy(&c.b[s..s + len]).to_ascii_uppercase());
    }
    let (n, len) = read_uint(&c.b[c.i..])?;
    c.i += len;
    Some(n.to_string())
}

impl Operands for Interp<'_, '_> {
    fn operand(&mut self, c: &mut Cursor<'_>, _lang: Lang) -> Result<Option<f64>, Fail> {
        c.skip_ws();
        let start = c.i;
        let Some(r) = self.q_ref(c)? else {
            return Ok(None);
        };
        let _ = start;
        Ok(Some(self.q_get(r)))
    }
}

/// A Q parameter: kind (0 Q, 1 QL, 2 QR) and number.
type QRef = (u8, usize);

impl<'a> Interp<'a, '_> {
    /// `Q12`, `QL3`, `QR4` at the cursor.
    fn q_ref(&mut self, c: &mut Cursor<'_>) -> Result<Option<QRef>, Fail> {
        let start = c.i;
        if !matches!(c.peek(), Some(b'Q' | b'q')) {
            return Ok(None);
        }
        let mut k = c.i + 1;
        let kind = match c.b.get(k).map(u8::to_ascii_uppercase) {
            Some(b'L') => {
                k += 1;
                1
            }
            Some(b'R') => {
                k += 1;
                2
            }
            _ => 0,
        };
        let Some((n, len)) = read_uint(&c.b[k..]) else {
            return Ok(None);
        };
        let limit = if kind == 0 { Q_PARAMS } else { QL_PARAMS };
        if n as usize >= limit {
            return fail(
                start,
                k + len - start,
                format!("Q parameter number {n} is out of range"),
            );
        }
        c.i = k + len;
        Ok(Some((kind, n as usize)))
    }

    fn q_get(&self, (kind, n): QRef) -> f64 {
        match kind {
            0 => self.q[n],
            1 => self.ql[n],
            _ => self.qr[n],
        }
    }

    fn q_set(&mut self, (kind, n): QRef, v: f64) {
        match kind {
            0 => self.q[n] = v,
            1 => self.ql[n] = v,
            _ => self.qr[n] = v,
        }
    }

    fn eval(&mut self, c: &mut Cursor<'_>) -> Result<f64, Fail> {
        expr::eval(c, Lang::Heidenhain, self)
    }

    fn line(&mut self, line: &Line<'a>) -> Result<(), Fail> {
        let b = line.text.as_bytes();
        let mut c = Cursor::new(b, 0);
        c.skip_ws();
        if c.at_end() || c.peek() == Some(b';') {
            return Ok(());
        }
        self.m.count_block()?;
        if c.peek() == Some(b'/') && self.m.options.block_delete {
            return Ok(());
        }
        let (number, start) = head(b);
        self.m.at_line(line.no, number);
        let mut c = Cursor::new(b, start);
        c.skip_ws();
        if c.at_end() || matches!(c.peek(), Some(b';' | b'*')) {
            return Ok(());
        }
        // Cycle parameters on lines of their own (`Q200=2 ;SET-UP
        // CLEARANCE`, `~` continuations): assignments.
        if c.peek() == Some(b'~') {
            c.i += 1;
        }
        if self.fast_line(b, c.i) {
            return Ok(());
        }
        self.statement(line, &mut c)
    }

    fn statement(&mut self, line: &Line<'a>, c: &mut Cursor<'_>) -> Result<(), Fail> {
        let start = c.i;
        if matches!(c.peek(), Some(b'Q' | b'q'))
            && let Some(r) = self.q_ref(c)?
        {
            if !c.eat(b'=') {
                return fail(start, c.i - start, "`=` expected after the Q parameter");
            }
            let v = self.eval(c)?;
            self.q_set(r, v);
            if self.pending_preset && r == (0, 339) {
                self.pending_preset = false;
                if !(0.0..=65535.0 - 1000.0).contains(&v) || v.fract() != 0.0 {
                    return fail(start, c.i - start, format!("preset number {v}"));
                }
                let k = 1000 + v as u16;
                self.m
                    .select_offset(WorkOffset::Numbered(k), &format!("preset {v}"));
            }
            return self.rest_is_comment(c);
        }
        let Some(id) = c.ident().map(Upper::of) else {
            return fail(c.i, 1, "a Heidenhain block is expected");
        };
        match &*id {
            "BEGIN" => self.begin_pgm(c),
            "END" => {
                if c.eat_kw("PGM", true) {
                    self.m.emit(Event::Stop(StopKind::End));
                    self.ended = true;
                    Ok(())
                } else {
                    fail(start, 3, "END PGM expected")
                }
            }
            "BLK" => self.blk_form(c, start),
            "TOOL" => self.tool(c, start),
            "L" | "C" | "CR" | "CT" | "CC" | "LP" | "CP" => self.contour(&id, line, c, start),
            "RND" | "CHF" => fail(
                start,
                id.len(),
                format!(
                    "{id} (rounding / chamfer between contour elements) is not supported: program the arc or line"
                ),
            ),
            "APPR" | "DEP" => fail(
                start,
                id.len(),
                format!("{id} (approach / departure contours) is not supported"),
            ),
            "FN" => self.fn_statement(c, start),
            "LBL" => {
                let Some(name) = label_name(c) else {
                    return fail(c.i, 1, "label number or \"name\" expected");
                };
                self.labels.insert(name.clone(), self.src.position());
                if name == "0"
                    && let Some(ret) = self.calls.pop()
                {
                    self.src.seek(ret);
                }
                Ok(())
            }
            "CALL" => self.call(line, c, start),
            "CYCL" => self.cycl(line, c, start),
            "FUNCTION" => self.function(c, start),
            "PLANE" => {
                if c.eat_kw("RESET", true) {
                    Ok(())
                } else {
                    fail(
                        start,
                        5,
                        "PLANE (tilted working plane) is not supported: the virtual machine cannot follow it",
                    )
                }
            }
            "STOP" => {
                self.m.emit(Event::Stop(StopKind::Program));
                self.m_words(line, c)
            }
            "M" => {
                c.i = start;
                self.m_words(line, c)
            }
            _ if id.starts_with('M') && id[1..].bytes().all(|d| d.is_ascii_digit()) => {
                c.i = start;
                self.m_words(line, c)
            }
            _ => fail(
                start,
                id.len(),
                format!("`{id}` is not a block the interpreter knows"),
            ),
        }
    }

    fn rest_is_comment(&self, c: &mut Cursor<'_>) -> Result<(), Fail> {
        c.skip_ws();
        if c.at_end() || matches!(c.peek(), Some(b';' | b'~')) {
            Ok(())
        } else {
            fail(c.i, c.b.len() - c.i, "unexpected text")
        }
    }

    fn begin_pgm(&mut self, c: &mut Cursor<'_>) -> Result<(), Fail> {
        if !c.eat_kw("PGM", true) {
            return fail(c.i, 1, "BEGIN PGM expected");
        }
        c.skip_ws();
        while c.peek().is_some_and(|x| x != b' ') {
            c.i += 1;
        }
        if c.eat_kw("INCH", true) {
            self.m.set_units(true);
        } else if !c.eat_kw("MM", true) {
            return fail(c.i, 1, "MM or INCH expected after the program name");
        }
        Ok(())
    }

    /// `BLK FORM 0.1 Z X… Y… Z…` / `BLK FORM 0.2 X… Y… Z…` (or `IX…`).
    fn blk_form(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        if !c.eat_kw("FORM", true) {
            return fail(at, 3, "BLK FORM expected");
        }
        c.skip_ws();
        let Some(n) = read_number(&c.b[c.i..]) else {
            return fail(c.i, 1, "0.1 or 0.2 expected");
        };
        c.i += n.len;
        if n.value == 0.1 {
            let _axis = c.ident();
        }
        let mut p = self.blank_min.unwrap_or([0.0; 3]);
        let min = p;
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else { break };
            if ch == b';' {
                break;
            }
            let inc = matches!(ch, b'I' | b'i');
            let letter_at = if inc { c.i + 1 } else { c.i };
            let Some(k) =
                c.b.get(letter_at)
                    .and_then(|l| b"XYZ".iter().position(|x| *x == l.to_ascii_uppercase()))
            else {
                return fail(c.i, 1, "X, Y or Z expected in BLK FORM");
            };
            c.i = letter_at + 1;
            let v = self.number_value(c)? * self.m.unit();
            p[k] = if inc { min[k] + v } else { v };
        }
        if n.value == 0.1 {
            self.blank_min = Some(p);
        } else {
            let lo = self.blank_min.take().unwrap_or([0.0; 3]);
            let min_mm = [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])];
            let max_mm = [lo[0].max(p[0]), lo[1].max(p[1]), lo[2].max(p[2])];
            self.m.emit(Event::BlankForm { min_mm, max_mm });
        }
        Ok(())
    }

    /// A signed number or a Q parameter (`+5`, `-Q3`, `Q3`, `+Q3`).
    fn number_value(&mut self, c: &mut Cursor<'_>) -> Result<f64, Fail> {
        c.skip_ws();
        if let Some(n) = read_number(&c.b[c.i..]) {
            c.i += n.len;
            return Ok(n.value);
        }
        let start = c.i;
        let mut sign = 1.0;
        if let Some(s @ (b'+' | b'-')) = c.peek() {
            if s == b'-' {
                sign = -1.0;
            }
            c.i += 1;
        }
        match self.q_ref(c)? {
            Some(r) => Ok(sign * self.q_get(r)),
            None => fail(start, 1, "a number or Q parameter is expected"),
        }
    }

    /// `TOOL CALL 5 Z S3000 F500 DL… DR…` / `TOOL DEF 5`.
    fn tool(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        if c.eat_kw("DEF", true) {
            c.skip_ws();
            let Some((t, len)) = read_uint(&c.b[c.i..]) else {
                return fail(c.i, 1, "tool number expected");
            };
            c.i += len;
            self.m.emit(Event::ToolSelect { tool: t as u32 });
            return Ok(());
        }
        if !c.eat_kw("CALL", true) {
            return fail(at, 4, "TOOL CALL or TOOL DEF expected");
        }
        c.skip_ws();
        if c.peek() == Some(b'"') {
            return fail(c.i, 1, "tool names are not supported: program tool numbers");
        }
        if let Some((t, len)) = read_uint(&c.b[c.i..]) {
            c.i += len;
            let t = t.min(u64::from(u32::MAX)) as u32;
            if self.m.state.tool != Some(t) {
                self.m.tool_change(t);
            }
            // The TNC applies the length of the called tool.
            self.m.set_tool_length(Some(t));
        }
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else { break };
            if ch == b';' {
                break;
            }
            let w_at = c.i;
            let id = c.ident().map(str::to_ascii_uppercase).unwrap_or_default();
            match id.as_str() {
                "X" => self.m.set_plane(ArcPlane::Yz),
                "Y" => self.m.set_plane(ArcPlane::Zx),
                "Z" => self.m.set_plane(ArcPlane::Xy),
                _ if id.starts_with('S')
                    || id.starts_with('F')
                    || id.starts_with("DL")
                    || id.starts_with("DR") =>
                {
                    let skip = if id.starts_with('D') { 2 } else { 1 };
                    c.i = w_at + skip;
                    let v = self.number_value(c)?;
                    if id.starts_with('S') {
                        self.m.set_speed(v);
                    } else if id.starts_with('F') {
                        self.m.feed = v * self.m.unit();
                    }
                }
                _ => {
                    return fail(
                        w_at,
                        id.len().max(1),
                        format!("`{id}` in TOOL CALL is not supported"),
                    );
                }
            }
        }
        Ok(())
    }

    /// `FN 0: Q1 = +5`, … , `FN 9: IF +Q1 EQU +0 GOTO LBL 5`, `FN 14: ERROR = 10`.
    fn fn_statement(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        c.skip_ws();
        let Some((n, len)) = read_uint(&c.b[c.i..]) else {
            return fail(c.i, 1, "FN number expected");
        };
        c.i += len;
        if !c.eat(b':') {
            return fail(c.i, 1, "`:` expected after the FN number");
        }
        match n {
            0..=8 | 13 => {
                c.skip_ws();
                let q_at = c.i;
                let Some(r) = self.q_ref(c)? else {
                    return fail(q_at, 1, "Q parameter expected");
                };
                if !c.eat(b'=') {
                    return fail(c.i, 1, "`=` expected");
                }
                let v = match n {
                    5 => {
                        c.eat_kw("SQRT", true);
                        self.number_value(c)?.sqrt()
                    }
                    6 => {
                        c.eat_kw("SIN", true);
                        self.number_value(c)?.to_radians().sin()
                    }
                    7 => {
                        c.eat_kw("COS", true);
                        self.number_value(c)?.to_radians().cos()
                    }
                    _ => {
                        let a = self.number_value(c)?;
                        if n == 0 {
                            a
                        } else {
                            let op_at = c.i;
                            c.skip_ws();
                            let op = match n {
                                1 => c.eat(b'+'),
                                2 => c.eat(b'-'),
                                3 => c.eat(b'*'),
                                4 => c.eat_kw("DIV", true),
                                8 => c.eat_kw("LEN", true),
                                _ => c.eat_kw("ANG", true),
                            };
                            if !op {
                                return fail(op_at, 1, format!("FN {n}: operator expected"));
                            }
                            let b = self.number_value(c)?;
                            match n {
                                1 => a + b,
                                2 => a - b,
                                3 => a * b,
                                4 => {
                                    if b == 0.0 {
                                        return fail(op_at, 3, "FN 4: division by zero");
                                    }
                                    a / b
                                }
                                8 => a.hypot(b),
                                _ => b.atan2(a).to_degrees().rem_euclid(360.0),
                            }
                        }
                    }
                };
                if v.is_nan() {
                    return fail(at, c.i - at, format!("FN {n}: the result is not a number"));
                }
                self.q_set(r, v);
                self.rest_is_comment(c)
            }
            9..=12 => {
                if !c.eat_kw("IF", true) {
                    return fail(c.i, 1, "IF expected");
                }
                let a = self.number_value(c)?;
                c.skip_ws();
                let ok = match n {
                    9 => c.eat_kw("EQU", true),
                    10 => c.eat_kw("NE", true),
                    11 => c.eat_kw("GT", true),
                    _ => c.eat_kw("LT", true),
                };
                if !ok {
                    return fail(c.i, 1, "EQU / NE / GT / LT expected");
                }
                let b = self.number_value(c)?;
                if !(c.eat_kw("GOTO", true) && c.eat_kw("LBL", true)) {
                    return fail(c.i, 1, "GOTO LBL expected");
                }
                let l_at = c.i;
                let Some(name) = label_name(c) else {
                    return fail(c.i, 1, "label expected");
                };
                let jump = match n {
                    9 => a == b,
                    10 => a != b,
                    11 => a > b,
                    _ => a < b,
                };
                if jump {
                    let p = self.find_label(&name, l_at)?;
                    self.src.seek(p);
                }
                Ok(())
            }
            14 => {
                let v = if c.eat_kw("ERROR", true) && c.eat(b'=') {
                    self.number_value(c)?
                } else {
                    0.0
                };
                fail(
                    at,
                    c.b.len() - at,
                    format!("FN 14: the program raises error {v}"),
                )
            }
            _ => fail(
                at,
                c.i - at,
                format!("FN {n} is not supported by the interpreter"),
            ),
        }
    }

    /// The line after `LBL name`: known, or searched in the whole program.
    fn find_label(&mut self, name: &str, at: usize) -> Result<Pos, Fail> {
        if let Some(p) = self.labels.get(name) {
            return Ok(*p);
        }
        let mut s = Source::new(self.src.text);
        while let Some(l) = s.next_line() {
            if label_of(l.text).as_deref() == Some(name) {
                let p = s.position();
                self.labels.insert(name.to_string(), p);
                return Ok(p);
            }
        }
        fail(at, name.len(), format!("LBL {name} is not in the program"))
    }

    /// `CALL LBL n [REP m]`: a section repeat (REP, label before) or a
    /// subprogram call (to LBL 0); `CALL PGM` is not supported.
    fn call(&mut self, line: &Line<'_>, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        if !c.eat_kw("LBL", true) {
            return fail(
                at,
                c.i - at + 1,
                "CALL LBL expected (CALL PGM: other files are not searched)",
            );
        }
        c.skip_ws();
        let l_at = c.i;
        let Some(name) = label_name(c) else {
            return fail(c.i, 1, "label expected");
        };
        let target = self.find_label(&name, l_at)?;
        if c.eat_kw("REP", true) {
            c.skip_ws();
            let Some((m, len)) = read_uint(&c.b[c.i..]) else {
                return fail(c.i, 1, "repeat count expected");
            };
            c.i += len;
            if target.offset > line.pos.offset {
                return fail(
                    l_at,
                    name.len(),
                    format!("CALL LBL {name} REP: the label must come before the call"),
                );
            }
            let left = self.repeats.entry(line.pos.offset).or_insert(m);
            if *left > 0 {
                *left -= 1;
                self.src.seek(target);
            } else {
                self.repeats.remove(&line.pos.offset);
            }
            return Ok(());
        }
        if self.calls.len() >= self.m.options.max_call_depth {
            return fail(
                at,
                4,
                format!(
                    "subprogram calls nested deeper than {} (Options::max_call_depth)",
                    self.m.options.max_call_depth
                ),
            );
        }
        self.calls.push(self.src.position());
        self.src.seek(target);
        Ok(())
    }

    fn function(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        if c.eat_kw("TCPM", true) {
            self.m.set_tcp(true);
            return Ok(());
        }
        if c.eat_kw("RESET", true) && c.eat_kw("TCPM", true) {
            self.m.set_tcp(false);
            return Ok(());
        }
        c.i = at;
        c.ident();
        if c.eat_kw("MODE", true) && c.eat_kw("MILL", true) {
            return Ok(());
        }
        fail(
            at,
            c.b.len() - at,
            "this FUNCTION is not supported (FUNCTION TCPM, FUNCTION RESET TCPM and FUNCTION MODE MILL are)",
        )
    }
}

impl Interp<'_, '_> {
    fn warn_once(&mut self, line: &Line<'_>, key: &str, at: usize, len: usize, message: String) {
        if self.warned.iter().any(|k| k == key) {
            return;
        }
        self.warned.push(key.to_string());
        let d = diagnostic(self.file, line, Fail { at, len, message }, true);
        self.m.warn(d);
    }
}
