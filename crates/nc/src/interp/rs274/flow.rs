//! Control flow: LinuxCNC O-codes (sub/call/return, if/elseif/else,
//! while, do-while, repeat, break/continue) and Fanuc custom macro
//! statements (GOTO, IF … GOTO / THEN, WHILE … DO m / END m, G65, M98/M99).

use super::exec::whole;
use super::*;

/// The O-word of a line (name and keyword), if it has one.
fn o_word_of(text: &str) -> Option<(String, String, usize)> {
    let b = text.as_bytes();
    let mut c = Cursor::new(b, 0);
    c.skip_ws();
    if c.peek() == Some(b'/') {
        c.i += 1;
        c.skip_ws();
    }
    if matches!(c.peek(), Some(b'N' | b'n')) && c.peek_at(1).is_some_and(|d| d.is_ascii_digit()) {
        c.i += 1;
        while c.peek().is_some_and(|d| d.is_ascii_digit()) {
            c.i += 1;
        }
        c.skip_ws();
    }
    if !matches!(c.peek(), Some(b'O' | b'o')) {
        return None;
    }
    c.i += 1;
    let name = o_name(&mut c)?;
    let kw = c.ident()?.to_ascii_lowercase();
    Some((name, kw, c.i))
}

/// `<name>` or digits after the `o`.
fn o_name(c: &mut Cursor<'_>) -> Option<String> {
    c.skip_ws();
    if c.peek() == Some(b'<') {
        let end = c.b[c.i..].iter().position(|&x| x == b'>')?;
        let name: String = String::from_utf8_lossy(&c.b[c.i + 1..c.i + end])
            .chars()
            .filter(|ch| !ch.is_whitespace())
            .flat_map(char::to_lowercase)
            .collect();
        c.i += end + 1;
        return Some(name);
    }
    let (n, len) = read_uint(&c.b[c.i..])?;
    c.i += len;
    Some(n.to_string())
}

impl Interp<'_, '_> {
    /// A line starting with an O-word.
    pub(super) fn o_word(&mut self, line: &Line<'_>, mut c: Cursor<'_>) -> Result<(), Fail> {
        if self.flavour == Flavour::Fanuc {
            // `O1234 (NAME)`: the start of a program; nothing to do.
            return Ok(());
        }
        let start = c.i;
        c.i += 1;
        let Some(name) = o_name(&mut c) else {
            return fail(start, 1, "O-word without a number or <name>");
        };
        let Some(kw) = c.ident().map(str::to_ascii_lowercase) else {
            return fail(
                start,
                c.i - start + 1,
                "O-word without a keyword (sub, call, if, while, …)",
            );
        };
        let kw_at = c.i - kw.len();
        let here = line.pos;
        let next = self.src.position();
        match kw.as_str() {
            "sub" => {
                self.subs.insert(name.clone(), next);
                let end = self.find_o(next, &name, &["endsub"], start)?;
                self.src.seek(end.1);
            }
            "endsub" | "return" => {
                let value = if kw == "return" && !c.at_end() && c.eat(b'[') {
                    c.i -= 1;
                    Some(self.expr(&mut c)?)
                } else {
                    None
                };
                self.sub_return(&name, value, start)?;
            }
            "call" => self.o_call(&name, &mut c, start)?,
            "if" => {
                let cond = self.condition(&mut c, kw_at)?;
                if !cond {
                    self.skip_to_branch(&name, next, start)?;
                }
            }
            "elseif" | "else" => {
                // The branch before ran: on to endif.
                let end = self.find_o(next, &name, &["endif"], start)?;
                self.src.seek(end.1);
            }
            "endif" => {}
            "do" => self.oframes.push(OFrame {
                name,
                kind: OKind::Do,
                start: next,
            }),
            "while" => self.o_while(&name, here, next, &mut c, kw_at, start)?,
            "endwhile" => {
                let Some(f) = self
                    .oframes
                    .iter()
                    .rev()
                    .find(|f| f.name == name && f.kind == OKind::While)
                else {
                    return fail(
                        start,
                        kw_at + 8 - start,
                        format!("o{name} endwhile without its while"),
                    );
                };
                let back = f.start;
                self.src.seek(back);
            }
            "repeat" => {
                let n = self.condition_value(&mut c, kw_at)?;
                if n >= 1.0 {
                    self.oframes.push(OFrame {
                        name,
                        kind: OKind::Repeat(n as u64 - 1),
                        start: next,
                    });
                } else {
                    let end = self.find_o(next, &name, &["endrepeat"], start)?;
                    self.src.seek(end.1);
                }
            }
            "endrepeat" => self.end_repeat(&name, start, kw_at)?,
            "break" => self.o_break(&name, next, start)?,
            "continue" => self.o_continue(&name, next, start)?,
            _ => return fail(kw_at, kw.len(), format!("unknown O-word keyword `{kw}`")),
        }
        Ok(())
    }

