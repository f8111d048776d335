//! Motion: G0, G1, G2/G3 and the drilling cycles of both languages.

use super::exec::show_g;
use super::*;

impl Interp<'_, '_> {
    pub(super) fn motion(&mut self, b: &Block) -> Result<(), Fail> {
        let mut g53 = None;
        for &(code, at) in &b.g {
            match code {
                0 => self.set_motion(Motion::Rapid),
                10 => self.set_motion(Motion::Linear),
                20 => self.set_motion(Motion::Cw),
                30 => self.set_motion(Motion::Ccw),
                800 => {
                    self.motion = match self.flavour {
                        Flavour::Fanuc => self.base_motion,
                        Flavour::LinuxCnc => Motion::None,
                    };
                    self.cycle_initial = None;
                    self.m.emit(Event::CycleOff);
                }
                730 | 740 | 760 | 810..=890 => {
                    let c = code / 10;
                    if matches!(c, 87 | 88)
                        || self.flavour == Flavour::LinuxCnc && matches!(c, 74 | 76)
                    {
                        return fail(
                            at,
                            3,
                            format!("canned cycle G{c} is not supported by the interpreter"),
                        );
                    }
                    // The initial level stays from one cycle code to the
                    // next (rs274ngc's cycle_il): only G80 and G0..G3 end it.
                    self.motion = Motion::Cycle(c);
                    self.m.emit(Event::Cycle { code: c });
                }
                530 => g53 = Some(at),
                50..=53 => {
                    return fail(
                        at,
                        4,
                        format!(
                            "G{} (spline) is not supported by the interpreter",
                            show_g(code)
                        ),
                    );
                }
                330 | 331 | 382..=385 => {
                    return fail(
                        at,
                        4,
                        format!(
                            "G{} (threading / probing) is not supported by the interpreter",
                            show_g(code)
                        ),
                    );
                }
                _ => {}
            }
        }
        // Fanuc G04 X…: the X word is the dwell time.
        let dwell_x = self.flavour == Flavour::Fanuc && b.has_g(40).is_some() && !b.has(b'P');
        let uses_axes = dwell_x
            || [100, 280, 300, 920, 520]
                .iter()
                .any(|c| b.has_g(*c).is_some());
        let has_axes = b.has & AXIS_WORDS != 0;
        if uses_axes || !has_axes && !self.full_circle_words(b) {
            return Ok(());
        }
        match self.motion {
            Motion::Rapid | Motion::Linear => self.straight(b, g53),
            Motion::Cw | Motion::Ccw => {
                if let Some(at) = g53 {
                    return fail(at, 3, "G53 applies to G0 and G1 moves only");
                }
                self.arc_move(b)
            }
            Motion::Cycle(c) => self.cycle(b, c),
            Motion::None => {
                let at = first_axis(b);
                fail(
                    at,
                    1,
                    "axis words without a motion mode (G80 is in force): give G0, G1, G2 or G3",
                )
            }
        }
    }

    pub(super) fn set_motion(&mut self, m: Motion) {
        self.motion = m;
        self.base_motion = m;
        self.cycle_initial = None;
    }

    /// An arc block without axis words but with centre words (a full circle).
    fn full_circle_words(&self, b: &Block) -> bool {
        matches!(self.motion, Motion::Cw | Motion::Ccw)
            && (b.has(b'I') || b.has(b'J') || b.has(b'K'))
    }

    fn feed_check(&self, b: &Block, at: usize) -> Result<(), Fail> {
        if self.m.feed_mode == FeedMode::InverseTime && !b.has(b'F') {
            return fail(
                at,
                1,
                "inverse time feed (G93): every feed move needs its F word",
            );
        }
        if self.m.feed <= 0.0 {
            return fail(at, 1, "feed move with a zero feed rate (no F programmed)");
        }
        Ok(())
    }

