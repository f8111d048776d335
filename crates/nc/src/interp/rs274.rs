//! Fanuc ISO code with custom macro B, and LinuxCNC rs274ngc: the
//! word-address languages with `#` parameters.
//!
//! Rules followed: LinuxCNC documentation ("G-code overview": order of
//! execution, parameters, expressions, O-codes; "G codes": G2/G3 centre and
//! radius formats, canned cycles) checked against LinuxCNC's own `rs274`
//! (tests `crates/nc/tests/all/interp_rs274.rs`); Fanuc 0i-MF / 30i operator's
//! manuals (B-64604EN, B-63944EN): "Decimal point programming", "Custom
//! macro" (variables, operations, GOTO, IF, WHILE, G65), "Canned cycles for
//! drilling", "Subprogram" (M98/M99), "Tool center point control" (G43.4).

use std::collections::HashMap;

use super::arc::{self, Centre};
use super::cycle::{self, Hole, Op};
use super::expr::{self, Cursor, Lang, Operands, VACANT, is_vacant};
use super::machine::{MM_PER_INCH, Machine, RotaryMode};
use super::num::{read_number, read_uint};
use super::source::{Fail, Line, Pos, Source, diagnostic, fail};
use super::{
    ArcPlane, CutterComp, CycleRef, Event, FeedMode, MAX_AXES, MotionKind, Options, Report, Sink,
    SpindleDir, StopKind, WorkOffset,
};
use crate::AxisSpec;

/// Which of the two languages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flavour {
    Fanuc,
    LinuxCnc,
}

/// Axis letters of the languages, in LinuxCNC's parameter order.
const AXIS_LETTERS: [u8; 9] = *b"XYZABCUVW";

/// Numbered parameters of LinuxCNC (1..=5601 and the unused 0).
const LINUXCNC_PARAMS: usize = 5602;

/// Fanuc: the local variables #1..#33.
const FANUC_LOCALS: usize = 34;

/// One block's words.
#[derive(Debug, Clone, Default)]
struct Block {
    /// G-codes × 10 (`G43.4` → 434), in block order.
    g: Vec<(u16, usize)>,
    /// M-codes with their byte offset.
    m: Vec<(u32, usize)>,
    /// Values of the letter words A..Z.
    v: [f64; 26],
    /// Letters present (bit k = letter 'A' + k).
    has: u32,
    /// Letters whose literal number had no decimal point (Fanuc).
    no_point: u32,
    /// Byte offset of each letter word (for messages).
    at: [u16; 26],
    /// Parameter assignments of the line (LinuxCNC: applied at its end).
    assign: Vec<(Param, f64)>,
    /// Message comment of the line.
    message: Option<String>,
    /// The first G-code that needs the axis words (motion, G10, G28, G92).
    axis_user: bool,
}

impl Block {
    fn new() -> Block {
        Block {
            g: Vec::with_capacity(8),
            m: Vec::with_capacity(4),
            v: [0.0; 26],
            has: 0,
            no_point: 0,
            at: [0; 26],
            assign: Vec::new(),
            message: None,
            axis_user: false,
        }
    }

    fn clear(&mut self) {
        self.g.clear();
        self.m.clear();
        self.has = 0;
        self.no_point = 0;
        self.assign.clear();
        self.message = None;
        self.axis_user = false;
    }

    #[inline]
    fn has(&self, letter: u8) -> bool {
        self.has & (1 << (letter - b'A')) != 0
    }

    #[inline]
    fn get(&self, letter: u8) -> Option<f64> {
        self.has(letter).then(|| self.v[usize::from(letter - b'A')])
    }

    fn pos_of(&self, letter: u8) -> usize {
        usize::from(self.at[usize::from(letter - b'A')])
    }

    fn has_g(&self, code: u16) -> Option<usize> {
        self.g.iter().find(|(c, _)| *c == code).map(|(_, at)| *at)
    }
}

/// A parameter reference.
#[derive(Debug, Clone, PartialEq)]
enum Param {
    Numbered(usize),
    Named(String),
}

