//! Executing one block of words, in the order of execution of rs274ngc
//! (LinuxCNC "G-code overview", "Order of execution"), which Fanuc follows
//! for the words both know.

use super::*;

/// Modal groups of G-codes (× 10) that may appear once per block.
fn g_group(code: u16) -> Option<u8> {
    Some(match code {
        0
        | 10
        | 20
        | 30
        | 50
        | 51
        | 52
        | 53
        | 330
        | 331
        | 382..=385
        | 730
        | 740
        | 760
        | 800..=890 => 1,
        170 | 180 | 190 | 171 | 181 | 191 => 2,
        900 | 910 => 3,
        901 | 911 => 4,
        930 | 940 | 950 => 5,
        200 | 210 | 700 | 710 => 6,
        400 | 410 | 420 | 411 | 421 => 7,
        430 | 431 | 432 | 434 | 435 | 440 | 490 => 8,
        980 | 990 => 10,
        540 | 550 | 560 | 570 | 580 | 590 | 591..=593 | 541 => 12,
        610 | 611 | 640 => 13,
        _ => return None,
    })
}

impl Interp<'_, '_> {
    pub(super) fn execute(&mut self, b: &Block, line: &Line<'_>) -> Result<(), Fail> {
        self.check_groups(b)?;
        for (p, v) in &b.assign {
            self.set_param(p, *v, 0)?;
        }
        if b.m.len() + b.g.len() == 0 && b.has == 0 {
            if let Some(msg) = &b.message {
                self.m.emit(Event::Message(msg.clone()));
            }
            return Ok(());
        }
        if let Some(msg) = &b.message {
            self.m.emit(Event::Message(msg.clone()));
        }
        // Units first: every length and feed word of the block is in them.
        if b.has_g(200).is_some() {
            self.m.set_units(true);
        } else if b.has_g(210).is_some() {
            self.m.set_units(false);
        }
        self.feed_words(b)?;
        self.m_words_before_motion(b, line)?;
        self.dwell(b)?;
        self.modal_g(b)?;
        self.setup_g(b)?;
        self.motion(b)?;
        self.stops(b, line)
    }

    fn check_groups(&self, b: &Block) -> Result<(), Fail> {
        let mut seen = [None::<(u16, usize)>; 16];
        for &(code, at) in &b.g {
            let Some(g) = g_group(code) else {
                continue;
            };
            if let Some((other, _)) = seen[usize::from(g)] {
                return fail(
                    at,
                    2,
                    format!(
                        "G{} and G{} are in the same modal group: one of them per block",
                        show_g(other),
                        show_g(code)
                    ),
                );
            }
            seen[usize::from(g)] = Some((code, at));
        }
        Ok(())
    }

    /// Fanuc literal without a decimal point: least input increments.
    #[inline]
    pub(super) fn scaled(&self, b: &Block, letter: u8) -> Option<f64> {
        let v = b.get(letter)?;
        if is_vacant(v) {
            return None;
        }
        let k = letter - b'A';
        if self.flavour == Flavour::Fanuc
            && !self.m.options.fanuc_calculator_input
            && b.no_point & (1 << k) != 0
        {
            return Some(v * if self.m.inch { 1e-4 } else { 1e-3 });
        }
        Some(v)
    }

    /// A length word in mm.
    #[inline]
    pub(super) fn length(&self, b: &Block, letter: u8) -> Option<f64> {
        self.scaled(b, letter).map(|v| v * self.m.unit())
    }

    fn feed_words(&mut self, b: &Block) -> Result<(), Fail> {
        for (code, mode) in [
            (930, FeedMode::InverseTime),
            (940, FeedMode::PerMinute),
            (950, FeedMode::PerRevolution),
        ] {
            if b.has_g(code).is_some() {
                self.m.set_feed_mode(mode);
            }
        }
        if let Some(f) = b.get(b'F').filter(|v| !is_vacant(*v)) {
            if f < 0.0 {
                return fail(b.pos_of(b'F'), 1, "negative feed");
            }
            self.m.feed = match self.m.feed_mode {
                FeedMode::InverseTime => f,
                _ => f * self.m.unit(),
            };
        }
        if let Some(s) = b.get(b'S').filter(|v| !is_vacant(*v)) {
            if s < 0.0 {
                return fail(b.pos_of(b'S'), 1, "negative spindle speed");
            }
            self.m.set_speed(s);
        }
        if let Some(t) = b.get(b'T').filter(|v| !is_vacant(*v)) {
            let t = whole(t, b.pos_of(b'T'), "T")?;
            self.m.emit(Event::ToolSelect { tool: t });
            self.selected_tool = Some(t);
        }
        Ok(())
    }