    /// A bracketed condition after a keyword.
    fn condition(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<bool, Fail> {
        Ok(self.condition_value(c, at)? != 0.0)
    }

    fn condition_value(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<f64, Fail> {
        c.skip_ws();
        if c.peek() != Some(b'[') {
            return fail(at, 1, "a condition in brackets `[…]` is expected");
        }
        let v = self.expr(c)?;
        Ok(if is_vacant(v) { 0.0 } else { v })
    }

    /// The next line from `from` with O-word `name` and one of `kws`:
    /// the keyword and the position after that line.
    fn find_o(
        &self,
        from: Pos,
        name: &str,
        kws: &[&str],
        at: usize,
    ) -> Result<(String, Pos, Pos), Fail> {
        let mut s = Source::new(self.src.text);
        s.seek(from);
        while let Some(l) = s.next_line() {
            if let Some((n, kw, _)) = o_word_of(l.text)
                && n == name
                && kws.contains(&kw.as_str())
            {
                return Ok((kw, s.position(), l.pos));
            }
        }
        fail(
            at,
            1 + name.len(),
            format!("o{name}: no matching {} follows", kws.join(" / ")),
        )
    }

    fn skip_to_branch(&mut self, name: &str, mut from: Pos, at: usize) -> Result<(), Fail> {
        loop {
            let (kw, after, line_pos) =
                self.find_o(from, name, &["elseif", "else", "endif"], at)?;
            match kw.as_str() {
                "elseif" => {
                    let Some(l) = self.src.line_at(line_pos) else {
                        return fail(at, 1, "elseif line vanished");
                    };
                    let Some((_, _, after_kw)) = o_word_of(l.text) else {
                        return fail(at, 1, "elseif line unreadable");
                    };
                    let mut c = Cursor::new(l.text.as_bytes(), after_kw);
                    self.m.at_line(l.no, None);
                    let cond = self.condition(&mut c, after_kw).map_err(|mut f| {
                        f.message = format!("line {}: {}", l.no, f.message);
                        f
                    })?;
                    if cond {
                        self.src.seek(after);
                        return Ok(());
                    }
                    from = after;
                }
                _ => {
                    self.src.seek(after);
                    return Ok(());
                }
            }
        }
    }

    fn o_while(
        &mut self,
        name: &str,
        here: Pos,
        next: Pos,
        c: &mut Cursor<'_>,
        kw_at: usize,
        start: usize,
    ) -> Result<(), Fail> {
        let cond = self.condition(c, kw_at)?;
        // The end of a do … while.
        if let Some(k) = self
            .oframes
            .iter()
            .rposition(|f| f.name == name && f.kind == OKind::Do)
        {
            if cond {
                let back = self.oframes[k].start;
                self.src.seek(back);
            } else {
                self.oframes.truncate(k);
            }
            return Ok(());
        }
        let on_top = self
            .oframes
            .last()
            .is_some_and(|f| f.name == name && f.kind == OKind::While);
        if cond {
            if !on_top {
                self.oframes.push(OFrame {
                    name: name.to_string(),
                    kind: OKind::While,
                    start: here,
                });
            }
        } else {
            if on_top {
                self.oframes.pop();
            }
            let end = self.find_o(next, name, &["endwhile"], start)?;
            self.src.seek(end.1);
        }
        Ok(())
    }

    fn end_repeat(&mut self, name: &str, start: usize, kw_at: usize) -> Result<(), Fail> {
        let Some(k) = self
            .oframes
            .iter()
            .rposition(|f| f.name == name && matches!(f.kind, OKind::Repeat(_)))
        else {
            return fail(
                start,
                kw_at + 9 - start,
                format!("o{name} endrepeat without its repeat"),
            );
        };
        if let OKind::Repeat(left) = self.oframes[k].kind {
            if left > 0 {
                self.oframes[k].kind = OKind::Repeat(left - 1);
                let back = self.oframes[k].start;
                self.src.seek(back);
            } else {
                self.oframes.truncate(k);
            }
        }
        Ok(())
    }

    fn o_break(&mut self, name: &str, next: Pos, start: usize) -> Result<(), Fail> {
        let Some(k) = self.oframes.iter().rposition(|f| f.name == name) else {
            return fail(start, 1, format!("o{name} break outside its loop"));
        };
        let kind = self.oframes[k].kind.clone();
        self.oframes.truncate(k);
        let end = match kind {
            OKind::While => self.find_o(next, name, &["endwhile"], start)?,
            OKind::Do => self.find_o(next, name, &["while"], start)?,
            OKind::Repeat(_) => self.find_o(next, name, &["endrepeat"], start)?,
        };
        self.src.seek(end.1);
        Ok(())
    }

    fn o_continue(&mut self, name: &str, next: Pos, start: usize) -> Result<(), Fail> {
        let Some(k) = self.oframes.iter().rposition(|f| f.name == name) else {
            return fail(start, 1, format!("o{name} continue outside its loop"));
        };
        match self.oframes[k].kind {
            OKind::While => {
                let back = self.oframes[k].start;
                self.oframes.truncate(k + 1);
                self.src.seek(back);
            }
            OKind::Do => {
                let end = self.find_o(next, name, &["while"], start)?;
                self.oframes.truncate(k + 1);
                self.src.seek(end.2);
            }
            OKind::Repeat(_) => {
                let end = self.find_o(next, name, &["endrepeat"], start)?;
                self.oframes.truncate(k + 1);
                self.src.seek(end.2);
            }
        }
        Ok(())
    }

    fn o_call(&mut self, name: &str, c: &mut Cursor<'_>, start: usize) -> Result<(), Fail> {
        let mut args = Vec::new();
        loop {
            c.skip_ws();
            if c.peek() != Some(b'[') {
                break;
            }
            args.push(self.expr(c)?);
            if args.len() > 30 {
                return fail(start, c.i - start, "more than 30 arguments");
            }
        }
        c.skip_ws();
        if !c.at_end() && c.peek() != Some(b'(') && c.peek() != Some(b';') {
            return fail(
                c.i,
                1,
                "call arguments must be bracketed: `o100 call [1] [2]`",
            );
        }
        let entry = match self.subs.get(name) {
            Some(p) => *p,
            None => {
                let found = self
                    .find_o(Pos { offset: 0, line: 1 }, name, &["sub"], start)
                    .map_err(|_| Fail {
                        at: start,
                        len: 1 + name.len(),
                        message: format!("o{name} call: no `o{name} sub` in this program (subroutine files are not searched)"),
                    })?;
                self.subs.insert(name.to_string(), found.1);
                found.1
            }
        };
        self.push_call(entry, 0, true, name.to_string(), start)?;
        for (k, v) in args.into_iter().enumerate() {
            self.params[k + 1] = v;
        }
        self.returned = None;
        Ok(())
    }

    /// Enters a subprogram at `entry`; `own_locals` saves the local
    /// parameters (restored on return).
    fn push_call(
        &mut self,
        entry: Pos,
        repeats: u64,
        own_locals: bool,
        name: String,
        at: usize,
    ) -> Result<(), Fail> {
        if self.calls.len() >= self.m.options.max_call_depth {
            return fail(
                at,
                1,
                format!(
                    "subprogram calls nested deeper than {} (Options::max_call_depth): endless recursion?",
                    self.m.options.max_call_depth
                ),
            );
        }
        let locals = match self.flavour {
            Flavour::LinuxCnc => 31,
            Flavour::Fanuc => FANUC_LOCALS,
        };
        let saved_locals = own_locals.then(|| {
            let saved = self.params[1..locals].to_vec();
            let fresh = if self.flavour == Flavour::Fanuc {
                VACANT
            } else {
                0.0
            };
            for p in &mut self.params[1..locals] {
                *p = fresh;
            }
            saved
        });
        let named = (own_locals && self.flavour == Flavour::LinuxCnc)
            .then(|| std::mem::take(&mut self.named));
        self.calls.push(Call {
            ret: self.src.position(),
            repeats,
            entry,
            saved_locals,
            named,
            loops: self.oframes.len(),
            name,
        });
        self.src.seek(entry);
        Ok(())
    }

    fn pop_call(&mut self) -> Option<Call> {
        let call = self.calls.pop()?;
        if let Some(saved) = &call.saved_locals {
            self.params[1..=saved.len()].copy_from_slice(saved);
        }
        if let Some(named) = call.named.clone() {
            self.named = named;
        }
        self.oframes.truncate(call.loops);
        self.src.seek(call.ret);
        Some(call)
    }

    fn sub_return(&mut self, name: &str, value: Option<f64>, at: usize) -> Result<(), Fail> {
        match self.calls.last() {
            Some(c) if c.name == name => {
                self.pop_call();
                self.returned = value;
                Ok(())
            }
            _ => fail(
                at,
                1 + name.len(),
                format!("o{name} endsub/return outside a call of o{name}"),
            ),
        }
    }

    // ----- Fanuc -------------------------------------------------------------

    /// Fanuc macro statements; `true` when the line was one.
    pub(super) fn fanuc_statement(
        &mut self,
        line: &Line<'_>,
        c: &mut Cursor<'_>,
    ) -> Result<bool, Fail> {
        let save = c.i;
        let start = c.i;
        if c.eat_kw("IF", false) && {
            c.skip_ws();
            c.peek() == Some(b'[')
        } {
            let cond = self.condition(c, start)?;
            if c.eat_kw("GOTO", false) {
                let n = self.goto_target(c, start)?;
                if cond {
                    self.goto(n, start)?;
                }
                return Ok(true);
            }
            if c.eat_kw("THEN", false) {
                if cond {
                    c.skip_ws();
                    if c.peek() != Some(b'#') {
                        return fail(c.i, 1, "IF … THEN takes an assignment `#1 = …`");
                    }
                    let at = c.i;
                    let p = self.param_ref(c)?;
                    if !c.eat(b'=') {
                        return fail(at, c.i - at, "`=` expected");
                    }
                    let v = self.expr(c)?;
                    self.set_param(&p, v, at)?;
                }
                return Ok(true);
            }
            return fail(c.i, 1, "IF […] must be followed by GOTO n or THEN");
        }
        c.i = save;
        if c.eat_kw("GOTO", false) {
            let n = self.goto_target(c, start)?;
            self.goto(n, start)?;
            return Ok(true);
        }
        c.i = save;
        if c.eat_kw("WHILE", false) && {
            c.skip_ws();
            c.peek() == Some(b'[')
        } {
            let cond = self.condition(c, start)?;
            if !c.eat_kw("DO", false) {
                return fail(c.i, 1, "WHILE […] must be followed by DO m");
            }
            let m = self.loop_id(c, start)?;
            let here = line.pos;
            let on_top = self.do_loops.last() == Some(&(m, here));
            if cond {
                if !on_top {
                    self.do_loops.push((m, here));
                }
            } else {
                if on_top {
                    self.do_loops.pop();
                }
                self.skip_past_end(m, start)?;
            }
            return Ok(true);
        }
        c.i = save;
        if c.eat_kw("DO", false) && c.peek().is_some_and(|d| d.is_ascii_digit() || d == b' ') {
            let m = self.loop_id(c, start)?;
            let here = line.pos;
            if self.do_loops.last() != Some(&(m, here)) {
                self.do_loops.push((m, here));
            }
            return Ok(true);
        }
        c.i = save;
        if c.eat_kw("END", false) && c.peek().is_some_and(|d| d.is_ascii_digit() || d == b' ') {
            let m = self.loop_id(c, start)?;
            match self.do_loops.last() {
                Some(&(top, pos)) if top == m => self.src.seek(pos),
                _ => return fail(start, c.i - start, format!("END {m} without its DO {m}")),
            }
            return Ok(true);
        }
        c.i = save;
        // G65 macro call: every word after it is an argument.
        let mut d = *c;
        if d.eat_kw("G65", false) && !d.peek().is_some_and(|x| x.is_ascii_digit() || x == b'.') {
            self.g65(&mut d, start)?;
            return Ok(true);
        }
        c.i = save;
        Ok(false)
    }

    fn loop_id(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<u8, Fail> {
        c.skip_ws();
        match read_uint(&c.b[c.i..]) {
            Some((m, len)) if (1..=3).contains(&m) => {
                c.i += len;
                Ok(m as u8)
            }
            _ => fail(at, c.i - at + 1, "DO / END take a loop number 1, 2 or 3"),
        }
    }

    fn goto_target(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<u64, Fail> {
        c.skip_ws();
        let v = if matches!(c.peek(), Some(b'#' | b'[')) {
            self.expr_operand(c)?
        } else {
            match read_number(&c.b[c.i..]) {
                Some(n) => {
                    c.i += n.len;
                    n.value
                }
                None => return fail(c.i, 1, "GOTO needs a sequence number"),
            }
        };
        if !(1.0..=99_999_999.0).contains(&v) {
            return fail(
                at,
                c.i - at,
                format!("GOTO {v}: sequence numbers are 1..99999999"),
            );
        }
        Ok(v.round() as u64)
    }

    /// Jumps to the line with sequence number `n`: forward first, then from
    /// the start of the file.
    fn goto(&mut self, n: u64, at: usize) -> Result<(), Fail> {
        let here = self.src.position();
        let found = find_n(self.src.text, here, None, n)
            .or_else(|| find_n(self.src.text, Pos { offset: 0, line: 1 }, Some(here), n));
        match found {
            Some(p) => {
                self.src.seek(p);
                Ok(())
            }
            None => fail(at, 4, format!("GOTO {n}: no block N{n} in the program")),
        }
    }

    /// After `END m` of a loop whose condition failed.
    fn skip_past_end(&mut self, m: u8, at: usize) -> Result<(), Fail> {
        let mut s = Source::new(self.src.text);
        s.seek(self.src.position());
        while let Some(l) = s.next_line() {
            let t = l.text.trim_start();
            let t = strip_n(t).trim_start();
            if t.as_bytes()
                .get(..3)
                .is_some_and(|p| p.eq_ignore_ascii_case(b"END"))
            {
                // The first three bytes are ASCII: a boundary.
                let rest = t[3..].trim_start();
                if rest.starts_with(char::from(b'0' + m)) {
                    self.src.seek(s.position());
                    return Ok(());
                }
            }
        }
        fail(at, 5, format!("WHILE … DO {m} without its END {m}"))
    }

    /// `G65 P… L… A… B…`: a macro call with arguments (argument
    /// specification I: A→#1, B→#2, C→#3, I→#4, J→#5, K→#6, D→#7, E→#8,
    /// F→#9, H→#11, M→#13, Q→#17, R→#18, S→#19, T→#20, U→#21, V→#22,
    /// W→#23, X→#24, Y→#25, Z→#26).
    fn g65(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        let mut args: Vec<(usize, f64)> = Vec::new();
        let (mut program, mut repeats) = (None, 1u64);
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else { break };
            if ch == b'(' {
                break;
            }
            if !ch.is_ascii_alphabetic() {
                return fail(c.i, 1, "G65 arguments are letter words");
            }
            let letter = ch.to_ascii_uppercase();
            let word_at = c.i;
            c.i += 1;
            c.skip_ws();
            let (v, _) = self.value(c)?;
            match letter {
                b'P' => program = Some(whole(v, word_at, "P")?),
                b'L' => repeats = u64::from(whole(v, word_at, "L")?),
                _ => {
                    let var = match letter {
                        b'A' => 1,
                        b'B' => 2,
                        b'C' => 3,
                        b'I' => 4,
                        b'J' => 5,
                        b'K' => 6,
                        b'D' => 7,
                        b'E' => 8,
                        b'F' => 9,
                        b'H' => 11,
                        b'M' => 13,
                        b'Q' => 17,
                        b'R' => 18,
                        b'S' => 19,
                        b'T' => 20,
                        b'U' => 21,
                        b'V' => 22,
                        b'W' => 23,
                        b'X' => 24,
                        b'Y' => 25,
                        b'Z' => 26,
                        _ => {
                            return fail(
                                word_at,
                                1,
                                format!("{} cannot be a G65 argument", char::from(letter)),
                            );
                        }
                    };
                    args.push((var, v));
                }
            }
        }
        let Some(p) = program else {
            return fail(at, 3, "G65 needs the program number in P");
        };
        let entry = self.find_program(p, at)?;
        if repeats == 0 {
            return Ok(());
        }
        self.push_call(entry, repeats - 1, true, format!("O{p}"), at)?;
        for (var, v) in args {
            self.params[var] = v;
        }
        if let Some(call) = self.calls.last_mut() {
            call.entry = entry;
        }
        Ok(())
    }

    /// The line after `O p` in this file.
    fn find_program(&self, p: u32, at: usize) -> Result<Pos, Fail> {
        let mut s = Source::new(self.src.text);
        while let Some(l) = s.next_line() {
            let t = l.text.trim_start();
            let t = t.strip_prefix(['O', 'o', ':']).unwrap_or("");
            if let Some((n, len)) = read_uint(t.as_bytes())
                && n == u64::from(p)
                && !t
                    .as_bytes()
                    .get(len)
                    .is_some_and(|c| c.is_ascii_alphanumeric())
            {
                return Ok(s.position());
            }
        }
        fail(
            at,
            3,
            format!("program O{p} is not in this file (other files are not searched)"),
        )
    }

    /// `M98 P… L…`: a subprogram call (locals shared).
    pub(super) fn m98(&mut self, b: &Block, at: usize) -> Result<(), Fail> {
        let Some(p) = b.get(b'P') else {
            return fail(at, 3, "M98 needs the program number in P");
        };
        let p = whole(p, b.pos_of(b'P'), "P")?;
        let (program, mut repeats) = if p > 9999 && !b.has(b'L') {
            (p % 10000, p / 10000)
        } else {
            (p, 1)
        };
        if let Some(l) = b.get(b'L').or(b.get(b'K')) {
            repeats = whole(l, b.pos_of(b'L'), "L")?;
        }
        if repeats == 0 {
            return Ok(());
        }
        let entry = self.find_program(program, at)?;
        self.push_call(
            entry,
            u64::from(repeats - 1),
            false,
            format!("O{program}"),
            at,
        )
    }

    /// `M99`: back to the caller (after the calling block), or to the start
    /// of the program when there is none (Fanuc's endless main program).
    pub(super) fn m99(&mut self, at: usize) -> Result<(), Fail> {
        match self.calls.last_mut() {
            Some(call) if call.repeats > 0 => {
                call.repeats -= 1;
                let entry = call.entry;
                self.src.seek(entry);
            }
            Some(_) => {
                self.pop_call();
            }
            None => {
                let _ = at;
                self.src.seek(Pos { offset: 0, line: 1 });
            }
        }
        Ok(())
    }
}

/// `t` without a leading `N123`.
fn strip_n(t: &str) -> &str {
    let b = t.as_bytes();
    if b.first().is_some_and(|c| *c == b'N' || *c == b'n') {
        let digits = b[1..].iter().take_while(|c| c.is_ascii_digit()).count();
        if digits > 0 {
            return &t[1 + digits..];
        }
    }
    t
}

/// The position of the line numbered `N n`, searching from `from` up to
/// `until`.
fn find_n(text: &str, from: Pos, until: Option<Pos>, n: u64) -> Option<Pos> {
    let mut s = Source::new(text);
    s.seek(from);
    while let Some(l) = s.next_line() {
        if until.is_some_and(|u| l.pos.offset >= u.offset) {
            return None;
        }
        let t = l.text.trim_start();
        let t = t.strip_prefix('/').unwrap_or(t).trim_start();
        let b = t.as_bytes();
        if b.first().is_some_and(|c| *c == b'N' || *c == b'n')
            && let Some((k, len)) = read_uint(&b[1..])
            && k == n
            && b.get(1 + len) != Some(&b'.')
        {
            return Some(l.pos);
        }
    }
    None
}
