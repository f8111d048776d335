//! The program stage's statements beyond plain moves, out of the points'
//! loop: arcs (`CIRCLE`) and splines (`NURBS`) linearized into CL points,
//! canned cycles (`CYCLE`) expanded into moves per hole, stops, dwells,
//! the home move, cutter compensation, surface speeds, frames, clamps.
//! Every point made here goes through the planner and the closed-loop
//! check like a `GOTO` of the file, at the line of the statement it comes
//! from.

use std::f64::consts::PI;
use std::io::BufRead;

use kinpost_cl::{
    Arc, Circle, ClEvent, ClReader, CutcomSide, Dwell, Motion, Move, Nurbs, Plane, SpindleSpeed,
    Vec3,
};
use kinpost_diag::Severity;
use kinpost_machine::OutputMode;
use kinpost_machine::tolerance::DEFAULT_LINTOL_MM;
use kinpost_nc::Spindle;

use super::{Program, ProgramSink, locate};
use crate::command::Command;
use crate::config::{ArcMode, CycleMode, FeedMode, InsertMode};
use crate::cycle::{CycleError, HoleCycle, HoleStep};
use crate::error::{PostError, ProgramError};

/// What the `GOTO`s mean while it is set: the end of an arc, or holes.
#[derive(Debug, Default)]
pub(super) struct Modal {
    /// The `CIRCLE` whose arc the next `GOTO` ends.
    arc: Option<PendingArc>,
    /// The canned cycle on.
    cycle: Option<ActiveCycle>,
}

/// A `CIRCLE` and where its arc starts.
#[derive(Debug)]
struct PendingArc {
    circle: Box<Circle>,
    /// The current point when the `CIRCLE` was read.
    start: Vec3,
    /// The tool axis there.
    axis: Vec3,
}

/// A canned cycle and where the tool is.
#[derive(Debug)]
struct ActiveCycle {
    hole: HoleCycle,
    /// The tool's point: where the last hole left it (`None`: nowhere
    /// known yet, the cycle opens the program).
    at: Option<Vec3>,
}

/// The axis a fraction `t` of the way from `a` to `b` (normalized linear
/// blend); `b` itself when they are the same (the usual 3-axis arc), so
/// that the points carry the CL's axis exactly.
fn blend_axis(a: Vec3, b: Vec3, t: f64) -> Vec3 {
    if a == b {
        return b;
    }
    let v = [0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t);
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n < 1e-9 { b } else { v.map(|x| x / n) }
}

/// The first address word of `text` that moves an axis or changes a tool
/// (an axis letter X Y Z A B C U V W, `T` or `H`, with a number; `G0` to
/// `G3`; `M6`), as written.
fn moving_word(text: &str) -> Option<&str> {
    let bytes = text.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i].to_ascii_uppercase();
        // G-code words follow one another, a blank or a comment: after the
        // start, a blank, a digit (`X10Y20`) or `)`; a letter after `=` or
        // inside a name (`HOLDER=C40-32ER`) starts none.
        let starts_word =
            i == 0 || matches!(bytes[i - 1], b' ' | b'\t' | b')') || bytes[i - 1].is_ascii_digit();
        let mut j = i + 1;
        if starts_word && c.is_ascii_alphabetic() {
            if j < bytes.len() && (bytes[j] == b'=' || bytes[j] == b'-' || bytes[j] == b'+') {
                j += 1;
            }
            let digits = j;
            while j < bytes.len() && (bytes[j].is_ascii_digit() || bytes[j] == b'.') {
                j += 1;
            }
            let ends_word = j == bytes.len()
                || bytes[j].is_ascii_alphabetic()
                || matches!(bytes[j], b' ' | b'\t' | b'(' | b';');
            if j > digits && ends_word && bytes[digits..j].iter().any(u8::is_ascii_digit) {
                let number: f64 = text[digits..j].parse().unwrap_or(f64::NAN);
                let moves = match c {
                    b'X' | b'Y' | b'Z' | b'A' | b'B' | b'C' | b'U' | b'V' | b'W' | b'T' => true,
                    b'G' => (0.0..=3.0).contains(&number) && number.fract() == 0.0,
                    b'M' => number == 6.0,
                    _ => false,
                };
                if moves {
                    return Some(&text[i..j]);
                }
            }
        }
        i = j.max(i + 1);
    }
    None
}

