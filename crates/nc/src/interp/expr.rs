//! Expressions of the four languages, evaluated as they are parsed (no
//! tree, no allocation): numbers, operands of the family (parameters,
//! variables), brackets, unary functions and binary operators with each
//! language's precedence. Angles are degrees.
//!
//! Precedence, highest first:
//! - rs274ngc (LinuxCNC manual, "Expressions"): `**`; `* / MOD`; `+ -`;
//!   `EQ NE GT GE LT LE`; `AND OR XOR`.
//! - Fanuc custom macro B (Fanuc 0i-MF operator's manual, "Arithmetic and
//!   logic operation"): functions; `* / AND MOD`; `+ - OR XOR`; comparisons
//!   only in conditions (`EQ NE GT GE LT LE`, lowest here). `AND OR XOR`
//!   work bit by bit on integers.
//! - Sinumerik (840D sl programming manual, Job planning, "Priority of
//!   operators"): `NOT`; `* / DIV MOD`; `+ -`; `B_AND`; `B_XOR`; `B_OR`;
//!   `AND`; `XOR`; `OR`; `<<`; `== <> > < >= <=` (lowest).
//! - Heidenhain Q formulas (TNC 640 user's manual, "Entering formulas
//!   directly"): `^`; `* /`; `+ -`.

use super::source::{Fail, fail};

/// The language of an expression.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Lang {
    LinuxCnc,
    Fanuc,
    Sinumerik,
    Heidenhain,
}

/// Fanuc's vacant value (`#0`): a NaN with a payload of its own.
pub(crate) const VACANT: f64 = f64::from_bits(0x7ff8_0000_dead_beef);

/// Whether `v` is the vacant value.
#[inline]
pub(crate) fn is_vacant(v: f64) -> bool {
    v.to_bits() == VACANT.to_bits()
}

/// A byte cursor over one line.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cursor<'a> {
    pub b: &'a [u8],
    pub i: usize,
}

impl<'a> Cursor<'a> {
    pub fn new(b: &'a [u8], i: usize) -> Cursor<'a> {
        Cursor { b, i }
    }

    #[inline]
    pub fn skip_ws(&mut self) {
        while self.i < self.b.len() && (self.b[self.i] == b' ' || self.b[self.i] == b'\t') {
            self.i += 1;
        }
    }

    #[inline]
    pub fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    #[inline]
    pub fn peek_at(&self, k: usize) -> Option<u8> {
        self.b.get(self.i + k).copied()
    }

    pub fn at_end(&self) -> bool {
        self.i >= self.b.len()
    }

    /// Eats `c` after blanks.
    pub fn eat(&mut self, c: u8) -> bool {
        self.skip_ws();
        if self.peek() == Some(c) {
            self.i += 1;
            true
        } else {
            false
        }
    }

    /// Eats `s` (ASCII, any case) after blanks; `word` asks that no letter,
    /// digit or `_` follows.
    pub fn eat_kw(&mut self, s: &str, word: bool) -> bool {
        self.skip_ws();
        let n = s.len();
        if self.i + n > self.b.len()
            || !self.b[self.i..self.i + n].eq_ignore_ascii_case(s.as_bytes())
        {
            return false;
        }
        if word
            && self
                .b
                .get(self.i + n)
                .is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_')
        {
            return false;
        }
        self.i += n;
        true
    }

    /// An identifier (letters, digits, `_`, starting with a letter or `_`).
    pub fn ident(&mut self) -> Option<&'a str> {
        self.skip_ws();
        let s = self.i;
        let first = self.peek()?;
        if !(first.is_ascii_alphabetic() || first == b'_') {
            return None;
        }
        while self.i < self.b.len()
            && (self.b[self.i].is_ascii_alphanumeric() || self.b[self.i] == b'_')
        {
            self.i += 1;
        }
        std::str::from_utf8(&self.b[s..self.i]).ok()
    }
}

/// An identifier in upper case, on the stack when it is short (the hot
/// path reads one per word: no allocation).
pub(crate) struct Upper {
    buf: [u8; 24],
    len: usize,
    long: Option<String>,
}

