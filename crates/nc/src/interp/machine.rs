//! The state every family shares: axis positions, modal state, offsets,
//! units, and the emission of steps to the sink.

use std::collections::{BTreeMap, BTreeSet};

use kinpost_diag::Diagnostic;

use super::source::{Fail, fail};
use super::{
    ArcPlane, AxisValues, CutterComp, CycleRef, Event, FeedMode, MAX_AXES, ModalState, MotionKind,
    Move, Options, Report, Sink, SpindleDir, Step, WorkOffset,
};
use crate::AxisSpec;

/// Tolerances of the interpreter's geometry checks, in one place.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// How far the distance from the centre to the end of an arc may differ
    /// from the distance to its start, mm: the larger of this and
    /// `arc_radius_rel` × radius. 0.005 mm is what LinuxCNC accepts
    /// (`TOLERANCE_MM` of rs274ngc); CAM output rounded to 3 decimals stays
    /// well inside it. A wider difference is an error, not a spiral.
    pub arc_radius_mm: f64,
    /// Relative part of the arc radius check (0.1 %: large arcs written with
    /// few decimals).
    pub arc_radius_rel: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            arc_radius_mm: 0.005,
            arc_radius_rel: 1e-3,
        }
    }
}

/// mm per inch.
pub(crate) const MM_PER_INCH: f64 = 25.4;

/// Full turn of a rotary axis, degrees.
const TURN_DEG: f64 = 360.0;

/// How an absolute value reaches a rotary axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RotaryMode {
    /// A plain absolute value: on an endless axis the controller counts on
    /// without wrapping (Fanuc, LinuxCNC, Heidenhain), the position reported
    /// modulo 360.
    Continuous,
    /// Sinumerik plain absolute (`AC`) on a modulo axis: the value in
    /// [0, 360) reached directly, without passing 0.
    Direct,
    /// `DC`: the shortest way.
    Shortest,
    /// `ACP`: turning positive.
    Positive,
    /// `ACN`: turning negative.
    Negative,
}

/// The shared machine state of a run.
pub(crate) struct Machine<'s> {
    pub axes: Vec<AxisSpec>,
    pub n: usize,
    /// Indices of the axes named X, Y, Z.
    pub xyz: [Option<usize>; 3],
    /// Current position: work coordinates, mm/deg; endless axes in [0, 360).
    pub pos: [f64; MAX_AXES],
    /// Endless axes: the position counted on without wrapping.
    pub unwrapped: [f64; MAX_AXES],
    pub state: ModalState,
    pub feed: f64,
    pub feed_mode: FeedMode,
    /// Inch programming.
    pub inch: bool,
    /// Work offset tables (program `G10` and the options), by offset key.
    pub offsets: BTreeMap<u16, [f64; MAX_AXES]>,
    /// Shift on top of the work offset (G92, G52, Heidenhain cycle 7,
    /// Sinumerik TRANS).
    pub shift: [f64; MAX_AXES],
    pub report: Report,
    assumed: BTreeSet<String>,
    pub options: Options,
    sink: &'s mut dyn Sink,
    step: Step,
    /// Drilling cycle of the moves being emitted.
    pub cycle: Option<CycleRef>,
    /// The moves being emitted are machine coordinates (`G53`).
    pub machine_frame: bool,
    /// Moves of canned cycles emitted so far: bounded like the blocks
    /// executed (a cycle's repeat count and its pecks multiply its work).
    cycle_moves: u64,
}

