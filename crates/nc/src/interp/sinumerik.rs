//! Siemens Sinumerik 840D (Siemens mode, not ISO dialect).
//!
//! Rules followed: SINUMERIK 840D sl programming manuals "Fundamentals"
//! (6FC5398-1BP40) — addresses and `=` expressions, absolute/incremental
//! words `AC`/`IC`, rotary positioning `DC`/`ACP`/`ACN`, G-code groups,
//! `CIP`, `CT`, `CR=`, `TURN=`, `G4 F`/`G4 S`, `TRANS`/`ATRANS` — and "Job
//! planning" (6FC5398-2BP40) — R parameters, `DEF` variables, operators
//! and their priority, `IF`/`ELSE`/`ENDIF`, `WHILE`, `FOR`, `REPEAT`,
//! `LOOP`, `GOTOF`/`GOTOB`/`GOTO`/`GOTOC`, labels, `MSG`, `MCALL`; drilling
//! cycles from "Cycles" (6FC5398-3BP40): `CYCLE81`..`CYCLE86`.

use std::collections::HashMap;

use kinpost_diag::Diagnostic;

use super::arc::{self, Centre};
use super::cycle::{self, Hole, Op};
use super::expr::{self, Cursor, Lang, Operands, Upper};
use super::machine::{MM_PER_INCH, Machine, RotaryMode, wrap};
use super::num::{read_number, read_uint};
use super::source::{Fail, Line, Pos, Source, diagnostic, fail};
use super::{
    ArcPlane, CutterComp, CycleRef, Event, FeedMode, MAX_AXES, MotionKind, Options, Report, Sink,
    SpindleDir, StopKind, WorkOffset,
};
use crate::AxisSpec;

mod block;
mod fast;
mod flow;

/// R parameters R0..R999.
const R_PARAMS: usize = 1000;

/// A `DEF` variable.
#[derive(Debug, Clone, PartialEq)]
enum Var {
    Real(f64),
    Int(f64),
    Bool(f64),
    Str(String),
}

/// How an axis word is given.
#[derive(Debug, Clone, Copy, PartialEq)]
enum AxisMode {
    /// Plain value: G90/G91 decide.
    Plain,
    Ac,
    Ic,
    Dc,
    Acp,
    Acn,
}

/// Motion of group 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Motion {
    Rapid,
    Linear,
    Cw,
    Ccw,
    /// Circle through an intermediate point.
    Cip,
    /// Tangential circle.
    Ct,
}

/// A structured loop in progress.
#[derive(Debug, Clone, PartialEq)]
enum Frame {
    /// The WHILE line.
    While(Pos),
    For {
        var: String,
        end: f64,
        body: Pos,
        open: Pos,
    },
    /// Body and the REPEAT line.
    Repeat(Pos, Pos),
    /// Body and the LOOP line.
    Loop(Pos, Pos),
}

/// A modal drilling cycle (`MCALL CYCLE8x(...)`).
#[derive(Debug, Clone, PartialEq)]
struct CycleCall {
    code: u16,
    args: Vec<Option<f64>>,
    line: usize,
}

struct Interp<'a, 's> {
    file: &'a str,
    src: Source<'a>,
    m: Machine<'s>,
    r: Vec<f64>,
    vars: HashMap<String, Var>,
    motion: Motion,
    motion_set: bool,
    incremental: bool,
    frames: Vec<Frame>,
    mcall: Option<CycleCall>,
    selected_tool: Option<u32>,
    ended: bool,
    warned_axis: Vec<String>,
    /// Direction of the path at the end of the last move (for CT), X Y Z.
    tangent: Option<super::arc::LastElement>,
    /// Where the current line starts.
    current: Pos,
    /// The machine axis of each one-letter axis name A..Z (not the pressure
    /// word), for the hot path.
    letter_axis: [Option<usize>; 26],
}

/// Runs a Sinumerik program.
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
        r: vec![0.0; R_PARAMS],
        vars: HashMap::new(),
        motion: Motion::Rapid,
        motion_set: false,
        incremental: false,
        frames: Vec::new(),
        mcall: None,
        selected_tool: None,
        ended: false,
        warned_axis: Vec::new(),
        tangent: None,
        current: Pos { offset: 0, line: 1 },
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
        it.current = line.pos;
        it.m.at_line(line.no, None);
        if let Err(f) = it.line(&line) {
            return Err(diagnostic(file, &line, f, false));
        }
    }
    if let Some(f) = it.frames.last() {
        let (open, what) = match f {
            Frame::While(p) => (*p, "WHILE without its ENDWHILE"),
            Frame::For { open, .. } => (*open, "FOR without its ENDFOR"),
            Frame::Repeat(_, p) => (*p, "REPEAT without its UNTIL"),
            Frame::Loop(_, p) => (*p, "LOOP without its ENDLOOP"),
        };
        if !it.ended
            && let Some(line) = it.src.line_at(open)
        {
            return Err(diagnostic(
                file,
                &line,
                Fail {
                    at: 0,
                    len: line.text.len(),
                    message: format!("the program ends inside a loop: {what}"),
                },
                false,
            ));
        }
    }
    Ok(std::mem::take(&mut it.m.report))
}