impl Upper {
    pub fn of(s: &str) -> Upper {
        let mut u = Upper {
            buf: [0; 24],
            len: s.len(),
            long: None,
        };
        if s.len() <= u.buf.len() && s.is_ascii() {
            for (d, b) in u.buf.iter_mut().zip(s.bytes()) {
                *d = b.to_ascii_uppercase();
            }
        } else {
            u.long = Some(s.to_ascii_uppercase());
        }
        u
    }
}

impl std::ops::Deref for Upper {
    type Target = str;
    fn deref(&self) -> &str {
        match &self.long {
            Some(s) => s,
            // Upper-cased ASCII is ASCII.
            None => std::str::from_utf8(&self.buf[..self.len]).unwrap_or(""),
        }
    }
}

impl std::fmt::Display for Upper {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self)
    }
}

/// The operands of a family: parameters and variables.
pub(crate) trait Operands {
    /// Reads an operand at the cursor (after blanks) if the text there is
    /// one of this family's (a parameter, a variable); `Ok(None)` leaves the
    /// cursor where it was.
    fn operand(&mut self, c: &mut Cursor<'_>, lang: Lang) -> Result<Option<f64>, Fail>;
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Pow,
    Mul,
    Div,
    Mod,
    IntDiv,
    Add,
    Sub,
    Eq,
    Ne,
    Gt,
    Ge,
    Lt,
    Le,
    And,
    Or,
    Xor,
    BAnd,
    BOr,
    BXor,
}

/// Evaluates a whole expression at the cursor.
pub(crate) fn eval(c: &mut Cursor<'_>, lang: Lang, ops: &mut dyn Operands) -> Result<f64, Fail> {
    binary(c, lang, ops, 0, 0)
}

/// Depth guard: nested brackets deeper than this are refused (a stack
/// overflow is not an error message).
const MAX_DEPTH: usize = 200;

fn binary(
    c: &mut Cursor<'_>,
    lang: Lang,
    ops: &mut dyn Operands,
    min: u8,
    depth: usize,
) -> Result<f64, Fail> {
    if depth > MAX_DEPTH {
        return fail(c.i, 1, format!("expression nested deeper than {MAX_DEPTH}"));
    }
    let mut left = unary(c, lang, ops, depth)?;
    loop {
        let save = c.i;
        let Some(op) = operator(c, lang) else {
            return Ok(left);
        };
        let p = precedence(op, lang);
        if p < min {
            c.i = save;
            return Ok(left);
        }
        let op_at = save;
        // All left-associative except the power.
        let next = if op == Op::Pow { p } else { p + 1 };
        let right = binary(c, lang, ops, next, depth + 1)?;
        left = apply(op, left, right, lang).map_err(|m| Fail {
            at: op_at,
            len: c.i.saturating_sub(op_at).max(1),
            message: m,
        })?;
    }
}

fn operator(c: &mut Cursor<'_>, lang: Lang) -> Option<Op> {
    c.skip_ws();
    let two = |c: &mut Cursor<'_>, s: &[u8]| {
        if c.b[c.i..].starts_with(s) {
            c.i += s.len();
            true
        } else {
            false
        }
    };
    let ch = c.peek()?;
    match lang {
        Lang::LinuxCnc | Lang::Fanuc => {
            if two(c, b"**") {
                return Some(Op::Pow);
            }
            if let Some(op) = arithmetic(ch) {
                c.i += 1;
                return Some(op);
            }
            for (kw, op) in [
                ("MOD", Op::Mod),
                ("EQ", Op::Eq),
                ("NE", Op::Ne),
                ("GT", Op::Gt),
                ("GE", Op::Ge),
                ("LT", Op::Lt),
                ("LE", Op::Le),
                ("AND", Op::And),
                ("OR", Op::Or),
                ("XOR", Op::Xor),
            ] {
                // rs274 words may run together with what follows (`1EQ2`).
                if c.eat_kw(kw, false) {
                    return Some(op);
                }
            }
            None
        }
        Lang::Sinumerik => {
            for (s, op) in [
                (&b"=="[..], Op::Eq),
                (b"<>", Op::Ne),
                (b">=", Op::Ge),
                (b"<=", Op::Le),
            ] {
                if two(c, s) {
                    return Some(op);
                }
            }
            if c.b[c.i..].starts_with(b"<<") {
                return None;
            }
            let single = match ch {
                b'>' => Some(Op::Gt),
                b'<' => Some(Op::Lt),
                _ => arithmetic(ch),
            };
            if let Some(op) = single {
                c.i += 1;
                return Some(op);
            }
            for (kw, op) in [
                ("DIV", Op::IntDiv),
                ("MOD", Op::Mod),
                ("B_AND", Op::BAnd),
                ("B_OR", Op::BOr),
                ("B_XOR", Op::BXor),
                ("AND", Op::And),
                ("OR", Op::Or),
                ("XOR", Op::Xor),
            ] {
                if c.eat_kw(kw, true) {
                    return Some(op);
                }
            }
            None
        }
        Lang::Heidenhain => {
            let op = match ch {
                b'^' => Op::Pow,
                _ => arithmetic(ch)?,
            };
            c.i += 1;
            Some(op)
        }
    }
}

