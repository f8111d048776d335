//! Contour blocks (L, CC, C, CR, CT, LP, CP), M functions and cycles.

use super::*;

/// The words of a contour block.
#[derive(Debug, Default)]
pub(super) struct Contour {
    /// Axis values (mm / deg) and whether incremental.
    pub(super) axis: [Option<(f64, bool)>; MAX_AXES],
    pub(super) first_axis_at: Option<usize>,
    /// X Y Z words (for CC, also when the machine lacks an axis).
    pub(super) xyz: [Option<(f64, bool)>; 3],
    pub(super) radius: Option<f64>,
    pub(super) dr: Option<bool>,
    pub(super) pr: Option<(f64, bool)>,
    pub(super) pa: Option<(f64, bool)>,
    pub(super) rapid: bool,
    pub(super) feed: Option<f64>,
    pub(super) per_rev: Option<f64>,
    pub(super) comp: Option<CutterComp>,
    pub(super) m: Vec<(u32, usize)>,
}

const AXIS_LETTERS: &[u8] = b"XYZABCUVW";

impl Interp<'_, '_> {
    fn contour_words(&mut self, line: &Line<'_>, c: &mut Cursor<'_>) -> Result<Contour, Fail> {
        let mut w = Contour::default();
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else { break };
            if ch == b';' {
                break;
            }
            let at = c.i;
            let Some(id) = c.ident().map(Upper::of) else {
                return fail(at, 1, format!("`{}` is not a word here", char::from(ch)));
            };
            self.contour_word(&id, at, line, c, &mut w)?;
        }
        Ok(w)
    }

    fn contour_word(
        &mut self,
        id: &str,
        at: usize,
        line: &Line<'_>,
        c: &mut Cursor<'_>,
        w: &mut Contour,
    ) -> Result<(), Fail> {
        let (inc, name) = match id.strip_prefix('I') {
            Some(rest)
                if !rest.is_empty()
                    && rest.len() <= 2
                    && rest.as_bytes()[0].is_ascii_alphabetic() =>
            {
                (true, rest)
            }
            _ => (false, id),
        };
        // An axis word: X+10, IX-5, A+30, X+Q3 (the identifier may have
        // swallowed digits: X10 → "X10").
        let letter = name.as_bytes()[0];
        if AXIS_LETTERS.contains(&letter)
            && (name.len() == 1 || name[1..].bytes().all(|d| d.is_ascii_digit()))
        {
            c.i = at + usize::from(inc) + 1;
            let v = self.number_value(c)?;
            let k = usize::from(letter);
            if let Some(p) = b"XYZ".iter().position(|x| usize::from(*x) == k) {
                w.xyz[p] = Some((v * self.m.unit(), inc));
            }
            match self.m.axis(&char::from(letter).to_string()) {
                Some(i) => {
                    w.first_axis_at.get_or_insert(at);
                    w.axis[i] = Some((v * self.m.unit_of(i), inc));
                }
                None => {
                    let key = char::from(letter).to_string();
                    self.warn_once(line, &key, at, 1, format!("{key} is not an axis of this machine: its words are not simulated (warned once)"));
                }
            }
            return Ok(());
        }
        match id {
            "R0" => w.comp = Some(CutterComp::Off),
            "RL" => w.comp = Some(CutterComp::Left),
            "RR" => w.comp = Some(CutterComp::Right),
            "DR" => {
                c.skip_ws();
                match c.peek() {
                    Some(b'+') => w.dr = Some(false),
                    Some(b'-') => w.dr = Some(true),
                    _ => return fail(c.i, 1, "DR+ or DR- expected"),
                }
                c.i += 1;
            }
            "PR" | "IPR" | "PA" | "IPA" => {
                let v = self.number_value(c)?;
                let inc = id.starts_with('I');
                if id.ends_with("PR") {
                    w.pr = Some((v * self.m.unit(), inc));
                } else {
                    w.pa = Some((v, inc));
                }
            }
            "FMAX" => w.rapid = true,
            "FAUTO" => {}
            "FZ" => {
                return fail(
                    at,
                    2,
                    "FZ (feed per tooth) needs the tool's teeth: not supported",
                );
            }
            "FU" => w.per_rev = Some(self.number_value(c)? * self.m.unit()),
            _ if id.starts_with('R') => {
                c.i = at + 1;
                w.radius = Some(self.number_value(c)? * self.m.unit());
            }
            _ if id.starts_with('F') => {
                c.i = at + 1;
                w.feed = Some(self.number_value(c)?);
            }
            _ if id.starts_with('M') => {
                c.i = at + 1;
                let Some((n, len)) = read_uint(&c.b[c.i..]) else {
                    return fail(at, 1, "M number expected");
                };
                c.i += len;
                w.m.push((n.min(u64::from(u32::MAX)) as u32, at));
            }
            _ => {
                return fail(
                    at,
                    id.len(),
                    format!("`{id}` is not a word of a contour block"),
                );
            }
        }
        Ok(())
    }

    /// L, CC, C, CR, CT, LP, CP.
    pub(super) fn contour(
        &mut self,
        kind: &str,
        line: &Line<'_>,
        c: &mut Cursor<'_>,
        at: usize,
    ) -> Result<(), Fail> {
        let w = self.contour_words(line, c)?;
        if let Some(f) = w.feed {
            self.m.set_feed_mode(FeedMode::PerMinute);
            self.m.feed = f * self.m.unit();
        }
        if let Some(f) = w.per_rev {
            self.m.set_feed_mode(FeedMode::PerRevolution);
            self.m.feed = f;
        }
        if let Some(comp) = w.comp {
            self.m.set_cutter_comp(comp);
        }
        self.m_codes(line, &w.m, true)?;
        let machine_frame = w.m.iter().any(|(m, _)| *m == 91);
        let moved = match kind {
            "CC" => {
                let p = self.m.xyz_pos();
                let mut cc = self.cc.unwrap_or(p);
                for k in 0..3 {
                    if let Some((v, inc)) = w.xyz[k] {
                        cc[k] = if inc { p[k] + v } else { v };
                    } else if w.xyz.iter().all(Option::is_none) {
                        cc[k] = p[k];
                    }
                }
                self.cc = Some(cc);
                false
            }
            "L" => self.straight(&w, machine_frame, at)?,
            "LP" => self.polar_line(&w, at)?,
            _ => self.arc_block(kind, &w, at)?,
        };
        if moved && (w.m.iter().any(|(m, _)| *m == 99) || self.modal_call) {
            self.call_cycle(at)?;
        }
        self.m_codes(line, &w.m, false)
    }

    /// The target of the axis words (rotary: the shortest way under M126).
    fn targets(
        &mut self,
        w: &Contour,
        machine_frame: bool,
    ) -> ([f64; MAX_AXES], [f64; MAX_AXES], u32, u32) {
        let mut t = self.m.pos;
        let mut travel = [0.0; MAX_AXES];
        let (mut programmed, mut turned) = (0u32, 0u32);
        for i in 0..self.m.n {
            let Some((v, inc)) = w.axis[i] else { continue };
            programmed |= 1 << i;
            if machine_frame {
                t[i] = v - self.m.state.offset[i];
            } else if inc {
                if self.m.axes[i].endless {
                    travel[i] = v;
                    t[i] = super::super::machine::wrap(self.m.pos[i] + v);
                    turned |= 1 << i;
                } else {
                    t[i] = self.m.pos[i] + v;
                }
            } else if self.m.axes[i].rotary {
                let mode = if self.shortest {
                    RotaryMode::Shortest
                } else {
                    RotaryMode::Continuous
                };
                let (e, d) = self.m.rotary_target(i, v, mode);
                t[i] = e;
                travel[i] = d;
                turned |= 1 << i;
            } else {
                t[i] = v;
            }
        }
        (t, travel, programmed, turned)
    }

    pub(super) fn straight(
        &mut self,
        w: &Contour,
        machine_frame: bool,
        at: usize,
    ) -> Result<bool, Fail> {
        let (t, travel, programmed, turned) = self.targets(w, machine_frame);
        if programmed == 0 {
            return Ok(false);
        }
        if !w.rapid && self.m.feed <= 0.0 {
            return fail(
                w.first_axis_at.unwrap_or(at),
                1,
                "feed move with a zero feed rate (no F programmed)",
            );
        }
        let kind = if w.rapid {
            MotionKind::Rapid
        } else {
            MotionKind::Linear
        };
        let before = self.m.xyz_pos();
        self.m.machine_frame = machine_frame;
        self.m.move_to(kind, &t, &travel, turned, programmed);
        self.m.machine_frame = false;
        self.note_tangent(before, None);
        Ok(true)
    }

    /// LP PR… PA…: a straight line to polar coordinates about the pole.
    fn polar_line(&mut self, w: &Contour, at: usize) -> Result<bool, Fail> {
        let Some(pole) = self.cc else {
            return fail(at, 2, "LP needs a pole: program CC first");
        };
        let [pa, pb, _] = self.m.state.plane.axes();
        let p = self.m.xyz_pos();
        let (r0, a0) = (
            (p[pa] - pole[pa]).hypot(p[pb] - pole[pb]),
            (p[pb] - pole[pb]).atan2(p[pa] - pole[pa]).to_degrees(),
        );
        let r = match w.pr {
            Some((v, true)) => r0 + v,
            Some((v, false)) => v,
            None => r0,
        };
        let a = match w.pa {
            Some((v, true)) => a0 + v,
            Some((v, false)) => v,
            None => a0,
        };
        let mut w2 = Contour {
            axis: w.axis,
            rapid: w.rapid,
            ..Contour::default()
        };
        for (k, v) in [
            (pa, pole[pa] + r * a.to_radians().cos()),
            (pb, pole[pb] + r * a.to_radians().sin()),
        ] {
            if let Some(i) = self.m.xyz[k] {
                w2.axis[i] = Some((v, false));
            }
        }
        w2.first_axis_at = Some(at);
        self.straight(&w2, false, at)
    }

    /// C, CR, CT, CP.
    fn arc_block(&mut self, kind: &str, w: &Contour, at: usize) -> Result<bool, Fail> {
        let [Some(x), Some(y), Some(z)] = self.m.xyz else {
            return fail(at, 1, "arcs need a machine with X, Y and Z axes");
        };
        if self.m.feed <= 0.0 {
            return fail(at, 1, "arc with a zero feed rate (no F programmed)");
        }
        let plane = self.m.state.plane;
        let [pa, pb, pn] = plane.axes();
        let start = self.m.xyz_pos();
        let mut w2 = Contour {
            axis: w.axis,
            ..Contour::default()
        };
        let mut turns = 0;
        if kind == "CP" {
            // Polar arc: about the pole to the angle PA (IPA may exceed a turn).
            let Some(pole) = self.cc else {
                return fail(at, 2, "CP needs a pole: program CC first");
            };
            let r = (start[pa] - pole[pa]).hypot(start[pb] - pole[pb]);
            let a0 = (start[pb] - pole[pb])
                .atan2(start[pa] - pole[pa])
                .to_degrees();
            let a = match w.pa {
                Some((v, true)) => {
                    turns = (v.abs() / 360.0).floor() as u32;
                    if (v.abs() / 360.0).fract() == 0.0 && turns > 0 {
                        turns -= 1;
                    }
                    a0 + v
                }
                Some((v, false)) => v,
                None => return fail(at, 2, "CP needs PA or IPA"),
            };
            for (k, v) in [
                (pa, pole[pa] + r * a.to_radians().cos()),
                (pb, pole[pb] + r * a.to_radians().sin()),
            ] {
                if let Some(i) = self.m.xyz[k] {
                    w2.axis[i] = Some((v, false));
                }
            }
        }
        let (t, travel, programmed, turned) = self.targets(&w2, false);
        let end = [t[x], t[y], t[z]];
        let tol = self.m.options.tolerances;
        let err = |e: super::super::arc::ArcError| Fail {
            at,
            len: 1,
            message: e.to_string(),
        };
        let a = match kind {
            "C" | "CP" => {
                let Some(cc) = self.cc else {
                    return fail(at, 1, "C needs the circle centre: program CC first");
                };
                let cw = w.dr.ok_or_else(|| Fail {
                    at,
                    len: 1,
                    message: "C needs its direction DR+ or DR-".into(),
                })?;
                arc::arc(
                    plane,
                    cw,
                    start,
                    end,
                    Centre::At([cc[pa], cc[pb]]),
                    turns,
                    &tol,
                )
                .map_err(err)?
            }
            "CR" => {
                let r = w.radius.ok_or_else(|| Fail {
                    at,
                    len: 2,
                    message: "CR needs its radius R".into(),
                })?;
                let cw = w.dr.ok_or_else(|| Fail {
                    at,
                    len: 2,
                    message: "CR needs its direction DR+ or DR-".into(),
                })?;
                // R > 0: the shorter arc (< 180°); R < 0: the longer one.
                arc::arc(plane, cw, start, end, Centre::Radius(r), 0, &tol).map_err(err)?
            }
            _ => {
                let Some(tg) = self.tangent.and_then(super::super::arc::end_tangent) else {
                    return fail(at, 2, "CT needs a contour element before it (its tangent)");
                };
                let (c, cw) = arc::tangent_centre(
                    [start[pa], start[pb]],
                    [tg[pa], tg[pb]],
                    [end[pa], end[pb]],
                )
                .ok_or_else(|| Fail {
                    at,
                    len: 2,
                    message: "CT: the end point lies on the tangent".into(),
                })?;
                arc::arc(plane, cw, start, end, Centre::At(c), 0, &tol).map_err(err)?
            }
        };
        let _ = pn;
        let arc_copy = a;
        self.m
            .move_to(MotionKind::Arc(a), &t, &travel, turned, programmed);
        self.note_tangent(start, Some(arc_copy));
        Ok(true)
    }

    pub(super) fn note_tangent(&mut self, before: [f64; 3], arc: Option<super::super::Arc>) {
        let after = self.m.xyz_pos();
        if arc.is_some() || after != before {
            self.tangent = Some((before, after, arc));
        }
    }

    /// M functions on a line of their own.
    pub(super) fn m_words(&mut self, line: &Line<'_>, c: &mut Cursor<'_>) -> Result<(), Fail> {
        let mut ms = Vec::new();
        loop {
            c.skip_ws();
            let Some(ch) = c.peek() else { break };
            if ch == b';' {
                break;
            }
            let at = c.i;
            if !matches!(ch, b'M' | b'm') {
                return fail(at, 1, "M function expected");
            }
            c.i += 1;
            let Some((n, len)) = read_uint(&c.b[c.i..]) else {
                return fail(at, 1, "M number expected");
            };
            c.i += len;
            ms.push((n.min(u64::from(u32::MAX)) as u32, at));
        }
        self.m_codes(line, &ms, true)?;
        if ms.iter().any(|(m, _)| *m == 99) {
            self.call_cycle(0)?;
        }
        self.m_codes(line, &ms, false)
    }

    /// M functions effective at the start of the block (`start`) or at its
    /// end.
    fn m_codes(&mut self, line: &Line<'_>, ms: &[(u32, usize)], start: bool) -> Result<(), Fail> {
        for &(code, at) in ms {
            let at_start = matches!(code, 3 | 4 | 7 | 8 | 13 | 14 | 89 | 91 | 126 | 127 | 128);
            if at_start != start {
                continue;
            }
            match code {
                3 => self.m.set_spindle(SpindleDir::Cw),
                4 => self.m.set_spindle(SpindleDir::Ccw),
                5 => self.m.set_spindle(SpindleDir::Off),
                7 => self.m.coolant(Some(true), None),
                8 => self.m.coolant(None, Some(true)),
                9 => self.m.coolant(Some(false), Some(false)),
                13 | 14 => {
                    self.m.set_spindle(if code == 13 {
                        SpindleDir::Cw
                    } else {
                        SpindleDir::Ccw
                    });
                    self.m.coolant(None, Some(true));
                }
                0 => self.m.emit(Event::Stop(StopKind::Program)),
                1 => self.m.emit(Event::Stop(StopKind::Optional)),
                2 | 30 => {
                    self.m.emit(Event::Stop(StopKind::End));
                    self.ended = true;
                }
                89 => self.modal_call = true,
                99 | 91 => {}
                126 => self.shortest = true,
                127 => self.shortest = false,
                128 => self.m.set_tcp(true),
                129 => self.m.set_tcp(false),
                92 | 140 => {
                    return fail(
                        at,
                        4,
                        format!("M{code} is not supported by the interpreter"),
                    );
                }
                c => {
                    let key = format!("M{c}");
                    self.warn_once(line, &key, at, key.len(), format!("{key} has no meaning for the interpreter (a machine-specific M function?): passed on, not simulated"));
                    self.m.emit(Event::MCode(c));
                }
            }
        }
        Ok(())
    }

    /// `CYCL DEF n NAME`, `CYCL DEF 7.1 X+10`, `CYCL CALL [POS …]`.
    pub(super) fn cycl(
        &mut self,
        line: &Line<'_>,
        c: &mut Cursor<'_>,
        at: usize,
    ) -> Result<(), Fail> {
        if c.eat_kw("CALL", true) {
            if c.eat_kw("POS", true) {
                let mut w = self.contour_words(line, c)?;
                w.rapid = true;
                self.m_codes(line, &w.m, true)?;
                self.straight(&w, false, at)?;
                self.call_cycle(at)?;
                return self.m_codes(line, &w.m, false);
            }
            let w = self.contour_words(line, c)?;
            if let Some(f) = w.feed {
                self.m.feed = f * self.m.unit();
            }
            self.m_codes(line, &w.m, true)?;
            self.call_cycle(at)?;
            return self.m_codes(line, &w.m, false);
        }
        if !c.eat_kw("DEF", true) {
            return fail(at, 4, "CYCL DEF or CYCL CALL expected");
        }
        c.skip_ws();
        let n_at = c.i;
        let Some(n) = read_number(&c.b[c.i..]) else {
            return fail(c.i, 1, "cycle number expected");
        };
        c.i += n.len;
        let major = n.value.trunc() as u32;
        let minor = ((n.value - n.value.trunc()) * 10.0).round() as u32;
        match (major, minor) {
            (200 | 201 | 203 | 207, _) => {
                self.cycle = Some(CycleDef {
                    code: major as u16,
                    line: line.no,
                });
                self.m.emit(Event::Cycle { code: major as u16 });
            }
            (7, 0) | (9, 0) | (32, _) => {}
            (7, _) => {
                let w = self.contour_words(line, c)?;
                for i in 0..self.m.n {
                    if let Some((v, inc)) = w.axis[i] {
                        self.m.shift[i] = if inc { self.m.shift[i] + v } else { v };
                    }
                }
                self.m.refresh_offset(None);
                self.m.emit(Event::WorkOffset(self.m.state.work_offset));
            }
            (9, _) => {
                c.eat_kw("DWELL", true);
                let v = self.number_value(c)?;
                self.m.dwell(v);
            }
            (247, _) => {
                // The preset number follows as Q339.
                self.pending_preset = true;
            }
            _ => {
                return fail(
                    n_at,
                    n.len,
                    format!(
                        "cycle {} is not supported by the interpreter (200, 201, 203, 207, 7, 9, 32 and 247 are)",
                        n.value
                    ),
                );
            }
        }
        Ok(())
    }

    /// Runs the defined cycle at the current position.
    fn call_cycle(&mut self, at: usize) -> Result<(), Fail> {
        let Some(def) = self.cycle.clone() else {
            return fail(at, 1, "cycle call without a cycle definition (CYCL DEF)");
        };
        let [pa, pb, _] = self.m.state.plane.axes();
        let p = self.m.xyz_pos();
        let q = |k: usize| self.q[k];
        let surface = q(203) * self.m.unit();
        let clearance = q(200).abs() * self.m.unit();
        let depth = q(201) * self.m.unit();
        let second = q(204).abs() * self.m.unit();
        let r = surface + clearance;
        let bottom = surface - depth.abs();
        let plunge_feed = q(206) * self.m.unit();
        let mut ops = Vec::new();
        match def.code {
            200 => {
                let step = q(202).abs() * self.m.unit();
                let step = if step <= 0.0 { depth.abs() } else { step };
                let mut d = surface;
                let mut n = 0;
                loop {
                    d = (d - step).max(bottom);
                    ops.push(Op::FeedAt(d, plunge_feed));
                    if d <= bottom {
                        break;
                    }
                    ops.push(Op::Rapid(r));
                    if q(210) > 0.0 {
                        ops.push(Op::Dwell(q(210)));
                    }
                    ops.push(Op::Rapid(d + clearance));
                    n += 1;
                    if n > 100_000 {
                        return fail(at, 1, "cycle 200 makes more than 100000 pecks");
                    }
                }
                if q(211) > 0.0 {
                    ops.push(Op::Dwell(q(211)));
                }
                ops.push(Op::Rapid(r));
            }
            201 => {
                ops.push(Op::FeedAt(bottom, plunge_feed));
                if q(211) > 0.0 {
                    ops.push(Op::Dwell(q(211)));
                }
                let back = if q(208) > 0.0 {
                    q(208) * self.m.unit()
                } else {
                    plunge_feed
                };
                ops.push(Op::FeedAt(r, back));
            }
            203 => self.universal_drilling(&mut ops, surface, bottom, r, clearance, at)?,
            207 => {
                let speed = self.m.state.spindle_speed;
                if speed <= 0.0 {
                    return fail(at, 1, "cycle 207 (rigid tapping) with no spindle speed");
                }
                let pitch = q(239) * self.m.unit();
                let feed = pitch.abs() * speed;
                let saved = self.m.state.spindle;
                ops.push(Op::Spindle(if pitch >= 0.0 {
                    SpindleDir::Cw
                } else {
                    SpindleDir::Ccw
                }));
                ops.push(Op::FeedAt(bottom, feed));
                ops.push(Op::SpindleReverse);
                ops.push(Op::FeedAt(r, feed));
                ops.push(Op::Spindle(saved));
            }
            _ => return fail(at, 1, format!("cycle {} cannot be called", def.code)),
        }
        if second > 0.0 {
            ops.push(Op::Rapid(surface + second));
        }
        let hole = Hole {
            cycle: CycleRef {
                code: def.code,
                line: def.line,
            },
            at: [p[pa], p[pb]],
            r,
            up_to_r_first: false,
            travel_level: None,
            ops,
        };
        cycle::drill(&mut self.m, &hole)?;
        Ok(())
    }

    /// Cycle 203: plunges that shrink by Q212 down to Q205, chip breaks by
    /// Q256 (at the retraction feed Q208) for Q213 plunges, then a full
    /// retract to the set-up clearance with the dwell Q210.
    fn universal_drilling(
        &mut self,
        ops: &mut Vec<Op>,
        surface: f64,
        bottom: f64,
        r: f64,
        clearance: f64,
        at: usize,
    ) -> Result<(), Fail> {
        let u = self.m.unit();
        let q = |k: usize| self.q[k];
        let feed = q(206) * u;
        let back = if q(208) > 0.0 { q(208) * u } else { feed };
        let decrement = q(212).abs() * u;
        let min_step = q(205).abs() * u;
        let breaks = q(213).max(0.0) as u32;
        let chip = if q(256) > 0.0 { q(256) * u } else { 0.2 };
        let mut step = q(202).abs() * u;
        if step <= 0.0 {
            step = surface - bottom;
        }
        let mut d = surface;
        let mut count = 0u32;
        let mut n = 0;
        loop {
            d = (d - step).max(bottom);
            ops.push(Op::FeedAt(d, feed));
            if d <= bottom {
                break;
            }
            count += 1;
            if count <= breaks {
                ops.push(Op::FeedAt(d + chip, back));
            } else {
                ops.push(Op::FeedAt(r, back));
                if q(210) > 0.0 {
                    ops.push(Op::Dwell(q(210)));
                }
                ops.push(Op::Rapid(d + clearance));
                count = 0;
            }
            if decrement > 0.0 {
                step = (step - decrement).max(min_step).max(1e-3);
            }
            n += 1;
            if n > 100_000 {
                return fail(at, 1, "cycle 203 makes more than 100000 plunges");
            }
        }
        if q(211) > 0.0 {
            ops.push(Op::Dwell(q(211)));
        }
        ops.push(Op::FeedAt(r, back));
        Ok(())
    }
}
