//! A Sinumerik block of words: read, then executed.

use super::*;

/// Keywords of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Kw {
    Traori,
    Trafoof,
    Cip,
    Ct,
    Trans,
    Atrans,
    Supa,
    Mcall,
}

/// Keywords that change nothing the interpreter reports: path control,
/// acceleration and look-ahead modes (corner rounding is the controller's;
/// the programmed path is reported).
const QUIET: &[&str] = &[
    "SOFT",
    "BRISK",
    "DRIVE",
    "FFWON",
    "FFWOF",
    "CFC",
    "CFTCP",
    "CFIN",
    "DIAMOF",
    "COMPOF",
    "COMPCAD",
    "COMPCURV",
    "UPATH",
    "SPATH",
    "ORIWKS",
    "ORIMKS",
    "ORIAXES",
    "ORIVECT",
    "CPRECON",
    "CPRECOF",
    "ACN_OFF",
    "STOPFIFO",
    "STARTFIFO",
    "WAITM",
    "DISPLON",
    "DISPLOF",
    "SBLON",
    "SBLOF",
];

#[derive(Debug, Clone, Default)]
struct Words {
    g: Vec<(u16, usize)>,
    m: Vec<(u32, usize)>,
    kw: Vec<(Kw, usize)>,
    axis_value: [f64; MAX_AXES],
    axis_mode: [Option<AxisMode>; MAX_AXES],
    axes: u32,
    first_axis_at: usize,
    f: Option<(f64, usize)>,
    s: Option<(f64, usize)>,
    t: Option<(u32, usize)>,
    d: Option<(u32, usize)>,
    /// I, J, K: value and whether absolute (`=AC(…)`).
    ijk: [Option<(f64, bool)>; 3],
    /// I1, J1, K1 (CIP intermediate point).
    ijk1: [Option<(f64, bool)>; 3],
    cr: Option<f64>,
    turn: Option<u32>,
    cycle: Option<CycleCall>,
}