/// Motion mode of group 1 (and LinuxCNC's cycles).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Motion {
    Rapid,
    Linear,
    Cw,
    Ccw,
    /// A drilling cycle, by code (81, 73, …).
    Cycle(u16),
    /// `G80` (LinuxCNC: no motion mode).
    None,
}

/// A loop or conditional of LinuxCNC O-codes.
#[derive(Debug, Clone)]
struct OFrame {
    name: String,
    kind: OKind,
    /// The line to come back to (the `while`, `do` or `repeat` line).
    start: Pos,
}

#[derive(Debug, Clone, PartialEq)]
enum OKind {
    While,
    Do,
    Repeat(u64),
}

/// A subprogram / macro call.
struct Call {
    ret: Pos,
    /// Fanuc M98 repeats left, G65 L repeats left (re-entering at `entry`).
    repeats: u64,
    entry: Pos,
    /// Saved local parameters (#1..#30 / #1..#33) when the call has its own.
    saved_locals: Option<Vec<f64>>,
    named: Option<HashMap<String, f64>>,
    loops: usize,
    /// LinuxCNC sub name (for `return`/`endsub`).
    name: String,
}

struct Interp<'a, 's> {
    flavour: Flavour,
    lang: Lang,
    file: &'a str,
    src: Source<'a>,
    m: Machine<'s>,
    /// Machine axis of each of the letters X Y Z A B C U V W.
    letter_axis: [Option<usize>; 9],
    params: Vec<f64>,
    named: HashMap<String, f64>,
    globals: HashMap<String, f64>,
    motion: Motion,
    /// Fanuc: the group 1 motion under a canned cycle.
    base_motion: Motion,
    incremental: bool,
    /// LinuxCNC G90.1: arc centres absolute.
    arc_absolute: bool,
    /// G98 (back to the initial level).
    retract_initial: bool,
    /// Initial level of the cycle run in force.
    cycle_initial: Option<f64>,
    /// Sticky cycle words.
    cycle_r: f64,
    cycle_z: f64,
    cycle_q: f64,
    cycle_p: f64,
    oframes: Vec<OFrame>,
    /// Fanuc WHILE … DO m loops: m and the WHILE line.
    do_loops: Vec<(u8, Pos)>,
    calls: Vec<Call>,
    subs: HashMap<String, Pos>,
    /// The block being read (boxed: lent out and back per line by moving
    /// a pointer).
    block: Option<Box<Block>>,
    /// Seen the first `%` line.
    percent: bool,
    ended: bool,
    /// Words of axes the machine lacks, warned once per letter.
    warned_axis: u32,
    /// G10 L1/L10 tool lengths by tool (reported with G43).
    tool_lengths: HashMap<u32, f64>,
    /// The value returned by the last LinuxCNC sub.
    returned: Option<f64>,
    /// Tool selected by T, for the next M6.
    selected_tool: Option<u32>,
    /// Where the line being executed starts.
    current_pos: Pos,
}

/// Runs a Fanuc or LinuxCNC program.
pub(crate) fn run(
    text: &str,
    flavour: Flavour,
    axes: &[AxisSpec],
    options: &Options,
    file: &str,
    sink: &mut dyn Sink,
) -> Result<Report, kinpost_diag::Diagnostic> {
    let mut it = Interp::new(text, flavour, axes, options, file, sink);
    it.run()?;
    Ok(std::mem::take(&mut it.m.report))
}