/// The one-character arithmetic operators every language writes alike.
fn arithmetic(ch: u8) -> Option<Op> {
    match ch {
        b'*' => Some(Op::Mul),
        b'/' => Some(Op::Div),
        b'+' => Some(Op::Add),
        b'-' => Some(Op::Sub),
        _ => None,
    }
}

fn precedence(op: Op, lang: Lang) -> u8 {
    use Op::*;
    match lang {
        Lang::LinuxCnc => match op {
            Pow => 5,
            Mul | Div | Mod | IntDiv => 4,
            Add | Sub => 3,
            Eq | Ne | Gt | Ge | Lt | Le => 2,
            _ => 1,
        },
        Lang::Fanuc => match op {
            Pow => 5,
            Mul | Div | Mod | IntDiv | And | BAnd => 4,
            Add | Sub | Or | Xor | BOr | BXor => 3,
            Eq | Ne | Gt | Ge | Lt | Le => 2,
        },
        Lang::Sinumerik => match op {
            Pow => 12,
            Mul | Div | Mod | IntDiv => 11,
            Add | Sub => 10,
            BAnd => 9,
            BXor => 8,
            BOr => 7,
            And => 6,
            Xor => 5,
            Or => 4,
            Eq | Ne | Gt | Ge | Lt | Le => 2,
        },
        Lang::Heidenhain => match op {
            Pow => 5,
            Mul | Div => 4,
            _ => 3,
        },
    }
}

fn truth(v: f64) -> bool {
    v != 0.0 && !is_vacant(v)
}

fn int_of(v: f64, what: &str) -> Result<i64, String> {
    if v.is_finite() && v.abs() < 9.0e15 {
        Ok(v.round() as i64)
    } else {
        Err(format!("{what}: {v} is not an integer"))
    }
}