/// Strips `N123` / `:123` and a label `NAME:` from the start of a line:
/// the block number, the label and where the statements start.
fn line_head(b: &[u8]) -> (Option<u64>, Option<(usize, usize)>, usize) {
    let mut c = Cursor::new(b, 0);
    c.skip_ws();
    if c.peek() == Some(b'/') {
        c.i += 1;
        c.skip_ws();
    }
    let mut number = None;
    if matches!(c.peek(), Some(b'N' | b'n' | b':'))
        && c.peek_at(1).is_some_and(|d| d.is_ascii_digit())
    {
        if let Some((n, len)) = read_uint(&b[c.i + 1..]) {
            number = Some(n);
            c.i += 1 + len;
        }
        c.skip_ws();
    }
    // A label: an identifier and `:`.
    let mut label = None;
    let start = c.i;
    if b.get(start)
        .is_some_and(|x| x.is_ascii_alphabetic() || *x == b'_')
    {
        let end = b[start..]
            .iter()
            .position(|x| !(x.is_ascii_alphanumeric() || *x == b'_'))
            .map_or(b.len(), |k| start + k);
        let mut d = Cursor::new(b, end);
        d.skip_ws();
        if d.peek() == Some(b':') && d.peek_at(1) != Some(b'=') {
            label = Some((start, end));
            c.i = d.i + 1;
        }
    }
    (number, label, c.i)
}

impl<'a> Interp<'a, '_> {
    fn line(&mut self, line: &Line<'a>) -> Result<(), Fail> {
        let b = line.text.as_bytes();
        let mut c = Cursor::new(b, 0);
        c.skip_ws();
        if c.at_end() || c.peek() == Some(b';') {
            return Ok(());
        }
        if c.peek() == Some(b'%') {
            return Ok(());
        }
        self.m.count_block()?;
        if c.peek() == Some(b'/') && self.m.options.block_delete {
            return Ok(());
        }
        let (number, _label, start) = line_head(b);
        self.m.at_line(line.no, number);
        let mut c = Cursor::new(b, start);
        c.skip_ws();
        if c.at_end() || c.peek() == Some(b';') {
            return Ok(());
        }
        if self.fast_line(c.b, c.i) {
            return Ok(());
        }
        if self.statement(line, &mut c)? {
            return Ok(());
        }
        self.block(line, c)
    }
}

impl Operands for Interp<'_, '_> {
    fn operand(&mut self, c: &mut Cursor<'_>, _lang: Lang) -> Result<Option<f64>, Fail> {
        c.skip_ws();
        let start = c.i;
        let Some(ch) = c.peek() else {
            return Ok(None);
        };
        if ch == b'$' {
            let name = self.system_var_name(c)?;
            return self.system_var(&name, start).map(Some);
        }
        if !(ch.is_ascii_alphabetic() || ch == b'_') {
            return Ok(None);
        }
        // R parameters: R5, R[expr].
        if (ch == b'R' || ch == b'r')
            && c.peek_at(1)
                .is_some_and(|d| d.is_ascii_digit() || d == b'[')
        {
            let save = c.i;
            c.i += 1;
            if c.peek() == Some(b'[') {
                c.i += 1;
                let v = expr::eval(c, Lang::Sinumerik, self)?;
                if !c.eat(b']') {
                    return fail(c.i, 1, "`]` expected");
                }
                let k = self.r_index(v, start, c.i - start)?;
                return Ok(Some(self.r[k]));
            }
            let (n, len) = read_uint(&c.b[c.i..]).unwrap_or((0, 0));
            let next = c.b.get(c.i + len).copied();
            if !next.is_some_and(|d| d.is_ascii_alphanumeric() || d == b'_') {
                c.i += len;
                let k = self.r_index(n as f64, start, c.i - start)?;
                return Ok(Some(self.r[k]));
            }
            c.i = save;
        }
        let save = c.i;
        let Some(id) = c.ident() else {
            return Ok(None);
        };
        let key = id.to_ascii_uppercase();
        let key = if c.peek() == Some(b'[') {
            let Some(k) = self.array_key(&key, c)? else {
                c.i = save;
                return Ok(None);
            };
            k
        } else {
            key
        };
        match self.vars.get(&key) {
            Some(Var::Real(v) | Var::Int(v) | Var::Bool(v)) => Ok(Some(*v)),
            Some(Var::Str(_)) => fail(
                start,
                c.i - start,
                format!("{key} is a STRING, not a number"),
            ),
            // An array element not yet set.
            None if key.contains('[') => Ok(Some(0.0)),
            None => {
                c.i = save;
                Ok(None)
            }
        }
    }
}