impl<'a, 's> Interp<'a, 's> {
    fn new(
        text: &'a str,
        flavour: Flavour,
        axes: &[AxisSpec],
        options: &Options,
        file: &'a str,
        sink: &'s mut dyn Sink,
    ) -> Interp<'a, 's> {
        let m = Machine::new(axes, options, sink);
        let mut letter_axis = [None; 9];
        for (k, l) in AXIS_LETTERS.iter().enumerate() {
            letter_axis[k] = m.axis(std::str::from_utf8(&[*l]).unwrap_or("X"));
        }
        let lang = match flavour {
            Flavour::Fanuc => Lang::Fanuc,
            Flavour::LinuxCnc => Lang::LinuxCnc,
        };
        let params = match flavour {
            Flavour::LinuxCnc => vec![0.0; LINUXCNC_PARAMS],
            // #0 vacant, locals and commons start vacant.
            Flavour::Fanuc => vec![VACANT; 1000],
        };
        Interp {
            flavour,
            lang,
            file,
            src: Source::new(text),
            m,
            letter_axis,
            params,
            named: HashMap::new(),
            globals: HashMap::new(),
            motion: Motion::None,
            base_motion: Motion::None,
            incremental: false,
            arc_absolute: false,
            retract_initial: flavour == Flavour::Fanuc,
            cycle_initial: None,
            cycle_r: 0.0,
            cycle_z: 0.0,
            cycle_q: 0.0,
            cycle_p: 0.0,
            oframes: Vec::new(),
            do_loops: Vec::new(),
            calls: Vec::new(),
            subs: HashMap::new(),
            block: Some(Box::new(Block::new())),
            percent: false,
            ended: false,
            warned_axis: 0,
            tool_lengths: HashMap::new(),
            returned: None,
            selected_tool: None,
            current_pos: Pos { offset: 0, line: 1 },
        }
    }

    fn run(&mut self) -> Result<(), kinpost_diag::Diagnostic> {
        while !self.ended {
            let Some(line) = self.src.next_line() else {
                break;
            };
            self.m.at_line(line.no, None);
            self.current_pos = line.pos;
            if let Err(f) = self.line(&line) {
                return Err(diagnostic(self.file, &line, f, false));
            }
        }
        if !self.ended {
            let open = self
                .do_loops
                .last()
                .map(|(m, p)| (*p, format!("WHILE … DO {m} without its END {m}")))
                .or_else(|| {
                    self.oframes
                        .last()
                        .map(|f| (f.start, format!("o{} loop without its end", f.name)))
                });
            if let Some((pos, what)) = open
                && let Some(line) = self.src.line_at(pos)
            {
                let len = line.text.len();
                return Err(diagnostic(
                    self.file,
                    &line,
                    Fail {
                        at: 0,
                        len,
                        message: what,
                    },
                    false,
                ));
            }
        }
        if !self.calls.is_empty() && !self.ended {
            let name = self
                .calls
                .last()
                .map(|c| c.name.clone())
                .unwrap_or_default();
            return Err(kinpost_diag::Diagnostic::error(
                self.file,
                0,
                0,
                0,
                "",
                format!("the program ends inside subprogram {name} (no M99 / endsub)"),
            ));
        }
        Ok(())
    }

    /// One line.
    fn line(&mut self, line: &Line<'a>) -> Result<(), Fail> {
        let b = line.text.as_bytes();
        let mut c = Cursor::new(b, 0);
        c.skip_ws();
        if c.at_end() {
            return Ok(());
        }
        if c.peek() == Some(b'%') {
            if self.percent && self.flavour == Flavour::LinuxCnc {
                self.ended = true;
            }
            self.percent = true;
            return Ok(());
        }
        self.m.count_block()?;
        if c.peek() == Some(b'/') {
            if self.m.options.block_delete {
                return Ok(());
            }
            c.i += 1;
        }
        c.skip_ws();
        // Block number.
        let mut number = None;
        if matches!(c.peek(), Some(b'N' | b'n')) {
            let mut d = c;
            d.i += 1;
            d.skip_ws();
            if let Some((n, len)) = read_uint(&b[d.i..]) {
                // `N10.5` is not a block number.
                if b.get(d.i + len) != Some(&b'.') {
                    number = Some(n);
                    c.i = d.i + len;
                }
            }
        }
        self.m.at_line(line.no, number);
        c.skip_ws();
        if matches!(c.peek(), Some(b'O' | b'o')) {
            return self.o_word(line, c);
        }
        if self.fast_line(b, c.i) {
            return Ok(());
        }
        if self.flavour == Flavour::Fanuc && self.fanuc_statement(line, &mut c)? {
            return Ok(());
        }
        // The block's buffers go back to `self.block`: no allocation per line.
        let mut block = self.block.take().unwrap_or_default();
        block.clear();
        let r = self
            .read_block(b, c, &mut block)
            .and_then(|()| self.execute(&block, line));
        self.block = Some(block);
        r
    }

