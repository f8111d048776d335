//! Sinumerik statements: jumps, structured control flow, `DEF`, `MSG`.

use super::*;

/// The upper-case keyword a line's statements start with, and whether the
/// line holds a jump (`IF … GOTOF` is no block IF).
fn first_keyword(text: &str) -> (Option<String>, bool) {
    let b = text.as_bytes();
    let (_, _, start) = line_head(b);
    let mut c = Cursor::new(b, start);
    let kw = c.ident().map(str::to_ascii_uppercase);
    let mut jump = false;
    while !c.at_end() {
        match c.peek() {
            Some(b';') => break,
            Some(b'"') => {
                c.i += 1;
                while c.peek().is_some_and(|x| x != b'"') {
                    c.i += 1;
                }
                c.i += 1;
            }
            Some(x) if x.is_ascii_alphabetic() || x == b'_' => {
                let id = c.ident().unwrap_or("");
                if ["GOTOF", "GOTOB", "GOTO", "GOTOC"]
                    .iter()
                    .any(|g| id.eq_ignore_ascii_case(g))
                {
                    jump = true;
                }
            }
            _ => c.i += 1,
        }
    }
    (kw, jump)
}

impl Interp<'_, '_> {
    /// A control statement; `false` when the line is a block of words.
    pub(super) fn statement(&mut self, line: &Line<'_>, c: &mut Cursor<'_>) -> Result<bool, Fail> {
        let save = c.i;
        let start = c.i;
        let Some(id) = c.ident() else {
            return Ok(false);
        };
        let kw = Upper::of(id);
        let next = self.src.position();
        match &*kw {
            "IF" => {
                let cond = self.eval(c)? != 0.0;
                let save2 = c.i;
                c.skip_ws();
                let g_at = c.i;
                match c.ident().map(str::to_ascii_uppercase).as_deref() {
                    Some(g @ ("GOTOF" | "GOTOB" | "GOTO" | "GOTOC")) => {
                        let g = g.to_string();
                        let target = self.jump_target(c)?;
                        if cond {
                            self.jump(&g, &target, line.pos, g_at)?;
                        }
                    }
                    _ => {
                        c.i = save2;
                        self.expect_end(c)?;
                        if !cond {
                            self.skip_structure(next, "IF", "ENDIF", true, start)?;
                        }
                    }
                }
            }
            "ELSE" => self.skip_structure(next, "IF", "ENDIF", false, start)?,
            "ENDIF" => {}
            "WHILE" => {
                let cond = self.eval(c)? != 0.0;
                let on_top = self.frames.last() == Some(&Frame::While(line.pos));
                if cond {
                    if !on_top {
                        self.frames.push(Frame::While(line.pos));
                    }
                } else {
                    if on_top {
                        self.frames.pop();
                    }
                    self.skip_structure(next, "WHILE", "ENDWHILE", false, start)?;
                }
            }
            "ENDWHILE" => match self
                .frames
                .iter()
                .rposition(|f| matches!(f, Frame::While(_)))
            {
                Some(k) => {
                    let Frame::While(p) = self.frames[k] else {
                        unreachable!()
                    };
                    self.frames.truncate(k + 1);
                    self.src.seek(p);
                }
                None => return fail(start, 8, "ENDWHILE without its WHILE"),
            },
            "FOR" => self.for_loop(c, next, line.pos, start)?,
            "ENDFOR" => self.end_for(start)?,
            "REPEAT" => self.frames.push(Frame::Repeat(next, line.pos)),
            "UNTIL" => {
                let cond = self.eval(c)? != 0.0;
                match self
                    .frames
                    .iter()
                    .rposition(|f| matches!(f, Frame::Repeat(..)))
                {
                    Some(k) => {
                        let Frame::Repeat(body, _) = self.frames[k] else {
                            unreachable!()
                        };
                        if cond {
                            self.frames.truncate(k);
                        } else {
                            self.frames.truncate(k + 1);
                            self.src.seek(body);
                        }
                    }
                    None => return fail(start, 5, "UNTIL without its REPEAT"),
                }
            }
            "LOOP" => self.frames.push(Frame::Loop(next, line.pos)),
            "ENDLOOP" => match self
                .frames
                .iter()
                .rposition(|f| matches!(f, Frame::Loop(..)))
            {
                Some(k) => {
                    let Frame::Loop(body, _) = self.frames[k] else {
                        unreachable!()
                    };
                    self.frames.truncate(k + 1);
                    self.src.seek(body);
                }
                None => return fail(start, 7, "ENDLOOP without its LOOP"),
            },
            "GOTOF" | "GOTOB" | "GOTO" | "GOTOC" => {
                let target = self.jump_target(c)?;
                self.jump(&kw, &target, line.pos, start)?;
            }
            "DEF" => self.def(c, start)?,
            "MSG" => {
                if !c.eat(b'(') {
                    return fail(c.i, 1, "MSG(\"…\") expected");
                }
                if c.eat(b')') {
                    return Ok(true);
                }
                let text = self.string_expr(c)?;
                if !c.eat(b')') {
                    return fail(c.i, 1, "`)` expected");
                }
                self.m.emit(Event::Message(text));
            }
            "RET" => {
                self.m.emit(Event::Stop(StopKind::End));
                self.ended = true;
            }
            "STOPRE" => {}
            "PROC" => {
                return fail(
                    start,
                    4,
                    "PROC: subprogram definitions are not supported (the interpreter reads one main program)",
                );
            }
            _ => {
                c.i = save;
                return Ok(false);
            }
        }
        Ok(true)
    }