impl<'s> Machine<'s> {
    pub fn new(axes: &[AxisSpec], options: &Options, sink: &'s mut dyn Sink) -> Machine<'s> {
        let n = axes.len().min(MAX_AXES);
        let find = |name: &str| axes.iter().position(|a| a.name.eq_ignore_ascii_case(name));
        let mut pos = [0.0; MAX_AXES];
        if let Some(start) = &options.start {
            for (i, v) in start.iter().take(n).enumerate() {
                pos[i] = *v;
            }
        }
        let unwrapped = pos;
        for (i, a) in axes.iter().take(n).enumerate() {
            if a.endless {
                pos[i] = wrap(pos[i]);
            }
        }
        let mut offsets = BTreeMap::new();
        for (k, v) in &options.work_offsets {
            let mut o = [0.0; MAX_AXES];
            for (i, x) in v.iter().take(n).enumerate() {
                o[i] = *x;
            }
            offsets.insert(*k, o);
        }
        let state = ModalState {
            work_offset: WorkOffset::None,
            offset: AxisValues::zeros(n),
            tool_length: None,
            cutter_comp: CutterComp::Off,
            tcp: false,
            spindle: SpindleDir::Off,
            spindle_speed: 0.0,
            coolant_mist: false,
            coolant_flood: false,
            tool: None,
            plane: ArcPlane::Xy,
        };
        Machine {
            axes: axes[..n].to_vec(),
            n,
            xyz: [find("X"), find("Y"), find("Z")],
            pos,
            unwrapped,
            state,
            feed: 0.0,
            feed_mode: FeedMode::PerMinute,
            inch: false,
            offsets,
            shift: [0.0; MAX_AXES],
            report: Report::default(),
            assumed: BTreeSet::new(),
            options: options.clone(),
            sink,
            step: Step {
                line: 0,
                number: None,
                cl_line: None,
                event: Event::Stop(super::StopKind::End),
            },
            cycle: None,
            machine_frame: false,
            cycle_moves: 0,
        }
    }

    /// The axis named `name` (case-insensitive).
    pub fn axis(&self, name: &str) -> Option<usize> {
        self.axes
            .iter()
            .position(|a| a.name.eq_ignore_ascii_case(name))
    }

    /// Sets the line and block number of the steps that follow.
    #[inline]
    pub fn at_line(&mut self, line: usize, number: Option<u64>) {
        self.step.line = line;
        self.step.number = number;
    }

    /// Counts one executed block; fails past the limit.
    #[inline]
    pub fn count_block(&mut self) -> Result<(), Fail> {
        self.report.executed_blocks += 1;
        if self.report.executed_blocks > self.options.max_executed_blocks {
            return fail(
                0,
                1,
                format!(
                    "more than {} blocks executed (Options::max_executed_blocks): an endless \
                     loop, or raise the limit",
                    self.options.max_executed_blocks
                ),
            );
        }
        Ok(())
    }

    /// Charges `moves` moves of a canned cycle (a hole); fails past
    /// [`Options::max_executed_blocks`], like a loop.
    pub fn charge_cycle(&mut self, moves: usize) -> Result<(), Fail> {
        self.cycle_moves = self.cycle_moves.saturating_add(moves as u64);
        if self.cycle_moves > self.options.max_executed_blocks {
            return fail(
                0,
                1,
                format!(
                    "canned cycles make more than {} moves (Options::max_executed_blocks): a repeat count or a peck depth out of proportion, or raise the limit",
                    self.options.max_executed_blocks
                ),
            );
        }
        Ok(())
    }

    /// Records an assumption once.
    pub fn assume(&mut self, text: String) {
        if self.assumed.insert(text.clone()) {
            self.report.assumed.push(text);
        }
    }

    pub fn warn(&mut self, d: Diagnostic) {
        self.report.warnings.push(d);
    }

    /// The value of an external input (`$A_IN[5]`), 0 with an assumption
    /// when the options do not give it.
    pub fn input(&mut self, name: &str) -> f64 {
        let key = super::normalize_input(name);
        if let Some(v) = self.options.inputs.get(&key) {
            return *v;
        }
        self.assume(format!(
            "input {key} = 0 (not given; set it with --input '{key}=VALUE')"
        ));
        0.0
    }

    /// Emits one event at the current line.
    #[inline]
    pub fn emit(&mut self, event: Event) {
        self.step.event = event;
        self.sink.step(&self.step);
    }

    /// Linear factor of program values: 25.4 in inch mode.
    #[inline]
    pub fn unit(&self) -> f64 {
        if self.inch { MM_PER_INCH } else { 1.0 }
    }

    /// Factor from program units to mm/deg for axis `i` (rotary axes are
    /// degrees in every unit system).
    #[inline]
    pub fn unit_of(&self, i: usize) -> f64 {
        if self.axes[i].rotary || self.axes[i].pressure {
            1.0
        } else {
            self.unit()
        }
    }

    /// The value a rotary axis reaches and how far it turns, for an
    /// absolute programmed value `v` (degrees) in `mode`.
    pub fn rotary_target(&self, i: usize, v: f64, mode: RotaryMode) -> (f64, f64) {
        let endless = self.axes[i].endless;
        let cur = self.pos[i];
        let (end, travel) = match mode {
            RotaryMode::Continuous if endless => (wrap(v), v - self.unwrapped[i]),
            RotaryMode::Continuous => (v, v - cur),
            RotaryMode::Direct => {
                if endless {
                    let e = wrap(v);
                    (e, e - cur)
                } else {
                    (v, v - cur)
                }
            }
            RotaryMode::Shortest | RotaryMode::Positive | RotaryMode::Negative => {
                let e = wrap(v);
                // Both in [0, 360): the difference is in (-360, 360), and
                // adding a turn is exactly what rem_euclid would do.
                let mut d = e - wrap(cur);
                if d < 0.0 {
                    d += TURN_DEG;
                }
                match mode {
                    RotaryMode::Shortest if d > TURN_DEG / 2.0 => d -= TURN_DEG,
                    RotaryMode::Negative if d > 0.0 => d -= TURN_DEG,
                    _ => {}
                }
                if endless { (e, d) } else { (cur + d, d) }
            }
        };
        (end, travel)
    }

    /// Emits a move to `target` (work coordinates; rotary travel in
    /// `travel` for the axes whose bit is in `turned`, else end − start).
    #[inline]
    pub fn move_to(
        &mut self,
        kind: MotionKind,
        target: &[f64; MAX_AXES],
        travel_in: &[f64; MAX_AXES],
        turned: u32,
        programmed: u32,
    ) {
        self.report.moves += 1;
        // The step keeps its Move between blocks: filled in place, no copy
        // of the whole event per block.
        if !matches!(self.step.event, Event::Move(_)) {
            self.step.event = Event::Move(Box::new(Move {
                kind: MotionKind::Rapid,
                end: AxisValues::zeros(self.n),
                travel: AxisValues::zeros(self.n),
                programmed: 0,
                machine_frame: false,
                feed: 0.0,
                feed_mode: FeedMode::PerMinute,
                cycle: None,
                state: self.state,
            }));
        }
        let Event::Move(mv) = &mut self.step.event else {
            unreachable!("made a Move above")
        };
        {
            let e = mv.end.as_mut_slice();
            let t = mv.travel.as_mut_slice();
            for i in 0..self.n {
                if turned & (1 << i) != 0 {
                    t[i] = travel_in[i];
                    e[i] = target[i];
                    self.unwrapped[i] += travel_in[i];
                } else {
                    t[i] = target[i] - self.pos[i];
                    e[i] = target[i];
                    if self.axes[i].endless {
                        e[i] = wrap(target[i]);
                        self.unwrapped[i] += t[i];
                    }
                }
                self.pos[i] = e[i];
            }
        }
        mv.kind = kind;
        mv.programmed = programmed;
        mv.machine_frame = self.machine_frame;
        mv.feed = self.feed;
        mv.feed_mode = self.feed_mode;
        mv.cycle = self.cycle;
        mv.state = self.state;
        self.sink.step(&self.step);
    }

    /// A straight move of the X, Y, Z axes (others stay), e.g. for cycles.
    pub fn move_xyz(&mut self, rapid: bool, x: Option<f64>, y: Option<f64>, z: Option<f64>) {
        let mut target = self.pos;
        let mut programmed = 0;
        for (k, v) in [x, y, z].into_iter().enumerate() {
            if let (Some(v), Some(i)) = (v, self.xyz[k]) {
                target[i] = v;
                programmed |= 1 << i;
            }
        }
        let kind = if rapid {
            MotionKind::Rapid
        } else {
            MotionKind::Linear
        };
        self.move_to(kind, &target, &[0.0; MAX_AXES], 0, programmed);
    }

    /// Current X, Y, Z (0 for an axis the machine lacks).
    pub fn xyz_pos(&self) -> [f64; 3] {
        let mut p = [0.0; 3];
        for (k, i) in self.xyz.iter().enumerate() {
            if let Some(i) = i {
                p[k] = self.pos[*i];
            }
        }
        p
    }

    /// Selects a work offset: its values from the table (program or
    /// options), zeros with an assumption otherwise.
    pub fn select_offset(&mut self, wo: WorkOffset, name: &str) {
        self.state.work_offset = wo;
        self.refresh_offset(Some(name));
        self.emit(Event::WorkOffset(wo));
    }

    /// Recomputes the offset in force (work offset + shift) and moves the
    /// positions into the new frame (the machine does not move).
    pub fn refresh_offset(&mut self, name: Option<&str>) {
        let base = match self.state.work_offset {
            WorkOffset::None => [0.0; MAX_AXES],
            WorkOffset::Numbered(k) => match self.offsets.get(&k) {
                Some(v) => *v,
                None => {
                    if let Some(name) = name {
                        self.assume(format!(
                            "work offset {name} = 0 on every axis (the controller's table is \
                             not known; give it in the options)"
                        ));
                    }
                    [0.0; MAX_AXES]
                }
            },
        };
        let old = self.state.offset;
        let mut new = AxisValues::zeros(self.n);
        for i in 0..self.n {
            new.as_mut_slice()[i] = base[i] + self.shift[i];
            let d = new[i] - old[i];
            if d != 0.0 {
                // Same machine position, new coordinates.
                if self.axes[i].endless {
                    self.pos[i] = wrap(self.pos[i] - d);
                } else {
                    self.pos[i] -= d;
                }
                self.unwrapped[i] -= d;
            }
        }
        self.state.offset = new;
    }

    pub fn set_plane(&mut self, p: ArcPlane) {
        if self.state.plane != p {
            self.state.plane = p;
            self.emit(Event::ArcPlane(p));
        }
    }

    pub fn set_feed_mode(&mut self, m: FeedMode) {
        if self.feed_mode != m {
            self.feed_mode = m;
            self.emit(Event::FeedMode(m));
        }
    }

    pub fn set_units(&mut self, inch: bool) {
        if self.inch != inch {
            self.inch = inch;
            self.emit(Event::Units { inch });
        }
    }

    pub fn set_spindle(&mut self, dir: SpindleDir) {
        self.state.spindle = dir;
        let speed = self.state.spindle_speed;
        self.emit(Event::Spindle { dir, speed });
    }

    pub fn set_speed(&mut self, speed: f64) {
        self.state.spindle_speed = speed;
        let dir = self.state.spindle;
        self.emit(Event::Spindle { dir, speed });
    }

    pub fn coolant(&mut self, mist: Option<bool>, flood: Option<bool>) {
        if let Some(m) = mist {
            self.state.coolant_mist = m;
        }
        if let Some(f) = flood {
            self.state.coolant_flood = f;
        }
        let (mist, flood) = (self.state.coolant_mist, self.state.coolant_flood);
        self.emit(Event::Coolant { mist, flood });
    }

    pub fn tool_change(&mut self, tool: u32) {
        self.state.tool = Some(tool);
        self.emit(Event::ToolChange { tool });
    }

    pub fn set_tcp(&mut self, on: bool) {
        self.state.tcp = on;
        self.emit(Event::Tcp(on));
    }

    pub fn set_cutter_comp(&mut self, c: CutterComp) {
        if self.state.cutter_comp != c {
            self.state.cutter_comp = c;
            self.emit(Event::CutterComp(c));
        }
    }

    pub fn set_tool_length(&mut self, h: Option<u32>) {
        self.state.tool_length = h;
        self.emit(Event::ToolLength(h));
    }

    /// Dwell for `seconds`.
    pub fn dwell(&mut self, seconds: f64) {
        self.emit(Event::Dwell { seconds });
    }
}

/// The (first, second, normal) indices into (X, Y, Z) of a plane, in the
/// right-handed order arcs turn in (G18: Z, X, Y).
/// An angle in [0, 360).
#[inline]
pub(crate) fn wrap(v: f64) -> f64 {
    // Most values are already in range: no division (fmod is slow).
    if (0.0..TURN_DEG).contains(&v) {
        return v + 0.0;
    }
    let r = v.rem_euclid(TURN_DEG);
    // rem_euclid may round up to the period itself; -0.0 reads 0.
    if r >= TURN_DEG { 0.0 } else { r + 0.0 }
}

impl Machine<'_> {
    /// A move of a CSV row to the written values (endless axes counted on
    /// without wrapping, as the post wrote them), with the row's CL line.
    pub fn emit_cl_move(
        &mut self,
        cl_line: Option<usize>,
        kind: MotionKind,
        values: &[f64; MAX_AXES],
        programmed: u32,
    ) {
        let mut target = self.pos;
        let mut travel = [0.0; MAX_AXES];
        let mut turned = 0u32;
        for i in 0..self.n {
            if programmed & (1 << i) == 0 {
                continue;
            }
            if self.axes[i].endless {
                let (e, d) = self.rotary_target(i, values[i], RotaryMode::Continuous);
                target[i] = e;
                travel[i] = d;
                turned |= 1 << i;
            } else {
                target[i] = values[i];
            }
        }
        self.step.cl_line = cl_line;
        self.move_to(kind, &target, &travel, turned, programmed);
        self.step.cl_line = None;
    }
}