impl Interp<'_, '_> {
    fn r_index(&self, v: f64, at: usize, len: usize) -> Result<usize, Fail> {
        if v >= 0.0 && v < R_PARAMS as f64 && v.fract() == 0.0 {
            Ok(v as usize)
        } else {
            fail(
                at,
                len,
                format!("R{v} is not an R parameter (R0..R{})", R_PARAMS - 1),
            )
        }
    }

    /// `NAME[i, j]` for a DEF array: its element key, `None` when `NAME` is
    /// not an array.
    fn array_key(&mut self, name: &str, c: &mut Cursor<'_>) -> Result<Option<String>, Fail> {
        if !self.vars.contains_key(&format!("{name}[]")) {
            return Ok(None);
        }
        c.i += 1;
        let mut key = format!("{name}[");
        loop {
            let v = expr::eval(c, Lang::Sinumerik, self)?;
            key.push_str(&format!("{}", v as i64));
            if c.eat(b',') {
                key.push(',');
                continue;
            }
            if !c.eat(b']') {
                return fail(c.i, 1, "`]` expected");
            }
            key.push(']');
            return Ok(Some(key));
        }
    }

    /// `$A_IN[5]`, `$AA_IW[X]`: the name with its index evaluated.
    fn system_var_name(&mut self, c: &mut Cursor<'_>) -> Result<String, Fail> {
        c.i += 1;
        let mut name = String::from("$");
        name.push_str(&c.ident().unwrap_or("").to_ascii_uppercase());
        if c.peek() == Some(b'[') {
            c.i += 1;
            name.push('[');
            loop {
                c.skip_ws();
                let save = c.i;
                // An axis name as index, else an expression.
                let ident = c.ident().map(str::to_ascii_uppercase);
                match ident {
                    Some(id)
                        if self.m.axis(&id).is_some() && matches!(c.peek(), Some(b']' | b',')) =>
                    {
                        name.push_str(&id)
                    }
                    _ => {
                        c.i = save;
                        let v = expr::eval(c, Lang::Sinumerik, self)?;
                        name.push_str(&format!("{}", v as i64));
                    }
                }
                if c.eat(b',') {
                    name.push(',');
                    continue;
                }
                if !c.eat(b']') {
                    return fail(c.i, 1, "`]` expected");
                }
                name.push(']');
                break;
            }
        }
        Ok(name)
    }

    /// A system variable: from the options; machine inputs read 0 (said);
    /// anything else not given is an error.
    fn system_var(&mut self, name: &str, at: usize) -> Result<f64, Fail> {
        let key = super::normalize_input(name);
        if self.m.options.inputs.contains_key(&key)
            || key.starts_with("$A_IN[")
            || key.starts_with("$A_INA[")
        {
            return Ok(self.m.input(&key));
        }
        if let Some(axis) = key
            .strip_prefix("$AA_IW[")
            .and_then(|r| r.strip_suffix(']'))
            && let Some(i) = self.m.axis(axis)
        {
            return Ok(self.m.pos[i]);
        }
        fail(
            at,
            name.len(),
            format!(
                "system variable {name} is not modelled: give its value with --input '{key}=VALUE'"
            ),
        )
    }

    fn eval(&mut self, c: &mut Cursor<'_>) -> Result<f64, Fail> {
        expr::eval(c, Lang::Sinumerik, self)
    }

    /// A string expression: `"text" << R1 << "…"` (MSG, STRING variables).
    fn string_expr(&mut self, c: &mut Cursor<'_>) -> Result<String, Fail> {
        let mut out = String::new();
        loop {
            c.skip_ws();
            if c.peek() == Some(b'"') {
                let start = c.i + 1;
                let Some(len) = c.b[start..].iter().position(|&x| x == b'"') else {
                    return fail(c.i, c.b.len() - c.i, "string without its closing `\"`");
                };
                out.push_str(&String::from_utf8_lossy(&c.b[start..start + len]));
                c.i = start + len + 1;
            } else {
                let save = c.i;
                let id = c.ident().map(str::to_ascii_uppercase);
                match id.and_then(|k| match self.vars.get(&k) {
                    Some(Var::Str(s)) => Some(s.clone()),
                    _ => None,
                }) {
                    Some(s) => out.push_str(&s),
                    None => {
                        c.i = save;
                        let v = self.eval(c)?;
                        out.push_str(&show_number(v));
                    }
                }
            }
            c.skip_ws();
            if c.b[c.i..].starts_with(b"<<") {
                c.i += 2;
                continue;
            }
            return Ok(out);
        }
    }
}

/// A number as Sinumerik shows it in a string: no trailing zeros.
fn show_number(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.to_string() }
}
