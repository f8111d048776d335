//! The program stage: CL statements to the program's points and commands.
//! It keeps the CL's modal state (units, feed rate, spindle speed, tool,
//! pressure), turns every `GOTO` into a tool pose in the part frame (mm)
//! with the feed and pressure in force, and every other statement that
//! says something to the controller into a [`Command`], in order, to a
//! [`ProgramSink`]: the planner of the next stage.

use std::io::BufRead;

use kinpost_cl::{ClEvent, ClReader, FeedUnit, Motion, Move, Next, SpindleDir, Statement};
use kinpost_diag::{Diagnostic, Located, Severity};
use kinpost_machine::tolerance::REFERENCE_SKEW_DEG;
use kinpost_machine::{Machine, OutputMode, Pose};
use kinpost_nc::{AxisSpec, Dialect, ProgramInfo, Spindle};
use kinpost_plan::PathPoint;
use nalgebra::Vector3;

use crate::command::{Command, Pending};
use crate::config::{Config, FrameMode};
use crate::error::{PointError, PostError, ProgramError};
use crate::pressure::check_pressure;

mod events;
mod frame;

use events::Modal;

/// Where the program stage's points and commands go.
pub trait ProgramSink {
    /// The program starts: before its first point (or at its end, when it
    /// has none), with what the header says and whether the program gives
    /// reference directions (6-axis output).
    fn start(&mut self, info: &ProgramInfo, six_axis: bool) -> Result<(), PostError>;

    /// A CL point; `source`: the text of its CL line. An error of the
    /// point itself (no configuration reaches it) comes back as
    /// [`PointError::Point`], for the caller to locate at its statement.
    fn point(&mut self, point: PathPoint, source: &[u8]) -> Result<(), PointError>;

    /// A command, in its place among the points.
    fn command(&mut self, pending: Pending) -> Result<(), PostError>;

    /// The path is interrupted here (an operation ends, the tool changes):
    /// the next point starts a segment.
    fn break_segment(&mut self);
}

/// What the program stage read, for the summary.
#[derive(Debug, Clone, Default)]
pub struct ProgramReport {
    /// CL points read: `GOTO`s (an arc's end, a hole), `NURBS`, `GOHOME`;
    /// not the points an arc, a spline or a cycle is cut into.
    pub cl_points: u64,
    /// What the header and footer say.
    pub info: ProgramInfo,
    /// Warnings about the CL, at their lines.
    pub warnings: Vec<Diagnostic>,
}

/// The program stage (see the module's documentation).
pub struct Program<'a> {
    machine: &'a Machine,
    dialect: &'a Dialect,
    config: &'a Config,
    /// The pressure word's spec, for its written value.
    pressure_spec: Option<AxisSpec>,
    info: ProgramInfo,
    /// The program has its name (from the options, `PARTNO` or the first
    /// `TOOL PATH`).
    named: bool,
    /// The first point decided 5- or 6-axis output (`None`: no point yet).
    six_axis: Option<bool>,
    feed: Option<f64>,
    /// The spindle speed last programmed, rpm.
    rpm: Option<f64>,
    /// A feed given per revolution (mm): `feed` follows the spindle speed.
    feed_per_rev: Option<f64>,
    /// The pressure programmed for the following points, as written (NaN:
    /// none).
    pressure: f64,
    /// Pressures already warned about as not compensated (bits).
    uncompensated: Vec<u64>,
    tool_loaded: bool,
    /// The tool changed to last (`None`: the header's, `tool_number`).
    spindle_tool: Option<u32>,
    /// The length offset register in force (`G43 H`), once a tool is loaded.
    length_register: Option<u32>,
    /// The first `MSYS` (origin and axes as written, mm) and its line:
    /// every point is posted in the machine file's part frame, so a later
    /// `MSYS` must not change it.
    msys: Option<([f64; 9], usize)>,
    /// `--frame absolute`: the frame of the `MSYS` in force, when it is
    /// not the identity (every point and axis is mapped out of it).
    frame: Option<Box<kinpost_cl::Frame>>,
    /// An arc waiting for its end point, a canned cycle on (`None`: the
    /// `GOTO`s are plain moves, the fast path).
    modal: Option<Box<Modal>>,
    /// The spindle turns counter-clockwise (`SPINDL/…,CCLW`).
    spindle_ccw: bool,
    /// The diameter of the tool last described (`TLDATA`, `CUTTER`), mm.
    tool_diameter_mm: Option<f64>,
    /// Cutter radius compensation is on.
    cutcom_on: bool,
    /// A `CSYS` with a rotation or offset was remarked on.
    csys_remarked: bool,
    /// A `FROM` gave the tool's start.
    position_known: bool,
    remarked: Remarked,
    report: ProgramReport,
}