    fn straight(&mut self, b: &Block, g53: Option<usize>) -> Result<(), Fail> {
        if let Some(at) = g53
            && self.incremental
        {
            return fail(at, 3, "G53 with incremental distance (G91)");
        }
        let rapid = self.motion == Motion::Rapid;
        if !rapid {
            self.feed_check(b, first_axis(b))?;
        }
        let (t, programmed, travel, turned) = self.target(b, g53.is_some())?;
        let kind = if rapid {
            MotionKind::Rapid
        } else {
            MotionKind::Linear
        };
        self.m.machine_frame = g53.is_some();
        self.m.move_to(kind, &t, &travel, turned, programmed);
        self.m.machine_frame = false;
        Ok(())
    }

    fn arc_move(&mut self, b: &Block) -> Result<(), Fail> {
        let at = if b.has & AXIS_WORDS != 0 {
            first_axis(b)
        } else {
            b.pos_of(if b.has(b'I') {
                b'I'
            } else if b.has(b'J') {
                b'J'
            } else {
                b'K'
            })
        };
        self.feed_check(b, at)?;
        let [x, y, z] = self.m.xyz;
        let (Some(x), Some(y), Some(z)) = (x, y, z) else {
            return fail(at, 2, "arcs need a machine with X, Y and Z axes");
        };
        let idx = [x, y, z];
        let start = [self.m.pos[x], self.m.pos[y], self.m.pos[z]];
        let (t, programmed, travel, turned) = self.target(b, false)?;
        let end = [t[x], t[y], t[z]];
        let plane = self.m.state.plane;
        let [pa, pb, _] = plane.axes();
        let letters = [b'I', b'J', b'K'];
        let has_ijk = b.has(letters[pa]) || b.has(letters[pb]);
        let centre = match (b.get(b'R'), has_ijk) {
            (Some(_), true) => return fail(b.pos_of(b'R'), 1, "an arc with both R and I/J/K"),
            (Some(_), false) => Centre::Radius(self.length(b, b'R').unwrap_or(0.0)),
            (None, true) => {
                let off = |l: u8| self.length(b, l).unwrap_or(0.0);
                let (oa, ob) = (off(letters[pa]), off(letters[pb]));
                if self.arc_absolute {
                    Centre::At([oa, ob])
                } else {
                    Centre::At([start[pa] + oa, start[pb] + ob])
                }
            }
            (None, false) => {
                return fail(at, 1, "an arc needs its centre (I, J, K) or its radius (R)");
            }
        };
        let turns = match (self.flavour, b.get(b'P')) {
            (Flavour::LinuxCnc, Some(p)) => {
                let p = super::exec::whole(p, b.pos_of(b'P'), "P")?;
                if p == 0 {
                    return fail(b.pos_of(b'P'), 1, "P0 turns");
                }
                p - 1
            }
            _ => 0,
        };
        let tol = self.m.options.tolerances;
        let cw = self.motion == Motion::Cw;
        let a = arc::arc(plane, cw, start, end, centre, turns, &tol).map_err(|e| Fail {
            at,
            len: 1,
            message: e.to_string(),
        })?;
        let _ = idx;
        self.m
            .move_to(MotionKind::Arc(a), &t, &travel, turned, programmed);
        Ok(())
    }