    fn expect_end(&self, c: &mut Cursor<'_>) -> Result<(), Fail> {
        c.skip_ws();
        if c.at_end() || c.peek() == Some(b';') {
            Ok(())
        } else {
            fail(c.i, c.b.len() - c.i, "unexpected text after the condition")
        }
    }

    /// A label or block number after GOTOF / GOTOB / GOTO.
    fn jump_target(&mut self, c: &mut Cursor<'_>) -> Result<String, Fail> {
        c.skip_ws();
        let at = c.i;
        match c.ident() {
            Some(id) => Ok(id.to_ascii_uppercase()),
            None => fail(at, 1, "a label or block number is expected after the jump"),
        }
    }

    /// Jumps to the label or block number `target`: forward (GOTOF),
    /// backward (GOTOB), forward then backward (GOTO, GOTOC); GOTOC goes on
    /// when there is none.
    fn jump(&mut self, kind: &str, target: &str, here: Pos, at: usize) -> Result<(), Fail> {
        let next = self.src.position();
        let forward = || find_label(self.src.text, next, None, target, false);
        let backward = || {
            find_label(
                self.src.text,
                Pos { offset: 0, line: 1 },
                Some(here),
                target,
                true,
            )
        };
        let found = match kind {
            "GOTOF" => forward(),
            "GOTOB" => backward(),
            _ => forward().or_else(backward),
        };
        match found {
            Some(p) => {
                self.src.seek(p);
                Ok(())
            }
            None if kind == "GOTOC" => Ok(()),
            None => fail(
                at,
                kind.len() + 1 + target.len(),
                format!(
                    "{kind} {target}: jump destination not found {} (alarm 14080)",
                    match kind {
                        "GOTOF" => "after this block",
                        "GOTOB" => "before this block",
                        _ => "in the program",
                    }
                ),
            ),
        }
    }

    /// Skips to after the end of a structure (`end`), or to after its ELSE
    /// when `to_else`, counting nested ones.
    fn skip_structure(
        &mut self,
        from: Pos,
        open: &str,
        end: &str,
        to_else: bool,
        at: usize,
    ) -> Result<(), Fail> {
        let mut s = Source::new(self.src.text);
        s.seek(from);
        let mut depth = 0usize;
        while let Some(l) = s.next_line() {
            let (kw, jump) = first_keyword(l.text);
            let Some(kw) = kw else { continue };
            if kw == open && !(open == "IF" && jump) {
                depth += 1;
            } else if kw == end {
                if depth == 0 {
                    self.src.seek(s.position());
                    return Ok(());
                }
                depth -= 1;
            } else if to_else && depth == 0 && kw == "ELSE" {
                self.src.seek(s.position());
                return Ok(());
            }
        }
        fail(at, open.len(), format!("{open} without its {end}"))
    }

    fn for_loop(
        &mut self,
        c: &mut Cursor<'_>,
        next: Pos,
        open: Pos,
        at: usize,
    ) -> Result<(), Fail> {
        let Some(var) = c.ident().map(str::to_ascii_uppercase) else {
            return fail(c.i, 1, "FOR needs a variable: FOR I = 1 TO 10");
        };
        let is_r =
            var.starts_with('R') && var[1..].bytes().all(|d| d.is_ascii_digit()) && var.len() > 1;
        if !is_r && !self.vars.contains_key(&var) {
            return fail(
                at,
                c.i - at,
                format!("FOR variable {var} is not defined (DEF INT {var})"),
            );
        }
        if !c.eat(b'=') {
            return fail(c.i, 1, "`=` expected");
        }
        let from = self.eval(c)?;
        if !c.eat_kw("TO", true) {
            return fail(c.i, 1, "TO expected");
        }
        let to = self.eval(c)?;
        self.set_var(&var, from, at)?;
        if from > to {
            self.skip_structure(next, "FOR", "ENDFOR", false, at)?;
        } else {
            self.frames.push(Frame::For {
                var,
                end: to,
                body: next,
                open,
            });
        }
        Ok(())
    }