/// Which remarks on reference directions were made (each once a file).
#[derive(Debug, Default)]
struct Remarked {
    ignored: bool,
    skew: bool,
}

impl<'a> Program<'a> {
    /// The program of `machine` in `dialect` with `config`; `warnings`:
    /// those of the options, first among the program's.
    pub fn new(
        machine: &'a Machine,
        dialect: &'a Dialect,
        config: &'a Config,
        warnings: Vec<Diagnostic>,
    ) -> Self {
        let stem = std::path::Path::new(&config.cl_file)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|s| s != "-" && s != "<stdin>")
            .unwrap_or_else(|| "PROGRAM".to_string());
        let pressure_spec = crate::pressure::pressure_spec(machine);
        let pressure = match (&pressure_spec, config.pressure) {
            (Some(spec), Some(p)) => dialect.quantize(spec, p),
            _ => f64::NAN,
        };
        Program {
            machine,
            dialect,
            config,
            pressure_spec,
            info: ProgramInfo {
                program_name: config.program_name.clone().unwrap_or(stem),
                date: config.date.clone(),
                machine: machine.name.clone(),
                tool: String::new(),
                tool_number: 1,
                length_register: 1,
                tcp_output: config.output == OutputMode::Tcp,
                cl_file: config.cl_file.clone(),
                ..ProgramInfo::default()
            },
            named: config.program_name.is_some(),
            six_axis: None,
            feed: None,
            rpm: None,
            feed_per_rev: None,
            pressure,
            uncompensated: Vec::new(),
            tool_loaded: false,
            spindle_tool: None,
            length_register: None,
            msys: None,
            frame: None,
            modal: None,
            spindle_ccw: false,
            tool_diameter_mm: None,
            cutcom_on: false,
            csys_remarked: false,
            position_known: false,
            remarked: Remarked::default(),
            report: ProgramReport {
                warnings,
                ..ProgramReport::default()
            },
        }
    }

    /// Notes a pressure about to be programmed by the options: remembered
    /// as warned about when it is not compensated (the CL's `PRESSURE` of
    /// the same value then says nothing more).
    pub fn note_option_pressure(&mut self, value: f64, uncompensated: bool) {
        if uncompensated {
            self.uncompensated.push(value.to_bits());
        }
    }

    /// Reads the whole CL from `reader` into `sink`, then starts the sink if
    /// no point did. Returns what was read.
    pub fn run<R: BufRead, S: ProgramSink>(
        mut self,
        reader: &mut ClReader<R>,
        sink: &mut S,
    ) -> Result<ProgramReport, PostError> {
        // The loop over the points stays small: every other statement is read
        // out of line (`statement`), so that what it does cannot crowd the
        // registers of the points' code.
        let mut goto = Move::default();
        loop {
            match reader.next_move(&mut goto)? {
                Next::Move => {
                    if let Some(f) = &self.frame {
                        frame::move_out(f, &mut goto);
                    }
                    if self.modal.is_none() {
                        self.goto(&goto, reader, sink)?
                    } else {
                        self.modal_goto(&goto, reader, sink)?
                    }
                }
                Next::Statement(s) => {
                    if !self.statement(s, &mut goto, reader, sink)? {
                        break;
                    }
                }
                Next::End => break,
            }
        }
        if self.six_axis.is_none() {
            sink.start(&self.info, false)?;
        }
        self.report.info = self.info;
        Ok(self.report)
    }

    /// A command of the current statement, in its place among the points.
    #[inline(never)]
    fn command<R: BufRead, S: ProgramSink>(
        &mut self,
        command: Command,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        sink.command(Pending {
            command,
            at: Box::new(reader.statement_diagnostic(Severity::Error, "")),
        })
    }

    /// A CL statement other than a plain `GOTO` line: `false` at `FINI`.
    /// `last`: the last `GOTO` (the current point and axis), kept up to
    /// date by every statement that moves the tool.
    #[inline(never)]
    fn statement<R: BufRead, S: ProgramSink>(
        &mut self,
        statement: Statement,
        last: &mut Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<bool, PostError> {
        let line = statement.line;
        let event = match &self.frame {
            Some(f) => frame::event_out(f, statement.event),
            None => statement.event,
        };
        match event {
            ClEvent::Goto {
                point,
                axis,
                reference,
                motion,
            } => {
                *last = Move {
                    line,
                    point,
                    axis,
                    reference,
                    motion,
                };
                if self.modal.is_none() {
                    self.goto(last, reader, sink)?;
                } else {
                    self.modal_goto(last, reader, sink)?;
                }
            }
            ClEvent::Feedrate { value, unit } => self.feedrate(value, unit, reader)?,
            // The reader gives every length in mm.
            ClEvent::Units(_) => {}
            ClEvent::PartNo(name) => self.name(&name),
            ClEvent::ToolPath { name, words } => {
                self.name(&name);
                if let Some(pos) = words.iter().position(|w| w.eq_ignore_ascii_case("TOOL"))
                    && let Some(tool) = words.get(pos + 1)
                {
                    self.info.tool = tool.clone();
                }
                sink.break_segment();
                self.command(Command::Comment(format!("TOOL PATH: {name}")), reader, sink)?;
            }
            ClEvent::Comment(text) => {
                self.command(Command::Comment(text.trim().to_string()), reader, sink)?
            }
            ClEvent::LoadTool { number, adjust } => {
                if self.modal.is_some() {
                    self.end_cycle_at_tool_change(last, reader);
                }
                self.load_tool(number, adjust, reader, sink)?
            }
            ClEvent::SelectTool { .. } => {}
            ClEvent::Spindle {
                speed,
                dir,
                range,
                max_rpm,
            } => {
                let rpm = self.spindle_rpm(speed, range, max_rpm, reader)?;
                self.spindle_ccw = dir == SpindleDir::CounterClockwise;
                self.rpm = Some(rpm);
                if let Some(per_rev) = self.feed_per_rev {
                    self.feed = Some(per_rev * rpm);
                }
                let state = match dir {
                    SpindleDir::Clockwise => Spindle::Cw(rpm),
                    SpindleDir::CounterClockwise => Spindle::Ccw(rpm),
                };
                self.command(Command::Spindle(state), reader, sink)?
            }
            ClEvent::SpindleOff => {
                // No speed now: a feed per revolution gives no feed rate.
                self.rpm = None;
                if self.feed_per_rev.is_some() {
                    self.feed = None;
                }
                self.command(Command::Spindle(Spindle::Off), reader, sink)?
            }
            ClEvent::Coolant { on, mode } => {
                self.command(Command::Coolant(on.then_some(mode)), reader, sink)?
            }
            ClEvent::Insert(text) => self.insert(text, reader, sink)?,
            ClEvent::EndOfPath => sink.break_segment(),
            ClEvent::Pressure { word, value } => self.pressure(word.as_deref(), value, reader)?,
            ClEvent::ToolData(data) => {
                if data.diameter_mm.is_some() {
                    self.tool_diameter_mm = data.diameter_mm;
                }
            }
            ClEvent::Multax(_) => {}
            ClEvent::MachineSystem {
                origin,
                x,
                y,
                frame,
            } => {
                if self.config.frame == FrameMode::Absolute {
                    self.absolute_frame(origin, x, y, frame, reader)?
                } else {
                    self.machine_system(origin, x, y, line, reader)?
                }
            }
            ClEvent::CoordinateSystem(frame) if frame.is_identity(1e-9) => {}
            // Informational: the CAM system's post name, names, setups, marks.
            ClEvent::Machine { .. }
            | ClEvent::OperationName(_)
            | ClEvent::Setup { .. }
            | ClEvent::TapeMark => {}
            ClEvent::Fini => return Ok(false),
            other => self.event(other, last, reader, sink)?,
        }
        Ok(true)
    }

    /// `MSYS`: the first is the part frame the CL was written in; a later
    /// one must not change it (every point is posted in the machine file's
    /// part frame).
    fn machine_system<R: BufRead>(
        &mut self,
        origin: [f64; 3],
        x: Option<[f64; 3]>,
        y: Option<[f64; 3]>,
        line: usize,
        reader: &ClReader<R>,
    ) -> Result<(), PostError> {
        let zero = [0.0; 3];
        let (x, y) = (x.unwrap_or(zero), y.unwrap_or(zero));
        let mut v = [0.0; 9];
        v[..3].copy_from_slice(&origin);
        v[3..6].copy_from_slice(&x);
        v[6..].copy_from_slice(&y);
        match self.msys {
            None => self.msys = Some((v, line)),
            Some((first, first_line)) => {
                if v.iter().zip(&first).any(|(a, b)| (a - b).abs() > 1e-6) {
                    return Err(
                        locate(reader, ProgramError::MachineSystemChanged { first_line }).into(),
                    );
                }
            }
        }
        Ok(())
    }

    /// `MSYS` under `--frame absolute`: the frame the points that follow
    /// are mapped out of (an origin alone moves them; the identity maps
    /// nothing).
    fn absolute_frame<R: BufRead>(
        &mut self,
        origin: [f64; 3],
        x: Option<[f64; 3]>,
        y: Option<[f64; 3]>,
        frame: Option<Box<kinpost_cl::Frame>>,
        reader: &ClReader<R>,
    ) -> Result<(), PostError> {
        let frame = match (frame, x, y) {
            (Some(f), _, _) => f,
            (None, None, None) => Box::new(kinpost_cl::Frame {
                origin,
                ..kinpost_cl::Frame::IDENTITY
            }),
            _ => return Err(locate(reader, ProgramError::MachineSystemIncomplete).into()),
        };
        self.frame = (!frame.is_identity(0.0)).then_some(frame);
        Ok(())
    }

    /// `FEDRAT/…`: the feed rate of the moves that follow, per minute.
    fn feedrate<R: BufRead>(
        &mut self,
        value: f64,
        unit: FeedUnit,
        reader: &ClReader<R>,
    ) -> Result<(), PostError> {
        let mm = match unit {
            FeedUnit::Mmpm | FeedUnit::Mmpr => value,
            FeedUnit::Ipm | FeedUnit::Ipr => value * 25.4,
        };
        self.feed_per_rev = None;
        self.feed = Some(if matches!(unit, FeedUnit::Mmpr | FeedUnit::Ipr) {
            // The feed word is per minute: per revolution times the
            // spindle speed, now and after every speed change.
            let Some(rpm) = self.rpm else {
                return Err(locate(reader, ProgramError::FeedPerRevWithoutSpindle).into());
            };
            self.feed_per_rev = Some(mm);
            mm * rpm
        } else {
            mm
        });
        Ok(())
    }

    /// `PARTNO` or the first `TOOL PATH`: the program's name, unless it has
    /// one.
    fn name(&mut self, name: &str) {
        if !self.named && !name.trim().is_empty() {
            self.info.program_name = name.trim().to_string();
            self.named = true;
        }
    }

    /// `LOAD/TOOL,n`: the header loads the first tool (it knows
    /// `tool_number`); later ones are tool changes. (The tool in the spindle
    /// again, as CAM systems write at the start of every operation: no tool
    /// change cycle.)
    fn load_tool<R: BufRead, S: ProgramSink>(
        &mut self,
        number: u32,
        adjust: Option<u32>,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        sink.break_segment();
        let register = adjust.unwrap_or(number);
        let in_spindle = self
            .spindle_tool
            .or(self.info.tool_loaded.then_some(self.info.tool_number));
        if !self.tool_loaded && self.six_axis.is_none() {
            self.info.tool_number = number;
            self.info.tool_loaded = true;
            self.info.length_register = register;
        } else if Some(number) != in_spindle
            // The same tool with another length register (CATIA's
            // `LOADTL/2` then `LOADTL/2,1`): the change again, so that the
            // program's `G43 H` is the CL's.
            || (adjust.is_some() && self.length_register != Some(register))
        {
            let tool = self.info.tool.clone();
            self.command(Command::ToolChange(number, tool, register), reader, sink)?;
            self.spindle_tool = Some(number);
        } else {
            return Ok(());
        }
        self.tool_loaded = true;
        self.length_register = Some(register);
        Ok(())
    }

    /// `PRESSURE/[word,]value`: the pressure of the points that follow.
    fn pressure<R: BufRead>(
        &mut self,
        word: Option<&str>,
        value: f64,
        reader: &ClReader<R>,
    ) -> Result<(), PostError> {
        let Some(p) = &self.machine.pressure else {
            self.report.warnings.push(reader.statement_diagnostic(
                Severity::Warning,
                "PRESSURE ignored: this machine has no pressure axis",
            ));
            return Ok(());
        };
        if let Some(w) = word.filter(|w| !w.eq_ignore_ascii_case(&p.name)) {
            let e = ProgramError::PressureWord {
                word: w.to_string(),
                machine: self.machine.name.clone(),
                axis: p.name.clone(),
            };
            return Err(locate(reader, e).into());
        }
        let check = check_pressure(
            self.machine,
            self.dialect,
            self.config.output,
            self.config.compensate_pressure,
            value,
        )
        .map_err(|e| PostError::from(locate(reader, ProgramError::Pressure(e))))?;
        let mut warnings = check.warnings;
        if check.uncompensated {
            if self.uncompensated.contains(&value.to_bits()) {
                warnings.pop();
            } else {
                self.uncompensated.push(value.to_bits());
            }
        }
        for w in warnings {
            self.report
                .warnings
                .push(reader.statement_diagnostic(Severity::Warning, w.to_string()));
        }
        if let Some(spec) = &self.pressure_spec {
            self.pressure = self.dialect.quantize(spec, value);
        }
        Ok(())
    }

    /// A `GOTO`: its pose in the part frame (mm), to the sink with the feed
    /// and pressure in force.
    #[inline(always)]
    fn goto<R: BufRead, S: ProgramSink>(
        &mut self,
        goto: &Move,
        reader: &ClReader<R>,
        sink: &mut S,
    ) -> Result<(), PostError> {
        let pose = Pose {
            point: Vector3::from(goto.point),
            axis: Vector3::from(goto.axis),
            reference: goto.reference.map(Vector3::from),
        };
        if let Some(r) = &pose.reference
            && let Some(message) = reference_remark(self.machine, &pose.axis, r, &mut self.remarked)
        {
            self.report
                .warnings
                .push(reader.statement_diagnostic(Severity::Warning, message));
        }
        self.report.cl_points += 1;
        let six_axis = pose.reference.is_some() && self.machine.unlocks_with_reference();
        match self.six_axis {
            None => {
                sink.start(&self.info, six_axis)?;
                self.six_axis = Some(six_axis);
            }
            Some(began) if began != six_axis => {
                return Err(locate(reader, ProgramError::ReferenceMismatch(began)).into());
            }
            Some(_) => {}
        }
        if goto.motion == Motion::Feed && self.feed.is_none() {
            let e = if self.feed_per_rev.is_some() {
                ProgramError::SpindleOffForFeedPerRev
            } else {
                ProgramError::NoFeedRate
            };
            return Err(locate(reader, e).into());
        }
        let point = PathPoint {
            pose,
            motion: match goto.motion {
                Motion::Rapid => kinpost_nc::Motion::Rapid,
                Motion::Feed => kinpost_nc::Motion::Feed,
            },
            line: goto.line,
            feed: self.feed,
            pressure: self.pressure,
        };
        let (_, source) = reader.statement_line();
        sink.point(point, source).map_err(|e| match e {
            PointError::Point(e) => PostError::from(locate(reader, e)),
            PointError::Post(e) => e,
        })
    }
}