    // ----- reading a block -------------------------------------------------

    fn read_block(&mut self, b: &[u8], mut c: Cursor<'_>, block: &mut Block) -> Result<(), Fail> {
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else {
                break;
            };
            match ch {
                b'(' => {
                    let start = c.i;
                    let Some(end) = b[start..].iter().position(|&x| x == b')') else {
                        return fail(start, b.len() - start, "comment without its `)`");
                    };
                    let text = &b[start + 1..start + end];
                    if self.flavour == Flavour::LinuxCnc && text.contains(&b'(') {
                        return fail(
                            start,
                            end + 1,
                            "nested comment (LinuxCNC does not allow `(` inside a comment)",
                        );
                    }
                    self.comment(text, block);
                    c.i = start + end + 1;
                }
                b';' => break,
                b'#' => {
                    let start = c.i;
                    let p = self.param_ref(&mut c)?;
                    if !c.eat(b'=') {
                        return fail(start, c.i - start, "a parameter here must be set: `#1 = …`");
                    }
                    let v = self.expr(&mut c)?;
                    if self.flavour == Flavour::Fanuc {
                        self.set_param(&p, v, start)?;
                    } else {
                        block.assign.push((p, v));
                    }
                }
                _ if ch.is_ascii_alphabetic() => self.word(&mut c, block)?,
                _ => {
                    return fail(
                        c.i,
                        1,
                        format!("`{}` is not the start of a word", char::from(ch)),
                    );
                }
            }
        }
        Ok(())
    }

    /// A comment: messages and LinuxCNC's `(PRINT,…)`, `(DEBUG,…)`.
    fn comment(&mut self, text: &[u8], block: &mut Block) {
        let t = String::from_utf8_lossy(text);
        let trimmed = t.trim_start();
        for kw in ["MSG,", "PRINT,", "DEBUG,"] {
            // ASCII comparison: the keyword's bytes end on a boundary.
            if trimmed
                .as_bytes()
                .get(..kw.len())
                .is_some_and(|p| p.eq_ignore_ascii_case(kw.as_bytes()))
            {
                block.message = Some(trimmed[kw.len()..].to_string());
                return;
            }
        }
    }

    /// One letter word.
    #[inline]
    fn word(&mut self, c: &mut Cursor<'_>, block: &mut Block) -> Result<(), Fail> {
        let start = c.i;
        let letter = c.b[c.i].to_ascii_uppercase();
        c.i += 1;
        c.skip_ws();
        let (v, point) = self.value(c)?;
        let k = usize::from(letter - b'A');
        match letter {
            b'G' => {
                let code = g_code(v).ok_or_else(|| Fail {
                    at: start,
                    len: c.i - start,
                    message: format!("`G{v}` is not a G-code"),
                })?;
                block.g.push((code, start));
            }
            b'M' => {
                if !((0.0..1e6).contains(&v) && v.fract() == 0.0) {
                    return fail(start, c.i - start, format!("`M{v}` is not an M-code"));
                }
                block.m.push((v as u32, start));
            }
            _ => {
                if block.has & (1 << k) != 0 {
                    return fail(
                        start,
                        c.i - start,
                        format!("two {} words in one block", char::from(letter)),
                    );
                }
                block.has |= 1 << k;
                block.v[k] = v;
                block.at[k] = start.min(u16::MAX as usize) as u16;
                if !point {
                    block.no_point |= 1 << k;
                }
            }
        }
        Ok(())
    }

    /// The value of a word: a number, a parameter, an expression or a
    /// unary function; whether it was a literal with a decimal point (or not
    /// a literal at all).
    #[inline]
    fn value(&mut self, c: &mut Cursor<'_>) -> Result<(f64, bool), Fail> {
        if let Some(n) = read_number(&c.b[c.i..]) {
            c.i += n.len;
            return Ok((n.value, n.has_point));
        }
        let start = c.i;
        let v = self.expr_operand(c)?;
        if is_vacant(v) {
            return Ok((VACANT, true));
        }
        let _ = start;
        Ok((v, true))
    }

    /// A word value that is not a literal: `#…`, `[…]`, `-#1`, `SIN[…]`.
    fn expr_operand(&mut self, c: &mut Cursor<'_>) -> Result<f64, Fail> {
        // One unary term: sign, then a parameter / bracket / function.
        let start = c.i;
        let mut sign = 1.0;
        while let Some(ch @ (b'-' | b'+')) = c.peek() {
            if ch == b'-' {
                sign = -sign;
            }
            c.i += 1;
            c.skip_ws();
        }
        let lang = self.lang;
        let v = match c.peek() {
            Some(b'#') => {
                let p = self.param_ref(c)?;
                self.get_param(&p, start)?
            }
            Some(b'[') => expr::eval(c, lang, self)?,
            Some(ch) if ch.is_ascii_alphabetic() => {
                // A unary function of a bracket (`SIN[30]`): evaluated as an
                // expression bounded by the call's closing bracket.
                let end = find_call_end(c.b, c.i);
                let mut d = Cursor::new(&c.b[..end], c.i);
                let v = expr::eval(&mut d, lang, self)?;
                if d.i != end {
                    return fail(
                        start,
                        end - start,
                        "a number, parameter or expression was expected",
                    );
                }
                c.i = end;
                v
            }
            _ => return fail(start, 1, "a number, parameter or expression was expected"),
        };
        if is_vacant(v) {
            return Ok(if sign < 0.0 { 0.0 } else { VACANT });
        }
        Ok(sign * v)
    }

    fn expr(&mut self, c: &mut Cursor<'_>) -> Result<f64, Fail> {
        let lang = self.lang;
        expr::eval(c, lang, self)
    }

    /// `#12`, `#[expr]`, `#<name>` at the cursor.
    fn param_ref(&mut self, c: &mut Cursor<'_>) -> Result<Param, Fail> {
        let start = c.i;
        c.i += 1; // '#'
        c.skip_ws();
        match c.peek() {
            Some(b'<') if self.flavour == Flavour::LinuxCnc => {
                let Some(end) = c.b[c.i..].iter().position(|&x| x == b'>') else {
                    return fail(start, c.b.len() - start, "named parameter without its `>`");
                };
                let name: String = String::from_utf8_lossy(&c.b[c.i + 1..c.i + end])
                    .chars()
                    .filter(|ch| !ch.is_whitespace())
                    .flat_map(char::to_lowercase)
                    .collect();
                c.i += end + 1;
                if name.is_empty() {
                    return fail(start, c.i - start, "empty parameter name");
                }
                Ok(Param::Named(name))
            }
            Some(b'#' | b'[') => {
                let v = if c.peek() == Some(b'#') {
                    let p = self.param_ref(c)?;
                    self.get_param(&p, start)?
                } else {
                    self.expr(c)?
                };
                self.param_index(v, start, c.i - start)
            }
            _ => {
                let Some(n) = read_number(&c.b[c.i..]) else {
                    return fail(start, 1, "parameter number expected after `#`");
                };
                c.i += n.len;
                self.param_index(n.value, start, c.i - start)
            }
        }
    }

    fn param_index(&self, v: f64, at: usize, len: usize) -> Result<Param, Fail> {
        let limit = match self.flavour {
            Flavour::LinuxCnc => LINUXCNC_PARAMS as f64,
            Flavour::Fanuc => 100_000.0,
        };
        if !(v >= 0.0 && v < limit && v.fract() == 0.0) {
            return fail(at, len, format!("#{v} is not a parameter number"));
        }
        Ok(Param::Numbered(v as usize))
    }

    fn get_param(&mut self, p: &Param, at: usize) -> Result<f64, Fail> {
        match p {
            Param::Numbered(n) => self.get_numbered(*n, at),
            Param::Named(name) => self.get_named(name, at),
        }
    }

    fn get_numbered(&mut self, n: usize, at: usize) -> Result<f64, Fail> {
        if let Some(v) = self.offset_param(n) {
            return Ok(v);
        }
        match self.flavour {
            Flavour::LinuxCnc => {
                if (5420..=5428).contains(&n) {
                    return Ok(self.letter_pos(n - 5420));
                }
                if n == 5400 {
                    return Ok(f64::from(self.m.state.tool.unwrap_or(0)));
                }
                if n == 5220 {
                    return Ok(match self.m.state.work_offset {
                        WorkOffset::Numbered(k) => f64::from(k),
                        WorkOffset::None => 1.0,
                    });
                }
                Ok(self.params[n])
            }
            Flavour::Fanuc => {
                if n < 1000 {
                    return Ok(self.params[n]);
                }
                if (5001..=5008).contains(&n) || (5041..=5048).contains(&n) {
                    return Ok(self.letter_pos(n % 10 - 1));
                }
                let key = format!("#{n}");
                if self.m.options.inputs.contains_key(&key) || (1000..1100).contains(&n) {
                    return Ok(self.m.input(&key));
                }
                fail(
                    at,
                    1,
                    format!(
                        "system variable #{n} is not modelled (give it as an input `#{n}=VALUE`)"
                    ),
                )
            }
        }
    }

    /// The work offset parameters #5221.. (G54 X, step 20 per system), and
    /// LinuxCNC's G92 #5211..; shared by both languages.
    fn offset_param(&self, n: usize) -> Option<f64> {
        if !(5221..5400).contains(&n) {
            return None;
        }
        let system = (n - 5221) / 20 + 1;
        let k = (n - 5221) % 20;
        if k >= 9 || system > 9 {
            return None;
        }
        let axis = self.letter_axis[k]?;
        Some(
            self.m
                .offsets
                .get(&(system as u16))
                .map_or(0.0, |o| o[axis]),
        )
    }

    fn letter_pos(&self, k: usize) -> f64 {
        self.letter_axis
            .get(k)
            .copied()
            .flatten()
            .map_or(0.0, |i| self.m.pos[i] / self.m.unit_of(i))
    }

    fn get_named(&mut self, name: &str, at: usize) -> Result<f64, Fail> {
        if let Some(v) = self.named.get(name).or_else(|| self.globals.get(name)) {
            return Ok(*v);
        }
        if let Some(v) = self.predefined(name) {
            return Ok(v);
        }
        if name.starts_with("_hal[") || name.starts_with("_ini[") {
            return Ok(self.m.input(name));
        }
        fail(at, 1, format!("named parameter #<{name}> is not defined"))
    }

    /// LinuxCNC's predefined named parameters that describe the state.
    fn predefined(&self, name: &str) -> Option<f64> {
        let letters = ["_x", "_y", "_z", "_a", "_b", "_c", "_u", "_v", "_w"];
        if let Some(k) = letters.iter().position(|l| *l == name) {
            return Some(self.letter_pos(k));
        }
        let b = |x: bool| f64::from(u8::from(x));
        Some(match name {
            "_metric" => b(!self.m.inch),
            "_imperial" => b(self.m.inch),
            "_absolute" => b(!self.incremental),
            "_incremental" => b(self.incremental),
            "_feed" => self.m.feed / self.m.unit(),
            "_rpm" => self.m.state.spindle_speed,
            "_current_tool" => f64::from(self.m.state.tool.unwrap_or(0)),
            "_value" => self.returned.unwrap_or(0.0),
            "_value_returned" => b(self.returned.is_some()),
            "_motion_mode" => match self.motion {
                Motion::Rapid => 0.0,
                Motion::Linear => 10.0,
                Motion::Cw => 20.0,
                Motion::Ccw => 30.0,
                Motion::Cycle(c) => f64::from(c) * 10.0,
                Motion::None => 800.0,
            },
            _ => return None,
        })
    }

    fn set_param(&mut self, p: &Param, v: f64, at: usize) -> Result<(), Fail> {
        match p {
            Param::Numbered(n) => {
                let n = *n;
                if (5221..5400).contains(&n) && self.offset_param(n).is_some() {
                    let system = ((n - 5221) / 20 + 1) as u16;
                    let axis = self.letter_axis[(n - 5221) % 20].unwrap_or(0);
                    let u = if axis < 3 { self.m.unit() } else { 1.0 };
                    let entry = self.m.offsets.entry(system).or_insert([0.0; MAX_AXES]);
                    entry[axis] = v * u;
                    self.m.refresh_offset(None);
                    return Ok(());
                }
                match self.flavour {
                    Flavour::LinuxCnc => {
                        if n == 0 || (5420..=5428).contains(&n) || n == 5400 || n == 5220 {
                            return fail(at, 1, format!("parameter #{n} is read-only"));
                        }
                        self.params[n] = v;
                    }
                    Flavour::Fanuc => {
                        if n == 0 || n >= 1000 {
                            return fail(
                                at,
                                1,
                                format!("#{n} cannot be set (vacant #0 or a system variable)"),
                            );
                        }
                        self.params[n] = v;
                    }
                }
            }
            Param::Named(name) => {
                if self.predefined(name).is_some() {
                    return fail(at, 1, format!("#<{name}> is read-only"));
                }
                if name.starts_with('_') {
                    self.globals.insert(name.clone(), v);
                } else {
                    self.named.insert(name.clone(), v);
                }
            }
        }
        Ok(())
    }
}