    fn end_for(&mut self, at: usize) -> Result<(), Fail> {
        let Some(k) = self
            .frames
            .iter()
            .rposition(|f| matches!(f, Frame::For { .. }))
        else {
            return fail(at, 6, "ENDFOR without its FOR");
        };
        let Frame::For { var, end, body, .. } = self.frames[k].clone() else {
            unreachable!()
        };
        let v = self.get_var(&var) + 1.0;
        self.set_var(&var, v, at)?;
        if v <= end {
            self.frames.truncate(k + 1);
            self.src.seek(body);
        } else {
            self.frames.truncate(k);
        }
        Ok(())
    }

    pub(super) fn get_var(&self, name: &str) -> f64 {
        if let Some(n) = name.strip_prefix('R').and_then(|r| r.parse::<usize>().ok()) {
            return self.r.get(n).copied().unwrap_or(0.0);
        }
        match self.vars.get(name) {
            Some(Var::Real(v) | Var::Int(v) | Var::Bool(v)) => *v,
            _ => 0.0,
        }
    }

    /// Sets an R parameter or a DEF variable (INT rounds, BOOL is 0/1).
    pub(super) fn set_var(&mut self, name: &str, v: f64, at: usize) -> Result<(), Fail> {
        if let Some(n) = name.strip_prefix('R').and_then(|r| r.parse::<f64>().ok()) {
            let k = self.r_index(n, at, name.len())?;
            self.r[k] = v;
            return Ok(());
        }
        let base = name.split('[').next().unwrap_or(name);
        let kind = self
            .vars
            .get(name)
            .or_else(|| self.vars.get(&format!("{base}[]")))
            .cloned();
        let new = match kind {
            Some(Var::Real(_)) => Var::Real(v),
            Some(Var::Int(_)) => Var::Int(v.round()),
            Some(Var::Bool(_)) => Var::Bool(f64::from(u8::from(v != 0.0))),
            Some(Var::Str(_)) => return fail(at, name.len(), format!("{name} is a STRING")),
            None => {
                return fail(
                    at,
                    name.len(),
                    format!("{name} is not defined (DEF REAL {name})"),
                );
            }
        };
        self.vars.insert(name.to_string(), new);
        Ok(())
    }

    /// `DEF REAL A, B=2, C[3]`, `DEF INT`, `DEF BOOL`, `DEF STRING[n]`.
    fn def(&mut self, c: &mut Cursor<'_>, at: usize) -> Result<(), Fail> {
        let t_at = c.i;
        let Some(ty) = c.ident().map(str::to_ascii_uppercase) else {
            return fail(c.i, 1, "DEF needs a type");
        };
        let proto = match ty.as_str() {
            "REAL" => Var::Real(0.0),
            "INT" | "CHAR" => Var::Int(0.0),
            "BOOL" => Var::Bool(0.0),
            "STRING" => {
                if c.eat(b'[') {
                    self.eval(c)?;
                    if !c.eat(b']') {
                        return fail(c.i, 1, "`]` expected");
                    }
                }
                Var::Str(String::new())
            }
            _ => {
                return fail(
                    t_at,
                    ty.len(),
                    format!(
                        "DEF {ty}: only REAL, INT, BOOL, CHAR and STRING variables are supported"
                    ),
                );
            }
        };
        loop {
            let n_at = c.i;
            let Some(name) = c.ident().map(str::to_ascii_uppercase) else {
                return fail(c.i, 1, "variable name expected");
            };
            if c.peek() == Some(b'[') {
                // An array: elements start at 0 / empty.
                c.i += 1;
                loop {
                    self.eval(c)?;
                    if !c.eat(b',') {
                        break;
                    }
                }
                if !c.eat(b']') {
                    return fail(c.i, 1, "`]` expected");
                }
                self.vars.insert(format!("{name}[]"), proto.clone());
            } else {
                self.vars.insert(name.clone(), proto.clone());
            }
            if c.eat(b'=') {
                if let Var::Str(_) = proto {
                    let s = self.string_expr(c)?;
                    self.vars.insert(name.clone(), Var::Str(s));
                } else {
                    let v = self.eval(c)?;
                    self.set_var(&name, v, n_at)?;
                }
            }
            if !c.eat(b',') {
                break;
            }
        }
        let _ = at;
        self.expect_end(c)
    }
}

/// The position of the line with label or block number `target` from
/// `from` (up to `until`); with `last`, the last such line before it.
fn find_label(text: &str, from: Pos, until: Option<Pos>, target: &str, last: bool) -> Option<Pos> {
    let number = target.strip_prefix('N').and_then(|d| d.parse::<u64>().ok());
    let mut s = Source::new(text);
    s.seek(from);
    let mut found = None;
    while let Some(l) = s.next_line() {
        if until.is_some_and(|u| l.pos.offset >= u.offset) {
            break;
        }
        let b = l.text.as_bytes();
        let (n, label, _) = line_head(b);
        let hit = number.is_some() && n == number
            || label.is_some_and(|(a, e)| l.text[a..e].eq_ignore_ascii_case(target));
        if hit {
            found = Some(l.pos);
            if !last {
                break;
            }
        }
    }
    found
}