fn plane_name(plane: Plane) -> &'static str {
    match plane {
        Plane::Xy => "XY",
        Plane::Yz => "YZ",
        Plane::Zx => "ZX",
    }
}

impl Program<'_> {
    /// The chord tolerance of arcs and splines: `--lintol`, or its default
    /// when linearization is off (`--lintol 0`: a curve must still be cut
    /// into lines).
    fn chord_tolerance_mm(&self) -> f64 {
        if self.config.lintol_mm > 0.0 {
            self.config.lintol_mm
        } else {
            DEFAULT_LINTOL_MM
        }
    }

    /// A `GOTO` while an arc waits for its end or a cycle is on.
    #[cold]
    #[inline(never)]
    pub(super) fn modal_goto<R: BufRead, S: ProgramSink>(
        &mut self,
        goto: &Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        let Some(modal) = self.modal.as_mut() else {
            return self.goto(goto, reader, sink);
        };
        if let Some(arc) = modal.arc.take() {
            self.settle_modal();
            return self.arc_to(arc, goto, reader, sink);
        }
        if modal.cycle.is_some() {
            return self.hole(goto, reader, sink);
        }
        self.settle_modal();
        self.goto(goto, reader, sink)
    }

    /// No arc waits and no cycle is on: back to the fast path.
    fn settle_modal(&mut self) {
        if self
            .modal
            .as_ref()
            .is_some_and(|m| m.arc.is_none() && m.cycle.is_none())
        {
            self.modal = None;
        }
    }

    fn modal_mut(&mut self) -> &mut Modal {
        self.modal.get_or_insert_with(Box::default)
    }

    /// The arc of `pending` to the `GOTO`: points along it within the
    /// chord tolerance (equal angles), each with the tool axis blended from
    /// the start's to the `GOTO`'s, the last the `GOTO` itself. Where a
    /// circular block may be written (see [`Program::native_arc_pieces`]),
    /// the points of each piece stand between [`Command::ArcBegin`] and
    /// [`Command::ArcEnd`]: the closed-loop check writes them as one block
    /// where the machine can.
    fn arc_to<R: BufRead, S: ProgramSink>(
        &mut self,
        pending: PendingArc,
        goto: &Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        let arc = pending
            .circle
            .arc(pending.start, goto.point)
            .map_err(|e| PostError::from(locate(reader, ProgramError::Arc(e))))?;
        let counted = self.report.cl_points;
        if let Some(pieces) = self.native_arc_pieces(&arc, &pending, goto, reader)? {
            // The points of the whole arc, as --arcs linear has them (their
            // number rounded up to a multiple of the pieces), so that an
            // arc the check writes as lines is mostly written as there.
            let segments = arc
                .segments(self.chord_tolerance_mm())
                .map_err(|e| PostError::from(locate(reader, ProgramError::Sample(e))))?;
            let per_piece = segments.div_ceil(pieces.len());
            let total = (per_piece * pieces.len()) as f64;
            let mut m = *goto;
            for (j, piece) in pieces.into_iter().enumerate() {
                let begin = Command::ArcBegin {
                    arc: Box::new(piece),
                    xy_only: self.cutcom_on,
                };
                self.command(begin, reader, sink)?;
                for k in j * per_piece + 1..=(j + 1) * per_piece {
                    m.point = arc.point_at(k as f64 / total);
                    self.goto(&m, reader, sink)?;
                }
                self.command(Command::ArcEnd, reader, sink)?;
            }
        } else {
            let points = arc
                .sample(self.chord_tolerance_mm())
                .map_err(|e| PostError::from(locate(reader, ProgramError::Sample(e))))?;
            let n = points.len();
            let mut m = *goto;
            for (k, p) in points.iter().take(n.saturating_sub(1)).enumerate() {
                m.point = *p;
                m.axis = blend_axis(pending.axis, goto.axis, (k + 1) as f64 / n as f64);
                self.goto(&m, reader, sink)?;
            }
            self.goto(goto, reader, sink)?;
        }
        // The summary counts the CL's points: the arc is its GOTO.
        self.report.cl_points = counted + 1;
        Ok(())
    }

    /// The pieces of `arc` to offer as circular blocks: none (`None`) with
    /// `--arcs linear`, tool-centre-point output, a feed mode other than
    /// `tip` (a circular block has one feed word), a dialect without arc
    /// words, a rapid, or a tool axis that changes along the arc; the arc
    /// itself, or half turns where it turns a whole circle or more (a
    /// full circle is written as two halves: portable, and no controller
    /// takes a start equal to the end for a point).
    fn native_arc_pieces<R: BufRead>(
        &self,
        arc: &Arc,
        pending: &PendingArc,
        goto: &Move,
        reader: &ClReader<R>,
    ) -> Result<Option<Vec<Arc>>, PostError> {
        let c = self.config;
        if c.arcs != ArcMode::Native
            || c.output != OutputMode::Joint
            || c.feed_mode != FeedMode::Tip
            || self.dialect.arc_words().is_none()
            || goto.motion != Motion::Feed
            || pending.axis != goto.axis
        {
            return Ok(None);
        }
        let full = std::f64::consts::TAU;
        if arc.sweep_rad() < full - 1e-9 {
            return Ok(Some(vec![arc.clone()]));
        }
        let halves = (2.0 * arc.sweep_rad() / full).round().max(2.0) as usize;
        let mut pieces = Vec::with_capacity(halves);
        let mut from = arc.start();
        for k in 1..=halves {
            let to = arc.point_at(k as f64 / halves as f64);
            let piece = Arc::new(from, to, arc.centre(), arc.axis(), 1)
                .map_err(|e| PostError::from(locate(reader, ProgramError::Arc(e))))?;
            pieces.push(piece);
            from = to;
        }
        Ok(Some(pieces))
    }

    /// A `NURBS`: its points within the chord tolerance, at the feed, with
    /// the current tool axis; `last` ends at the curve's end.
    fn nurbs<R: BufRead, S: ProgramSink>(
        &mut self,
        nurbs: &Nurbs,
        line: usize,
        last: &mut Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        let points = nurbs
            .sample(self.chord_tolerance_mm())
            .map_err(|e| PostError::from(locate(reader, ProgramError::Sample(e))))?;
        last.line = line;
        last.motion = Motion::Feed;
        let counted = self.report.cl_points;
        for p in points {
            last.point = p;
            self.goto(last, reader, sink)?;
        }
        self.report.cl_points = counted + 1;
        Ok(())
    }

    /// A hole of the cycle on: its moves from where the tool is, at the
    /// cycle's feed, with its dwell and spindle reversals.
    fn hole<R: BufRead, S: ProgramSink>(
        &mut self,
        goto: &Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        let Some(cycle) = self.modal.as_ref().and_then(|m| m.cycle.as_ref()) else {
            return self.goto(goto, reader, sink);
        };
        let steps = match cycle.at {
            Some(from) => cycle.hole.expand(goto.point, goto.axis, from),
            None => cycle.hole.expand_from_unknown(goto.point, goto.axis),
        };
        let feed = Some(cycle.hole.feed_mm_min);
        let native = self.config.cycles == CycleMode::Native;
        if native {
            let begin = Command::HoleBegin {
                cycle: Box::new(cycle.hole.clone()),
                rpm: self.rpm,
                ccw: self.spindle_ccw,
            };
            self.command(begin, reader, sink)?;
        }
        let saved = std::mem::replace(&mut self.feed, feed);
        let mut m = *goto;
        let mut at = None;
        let counted = self.report.cl_points;
        for step in steps {
            match step {
                HoleStep::Rapid(p) | HoleStep::Feed(p) => {
                    m.point = p;
                    m.motion = if matches!(step, HoleStep::Rapid(_)) {
                        Motion::Rapid
                    } else {
                        Motion::Feed
                    };
                    self.goto(&m, reader, sink)?;
                    at = Some(p);
                }
                HoleStep::Dwell(s) => self.command(Command::Dwell(s), reader, sink)?,
                HoleStep::ReverseSpindle(reverse) => {
                    let Some(rpm) = self.rpm else {
                        let e = ProgramError::Cycle(CycleError::TapWithoutSpindle);
                        return Err(locate(reader, e).into());
                    };
                    let state = if self.spindle_ccw != reverse {
                        Spindle::Ccw(rpm)
                    } else {
                        Spindle::Cw(rpm)
                    };
                    self.command(Command::Spindle(state), reader, sink)?;
                }
            }
        }
        self.feed = saved;
        if native {
            self.command(Command::HoleEnd, reader, sink)?;
        }
        // The summary counts the CL's points: the hole is its GOTO.
        self.report.cl_points = counted + 1;
        if let Some(p) = at
            && let Some(c) = self.modal.as_mut().and_then(|m| m.cycle.as_mut())
        {
            c.at = Some(p);
        }
        Ok(())
    }

    /// A tool change while a canned cycle is on (SOLIDWORKS CAM writes no
    /// `CYCLE/OFF` after some drilling operations): the cycle belongs to
    /// its operation and ends here, with a warning; the `GOTO`s after the
    /// change are plain moves.
    #[cold]
    #[inline(never)]
    pub(super) fn end_cycle_at_tool_change<R: BufRead>(
        &mut self,
        last: &mut Move,
        reader: &ClReader<R>,
    ) {
        if let Some(c) = self.modal.as_mut().and_then(|m| m.cycle.take()) {
            if let Some(p) = c.at {
                last.point = p;
            }
            self.report.warnings.push(reader.statement_diagnostic(
                Severity::Warning,
                "the tool change ends the canned cycle on (the CL gives no CYCLE/OFF): the GOTOs after it are plain moves",
            ));
        }
        self.settle_modal();
    }

    /// `INSERT/text` as `--insert` says: verbatim (with a warning when the
    /// text has an address word that moves an axis or changes a tool: a
    /// note written as `INSERT` would become a motion block), as a
    /// comment, or not at all.
    pub(super) fn insert<R: BufRead, S: ProgramSink>(
        &mut self,
        text: String,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        match self.config.insert {
            InsertMode::Verbatim => {
                if let Some(word) = moving_word(&text) {
                    self.report.warnings.push(reader.statement_diagnostic(
                        Severity::Warning,
                        format!(
                            "INSERT is written as code, and its `{word}` moves an axis or changes a tool; if it is a note, give --insert comment"
                        ),
                    ));
                }
                self.command(Command::Insert(text), reader, sink)
            }
            InsertMode::Comment => self.command(Command::Comment(text), reader, sink),
            InsertMode::Drop => Ok(()),
        }
    }

    /// The spindle speed in rpm of a `SPINDL`: a surface speed turned
    /// into rpm with the tool diameter (n = 1000 v / (π d), v in m/min, d
    /// in mm), held to `MAXRPM`; a gear range is remarked on.
    pub(super) fn spindle_rpm<R: BufRead>(
        &mut self,
        speed: SpindleSpeed,
        range: Option<u32>,
        max_rpm: Option<f64>,
        reader: &ClReader<R>,
    ) -> Result<f64, PostError> {
        let mut rpm = match speed {
            SpindleSpeed::Rpm(rpm) => rpm,
            SpindleSpeed::SurfaceMetresPerMinute(v) => {
                let Some(d) = self.tool_diameter_mm.filter(|d| *d > 0.0) else {
                    return Err(locate(reader, ProgramError::SurfaceSpeedWithoutDiameter).into());
                };
                1000.0 * v / (PI * d)
            }
        };
        if let Some(max) = max_rpm
            && rpm > max
        {
            self.report.warnings.push(reader.statement_diagnostic(
                Severity::Warning,
                format!("spindle speed {rpm:.0} rpm held to MAXRPM {max}"),
            ));
            rpm = max;
        }
        if let Some(r) = range {
            self.report.warnings.push(reader.statement_diagnostic(
                Severity::Warning,
                format!(
                    "SPINDL RANGE,{r} is not written: the dialects have no gear-range code (the control chooses the range for the speed); add it with an INSERT if the machine needs it"
                ),
            ));
        }
        Ok(rpm)
    }

    /// The statements the points' loop does not know (see the module's
    /// documentation).
    #[cold]
    #[inline(never)]
    pub(super) fn event<R: BufRead, S: ProgramSink>(
        &mut self,
        event: ClEvent,
        last: &mut Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        let line = reader.statement_line().0;
        match event {
            ClEvent::Circle(circle) => {
                if self.modal.as_ref().is_some_and(|m| m.cycle.is_some()) {
                    return Err(locate(reader, ProgramError::CircleInCycle).into());
                }
                let (start, axis) = (last.point, last.axis);
                self.modal_mut().arc = Some(PendingArc {
                    circle,
                    start,
                    axis,
                });
            }
            ClEvent::Nurbs(nurbs) => self.nurbs(&nurbs, line, last, reader, sink)?,
            ClEvent::Cycle(cycle) => {
                let hole = HoleCycle::resolve(&cycle, self.feed, self.rpm)
                    .map_err(|e| PostError::from(locate(reader, ProgramError::Cycle(e))))?;
                if HoleCycle::single_peck(&cycle) {
                    self.report.warnings.push(reader.statement_diagnostic(
                        Severity::Warning,
                        "this peck cycle gives no peck length (STEP, INCR): each hole is drilled in one peck",
                    ));
                }
                let at = match self.modal.as_ref().and_then(|m| m.cycle.as_ref()) {
                    Some(c) => c.at,
                    None if last.line == 0 && !self.position_known => None,
                    None => Some(last.point),
                };
                self.modal_mut().cycle = Some(ActiveCycle { hole, at });
            }
            ClEvent::CycleOff => {
                if let Some(c) = self.modal.as_mut().and_then(|m| m.cycle.take()) {
                    // The tool is where the last hole left it.
                    if let Some(p) = c.at {
                        last.point = p;
                    }
                }
                self.settle_modal();
            }
            ClEvent::From { point, axis } => {
                self.position_known = true;
                last.point = point;
                if let Some(a) = axis {
                    last.axis = a;
                }
            }
            ClEvent::GoHome { point, axis } => {
                // The CL's home (its point, or FROM), else the machine's:
                // the tool pose its home axis values give.
                let (point, axis, reference) = match (point, &self.machine.post.home) {
                    (Some(p), _) => (p, axis.unwrap_or(last.axis), last.reference),
                    (None, Some(q)) => {
                        let pose = kinpost_machine::Kinematics::new(self.machine).fk(q);
                        let reference = pose.reference.map(|r| r.into()).or(last.reference);
                        (pose.point.into(), pose.axis.into(), reference)
                    }
                    (None, None) => return Err(locate(reader, ProgramError::NoHome).into()),
                };
                *last = Move {
                    line,
                    point,
                    axis,
                    reference,
                    motion: Motion::Rapid,
                };
                self.goto(last, reader, sink)?;
            }
            ClEvent::Stop => self.command(Command::Stop { optional: false }, reader, sink)?,
            ClEvent::OptionalStop => {
                self.command(Command::Stop { optional: true }, reader, sink)?
            }
            ClEvent::End => {
                // APT END: the end of a section: spindle and coolant off, and
                // the program stops (M00; the program's end is FINI).
                self.rpm = None;
                if self.feed_per_rev.is_some() {
                    self.feed = None;
                }
                self.command(Command::Spindle(Spindle::Off), reader, sink)?;
                self.command(Command::Coolant(None), reader, sink)?;
                self.command(Command::Stop { optional: false }, reader, sink)?;
            }
            ClEvent::Dwell(dwell) => {
                let seconds = match dwell {
                    Dwell::Seconds(s) => s,
                    Dwell::Revolutions(n) => match self.rpm {
                        Some(rpm) => n * 60.0 / rpm,
                        None => {
                            let e = ProgramError::DwellRevolutionsWithoutSpindle;
                            return Err(locate(reader, e).into());
                        }
                    },
                };
                if !(seconds.is_finite() && seconds >= 0.0) {
                    return Err(locate(reader, ProgramError::Dwell(seconds)).into());
                }
                if seconds > 0.0 {
                    self.command(Command::Dwell(seconds), reader, sink)?;
                }
            }
            ClEvent::CutterCompensation {
                side,
                plane,
                register,
            } => self.cutter_compensation(side, plane, register, reader, sink)?,
            ClEvent::CoordinateSystem(_) => {
                if !std::mem::replace(&mut self.csys_remarked, true) {
                    self.report.warnings.push(reader.statement_diagnostic(
                        Severity::Warning,
                        "CSYS with a rotation or an offset: the GOTOs are posted as written (SOLIDWORKS CAM writes them in the world frame and CSYS relates them to the original of a pattern; see docs/cl-statements.md); further ones are not reported",
                    ));
                }
            }
            ClEvent::Clamp { on, words } => {
                self.report.warnings.push(reader.statement_diagnostic(
                    Severity::Warning,
                    format!(
                        "CLAMP/{}{} is not written: the machine file and dialect have no clamp codes; use an INSERT with the machine's clamp M code if it needs one",
                        if on { "ON" } else { "OFF" },
                        words.iter().map(|w| format!(",{w}")).collect::<String>()
                    ),
                ));
            }
            ClEvent::Origin(p) => {
                if p.iter().any(|v| *v != 0.0) {
                    return Err(locate(reader, ProgramError::OriginOffset(p)).into());
                }
            }
            _ => {
                return Err(locate(
                    reader,
                    ProgramError::NotPosted {
                        what: "this statement",
                    },
                )
                .into());
            }
        }
        Ok(())
    }

    /// `CUTCOM`: on with the side and the offset register (the CL's, else
    /// the tool number), in the XY plane; off only when on.
    fn cutter_compensation<R: BufRead, S: ProgramSink>(
        &mut self,
        side: CutcomSide,
        plane: Option<Plane>,
        register: Option<u32>,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        match side {
            CutcomSide::Off => {
                if std::mem::replace(&mut self.cutcom_on, false) {
                    self.command(Command::CutterCompensation(None), reader, sink)?;
                }
            }
            CutcomSide::Left | CutcomSide::Right => {
                if let Some(p) = plane.filter(|p| *p != Plane::Xy) {
                    let e = ProgramError::CutcomPlane(plane_name(p));
                    return Err(locate(reader, e).into());
                }
                let register =
                    register.unwrap_or(self.spindle_tool.unwrap_or(self.info.tool_number));
                let left = side == CutcomSide::Left;
                self.command(
                    Command::CutterCompensation(Some((left, register))),
                    reader,
                    sink,
                )?;
                self.cutcom_on = true;
            }
        }
        Ok(())
    }
}