/// `error` at the reader's current statement.
fn locate<R: BufRead, E: std::fmt::Display>(reader: &ClReader<R>, error: E) -> Located<E> {
    Located {
        diagnostic: Box::new(reader.statement_diagnostic(Severity::Error, error.to_string())),
        error,
    }
}

/// A remark on the reference direction `r` of a CL point with tool axis
/// `axis`, the first time it applies: the machine has no rotary axis the
/// reference turns (it is ignored), or the reference is not perpendicular
/// to the tool axis (its part along the axis is ignored).
fn reference_remark(
    machine: &Machine,
    axis: &Vector3<f64>,
    r: &Vector3<f64>,
    remarked: &mut Remarked,
) -> Option<String> {
    let free_rotary = machine
        .axes
        .iter()
        .filter(|a| a.is_rotary() && (a.is_free() || a.free_with_reference))
        .count();
    if free_rotary < 3 {
        return (!std::mem::replace(&mut remarked.ignored, true)).then(|| {
            format!(
                "reference directions (GOTO values 7 to 9) are ignored: machine `{}` has no third rotary axis to turn them (further ones are not reported)",
                machine.name
            )
        });
    }
    let off = (axis.dot(r) / (axis.norm() * r.norm()))
        .clamp(-1.0, 1.0)
        .asin();
    (off.abs() > REFERENCE_SKEW_DEG.to_radians() && !std::mem::replace(&mut remarked.skew, true))
        .then(|| {
            format!(
                "the reference direction is {:.3}° off perpendicular to the tool axis: only its part perpendicular to it is used (further ones are not reported)",
                off.abs().to_degrees()
            )
        })
}