    /// A drilling cycle block: LinuxCNC's rules (convert_cycle of rs274ngc)
    /// and Fanuc's ("Canned cycle for drilling").
    fn cycle(&mut self, b: &Block, code: u16) -> Result<(), Fail> {
        let [pa, pb, pn] = self.m.state.plane.axes();
        let xyz = self.m.xyz;
        let (Some(ia), Some(ib), Some(inn)) = (xyz[pa], xyz[pb], xyz[pn]) else {
            return fail(
                first_axis(b),
                1,
                "canned cycles need the plane's axes and the axis normal to it",
            );
        };
        let letters = [b'X', b'Y', b'Z'];
        let (la, lb, ln) = (letters[pa], letters[pb], letters[pn]);
        let here = self.m.pos;
        let new_run = self.cycle_initial.is_none();
        let initial = *self.cycle_initial.get_or_insert(here[inn]);
        if let Some(r) = self.length(b, b'R') {
            self.cycle_r = r;
        } else if new_run && self.flavour == Flavour::LinuxCnc {
            return fail(
                first_axis(b),
                1,
                "the first block of a canned cycle needs R",
            );
        }
        if let Some(z) = self.length(b, ln) {
            self.cycle_z = z;
        } else if new_run && self.flavour == Flavour::LinuxCnc {
            return fail(
                first_axis(b),
                1,
                format!("the first block of a canned cycle needs {}", char::from(ln)),
            );
        }
        if let Some(q) = self.length(b, b'Q') {
            self.cycle_q = q;
        }
        if let Some(p) = b.get(b'P') {
            self.cycle_p = match self.flavour {
                Flavour::LinuxCnc => p,
                Flavour::Fanuc => p / 1000.0,
            };
        }
        let repeats = match self.flavour {
            Flavour::LinuxCnc => b.get(b'L'),
            Flavour::Fanuc => b.get(b'K').or(b.get(b'L')),
        };
        let repeats = match repeats {
            Some(l) => super::exec::whole(l, first_axis(b), "L")?,
            None => 1,
        };
        let (mut a, mut bb, r, bottom, inc_a, inc_b) = if self.incremental {
            let r = initial + self.cycle_r;
            let bottom = r + self.cycle_z;
            let da = self.length(b, la).unwrap_or(0.0);
            let db = self.length(b, lb).unwrap_or(0.0);
            (here[ia], here[ib], r, bottom, da, db)
        } else {
            let a = self.length(b, la).unwrap_or(here[ia]);
            let bb = self.length(b, lb).unwrap_or(here[ib]);
            (a, bb, self.cycle_r, self.cycle_z, 0.0, 0.0)
        };
        if r < bottom {
            return fail(
                b.pos_of(b'R'),
                1,
                format!("R plane {r} is below the bottom {bottom} of the cycle"),
            );
        }
        let mut init = initial;
        if init < r {
            init = r;
        }
        let clear = if self.retract_initial { init } else { r };
        let mut ops = Vec::new();
        self.cycle_ops(code, r, bottom, clear, &mut ops)
            .map_err(|m| Fail {
                at: first_axis(b),
                len: 1,
                message: m,
            })?;
        let line = self.m_line();
        for k in 0..repeats {
            if self.incremental {
                a += inc_a;
                bb += inc_b;
            }
            let hole = Hole {
                cycle: CycleRef { code, line },
                at: [a, bb],
                r,
                up_to_r_first: k == 0,
                // rs274ngc: under G98 the tool travels to the hole at the
                // initial level (checked with rs274); Fanuc positions at
                // the level the tool is at.
                travel_level: (k == 0 && self.retract_initial && self.flavour == Flavour::LinuxCnc)
                    .then(|| init.max(self.m.pos[inn])),
                ops: ops.clone(),
            };
            cycle::drill(&mut self.m, &hole)?;
        }
        self.cycle_initial = Some(init);
        Ok(())
    }

    fn m_line(&self) -> usize {
        self.current_pos.line
    }