fn apply(op: Op, a: f64, b: f64, lang: Lang) -> Result<f64, String> {
    use Op::*;
    // Vacant compares as itself, and counts as 0 in arithmetic (Fanuc).
    if matches!(op, Eq | Ne) && (is_vacant(a) || is_vacant(b)) {
        let same = is_vacant(a) == is_vacant(b) && (is_vacant(a) || a == b);
        return Ok(f64::from(u8::from(same == (op == Eq))));
    }
    let a = if is_vacant(a) { 0.0 } else { a };
    let b = if is_vacant(b) { 0.0 } else { b };
    let bool_of = |x: bool| f64::from(u8::from(x));
    let v = match op {
        Pow => a.powf(b),
        Mul => a * b,
        Div => {
            if b == 0.0 {
                return Err("division by zero".into());
            }
            a / b
        }
        Mod => {
            if b == 0.0 {
                return Err("MOD by zero".into());
            }
            // rs274ngc and Fanuc: the result has the sign of the divisor
            // side as fmod does; LinuxCNC makes it non-negative.
            if lang == Lang::LinuxCnc {
                a.rem_euclid(b.abs())
            } else {
                a % b
            }
        }
        IntDiv => {
            if b == 0.0 {
                return Err("DIV by zero".into());
            }
            (a / b).trunc()
        }
        Add => a + b,
        Sub => a - b,
        Eq => bool_of(eq_tol(a, b, lang)),
        Ne => bool_of(!eq_tol(a, b, lang)),
        Gt => bool_of(a > b),
        Ge => bool_of(a >= b),
        Lt => bool_of(a < b),
        Le => bool_of(a <= b),
        And | Or | Xor if lang == Lang::Fanuc => {
            let (x, y) = (int_of(a, "AND/OR/XOR")?, int_of(b, "AND/OR/XOR")?);
            (match op {
                And => x & y,
                Or => x | y,
                _ => x ^ y,
            }) as f64
        }
        And => bool_of(truth(a) && truth(b)),
        Or => bool_of(truth(a) || truth(b)),
        Xor => bool_of(truth(a) != truth(b)),
        BAnd | BOr | BXor => {
            let (x, y) = (
                int_of(a, "B_AND/B_OR/B_XOR")?,
                int_of(b, "B_AND/B_OR/B_XOR")?,
            );
            (match op {
                BAnd => x & y,
                BOr => x | y,
                _ => x ^ y,
            }) as f64
        }
    };
    if v.is_nan() {
        return Err(format!("the result of {a} and {b} is not a number"));
    }
    Ok(v)
}

/// rs274ngc compares with a tolerance of 1e-6 (`TOLERANCE_EQUAL`); the
/// others exactly.
fn eq_tol(a: f64, b: f64, lang: Lang) -> bool {
    if lang == Lang::LinuxCnc {
        (a - b).abs() < 1e-6
    } else {
        a == b
    }
}

fn open_bracket(lang: Lang) -> u8 {
    match lang {
        Lang::LinuxCnc | Lang::Fanuc => b'[',
        _ => b'(',
    }
}

fn close_bracket(lang: Lang) -> u8 {
    match lang {
        Lang::LinuxCnc | Lang::Fanuc => b']',
        _ => b')',
    }
}

fn unary(
    c: &mut Cursor<'_>,
    lang: Lang,
    ops: &mut dyn Operands,
    depth: usize,
) -> Result<f64, Fail> {
    c.skip_ws();
    let start = c.i;
    let Some(ch) = c.peek() else {
        return fail(c.i, 1, "expression expected");
    };
    if ch == b'-' || ch == b'+' {
        c.i += 1;
        let v = unary(c, lang, ops, depth + 1)?;
        return Ok(if ch == b'-' {
            if is_vacant(v) { -0.0 } else { -v }
        } else {
            v
        });
    }
    if lang == Lang::Sinumerik {
        let bitwise = c.eat_kw("B_NOT", true);
        if bitwise || c.eat_kw("NOT", true) {
            let v = unary(c, lang, ops, depth + 1)?;
            if bitwise {
                let n = int_of(v, "B_NOT").map_err(|m| Fail {
                    at: start,
                    len: 5,
                    message: m,
                })?;
                return Ok(!n as f64);
            }
            return Ok(f64::from(u8::from(!truth(v))));
        }
    }
    if ch == open_bracket(lang) {
        c.i += 1;
        let v = binary(c, lang, ops, 0, depth + 1)?;
        if !c.eat(close_bracket(lang)) {
            return fail(
                c.i,
                1,
                format!("`{}` expected", close_bracket(lang) as char),
            );
        }
        return Ok(v);
    }
    if ch.is_ascii_digit() || ch == b'.' {
        let Some(n) = super::num::read_number(&c.b[c.i..]) else {
            return fail(c.i, 1, "number expected");
        };
        c.i += n.len;
        return Ok(n.value);
    }
    if let Some(v) = ops.operand(c, lang)? {
        return Ok(v);
    }
    if let Some(v) = function(c, lang, ops, depth)? {
        return Ok(v);
    }
    let end = (c.i + 1..=c.b.len())
        .find(|&e| e == c.b.len() || !c.b[e].is_ascii_alphanumeric())
        .unwrap_or(c.b.len());
    fail(
        start,
        end - start,
        format!(
            "`{}` is not a number, parameter or function",
            String::from_utf8_lossy(&c.b[start..end])
        ),
    )
}