/// The end of a unary function call `NAME[…]` starting at `i`.
fn find_call_end(b: &[u8], i: usize) -> usize {
    let mut depth = 0usize;
    let mut k = i;
    while k < b.len() {
        match b[k] {
            b'[' => depth += 1,
            b']' => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    // `ATAN[..]/[..]`
                    if b.get(k + 1) == Some(&b'/') && b.get(k + 2) == Some(&b'[') {
                        k += 2;
                        continue;
                    }
                    return k + 1;
                }
            }
            _ => {}
        }
        k += 1;
    }
    b.len()
}

/// `G43.4` → 434; `None` for more than one decimal or a negative code.
fn g_code(v: f64) -> Option<u16> {
    let t = (v * 10.0).round();
    if !(0.0..10000.0).contains(&t) || (v * 10.0 - t).abs() > 1e-6 {
        return None;
    }
    Some(t as u16)
}

impl Operands for Interp<'_, '_> {
    fn operand(&mut self, c: &mut Cursor<'_>, _lang: Lang) -> Result<Option<f64>, Fail> {
        c.skip_ws();
        if c.peek() != Some(b'#') {
            // LinuxCNC EXISTS[#<name>].
            if self.flavour == Flavour::LinuxCnc {
                let save = c.i;
                if c.eat_kw("EXISTS", false) && c.eat(b'[') {
                    c.skip_ws();
                    let at = c.i;
                    let p = self.param_ref(c)?;
                    if !c.eat(b']') {
                        return fail(c.i, 1, "`]` expected");
                    }
                    let exists = match &p {
                        Param::Named(n) => {
                            self.named.contains_key(n)
                                || self.globals.contains_key(n)
                                || self.predefined(n).is_some()
                        }
                        Param::Numbered(_) => true,
                    };
                    let _ = at;
                    return Ok(Some(f64::from(u8::from(exists))));
                }
                c.i = save;
            }
            return Ok(None);
        }
        let start = c.i;
        let p = self.param_ref(c)?;
        self.get_param(&p, start).map(Some)
    }
}

mod exec;
mod fast;
mod flow;
mod motion;