    fn m_words_before_motion(&mut self, b: &Block, line: &Line<'_>) -> Result<(), Fail> {
        for &(code, at) in &b.m {
            match code {
                6 => {
                    let t = self.selected_tool.or(self.m.state.tool).unwrap_or(0);
                    self.m.tool_change(t);
                }
                61 if self.flavour == Flavour::LinuxCnc => {
                    let q = b.get(b'Q').ok_or_else(|| Fail {
                        at,
                        len: 3,
                        message: "M61 needs the tool number in Q".into(),
                    })?;
                    let t = whole(q, b.pos_of(b'Q'), "Q")?;
                    self.m.tool_change(t);
                }
                3 => self.m.set_spindle(SpindleDir::Cw),
                4 => self.m.set_spindle(SpindleDir::Ccw),
                5 => self.m.set_spindle(SpindleDir::Off),
                7 => self.m.coolant(Some(true), None),
                8 => self.m.coolant(None, Some(true)),
                9 => self.m.coolant(Some(false), Some(false)),
                62..=65 if self.flavour == Flavour::LinuxCnc => {
                    let p = b.get(b'P').ok_or_else(|| Fail {
                        at,
                        len: 3,
                        message: format!("M{code} needs the output number in P"),
                    })?;
                    let index = whole(p, b.pos_of(b'P'), "P")?;
                    self.m.emit(Event::DigitalOutput {
                        index,
                        on: code == 62 || code == 64,
                        synced: code <= 63,
                    });
                }
                66 if self.flavour == Flavour::LinuxCnc => {
                    let (key, n) = match (b.get(b'P'), b.get(b'E')) {
                        (Some(p), None) => ("M66", whole(p, b.pos_of(b'P'), "P")?),
                        (None, Some(e)) => ("M66E", whole(e, b.pos_of(b'E'), "E")?),
                        _ => {
                            return fail(at, 3, "M66 needs one of P (digital) or E (analog input)");
                        }
                    };
                    let v = self.m.input(&format!("{key}[{n}]"));
                    self.params[5399] = v;
                }
                0 | 1 | 2 | 30 | 60 | 99 | 98 => {}
                48..=53 if self.flavour == Flavour::LinuxCnc => self.m.emit(Event::MCode(code)),
                c if self
                    .m
                    .options
                    .tcp_mcodes
                    .is_some_and(|(on, off)| c == on || c == off) =>
                {
                    let on = self.m.options.tcp_mcodes.is_some_and(|(on, _)| c == on);
                    self.m.set_tcp(on);
                }
                c if self.flavour == Flavour::Fanuc && c == 19 => self.m.emit(Event::MCode(19)),
                c => {
                    let d = diagnostic(
                        self.file,
                        line,
                        Fail {
                            at,
                            len: 1 + c.to_string().len(),
                            message: format!(
                                "M{c} has no meaning for the interpreter (a machine-specific M-code?): passed on, not simulated"
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

    fn dwell(&mut self, b: &Block) -> Result<(), Fail> {
        let Some(at) = b.has_g(40) else {
            return Ok(());
        };
        let seconds = match self.flavour {
            Flavour::LinuxCnc => b.get(b'P').ok_or_else(|| Fail {
                at,
                len: 2,
                message: "G4 needs the dwell time in P (seconds)".into(),
            })?,
            // Fanuc: P in ms (no point), X/U in seconds (least increment
            // 0.001 s without a point).
            Flavour::Fanuc => {
                if let Some(p) = b.get(b'P') {
                    p / 1000.0
                } else if let Some(x) = self.scaled(b, b'X').or(self.scaled(b, b'U')) {
                    x
                } else {
                    return fail(at, 2, "G04 needs the dwell time in P (ms) or X (s)");
                }
            }
        };
        if seconds < 0.0 {
            return fail(at, 2, "negative dwell");
        }
        self.m.dwell(seconds);
        Ok(())
    }

    /// ArcPlane, units, compensation, coordinate system, distance and retract
    /// modes.
    fn modal_g(&mut self, b: &Block) -> Result<(), Fail> {
        for &(code, at) in &b.g {
            match code {
                170 => self.m.set_plane(ArcPlane::Xy),
                180 => self.m.set_plane(ArcPlane::Zx),
                190 => self.m.set_plane(ArcPlane::Yz),
                200 => self.m.set_units(true),
                210 => self.m.set_units(false),
                400 => self.m.set_cutter_comp(CutterComp::Off),
                410 | 411 => self.m.set_cutter_comp(CutterComp::Left),
                420 | 421 => self.m.set_cutter_comp(CutterComp::Right),
                430 | 431 | 432 | 434 | 435 => self.tool_length(b, code, at)?,
                490 => {
                    if self.m.state.tcp {
                        self.m.set_tcp(false);
                    }
                    self.m.set_tool_length(None);
                }
                540 | 550 | 560 | 570 | 580 | 590 => {
                    let k = code / 10 - 53;
                    self.m
                        .select_offset(WorkOffset::Numbered(k), &format!("G{}", code / 10));
                }
                591..=593 => {
                    let k = 6 + (code - 590);
                    self.m
                        .select_offset(WorkOffset::Numbered(k), &format!("G59.{}", code - 590));
                }
                541 => {
                    let p = b.get(b'P').ok_or_else(|| Fail {
                        at,
                        len: 5,
                        message: "G54.1 needs the offset number in P".into(),
                    })?;
                    let p = whole(p, b.pos_of(b'P'), "P")?;
                    self.m.select_offset(
                        WorkOffset::Numbered(100 + p as u16),
                        &format!("G54.1 P{p}"),
                    );
                }
                900 => self.incremental = false,
                910 => self.incremental = true,
                901 => self.arc_absolute = true,
                911 => self.arc_absolute = false,
                980 => self.retract_initial = true,
                990 => self.retract_initial = false,
                // Path control: corner rounding is the controller's; the
                // programmed path is what is reported.
                610 | 611 | 640 | 51 => {}
                _ => {}
            }
        }
        Ok(())
    }

    fn tool_length(&mut self, b: &Block, code: u16, at: usize) -> Result<(), Fail> {
        let h = match b.get(b'H').filter(|v| !is_vacant(*v)) {
            Some(h) => Some(whole(h, b.pos_of(b'H'), "H")?),
            None => self.m.state.tool,
        };
        if code == 431 || code == 432 {
            // LinuxCNC dynamic / added offsets: the tool in the spindle.
            self.m.set_tool_length(self.m.state.tool);
            return Ok(());
        }
        let Some(h) = h else {
            return fail(at, 3, "G43 without H and no tool in the spindle");
        };
        self.m.set_tool_length(Some(h));
        if code == 434 || code == 435 {
            if self.flavour == Flavour::LinuxCnc {
                return fail(
                    at,
                    5,
                    "G43.4/G43.5 is Fanuc's tool centre point control; LinuxCNC does TCP in its kinematics (see Options::tcp_mcodes)",
                );
            }
            self.m.set_tcp(true);
        }
        Ok(())
    }

    /// G10, G28/G30, G92, G52 (the non-modal group 0 besides G4 and G53).
    fn setup_g(&mut self, b: &Block) -> Result<(), Fail> {
        for &(code, at) in &b.g {
            match code {
                100 => self.g10(b, at)?,
                280 | 300 => self.home(b, code, at)?,
                281 | 301 => {}
                920 | 520 => self.g92(b, code)?,
                921 | 922 => {
                    self.m.shift = [0.0; MAX_AXES];
                    self.m.refresh_offset(None);
                    self.m.emit(Event::WorkOffset(self.m.state.work_offset));
                }
                923 => {}
                40 | 530 | 0 | 10 | 20 | 30 | 800..=890 | 730 | 740 | 760 => {}
                170
                | 180
                | 190
                | 200
                | 210
                | 400
                | 410
                | 411
                | 420
                | 421
                | 430
                | 431
                | 432
                | 434
                | 435
                | 490
                | 540
                | 550
                | 560
                | 570
                | 580
                | 590
                | 591..=593
                | 541
                | 900
                | 910
                | 901
                | 911
                | 930
                | 940
                | 950
                | 980
                | 990
                | 610
                | 611
                | 640
                | 51 => {}
                682 | 683 => {
                    return fail(
                        at,
                        5,
                        format!(
                            "G{} (tilted working plane) is not implemented: the virtual machine cannot follow it",
                            show_g(code)
                        ),
                    );
                }
                _ => {
                    return fail(
                        at,
                        1 + show_g(code).len(),
                        format!("G{} is not supported by the interpreter", show_g(code)),
                    );
                }
            }
        }
        Ok(())
    }

    fn g10(&mut self, b: &Block, at: usize) -> Result<(), Fail> {
        let l = b.get(b'L').ok_or_else(|| Fail {
            at,
            len: 3,
            message: "G10 needs L".into(),
        })?;
        let l = whole(l, b.pos_of(b'L'), "L")?;
        let p = whole(b.get(b'P').unwrap_or(0.0), b.pos_of(b'P'), "P")?;
        match (self.flavour, l) {
            (_, 1 | 10 | 11 | 12 | 13) => {
                // Tool table entries: kept, applied by the machine.
                if let Some(z) = self.length(b, b'Z').or(self.length(b, b'R')) {
                    self.tool_lengths.insert(p, z);
                }
                Ok(())
            }
            (_, 2 | 20) => {
                let key: u16 = match (self.flavour, l) {
                    (Flavour::LinuxCnc, _) if p == 0 => match self.m.state.work_offset {
                        WorkOffset::Numbered(k) => k,
                        WorkOffset::None => 1,
                    },
                    (Flavour::LinuxCnc, _) if (1..=9).contains(&p) => p as u16,
                    (Flavour::Fanuc, 2) if (1..=6).contains(&p) => p as u16,
                    (Flavour::Fanuc, 20) if (1..=300).contains(&p) => 100 + p as u16,
                    _ => {
                        return fail(
                            b.pos_of(b'P'),
                            2,
                            format!("G10 L{l}: P{p} is not a work offset"),
                        );
                    }
                };
                let mut o = self.m.offsets.get(&key).copied().unwrap_or([0.0; MAX_AXES]);
                let current = key_in_force(self.m.state.work_offset, key);
                for (k, letter) in AXIS_LETTERS.iter().enumerate() {
                    let Some(i) = self.letter_axis[k] else {
                        continue;
                    };
                    let Some(v) = self.scaled(b, *letter) else {
                        continue;
                    };
                    let v = v * self.m.unit_of(i);
                    let linux_l20 = self.flavour == Flavour::LinuxCnc && l == 20;
                    o[i] = if linux_l20 {
                        // The current point gets coordinate v.
                        self.m.pos[i] + self.m.state.offset[i] - self.m.shift[i] - v
                    } else if self.flavour == Flavour::Fanuc && self.incremental {
                        o[i] + v
                    } else {
                        v
                    };
                }
                self.m.offsets.insert(key, o);
                if current {
                    self.m.refresh_offset(None);
                }
                self.m.emit(Event::WorkOffset(self.m.state.work_offset));
                Ok(())
            }
            _ => fail(b.pos_of(b'L'), 3, format!("G10 L{l} is not supported")),
        }
    }

    /// G28 / G30: rapid to the intermediate point (the axis words), then
    /// to the home position of those axes (all axes without words).
    fn home(&mut self, b: &Block, code: u16, at: usize) -> Result<(), Fail> {
        let (t, programmed, travel, turned) = self.target(b, false)?;
        if programmed != 0 {
            self.m
                .move_to(MotionKind::Rapid, &t, &travel, turned, programmed);
        }
        let base = if code == 280 { 5161 } else { 5181 };
        let mut home = self.m.pos;
        let mut moved = 0u32;
        for k in 0..9 {
            let Some(i) = self.letter_axis[k] else {
                continue;
            };
            if programmed != 0 && programmed & (1 << i) == 0 {
                continue;
            }
            let machine = match self.flavour {
                Flavour::LinuxCnc => self.params[base + k] * self.m.unit_of(i),
                Flavour::Fanuc => {
                    self.m.assume(format!(
                        "G{} reference position = machine zero on every axis (parameter {} not known)",
                        code / 10,
                        if code == 280 { 1240 } else { 1241 }
                    ));
                    0.0
                }
            };
            home[i] = machine - self.m.state.offset[i];
            moved |= 1 << i;
        }
        let _ = at;
        self.m.machine_frame = true;
        self.m
            .move_to(MotionKind::Rapid, &home, &[0.0; MAX_AXES], 0, moved);
        self.m.machine_frame = false;
        Ok(())
    }

    fn g92(&mut self, b: &Block, code: u16) -> Result<(), Fail> {
        for (k, letter) in AXIS_LETTERS.iter().enumerate() {
            let Some(i) = self.letter_axis[k] else {
                continue;
            };
            let Some(v) = self.scaled(b, *letter) else {
                continue;
            };
            let v = v * self.m.unit_of(i);
            self.m.shift[i] = if code == 520 {
                v
            } else {
                // The current point gets coordinate v.
                self.m.shift[i] + self.m.pos[i] - v
            };
        }
        self.m.refresh_offset(None);
        self.m.emit(Event::WorkOffset(self.m.state.work_offset));
        Ok(())
    }

    /// The end point of a move: every axis word resolved.
    pub(super) fn target(
        &mut self,
        b: &Block,
        machine_frame: bool,
    ) -> Result<([f64; MAX_AXES], u32, [f64; MAX_AXES], u32), Fail> {
        let mut t = self.m.pos;
        let mut travel = [0.0; MAX_AXES];
        let (mut programmed, mut turned) = (0u32, 0u32);
        if b.has & AXIS_MASK == 0 {
            return Ok((t, 0, travel, 0));
        }
        for (k, letter) in AXIS_LETTERS.iter().enumerate() {
            if !b.has(*letter) {
                continue;
            }
            let Some(v) = self.scaled(b, *letter) else {
                continue;
            };
            let Some(i) = self.letter_axis[k] else {
                self.foreign_axis(*letter, b.pos_of(*letter));
                continue;
            };
            let v = v * self.m.unit_of(i);
            programmed |= 1 << i;
            if machine_frame {
                t[i] = v - self.m.state.offset[i];
            } else if self.incremental {
                if self.m.axes[i].endless {
                    travel[i] = v;
                    t[i] = super::super::machine::wrap(self.m.pos[i] + v);
                    turned |= 1 << i;
                } else {
                    t[i] = self.m.pos[i] + v;
                }
            } else if self.m.axes[i].endless {
                let (e, d) = self.m.rotary_target(i, v, RotaryMode::Continuous);
                t[i] = e;
                travel[i] = d;
                turned |= 1 << i;
            } else {
                t[i] = v;
            }
        }
        Ok((t, programmed, travel, turned))
    }

    fn foreign_axis(&mut self, letter: u8, at: usize) {
        let bit = 1u32 << (letter - b'A');
        if self.warned_axis & bit != 0 {
            return;
        }
        self.warned_axis |= bit;
        if let Some(line) = self.src.line_at(self.current_pos) {
            let d = diagnostic(
                self.file,
                &line,
                Fail {
                    at,
                    len: 1,
                    message: format!(
                        "{} is not an axis of this machine: its words are not simulated (warned once)",
                        char::from(letter)
                    ),
                },
                true,
            );
            self.m.warn(d);
        }
    }

    fn stops(&mut self, b: &Block, _line: &Line<'_>) -> Result<(), Fail> {
        for &(code, at) in &b.m {
            match code {
                0 | 60 => self.m.emit(Event::Stop(StopKind::Program)),
                1 => self.m.emit(Event::Stop(StopKind::Optional)),
                2 | 30 => {
                    self.m.emit(Event::Stop(StopKind::End));
                    self.ended = true;
                }
                99 if self.flavour == Flavour::Fanuc => self.m99(at)?,
                98 if self.flavour == Flavour::Fanuc => self.m98(b, at)?,
                _ => {}
            }
        }
        Ok(())
    }
}

/// Bits of the axis letters X Y Z A B C U V W in `Block::has`.
const AXIS_MASK: u32 = {
    let mut m = 0u32;
    let letters = AXIS_LETTERS;
    let mut k = 0;
    while k < letters.len() {
        m |= 1 << (letters[k] - b'A');
        k += 1;
    }
    m
};

fn key_in_force(wo: WorkOffset, key: u16) -> bool {
    wo == WorkOffset::Numbered(key)
}

/// `43.4` for 434.
pub(super) fn show_g(code: u16) -> String {
    if code.is_multiple_of(10) {
        format!("{}", code / 10)
    } else {
        format!("{}.{}", code / 10, code % 10)
    }
}

/// A whole non-negative number (tool, offset, output).
pub(super) fn whole(v: f64, at: usize, what: &str) -> Result<u32, Fail> {
    if v >= 0.0 && v <= f64::from(u32::MAX) && v.fract() == 0.0 {
        Ok(v as u32)
    } else {
        fail(at, 1, format!("{what}{v}: a whole number is expected"))
    }
}