    /// The cycle from the R plane down and out again.
    fn cycle_ops(
        &mut self,
        code: u16,
        r: f64,
        bottom: f64,
        clear: f64,
        ops: &mut Vec<Op>,
    ) -> Result<(), String> {
        let fanuc = self.flavour == Flavour::Fanuc;
        let delta = match self.flavour {
            // rs274ngc G83_RAPID_DELTA / G73 retract: 0.010 inch.
            Flavour::LinuxCnc => 0.010 * MM_PER_INCH,
            Flavour::Fanuc => match self.m.options.fanuc_peck_clearance_mm {
                Some(d) => d,
                None => {
                    if matches!(code, 73 | 83) {
                        self.m.assume("Fanuc G73 retract / G83 clearance d = 0.5 mm (parameters 5114/5115 not given)".into());
                    }
                    0.5
                }
            },
        };
        let p = self.cycle_p;
        let spindle = self.m.state.spindle;
        // Fanuc's feed-out cycles return to R at feed, then to the initial
        // level at rapid under G98.
        let feed_out = |ops: &mut Vec<Op>| {
            if fanuc {
                ops.push(Op::Feed(r));
                if clear != r {
                    ops.push(Op::Rapid(clear));
                }
            } else {
                ops.push(Op::Feed(clear));
            }
        };
        match code {
            81 => {
                ops.push(Op::Feed(bottom));
                ops.push(Op::Rapid(clear));
            }
            82 => {
                ops.push(Op::Feed(bottom));
                ops.push(Op::Dwell(p));
                ops.push(Op::Rapid(clear));
            }
            73 | 83 => {
                if self.cycle_q <= 0.0 {
                    return Err(format!("G{code} needs a positive peck depth Q"));
                }
                cycle::pecks(ops, r, bottom, self.cycle_q, delta, code == 83)?;
                if fanuc && p > 0.0 {
                    ops.push(Op::Dwell(p));
                }
                ops.push(Op::Rapid(clear));
            }
            84 | 74 => {
                if spindle == SpindleDir::Off {
                    return Err(format!("G{code} tapping with the spindle stopped"));
                }
                ops.push(Op::Feed(bottom));
                if fanuc && p > 0.0 {
                    ops.push(Op::Dwell(p));
                }
                ops.push(Op::SpindleStop);
                ops.push(Op::SpindleReverse);
                if !fanuc && p > 0.0 {
                    ops.push(Op::Dwell(p));
                }
                feed_out(ops);
                ops.push(Op::SpindleStop);
                ops.push(Op::Spindle(spindle));
            }
            85 => {
                ops.push(Op::Feed(bottom));
                if fanuc {
                    feed_out(ops);
                } else {
                    ops.push(Op::Feed(r));
                    if clear != r {
                        ops.push(Op::Rapid(clear));
                    }
                }
            }
            86 => {
                if spindle == SpindleDir::Off {
                    return Err("G86 boring with the spindle stopped".into());
                }
                ops.push(Op::Feed(bottom));
                ops.push(Op::Dwell(p));
                ops.push(Op::SpindleStop);
                ops.push(Op::Rapid(clear));
                ops.push(Op::Spindle(spindle));
            }
            89 => {
                ops.push(Op::Feed(bottom));
                ops.push(Op::Dwell(p));
                feed_out(ops);
            }
            76 => {
                // Fanuc fine boring: oriented stop, shift off the wall by Q,
                // rapid out, shift back.
                ops.push(Op::Feed(bottom));
                if p > 0.0 {
                    ops.push(Op::Dwell(p));
                }
                ops.push(Op::SpindleStop);
                self.m.assume(
                    "Fanuc G76 shift direction +X of the plane (parameters RD1/RD2 = 0)".into(),
                );
                let q = self.cycle_q.abs();
                ops.push(Op::Shift(q, 0.0));
                ops.push(Op::Rapid(clear));
                ops.push(Op::Shift(-q, 0.0));
                ops.push(Op::Spindle(spindle));
            }
            _ => {
                return Err(format!(
                    "canned cycle G{code} is not supported by the interpreter"
                ));
            }
        }
        Ok(())
    }
}

/// Bits of the axis letters.
const AXIS_WORDS: u32 = {
    let mut m = 0u32;
    let mut k = 0;
    while k < AXIS_LETTERS.len() {
        m |= 1 << (AXIS_LETTERS[k] - b'A');
        k += 1;
    }
    m
};

/// Offset of the first axis word of the block (for messages).
fn first_axis(b: &Block) -> usize {
    AXIS_LETTERS
        .iter()
        .filter(|l| b.has(**l))
        .map(|l| b.pos_of(*l))
        .min()
        .unwrap_or(0)
}