impl Interp<'_, '_> {
    pub(super) fn block(&mut self, line: &Line<'_>, mut c: Cursor<'_>) -> Result<(), Fail> {
        let mut w = Words::default();
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else { break };
            if ch == b';' {
                break;
            }
            if ch.is_ascii_alphabetic() || ch == b'_' {
                self.word(&mut c, &mut w, line)?;
            } else if ch == b'$' {
                let at = c.i;
                let name = self.system_var_name(&mut c)?;
                if c.eat(b'=') {
                    return fail(
                        at,
                        c.i - at,
                        format!("writing the system variable {name} is not supported"),
                    );
                }
                return fail(at, c.i - at, format!("`{name}` alone is not a statement"));
            } else {
                return fail(
                    c.i,
                    1,
                    format!("`{}` is not the start of a word", char::from(ch)),
                );
            }
        }
        self.execute(&w, line)
    }

    /// One word, assignment or keyword.
    fn word(&mut self, c: &mut Cursor<'_>, w: &mut Words, line: &Line<'_>) -> Result<(), Fail> {
        let start = c.i;
        let id = Upper::of(c.ident().unwrap_or(""));
        let save_after_ident = c.i;
        c.skip_ws();
        let assign = c.peek() == Some(b'=') && c.peek_at(1) != Some(b'=');
        if assign {
            c.i += 1;
            return self.assigned_word(&id, start, c, w, line);
        }
        if c.peek() == Some(b'(') && id.starts_with("CYCLE") {
            let code = cycle_code(&id).ok_or_else(|| Fail {
                at: start,
                len: id.len(),
                message: format!("{id} is not supported (drilling cycles CYCLE81..CYCLE86 are)"),
            })?;
            let args = self.cycle_args(c)?;
            w.cycle = Some(CycleCall {
                code,
                args,
                line: line.no,
            });
            return Ok(());
        }
        c.i = save_after_ident;
        let kw = match &*id {
            "TRAORI" => Some(Kw::Traori),
            "TRAFOOF" => Some(Kw::Trafoof),
            "CIP" => Some(Kw::Cip),
            "CT" => Some(Kw::Ct),
            "TRANS" => Some(Kw::Trans),
            "ATRANS" => Some(Kw::Atrans),
            "SUPA" => Some(Kw::Supa),
            "MCALL" => Some(Kw::Mcall),
            _ => None,
        };
        if let Some(k) = kw {
            w.kw.push((k, start));
            return Ok(());
        }
        if QUIET.contains(&&*id) {
            return Ok(());
        }
        // A one-letter address with a number: G642, M20, X10.5, F250.
        c.i = start;
        let letter = c.b[c.i].to_ascii_uppercase();
        let after = c.b.get(c.i + 1).copied();
        if after.is_some_and(|d| d.is_ascii_digit() || d == b'.' || d == b'-' || d == b'+') {
            c.i += 1;
            let Some(n) = read_number(&c.b[c.i..]) else {
                return fail(start, 2, "number expected");
            };
            c.i += n.len;
            return self.letter_word(letter, n.value, start, c.i - start, w, line);
        }
        let len = id.len().max(1);
        fail(
            start,
            len,
            format!("`{id}` is not a word, keyword or variable the interpreter knows"),
        )
    }

    /// `X10.5`, `G642`, `M20`, `F250`, `S3000`, `T1`, `D1`.
    fn letter_word(
        &mut self,
        letter: u8,
        v: f64,
        at: usize,
        len: usize,
        w: &mut Words,
        line: &Line<'_>,
    ) -> Result<(), Fail> {
        let whole = |v: f64| -> Result<u32, Fail> {
            if (0.0..1e9).contains(&v) && v.fract() == 0.0 {
                Ok(v as u32)
            } else {
                fail(
                    at,
                    len,
                    format!("{}{v}: a whole number is expected", char::from(letter)),
                )
            }
        };
        match letter {
            b'G' => w.g.push((whole(v)? as u16, at)),
            b'M' => w.m.push((whole(v)?, at)),
            b'F' => w.f = Some((v, at)),
            b'S' => w.s = Some((v, at)),
            b'T' => w.t = Some((whole(v)?, at)),
            b'D' => w.d = Some((whole(v)?, at)),
            b'I' | b'J' | b'K' => w.ijk[usize::from(letter - b'I')] = Some((v, false)),
            b'L' | b'P' => {
                return fail(
                    at,
                    len,
                    "subprogram calls (L…, P…) are not supported: the interpreter reads one program",
                );
            }
            _ => {
                let name = char::from(letter).to_string();
                match self.m.axis(&name) {
                    Some(i) => self.axis_word(i, v, AxisMode::Plain, at, w),
                    None => self.foreign(&name, at, line),
                }
            }
        }
        Ok(())
    }

    fn axis_word(&mut self, i: usize, v: f64, mode: AxisMode, at: usize, w: &mut Words) {
        if w.axes == 0 {
            w.first_axis_at = at;
        }
        w.axes |= 1 << i;
        w.axis_value[i] = v;
        w.axis_mode[i] = Some(mode);
    }

    fn foreign(&mut self, name: &str, at: usize, line: &Line<'_>) {
        if self.warned_axis.iter().any(|n| n == name) {
            return;
        }
        self.warned_axis.push(name.to_string());
        let d = diagnostic(
            self.file,
            line,
            Fail {
                at,
                len: name.len(),
                message: format!(
                    "{name} is not an axis of this machine: its words are not simulated (warned once)"
                ),
            },
            true,
        );
        self.m.warn(d);
    }

    /// `NAME=…`: an axis or address with an expression, an R parameter or
    /// a variable.
    fn assigned_word(
        &mut self,
        id: &str,
        at: usize,
        c: &mut Cursor<'_>,
        w: &mut Words,
        line: &Line<'_>,
    ) -> Result<(), Fail> {
        if let Some(i) = self.m.axis(id) {
            if self.m.axes[i].pressure {
                let v = self.eval(c)?;
                self.m.pos[i] = v;
                self.m.emit(Event::Pressure { axis: i, value: v });
                return Ok(());
            }
            let (v, mode) = self.moded_value(c)?;
            self.axis_word(i, v, mode, at, w);
            return Ok(());
        }
        match id {
            "F" => w.f = Some((self.eval(c)?, at)),
            "S" => w.s = Some((self.eval(c)?, at)),
            "CR" => w.cr = Some(self.eval(c)?),
            "TURN" => {
                let v = self.eval(c)?;
                if !((0.0..1e6).contains(&v) && v.fract() == 0.0) {
                    return fail(
                        at,
                        4,
                        format!("TURN={v}: a whole number of turns is expected"),
                    );
                }
                w.turn = Some(v as u32);
            }
            "I" | "J" | "K" | "I1" | "J1" | "K1" => {
                let (v, mode) = self.moded_value(c)?;
                let k = usize::from(id.as_bytes()[0] - b'I');
                let abs = mode == AxisMode::Ac;
                if id.len() == 2 {
                    w.ijk1[k] = Some((v, abs));
                } else {
                    w.ijk[k] = Some((v, abs));
                }
            }
            "T" => {
                c.skip_ws();
                if c.peek() == Some(b'"') {
                    return fail(
                        at,
                        2,
                        "tool names (T=\"…\") are not supported: program tool numbers",
                    );
                }
                let v = self.eval(c)?;
                if !((0.0..1e9).contains(&v) && v.fract() == 0.0) {
                    return fail(at, 1, format!("T={v}: a tool number is expected"));
                }
                w.t = Some((v as u32, at));
            }
            "D" => {
                let v = self.eval(c)?;
                w.d = Some((v.max(0.0) as u32, at));
            }
            _ if is_r(id) => {
                let v = self.eval(c)?;
                self.set_var(id, v, at)?;
            }
            _ if id.starts_with('H') && id[1..].bytes().all(|d| d.is_ascii_digit()) => {
                let v = self.eval(c)?;
                let d = diagnostic(
                    self.file,
                    line,
                    Fail {
                        at,
                        len: id.len(),
                        message: format!(
                            "{id}={v}: an H auxiliary function for the PLC (not a pressure axis of this machine): passed on, not simulated"
                        ),
                    },
                    true,
                );
                self.m.warn(d);
            }
            _ if self.vars.contains_key(id) || self.vars.contains_key(&format!("{id}[]")) => {
                if matches!(self.vars.get(id), Some(Var::Str(_))) {
                    let s = self.string_expr(c)?;
                    self.vars.insert(id.to_string(), Var::Str(s));
                } else {
                    let v = self.eval(c)?;
                    self.set_var(id, v, at)?;
                }
            }
            _ if id.len() == 1
                && id.as_bytes()[0].is_ascii_alphabetic()
                && b"XYZABCUVWE".contains(&id.as_bytes()[0]) =>
            {
                self.eval(c)?;
                self.foreign(id, at, line);
            }
            _ => {
                return fail(
                    at,
                    id.len(),
                    format!("`{id}` is not an address or variable the interpreter knows"),
                );
            }
        }
        Ok(())
    }

    /// `expr`, or `AC(expr)` / `IC(…)` / `DC(…)` / `ACP(…)` / `ACN(…)`.
    fn moded_value(&mut self, c: &mut Cursor<'_>) -> Result<(f64, AxisMode), Fail> {
        let save = c.i;
        if let Some(f) = c.ident().map(Upper::of) {
            let mode = match &*f {
                "AC" => Some(AxisMode::Ac),
                "IC" => Some(AxisMode::Ic),
                "DC" => Some(AxisMode::Dc),
                "ACP" => Some(AxisMode::Acp),
                "ACN" => Some(AxisMode::Acn),
                _ => None,
            };
            if let Some(mode) = mode
                && c.eat(b'(')
            {
                let v = self.eval(c)?;
                if !c.eat(b')') {
                    return fail(c.i, 1, "`)` expected");
                }
                return Ok((v, mode));
            }
        }
        c.i = save;
        Ok((self.eval(c)?, AxisMode::Plain))
    }

    /// `(a, , c)`: the arguments of a cycle call, empty ones `None`.
    fn cycle_args(&mut self, c: &mut Cursor<'_>) -> Result<Vec<Option<f64>>, Fail> {
        c.i += 1;
        let mut args = Vec::new();
        loop {
            c.skip_ws();
            if matches!(c.peek(), Some(b',' | b')')) {
                args.push(None);
            } else {
                args.push(Some(self.eval(c)?));
            }
            if c.eat(b',') {
                continue;
            }
            if c.eat(b')') {
                return Ok(args);
            }
            return fail(c.i, 1, "`,` or `)` expected in the cycle's arguments");
        }
    }

    fn execute(&mut self, w: &Words, line: &Line<'_>) -> Result<(), Fail> {
        for &(g, _) in &w.g {
            match g {
                70 | 700 => self.m.set_units(true),
                71 | 710 => self.m.set_units(false),
                _ => {}
            }
        }
        let dwell = w.g.iter().find(|(g, _)| *g == 4).map(|(_, at)| *at);
        if dwell.is_none() {
            if let Some((f, at)) = w.f {
                if f < 0.0 {
                    return fail(at, 1, "negative feed");
                }
                self.m.feed = if self.m.feed_mode == FeedMode::InverseTime {
                    f
                } else {
                    f * self.m.unit()
                };
            }
            if let Some((s, _)) = w.s {
                self.m.set_speed(s);
            }
        }
        if let Some((t, _)) = w.t {
            self.selected_tool = Some(t);
            self.m.emit(Event::ToolSelect { tool: t });
        }
        self.m_codes(w, line)?;
        if let Some((d, _)) = w.d {
            self.m.set_tool_length(if d == 0 { None } else { Some(d) });
        }
        if let Some(at) = dwell {
            let seconds = match (w.f, w.s) {
                (Some((f, _)), None) => f,
                (None, Some((s, _))) => {
                    if self.m.state.spindle_speed <= 0.0 {
                        return fail(at, 2, "G4 S… (revolutions) with no spindle speed");
                    }
                    s / self.m.state.spindle_speed * 60.0
                }
                _ => {
                    return fail(
                        at,
                        2,
                        "G4 needs the time in F (seconds) or S (spindle revolutions)",
                    );
                }
            };
            if seconds < 0.0 {
                return fail(at, 2, "negative dwell");
            }
            self.m.dwell(seconds);
        }
        self.modal_g(w)?;
        for &(k, _) in &w.kw {
            match k {
                Kw::Traori => self.m.set_tcp(true),
                Kw::Trafoof => self.m.set_tcp(false),
                Kw::Cip => self.set_motion(Motion::Cip),
                Kw::Ct => self.set_motion(Motion::Ct),
                _ => {}
            }
        }
        if w.kw
            .iter()
            .any(|(k, _)| matches!(k, Kw::Trans | Kw::Atrans))
        {
            return self.trans(w);
        }
        if let Some((_, at)) = w.kw.iter().find(|(k, _)| *k == Kw::Mcall) {
            self.mcall = w.cycle.clone();
            if self.mcall.is_none() {
                self.m.emit(Event::CycleOff);
            } else if let Some(cc) = &self.mcall {
                self.m.emit(Event::Cycle { code: cc.code });
            }
            if w.axes != 0 {
                return fail(*at, 5, "MCALL with axis words");
            }
        } else {
            let moved = self.motion_block(w)?;
            if let Some(cc) = &w.cycle {
                self.m.emit(Event::Cycle { code: cc.code });
                self.cycle(cc.clone())?;
            } else if moved && let Some(cc) = self.mcall.clone() {
                self.cycle(cc)?;
            }
        }
        self.stops(w)
    }

    fn m_codes(&mut self, w: &Words, line: &Line<'_>) -> Result<(), Fail> {
        for &(code, at) in &w.m {
            match code {
                6 => {
                    let t = self.selected_tool.or(self.m.state.tool).unwrap_or(0);
                    self.m.tool_change(t);
                }
                3 => self.m.set_spindle(SpindleDir::Cw),
                4 => self.m.set_spindle(SpindleDir::Ccw),
                5 => self.m.set_spindle(SpindleDir::Off),
                7 => self.m.coolant(Some(true), None),
                8 => self.m.coolant(None, Some(true)),
                9 => self.m.coolant(Some(false), Some(false)),
                0 | 1 | 2 | 17 | 30 => {}
                19 | 40..=45 => self.m.emit(Event::MCode(code)),
                c => {
                    let d = diagnostic(
                        self.file,
                        line,
                        Fail {
                            at,
                            len: 1 + c.to_string().len(),
                            message: format!(
                                "M{c} has no meaning for the interpreter (a machine-specific M function?): passed on, not simulated"
                            ),
                        },
                        true,
                    );
                    self.m.warn(d);
                    self.m.emit(Event::MCode(c));
                }
            }
        }
        Ok(())
    }

    fn stops(&mut self, w: &Words) -> Result<(), Fail> {
        for &(code, _) in &w.m {
            match code {
                0 => self.m.emit(Event::Stop(StopKind::Program)),
                1 => self.m.emit(Event::Stop(StopKind::Optional)),
                2 | 17 | 30 => {
                    self.m.emit(Event::Stop(StopKind::End));
                    self.ended = true;
                }
                _ => {}
            }
        }
        Ok(())
    }

    pub(super) fn set_motion(&mut self, m: Motion) {
        self.motion = m;
        self.motion_set = true;
    }

    fn modal_g(&mut self, w: &Words) -> Result<(), Fail> {
        for &(g, at) in &w.g {
            match g {
                0 => self.set_motion(Motion::Rapid),
                1 => self.set_motion(Motion::Linear),
                2 => self.set_motion(Motion::Cw),
                3 => self.set_motion(Motion::Ccw),
                17 => self.m.set_plane(ArcPlane::Xy),
                18 => self.m.set_plane(ArcPlane::Zx),
                19 => self.m.set_plane(ArcPlane::Yz),
                40 => self.m.set_cutter_comp(CutterComp::Off),
                41 => self.m.set_cutter_comp(CutterComp::Left),
                42 => self.m.set_cutter_comp(CutterComp::Right),
                500 => self.m.select_offset(WorkOffset::None, "G500"),
                54..=57 => self
                    .m
                    .select_offset(WorkOffset::Numbered(g - 53), &format!("G{g}")),
                505..=599 => self
                    .m
                    .select_offset(WorkOffset::Numbered(g - 500), &format!("G{g}")),
                90 => self.incremental = false,
                91 => self.incremental = true,
                93 => self.m.set_feed_mode(FeedMode::InverseTime),
                94 => self.m.set_feed_mode(FeedMode::PerMinute),
                95 => self.m.set_feed_mode(FeedMode::PerRevolution),
                // Exact stop and continuous path modes, speed limits: the
                // programmed path is what is reported.
                9
                | 60
                | 64
                | 641..=645
                | 601..=603
                | 4
                | 53
                | 153
                | 70
                | 71
                | 700
                | 710
                | 25
                | 26 if !(g == 25 || g == 26) || w.axes == 0 => {}
                _ => {
                    return fail(
                        at,
                        1 + g.to_string().len(),
                        format!("G{g} is not supported by the interpreter"),
                    );
                }
            }
        }
        Ok(())
    }

    /// `TRANS X… Y…` (replaces the programmable shift) / `ATRANS` (adds).
    fn trans(&mut self, w: &Words) -> Result<(), Fail> {
        let additive = w.kw.iter().any(|(k, _)| *k == Kw::Atrans);
        if !additive {
            self.m.shift = [0.0; MAX_AXES];
        }
        for i in 0..self.m.n {
            if w.axes & (1 << i) != 0 {
                self.m.shift[i] += w.axis_value[i] * self.m.unit_of(i);
            }
        }
        self.m.refresh_offset(None);
        self.m.emit(Event::WorkOffset(self.m.state.work_offset));
        Ok(())
    }

    /// The moves of a block; `true` when it moved.
    fn motion_block(&mut self, w: &Words) -> Result<bool, Fail> {
        let machine_frame = w.g.iter().any(|(g, _)| *g == 53 || *g == 153)
            || w.kw.iter().any(|(k, _)| *k == Kw::Supa);
        let circle_words = w.ijk.iter().any(Option::is_some) || w.cr.is_some();
        if w.axes == 0 && !(matches!(self.motion, Motion::Cw | Motion::Ccw) && circle_words) {
            return Ok(false);
        }
        if !self.motion_set {
            self.motion_set = true;
            self.m.assume(
                "motion G0 at the first move (the program sets no G0/G1/G2/G3 before it)".into(),
            );
        }
        let (target, travel, turned) = self.targets(w, machine_frame)?;
        let at = w.first_axis_at;
        let feed_check = |s: &Self| -> Result<(), Fail> {
            if s.m.feed <= 0.0 {
                return fail(at, 1, "feed move with a zero feed rate (no F programmed)");
            }
            Ok(())
        };
        match self.motion {
            Motion::Rapid | Motion::Linear => {
                let rapid = self.motion == Motion::Rapid;
                if !rapid {
                    feed_check(self)?;
                }
                let kind = if rapid {
                    MotionKind::Rapid
                } else {
                    MotionKind::Linear
                };
                self.m.machine_frame = machine_frame;
                let before = self.m.xyz_pos();
                self.m.move_to(kind, &target, &travel, turned, w.axes);
                self.m.machine_frame = false;
                self.note_tangent(before, None);
            }
            Motion::Cw | Motion::Ccw | Motion::Cip | Motion::Ct => {
                feed_check(self)?;
                let kind = self.circle(w, &target, at)?;
                let before = self.m.xyz_pos();
                let arc = if let MotionKind::Arc(a) = &kind {
                    Some(*a)
                } else {
                    None
                };
                self.m.move_to(kind, &target, &travel, turned, w.axes);
                self.note_tangent(before, arc);
            }
        }
        Ok(true)
    }

    /// Remembers the direction of the path at the end of the last move.
    pub(super) fn note_tangent(&mut self, before: [f64; 3], arc: Option<super::super::Arc>) {
        let after = self.m.xyz_pos();
        if arc.is_some() || after != before {
            self.tangent = Some((before, after, arc));
        }
    }

    /// End values of every axis word, resolved.
    fn targets(
        &mut self,
        w: &Words,
        machine_frame: bool,
    ) -> Result<([f64; MAX_AXES], [f64; MAX_AXES], u32), Fail> {
        self.targets_of(
            w.axes,
            &w.axis_value,
            &w.axis_mode,
            machine_frame,
            w.first_axis_at,
        )
    }

    /// End values of the axes in `axes` (bit i), given as `value` in `mode`.
    pub(super) fn targets_of(
        &mut self,
        axes: u32,
        value: &[f64; MAX_AXES],
        modes: &[Option<AxisMode>; MAX_AXES],
        machine_frame: bool,
        first_axis_at: usize,
    ) -> Result<([f64; MAX_AXES], [f64; MAX_AXES], u32), Fail> {
        let mut t = self.m.pos;
        let mut travel = [0.0; MAX_AXES];
        let mut turned = 0u32;
        for i in 0..self.m.n {
            if axes & (1 << i) == 0 {
                continue;
            }
            let Some(mode) = modes[i] else { continue };
            let rotary = self.m.axes[i].rotary;
            let v = value[i] * self.m.unit_of(i);
            if machine_frame {
                t[i] = v - self.m.state.offset[i];
                continue;
            }
            let incremental = mode == AxisMode::Ic || mode == AxisMode::Plain && self.incremental;
            if incremental {
                if self.m.axes[i].endless {
                    travel[i] = v;
                    t[i] = wrap(self.m.pos[i] + v);
                    turned |= 1 << i;
                } else {
                    t[i] = self.m.pos[i] + v;
                }
                continue;
            }
            let rmode = match mode {
                AxisMode::Dc => RotaryMode::Shortest,
                AxisMode::Acp => RotaryMode::Positive,
                AxisMode::Acn => RotaryMode::Negative,
                _ => RotaryMode::Direct,
            };
            if !rotary && rmode != RotaryMode::Direct {
                return fail(
                    first_axis_at,
                    1,
                    format!("DC/ACP/ACN on the linear axis {}", self.m.axes[i].name),
                );
            }
            if rotary {
                let (e, d) = self.m.rotary_target(i, v, rmode);
                t[i] = e;
                travel[i] = d;
                turned |= 1 << i;
            } else {
                t[i] = v;
            }
        }
        Ok((t, travel, turned))
    }

    /// The arc of a G2/G3/CIP/CT block ending at `target`.
    fn circle(
        &mut self,
        w: &Words,
        target: &[f64; MAX_AXES],
        at: usize,
    ) -> Result<MotionKind, Fail> {
        let [Some(x), Some(y), Some(z)] = self.m.xyz else {
            return fail(at, 1, "circles need a machine with X, Y and Z axes");
        };
        let start = [self.m.pos[x], self.m.pos[y], self.m.pos[z]];
        let end = [target[x], target[y], target[z]];
        let plane = self.m.state.plane;
        let [pa, pb, _] = plane.axes();
        let unit = self.m.unit();
        let tol = self.m.options.tolerances;
        let err = |e: super::super::arc::ArcError| Fail {
            at,
            len: 1,
            message: e.to_string(),
        };
        let a = match self.motion {
            Motion::Cip => {
                let mut mid = [0.0; 3];
                for k in 0..3 {
                    mid[k] = match w.ijk1[k] {
                        Some((v, abs)) => {
                            if abs || !self.incremental {
                                v * unit
                            } else {
                                start[k] + v * unit
                            }
                        }
                        None => start[k],
                    };
                }
                let plane = [ArcPlane::Xy, ArcPlane::Zx, ArcPlane::Yz]
                    .into_iter()
                    .find(|p| {
                        let n = p.axes()[2];
                        (mid[n] - start[n]).abs() < 1e-9 && (end[n] - start[n]).abs() < 1e-9
                    })
                    .ok_or_else(|| Fail { at, len: 3, message: "CIP through points that are not in a plane XY, ZX or YZ is not supported".into() })?;
                let [qa, qb, _] = plane.axes();
                let (c, cw) = arc::circle_through(
                    [start[qa], start[qb]],
                    [mid[qa], mid[qb]],
                    [end[qa], end[qb]],
                )
                .ok_or_else(|| Fail {
                    at,
                    len: 3,
                    message: "CIP: the three points lie on a line".into(),
                })?;
                arc::arc(plane, cw, start, end, Centre::At(c), 0, &tol).map_err(err)?
            }
            Motion::Ct => {
                let Some(t) = self.tangent.and_then(super::super::arc::end_tangent) else {
                    return fail(at, 2, "CT needs a move before it (its tangent)");
                };
                let (c, cw) =
                    arc::tangent_centre([start[pa], start[pb]], [t[pa], t[pb]], [end[pa], end[pb]])
                        .ok_or_else(|| Fail {
                            at,
                            len: 2,
                            message: "CT: the end point lies on the tangent (a straight line)"
                                .into(),
                        })?;
                arc::arc(plane, cw, start, end, Centre::At(c), 0, &tol).map_err(err)?
            }
            _ => {
                let cw = self.motion == Motion::Cw;
                let centre = match (w.cr, w.ijk[pa].is_some() || w.ijk[pb].is_some()) {
                    (Some(_), true) => return fail(at, 1, "a circle with both CR= and I/J/K"),
                    (Some(r), false) => Centre::Radius(r * unit),
                    (None, true) => {
                        let off = |k: usize| match w.ijk[k] {
                            Some((v, true)) => v * unit,
                            Some((v, false)) => start[k] + v * unit,
                            None => start[k],
                        };
                        Centre::At([off(pa), off(pb)])
                    }
                    (None, false) => {
                        return fail(
                            at,
                            1,
                            "a circle needs its centre (I, J, K) or its radius (CR=)",
                        );
                    }
                };
                arc::arc(plane, cw, start, end, centre, w.turn.unwrap_or(0), &tol).map_err(err)?
            }
        };
        Ok(MotionKind::Arc(a))
    }

    /// CYCLE81..CYCLE86 at the current position (Sinumerik "Cycles"
    /// programming manual, drilling cycles).
    fn cycle(&mut self, cc: CycleCall) -> Result<(), Fail> {
        let [pa, pb, pn] = self.m.state.plane.axes();
        let p = self.m.xyz_pos();
        let arg = |k: usize| cc.args.get(k).copied().flatten();
        let fail_arg = |m: String| Fail {
            at: 0,
            len: 1,
            message: m,
        };
        let unit = self.m.unit();
        let rtp = arg(0)
            .ok_or_else(|| fail_arg(format!("CYCLE{}: RTP (retraction plane) missing", cc.code)))?
            * unit;
        let rfp = arg(1).unwrap_or(0.0) * unit;
        let sdis = arg(2).unwrap_or(0.0).abs() * unit;
        let dp = match (arg(3), arg(4)) {
            (Some(dp), _) => dp * unit,
            (None, Some(dpr)) => rfp - dpr.abs() * unit,
            (None, None) => {
                return Err(fail_arg(format!(
                    "CYCLE{}: DP or DPR (depth) missing",
                    cc.code
                )));
            }
        };
        let start = rfp + sdis;
        if dp > start {
            return Err(fail_arg(format!(
                "CYCLE{}: the depth {dp} is above the start {start}",
                cc.code
            )));
        }
        let dtb = |k: usize| arg(k).map(|t| if t < 0.0 { 0.0 } else { t });
        let mut ops = Vec::new();
        let spindle = self.m.state.spindle;
        match cc.code {
            81 | 82 => {
                ops.push(Op::Feed(dp));
                if cc.code == 82
                    && let Some(t) = dtb(5)
                {
                    ops.push(Op::Dwell(t));
                }
            }
            83 => {
                let first = match (arg(5), arg(6)) {
                    (Some(fdep), _) => rfp - fdep * unit,
                    (None, Some(fdpr)) => fdpr.abs() * unit,
                    _ => start - dp,
                };
                let dam = arg(7).unwrap_or(0.0).abs() * unit;
                let swarf = arg(11).unwrap_or(0.0) == 1.0;
                self.m.assume("CYCLE83: chip breaking retracts 1 mm, swarf removal re-approaches to 1 mm above the last depth (the cycle's defaults)".into());
                let mut depth = start;
                let mut step = first.max(1e-3);
                let mut n = 0;
                loop {
                    depth = (depth - step).max(dp);
                    ops.push(Op::Feed(depth));
                    if let Some(t) = dtb(8) {
                        ops.push(Op::Dwell(t));
                    }
                    if depth <= dp {
                        break;
                    }
                    if swarf {
                        ops.push(Op::Rapid(start));
                        if let Some(t) = dtb(9) {
                            ops.push(Op::Dwell(t));
                        }
                    }
                    ops.push(Op::Rapid(depth + 1.0));
                    if dam > 0.0 && step - dam >= dam {
                        step -= dam;
                    }
                    n += 1;
                    if n > 100_000 {
                        return Err(fail_arg("CYCLE83 makes more than 100000 steps".into()));
                    }
                }
            }
            84 => {
                if spindle == SpindleDir::Off {
                    return Err(fail_arg("CYCLE84 tapping with the spindle stopped".into()));
                }
                ops.push(Op::Feed(dp));
                if let Some(t) = dtb(5) {
                    ops.push(Op::Dwell(t));
                }
                ops.push(Op::SpindleReverse);
                ops.push(Op::Feed(start));
                ops.push(Op::Spindle(spindle));
            }
            85 => {
                let ffr = arg(6).map(|f| f * unit).unwrap_or(self.m.feed);
                let rff = arg(7).map(|f| f * unit).unwrap_or(self.m.feed);
                ops.push(Op::FeedAt(dp, ffr));
                if let Some(t) = dtb(5) {
                    ops.push(Op::Dwell(t));
                }
                ops.push(Op::FeedAt(start, rff));
            }
            86 => {
                ops.push(Op::Feed(dp));
                if let Some(t) = dtb(5) {
                    ops.push(Op::Dwell(t));
                }
                ops.push(Op::SpindleStop);
                let (rpa, rpo, rpap) = (
                    arg(7).unwrap_or(0.0) * unit,
                    arg(8).unwrap_or(0.0) * unit,
                    arg(9).unwrap_or(0.0) * unit,
                );
                ops.push(Op::Shift(rpa, rpo));
                if rpap != 0.0 {
                    ops.push(Op::Rapid(dp + rpap));
                }
                ops.push(Op::Rapid(start));
                ops.push(Op::Shift(-rpa, -rpo));
                let dir = match arg(6).map(|d| d as i64) {
                    Some(4) => SpindleDir::Ccw,
                    Some(5) => SpindleDir::Off,
                    _ => SpindleDir::Cw,
                };
                ops.push(Op::Spindle(dir));
            }
            _ => return Err(fail_arg(format!("CYCLE{} is not supported", cc.code))),
        }
        ops.push(Op::Rapid(rtp));
        let hole = Hole {
            cycle: CycleRef {
                code: cc.code,
                line: cc.line,
            },
            at: [p[pa], p[pb]],
            r: start,
            up_to_r_first: false,
            travel_level: None,
            ops,
        };
        let _ = pn;
        cycle::drill(&mut self.m, &hole)?;
        Ok(())
    }
}

fn is_r(id: &str) -> bool {
    id.len() > 1 && id.starts_with('R') && id[1..].bytes().all(|d| d.is_ascii_digit())
}

fn cycle_code(id: &str) -> Option<u16> {
    match id {
        "CYCLE81" => Some(81),
        "CYCLE82" => Some(82),
        "CYCLE83" => Some(83),
        "CYCLE84" => Some(84),
        "CYCLE85" => Some(85),
        "CYCLE86" => Some(86),
        _ => None,
    }
}

#[allow(dead_code)]
const _UNITS: f64 = MM_PER_INCH;