/// A function call, or `None` when the text is not a function name.
fn function(
    c: &mut Cursor<'_>,
    lang: Lang,
    ops: &mut dyn Operands,
    depth: usize,
) -> Result<Option<f64>, Fail> {
    let save = c.i;
    let Some(name) = c.ident() else {
        return Ok(None);
    };
    let name = name.to_ascii_uppercase();
    let at = save;
    if lang == Lang::Heidenhain && name == "PI" {
        return Ok(Some(std::f64::consts::PI));
    }
    if lang == Lang::Sinumerik && (name == "TRUE" || name == "FALSE") {
        return Ok(Some(f64::from(u8::from(name == "TRUE"))));
    }
    if !c.eat(open_bracket(lang)) {
        c.i = save;
        return Ok(None);
    }
    let x = binary(c, lang, ops, 0, depth + 1)?;
    let mut second = None;
    if c.eat(b',') {
        second = Some(binary(c, lang, ops, 0, depth + 1)?);
    }
    if !c.eat(close_bracket(lang)) {
        return fail(
            c.i,
            1,
            format!("`{}` expected", close_bracket(lang) as char),
        );
    }
    // rs274: ATAN[y]/[x].
    if name == "ATAN" && second.is_none() && matches!(lang, Lang::LinuxCnc | Lang::Fanuc) {
        let save2 = c.i;
        if c.eat(b'/') && {
            c.skip_ws();
            c.peek() == Some(b'[')
        } {
            c.i += 1;
            second = Some(binary(c, lang, ops, 0, depth + 1)?);
            if !c.eat(b']') {
                return fail(c.i, 1, "`]` expected");
            }
        } else {
            c.i = save2;
        }
    }
    let x0 = if is_vacant(x) { 0.0 } else { x };
    let len = c.i - at;
    let bad = |m: String| Fail {
        at,
        len,
        message: m,
    };
    let v = match (name.as_str(), second) {
        ("SIN", None) => x0.to_radians().sin(),
        ("COS", None) => x0.to_radians().cos(),
        ("TAN", None) => x0.to_radians().tan(),
        ("ASIN", None) => x0.asin().to_degrees(),
        ("ACOS", None) => x0.acos().to_degrees(),
        ("ATAN", None) => x0.atan().to_degrees(),
        ("ATAN", Some(y)) | ("ATAN2", Some(y)) => x0.atan2(y).to_degrees(),
        ("SQRT", None) => x0.sqrt(),
        ("ABS", None) => x0.abs(),
        ("LN", None) => x0.ln(),
        ("EXP", None) => x0.exp(),
        ("ROUND", None) => x0.round(),
        ("FIX", None) if lang == Lang::LinuxCnc => x0.floor(),
        ("FIX", None) | ("TRUNC", None) | ("INT", None) => x0.trunc(),
        ("FUP", None) => {
            if lang == Lang::LinuxCnc {
                x0.ceil()
            } else {
                // Fanuc FUP rounds away from zero.
                x0.abs().ceil().copysign(x0)
            }
        }
        ("POT", None) | ("SQ", None) => x0 * x0,
        ("LOG", None) => x0.log10(),
        ("FRAC", None) => x0.fract(),
        ("SGN", None) => {
            if x0 > 0.0 {
                1.0
            } else if x0 < 0.0 {
                -1.0
            } else {
                0.0
            }
        }
        ("NEG", None) => -x0,
        ("MINVAL", Some(y)) => x0.min(y),
        ("MAXVAL", Some(y)) => x0.max(y),
        _ => {
            return Err(bad(format!(
                "unknown function `{name}` (or wrong number of arguments)"
            )));
        }
    };
    if v.is_nan() {
        return Err(bad(format!("{name} of {x0} is not a number")));
    }
    Ok(Some(v))
}
