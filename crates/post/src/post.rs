//! The post-processing pipeline (DESIGN.md §1): CL statements → tool poses →
//! inverse kinematics (every branch) → planner → NC blocks, each block run
//! back through the forward kinematics before it is written.
//!
//! Statements are read one at a time; CL points wait in the planner (see
//! `path.rs`) until it decides, at the latest every [`PLANNER_LAG`] points,
//! so memory is bounded by that window, not by the program.

use std::io::{BufRead, Write};
use std::time::Instant;

use kinpost_cl::{
    ClEvent, ClReader, CutcomSide, FeedUnit, Motion, Move, Next, SpindleDir, SpindleSpeed,
    Statement,
};
use kinpost_diag::{Diagnostic, Severity};
use kinpost_machine::{Kinematics, Machine, OutputMode, Pose};
use kinpost_nc::{
    AxisSpec, Dialect, DialectKind, NcError, NcWriter, ProgramInfo, Spindle, TemplateKind,
};
use kinpost_plan::{Costs, Rejection, Trellis};
use nalgebra::Vector3;

use crate::check::Tolerance;
use crate::emit::{EmitSettings, Emitter};
use crate::path::{PathPlan, PointError};
use crate::pressure::{Wheel, check_pressure, pressure_spec};
use crate::summary::Summary;

/// Settings of one post run.
#[derive(Debug, Clone, Default)]
pub struct PostOptions {
    /// Name of the CL input, for diagnostics and the header (`-` for stdin).
    pub cl_file: String,
    /// Program name for the header; default: the CL `PARTNO`, else the first
    /// `TOOL PATH` name, else the CL file stem.
    pub program_name: Option<String>,
    /// Date written by the header template; empty by default so that the same
    /// input gives the same bytes.
    pub date: String,
    /// Closed-loop tolerance in mm replacing the derived one.
    pub tolerance_mm: Option<f64>,
    /// Tool axis for `GOTO/x,y,z` before any axis is given (3-axis APT).
    pub default_axis: Option<[f64; 3]>,
    /// Joint or tool-centre-point output; default: the machine's (`[post]
    /// output`), else joint.
    pub output: Option<OutputMode>,
    /// How feed words are written; default: the dialect's.
    pub feed_mode: Option<FeedMode>,
    /// Whole-path or point-by-point choice of configurations.
    pub planner: PlannerMode,
    /// Linearization tolerance, mm (default [`DEFAULT_LINTOL_MM`]; 0: off).
    pub lintol_mm: Option<f64>,
    /// Singular cone half-angle, degrees (default: the machine's, else
    /// [`DEFAULT_SINGULAR_CONE_DEG`]).
    pub singular_cone_deg: Option<f64>,
    /// Retract distance of a reconfiguration, mm (default: the machine's,
    /// else [`DEFAULT_RETRACT_MM`]).
    pub retract_mm: Option<f64>,
    /// Fail instead of retracting and reconfiguring.
    pub no_reconfigure: bool,
    /// The pressure for CL points before any `PRESSURE` statement (machines
    /// with a pressure axis); without it and without `PRESSURE`, none is
    /// written and the reference pressure applies.
    pub pressure: Option<f64>,
    /// Write the pressure words but solve every block at the reference
    /// pressure, as the machine maker's post does (for comparison).
    pub no_pressure_compensation: bool,
    /// How far outside the directions the machine can point a CL tool axis
    /// may lie and be solved at the nearest one, radians (default
    /// [`AXIS_ROUNDING_RAD`](kinpost_machine::AXIS_ROUNDING_RAD), the
    /// rounding of 6 decimals; at most
    /// [`MAX_AXIS_ROUNDING_RAD`](kinpost_machine::MAX_AXIS_ROUNDING_RAD)):
    /// for a CL that writes its tool axes with fewer decimals.
    pub axis_rounding_rad: Option<f64>,
}

/// Default linearization tolerance, mm.
pub const DEFAULT_LINTOL_MM: f64 = 0.002;
/// Default half-angle of the singular cone, degrees.
pub const DEFAULT_SINGULAR_CONE_DEG: f64 = 0.5;
/// Default retract distance of a reconfiguration, mm.
pub const DEFAULT_RETRACT_MM: f64 = 50.0;
/// Points the whole-path planner looks ahead at most before it decides.
pub const PLANNER_LAG: usize = 1 << 15;

/// How the configuration of each point is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PlannerMode {
    /// Over the whole path (dynamic programming over up to
    /// [`PLANNER_LAG`] points at a time).
    #[default]
    Global,
    /// Point by point: least motion from the previous block.
    Nearest,
}

/// What the feed word of a feed block means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum FeedMode {
    /// The CL feed rate, mm/min at the tool (contact) point.
    #[default]
    Tip,
    /// Inverse time (`G93`): F = 1 / block time in minutes, the block time
    /// being the CL segment length over the CL feed rate. A block that does
    /// not move the tool point but turns rotary axes takes its largest
    /// rotary change in degrees over the feed rate (degrees per minute).
    InverseTime,
    /// Degrees per minute, the combined feed of a controller without
    /// inverse time: F = length of the vector of every axis change (mm and
    /// degrees together) / block time.
    Dpm,
}

/// Why a post run failed.
#[derive(Debug, thiserror::Error)]
pub enum PostError {
    /// Bad input, with the place it is in.
    #[error("{0}")]
    Input(Box<Diagnostic>),
    /// The output could not be written.
    #[error("cannot write the NC program: {0}")]
    Io(#[from] std::io::Error),
    /// A header, footer or event template failed.
    #[error("{0}")]
    Template(String),
    /// The machine and dialect cannot write this kind of program.
    #[error("{0}")]
    Setup(String),
}

impl FeedMode {
    /// `tip`, `inverse-time` or `dpm`.
    pub fn parse(name: &str) -> Option<FeedMode> {
        match name {
            "tip" => Some(FeedMode::Tip),
            "inverse-time" => Some(FeedMode::InverseTime),
            "dpm" => Some(FeedMode::Dpm),
            _ => None,
        }
    }
}

impl From<NcError> for PostError {
    fn from(e: NcError) -> Self {
        match e {
            NcError::Io(e) => PostError::Io(e),
            other => PostError::Template(other.to_string()),
        }
    }
}

impl From<Diagnostic> for PostError {
    fn from(d: Diagnostic) -> Self {
        PostError::Input(Box::new(d))
    }
}

/// An NC output of a CL statement other than a point: written in its place
/// among the points, once the planner has decided them (before the first
/// point, once that point decides which axes the program writes).
#[derive(Debug)]
pub(crate) enum Output {
    Comment(String),
    ToolChange(u32, String),
    Spindle(Spindle),
    Coolant(Option<String>),
    Insert(String),
}

/// An output waiting to be written, with its CL statement (a diagnostic
/// without its message yet): it is written after the reader has moved on,
/// and a template that fails on it names that statement.
#[derive(Debug)]
pub(crate) struct Pending {
    output: Output,
    at: Box<Diagnostic>,
}

impl Pending {
    /// A tool change: the machine goes where it changes tools.
    pub(crate) fn changes_tool(&self) -> bool {
        matches!(self.output, Output::ToolChange(..))
    }
}

/// The machine as this program drives it, fixed by the first CL point: with
/// reference directions, axes marked `free_with_reference` are free.
struct Setup<W: Write> {
    machine: Machine,
    six_axis: bool,
    kin: Kinematics,
    path: PathPlan,
    emitter: Emitter<W>,
    /// The pressure axis, whose kinematics `kin` is in force.
    wheel: Option<Wheel>,
}

/// State of the program being written.
struct Job<'a, W: Write> {
    machine: &'a Machine,
    dialect: &'a Dialect,
    options: &'a PostOptions,
    out: Option<W>,
    setup: Option<Setup<W>>,
    pending: Vec<Pending>,
    info: ProgramInfo,
    /// Scale from CL units to mm.
    scale: f64,
    feed: Option<f64>,
    /// The spindle speed last programmed, rpm.
    rpm: Option<f64>,
    /// A feed given per revolution (mm): `feed` follows the spindle speed.
    feed_per_rev: Option<f64>,
    cl_points: u64,
    /// Pressures already warned about as not compensated (bits).
    uncompensated: Vec<u64>,
    /// The pressure programmed for the following points, if any.
    pressure: Option<f64>,
}

/// Posts the CL text read from `input` for `machine` in `dialect`, writing
/// the program to `out`. Returns the summary; on error nothing more is
/// written and the caller discards `out`.
pub fn post<R: BufRead, W: Write>(
    input: R,
    machine: &Machine,
    dialect: &Dialect,
    out: W,
    options: &PostOptions,
) -> Result<Summary, PostError> {
    let started = Instant::now();
    let mut reader = ClReader::new(input, options.cl_file.clone());
    if let Some(axis) = options.default_axis {
        reader = reader.with_default_axis(axis);
    }
    let stem = std::path::Path::new(&options.cl_file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| s != "-" && s != "<stdin>")
        .unwrap_or_else(|| "PROGRAM".to_string());
    let mut job = Job {
        machine,
        dialect,
        options,
        out: Some(out),
        setup: None,
        pending: Vec::new(),
        info: ProgramInfo {
            program_name: options.program_name.clone().unwrap_or(stem),
            date: options.date.clone(),
            machine: machine.name.clone(),
            tool: String::new(),
            tool_number: 1,
            cl_file: options.cl_file.clone(),
            ..ProgramInfo::default()
        },
        scale: 1.0,
        feed: None,
        rpm: None,
        feed_per_rev: None,
        cl_points: 0,
        uncompensated: Vec::new(),
        pressure: None,
    };
    let mut warnings = Vec::new();
    if let Some(value) = options.pressure {
        let check = job.check_pressure(value).map_err(PostError::Setup)?;
        warnings.extend(check.into_iter().map(|message| {
            Diagnostic::warning(
                &options.cl_file,
                0,
                0,
                0,
                "",
                format!("--pressure: {message}"),
            )
        }));
        job.pressure = Some(value);
    }
    let mut reading = Reading {
        warnings,
        remarked: Remarked::default(),
        named: options.program_name.is_some(),
        tool_loaded: false,
        spindle_tool: None,
        msys: None,
    };
    // The loop over the points stays small: every other statement is read
    // out of line (`statement`), so that what it does cannot crowd the
    // registers of the points' code.
    let mut goto = Move::default();
    loop {
        match reader.next_move(&mut goto)? {
            Next::Move => job.goto(&goto, &reader, &mut reading.warnings, &mut reading.remarked)?,
            Next::Statement(s) => {
                if !statement(&mut job, &mut reading, s, &reader)? {
                    break;
                }
            }
            Next::End => break,
        }
    }
    let mut warnings = reading.warnings;
    job.open(false)?;
    let Some(mut setup) = job.setup.take() else {
        unreachable!("`open` sets the job up")
    };
    setup.path.flush(
        &setup.machine,
        &mut setup.kin,
        &mut setup.wheel,
        &mut setup.emitter,
        true,
    )?;
    let mut emitter = setup.emitter;
    warnings.append(&mut emitter.warnings);
    let mut writer = emitter.writer;
    if emitter.inverse_time_on {
        writer.inverse_time(false)?;
    }
    if emitter.settings.tcp.is_some() {
        writer.tcp(false)?;
    }
    writer.footer(
        &job.info,
        machine_template(machine, dialect, &machine.post.footer),
    )?;
    let tolerance = emitter.settings.tolerance;
    let blocks = writer.blocks_written();
    writer.finish()?;

    if job.cl_points == 0 {
        warnings.push(Diagnostic::warning(
            &options.cl_file,
            0,
            0,
            0,
            "",
            "the CL file has no motion (no GOTO): the program is its header and footer only"
                .to_string(),
        ));
    }
    warnings.extend(reader.take_warnings());
    warnings.sort_by_key(|w| (w.line, w.column));
    let mut planning = emitter.planning;
    planning.singular_stretches = setup.path.stretches;
    Ok(Summary {
        cl_points: job.cl_points,
        blocks,
        warnings,
        max_position_error_mm: emitter.stats.max_position_error_mm,
        max_position_error_line: emitter.stats.worst_line,
        max_axis_error_rad: emitter.stats.max_axis_error_rad,
        tolerance_mm: tolerance.position_mm,
        tolerance_rad: tolerance.axis_rad,
        seconds: started.elapsed().as_secs_f64(),
        planning,
    })
}

/// What the reading of the CL keeps besides the job.
struct Reading {
    warnings: Vec<Diagnostic>,
    remarked: Remarked,
    /// The program has its name (from the options, `PARTNO` or the first
    /// `TOOL PATH`).
    named: bool,
    tool_loaded: bool,
    /// The tool changed to last (`None`: the header's, `tool_number`).
    spindle_tool: Option<u32>,
    /// The first `MSYS` (origin and axes as written, mm) and its line:
    /// every point is posted in the machine file's part frame, so a later
    /// `MSYS` must not change it.
    msys: Option<([f64; 9], usize)>,
}

/// The error for a CL statement the post does not act on yet (the reader
/// gives it as an event; posting it is to come).
#[cold]
fn not_posted<R: BufRead>(reader: &ClReader<R>, what: &str) -> PostError {
    reader
        .statement_diagnostic(
            Severity::Error,
            format!("{what}: kinpost reads it but does not post it yet"),
        )
        .into()
}

/// A CL statement other than a plain `GOTO` line: `false` at `FINI`.
#[inline(never)]
fn statement<R: BufRead, W: Write>(
    job: &mut Job<'_, W>,
    r: &mut Reading,
    statement: Statement,
    reader: &ClReader<R>,
) -> Result<bool, PostError> {
    let line = statement.line;
    match statement.event {
        ClEvent::Goto {
            point,
            axis,
            reference,
            motion,
        } => {
            let goto = Move {
                line,
                point,
                axis,
                reference,
                motion,
            };
            job.goto(&goto, reader, &mut r.warnings, &mut r.remarked)?;
        }
        ClEvent::Feedrate { value, unit } => {
            let mm = match unit {
                FeedUnit::Mmpm | FeedUnit::Mmpr => value,
                FeedUnit::Ipm | FeedUnit::Ipr => value * 25.4,
            };
            job.feed_per_rev = None;
            job.feed = Some(if matches!(unit, FeedUnit::Mmpr | FeedUnit::Ipr) {
                // The feed word is per minute: per revolution times the
                // spindle speed, now and after every speed change.
                let Some(rpm) = job.rpm else {
                    return Err(reader
                        .statement_diagnostic(
                            Severity::Error,
                            "a feed per revolution needs the spindle speed: give SPINDL/rpm before it",
                        )
                        .into());
                };
                job.feed_per_rev = Some(mm);
                mm * rpm
            } else {
                mm
            });
        }
        // The reader gives every length in mm.
        ClEvent::Units(_) => {}
        ClEvent::PartNo(name) => {
            if !r.named && !name.trim().is_empty() {
                job.info.program_name = name.trim().to_string();
                r.named = true;
            }
        }
        ClEvent::ToolPath { name, words } => {
            if !r.named && !name.trim().is_empty() {
                job.info.program_name = name.trim().to_string();
                r.named = true;
            }
            if let Some(pos) = words.iter().position(|w| w.eq_ignore_ascii_case("TOOL"))
                && let Some(tool) = words.get(pos + 1)
            {
                job.info.tool = tool.clone();
            }
            job.break_segment();
            job.emit(Output::Comment(format!("TOOL PATH: {name}")), reader)?;
        }
        ClEvent::Comment(text) => job.emit(Output::Comment(text.trim().to_string()), reader)?,
        ClEvent::LoadTool { number, .. } => {
            job.break_segment();
            // The header loads the first tool (it knows `tool_number`).
            if !r.tool_loaded && job.setup.is_none() {
                job.info.tool_number = number;
            } else if number != r.spindle_tool.unwrap_or(job.info.tool_number) {
                job.emit(Output::ToolChange(number, job.info.tool.clone()), reader)?;
                r.spindle_tool = Some(number);
            }
            // (The tool in the spindle again, as CAM systems write at the
            // start of every operation: no tool change cycle.)
            r.tool_loaded = true;
        }
        ClEvent::SelectTool { .. } => {}
        ClEvent::Spindle {
            speed: SpindleSpeed::Rpm(rpm),
            dir,
            range: None,
            max_rpm: None,
        } => {
            job.rpm = Some(rpm);
            if let Some(per_rev) = job.feed_per_rev {
                job.feed = Some(per_rev * rpm);
            }
            let state = match dir {
                SpindleDir::Clockwise => Spindle::Cw(rpm),
                SpindleDir::CounterClockwise => Spindle::Ccw(rpm),
            };
            job.emit(Output::Spindle(state), reader)?
        }
        ClEvent::SpindleOff => {
            // No speed now: a feed per revolution gives no feed rate.
            job.rpm = None;
            if job.feed_per_rev.is_some() {
                job.feed = None;
            }
            job.emit(Output::Spindle(Spindle::Off), reader)?
        }
        ClEvent::Coolant { on, mode } => job.emit(Output::Coolant(on.then_some(mode)), reader)?,
        ClEvent::Insert(text) => job.emit(Output::Insert(text), reader)?,
        ClEvent::EndOfPath => job.break_segment(),
        ClEvent::Pressure { word, value } => {
            job.pressure(word.as_deref(), value, reader, &mut r.warnings)?;
        }
        ClEvent::ToolData(_) | ClEvent::Multax(_) => {}
        ClEvent::MachineSystem { origin, x, y, .. } => {
            let zero = [0.0; 3];
            let (x, y) = (x.unwrap_or(zero), y.unwrap_or(zero));
            let v = [origin, x, y].concat().try_into().expect("nine values");
            match r.msys {
                None => r.msys = Some((v, line)),
                Some((first, first_line)) => {
                    if v.iter().zip(&first).any(|(a, b)| (a - b).abs() > 1e-6) {
                        return Err(reader.statement_diagnostic(Severity::Error, format!(
                            "MSYS changes the machine coordinate system of line {first_line}: kinpost posts every point in the part frame of the machine file; post the operations of each coordinate system as a program of their own"
                        )).into());
                    }
                }
            }
        }
        ClEvent::CoordinateSystem(frame) if frame.is_identity(1e-9) => {}
        ClEvent::CutterCompensation {
            side: CutcomSide::Off,
            ..
        } => {}
        // Informational: the CAM system's post name, names, setups, marks,
        // and FROM (a position, no motion).
        ClEvent::Machine { .. }
        | ClEvent::OperationName(_)
        | ClEvent::Setup { .. }
        | ClEvent::TapeMark
        | ClEvent::From { .. } => {}
        ClEvent::Spindle { .. } => {
            return Err(not_posted(
                reader,
                "a spindle speed in surface units, a gear range or a speed limit",
            ));
        }
        ClEvent::CoordinateSystem(_) => {
            return Err(not_posted(reader, "CSYS with a rotation or an offset"));
        }
        ClEvent::Circle(_) => return Err(not_posted(reader, "CIRCLE (an arc)")),
        ClEvent::Nurbs(_) => return Err(not_posted(reader, "NURBS (a spline)")),
        ClEvent::Cycle(_) | ClEvent::CycleOff => {
            return Err(not_posted(reader, "CYCLE (a canned cycle)"));
        }
        ClEvent::GoHome { .. } => return Err(not_posted(reader, "GOHOME")),
        ClEvent::CutterCompensation { .. } => {
            return Err(not_posted(
                reader,
                "CUTCOM (cutter radius compensation: the GOTOs are the part contour, not tool positions)",
            ));
        }
        ClEvent::Dwell(_) => return Err(not_posted(reader, "DELAY (a dwell)")),
        ClEvent::Stop | ClEvent::OptionalStop | ClEvent::End => {
            return Err(not_posted(reader, "STOP, OPSTOP or END (a program stop)"));
        }
        ClEvent::Clamp { .. } => return Err(not_posted(reader, "CLAMP")),
        ClEvent::Origin(_) => return Err(not_posted(reader, "ORIGIN")),
        ClEvent::Fini => return Ok(false),
    }
    Ok(true)
}

impl<W: Write> Job<'_, W> {
    /// Checks a pressure about to be programmed: the warnings to give (each
    /// uncompensated pressure once), or why it cannot be.
    fn check_pressure(&mut self, value: f64) -> Result<Vec<String>, String> {
        let output = self
            .options
            .output
            .or(self.machine.post.output)
            .unwrap_or_default();
        let compensate = !self.options.no_pressure_compensation;
        let check = check_pressure(self.machine, self.dialect, output, compensate, value)?;
        let mut warnings = check.warnings;
        if check.uncompensated.is_some() {
            if self.uncompensated.contains(&value.to_bits()) {
                warnings.pop();
            } else {
                self.uncompensated.push(value.to_bits());
            }
        }
        Ok(warnings)
    }

    /// `PRESSURE/[word,]value`: the pressure of the points that follow.
    fn pressure<R: BufRead>(
        &mut self,
        word: Option<&str>,
        value: f64,
        reader: &ClReader<R>,
        warnings: &mut Vec<Diagnostic>,
    ) -> Result<(), PostError> {
        let Some(p) = &self.machine.pressure else {
            warnings.push(reader.statement_diagnostic(
                Severity::Warning,
                "PRESSURE ignored: this machine has no pressure axis",
            ));
            return Ok(());
        };
        if let Some(w) = word.filter(|w| !w.eq_ignore_ascii_case(&p.name)) {
            let message = format!(
                "PRESSURE names `{w}`, but the pressure word of machine `{}` is `{}`",
                self.machine.name, p.name
            );
            return Err(reader.statement_diagnostic(Severity::Error, message).into());
        }
        let check = self.check_pressure(value).map_err(|message| {
            PostError::from(reader.statement_diagnostic(Severity::Error, message))
        })?;
        for message in check {
            warnings.push(reader.statement_diagnostic(Severity::Warning, message));
        }
        self.pressure = Some(value);
        Ok(())
    }

    /// Sets the machine up for the program (once) and writes the header and
    /// whatever waited for it.
    fn open(&mut self, six_axis: bool) -> Result<(), PostError> {
        if self.setup.is_none() {
            let machine = if six_axis {
                self.machine.with_reference_axes_free()
            } else {
                self.machine.clone()
            };
            let axes = axis_specs(&machine);
            let resolution: Vec<f64> = axes
                .iter()
                .map(|a| 10f64.powi(-i32::from(self.dialect.word_format(a).number.decimals)))
                .collect();
            let mode = self
                .options
                .output
                .or(machine.post.output)
                .unwrap_or_default();
            let tcp = match mode {
                OutputMode::Joint => None,
                OutputMode::Tcp => Some(tcp_axes(&machine, self.dialect)?),
            };
            let derived = match tcp {
                None => Tolerance::from_resolution(&machine, |i| resolution[i]),
                Some(_) => Tolerance::for_tcp(&machine, |i| resolution[i]),
            };
            let tolerance = Tolerance {
                position_mm: self.options.tolerance_mm.unwrap_or(derived.position_mm),
                ..derived
            };
            let out = self.out.take().expect("the output is taken once, here");
            let feed_mode = self
                .options
                .feed_mode
                .or(self.dialect.default_feed_mode().and_then(FeedMode::parse))
                .unwrap_or_default();
            let mut writer = NcWriter::new(self.dialect, &axes, out);
            if feed_mode == FeedMode::InverseTime {
                writer.add_feed_mode_column();
            }
            writer.header(
                &self.info,
                machine_template(self.machine, self.dialect, &self.machine.post.header),
            )?;
            for p in std::mem::take(&mut self.pending) {
                write_pending(&mut writer, p)?;
            }
            if tcp.is_some() {
                writer.tcp(true)?;
            }
            // (Inverse time is switched on by the emitter, at the first feed
            // block whose start is known.)
            if feed_mode == FeedMode::InverseTime
                && self.dialect.kind() != DialectKind::Csv
                && self.dialect.template(TemplateKind::InverseTimeOn).is_none()
            {
                return Err(PostError::Setup(format!(
                    "dialect `{}` has no `inverse_time_on` template: it cannot write inverse-time feeds",
                    self.dialect.name()
                )));
            }
            // (A modulo axis reaches every angle: the kinematics sees it
            // without limits, `Axis::travel`, and takes the turn nearest the
            // previous point.)
            let mut kin = Kinematics::new(&machine);
            if let Some(rad) = self.options.axis_rounding_rad {
                kin.set_axis_rounding(rad);
            }
            let cone = self
                .options
                .singular_cone_deg
                .or(machine.post.singular_cone_deg)
                .unwrap_or(DEFAULT_SINGULAR_CONE_DEG);
            let lag = match self.options.planner {
                PlannerMode::Global => PLANNER_LAG,
                PlannerMode::Nearest => 1,
            };
            let costs = Costs::new(&machine, cone, kin.singularity().map(|s| s.axis));
            let path = PathPlan::new(
                &machine,
                &kin,
                Trellis::new(costs, lag),
                cone,
                &self.options.cl_file,
            );
            let settings = EmitSettings {
                feed_mode,
                lintol: self.options.lintol_mm.unwrap_or(DEFAULT_LINTOL_MM),
                retract_mm: self
                    .options
                    .retract_mm
                    .or(machine.post.retract)
                    .unwrap_or(DEFAULT_RETRACT_MM),
                reconfigure: !self.options.no_reconfigure,
                tolerance,
                tolerance_given: self.options.tolerance_mm.is_some(),
                tcp,
                resolution,
                singularity: kin.singularity(),
                cone_rad: cone.to_radians(),
            };
            self.setup = Some(Setup {
                emitter: Emitter::new(&machine, writer, settings),
                kin,
                path,
                wheel: Wheel::new(&machine, !self.options.no_pressure_compensation),
                machine,
                six_axis,
            });
        }
        Ok(())
    }

    /// Writes `output` of the current CL statement in its place among the
    /// points (once the program is set up). Out of line: six statements
    /// call it, and copies of it inlined into `post` crowd the registers of
    /// the loop that reads the points.
    #[inline(never)]
    fn emit<R: BufRead>(&mut self, output: Output, reader: &ClReader<R>) -> Result<(), PostError> {
        let p = Pending {
            output,
            at: Box::new(reader.statement_diagnostic(Severity::Error, "")),
        };
        match &mut self.setup {
            Some(s) if s.path.is_idle() => s.emitter.write_pending(p),
            Some(s) => {
                s.path.push_output(p);
                Ok(())
            }
            None => {
                self.pending.push(p);
                Ok(())
            }
        }
    }

    fn break_segment(&mut self) {
        if let Some(s) = &mut self.setup {
            s.path.break_segment();
        }
    }

    /// A `GOTO`: its pose in the part frame (mm), then [`Job::motion`].
    #[inline(always)]
    fn goto<R: BufRead>(
        &mut self,
        goto: &Move,
        reader: &ClReader<R>,
        warnings: &mut Vec<Diagnostic>,
        remarked: &mut Remarked,
    ) -> Result<(), PostError> {
        let s = self.scale;
        let [x, y, z] = goto.point;
        let pose = Pose {
            point: Vector3::new(x * s, y * s, z * s),
            axis: Vector3::from(goto.axis),
            reference: goto.reference.map(Vector3::from),
        };
        if let Some(r) = &pose.reference
            && let Some(message) = reference_remark(self.machine, &pose.axis, r, remarked)
        {
            warnings.push(reader.statement_diagnostic(Severity::Warning, message));
        }
        self.motion(&pose, goto.motion, goto.line, reader)
    }

    /// One CL point: solve and hand it to the planner, which writes it once
    /// the path around it is decided.
    fn motion<R: BufRead>(
        &mut self,
        pose: &Pose,
        motion: Motion,
        line: usize,
        reader: &ClReader<R>,
    ) -> Result<(), PostError> {
        self.cl_points += 1;
        let at = |message: String| -> PostError {
            reader.statement_diagnostic(Severity::Error, message).into()
        };
        let six_axis = pose.reference.is_some() && self.machine.unlocks_with_reference();
        if self.setup.is_none() {
            self.open(six_axis)?;
        }
        let Some(s) = self.setup.as_mut() else {
            unreachable!("`open` sets the job up")
        };
        if s.six_axis != six_axis {
            return Err(at(if s.six_axis {
                "this CL point has no reference direction, but the program began with them \
                 (6-axis output): give every GOTO nine values, or none"
                    .to_string()
            } else {
                "this CL point has a reference direction, but the program began without \
                 (5-axis output, locked axes stay locked): give every GOTO nine values, or none"
                    .to_string()
            }));
        }
        if motion == Motion::Feed && self.feed.is_none() {
            return Err(at(if self.feed_per_rev.is_some() {
                "feed move at a feed per revolution with the spindle off (SPINDL/OFF): give SPINDL/rpm before it"
                    .into()
            } else {
                "feed move before any FEDRAT: the controller has no feed rate for it".into()
            }));
        }
        let nc_motion = match motion {
            Motion::Rapid => kinpost_nc::Motion::Rapid,
            Motion::Feed => kinpost_nc::Motion::Feed,
        };
        // The block's pressure as written (NaN: none programmed), and the
        // kinematics of the wheel there (seed 001 eq. 3.4–3.7).
        let pressure = match &s.wheel {
            Some(_) => {
                let n = s.machine.axes.len();
                self.pressure
                    .map_or(f64::NAN, |p| s.emitter.writer.quantized(n, p))
            }
            None => f64::NAN,
        };
        select(&mut s.kin, &mut s.wheel, pressure);
        let (_, source) = reader.statement_line();
        if let Err(e) = s
            .path
            .push_point(&s.kin, *pose, nc_motion, line, self.feed, pressure, source)
        {
            return Err(at(match e {
                PointError::Ik(e) => format!("{e}: {}", describe(pose)),
                PointError::Rejected(Rejection::OutsideLimits(v)) => {
                    let a = &s.machine.axes[v.axis];
                    let [lo, hi] = a.limits.unwrap_or([f64::NAN, f64::NAN]);
                    format!(
                        "no solution inside the travel: {} would be {} (limits {lo} .. {hi}) for {}",
                        a.name,
                        Mm(v.value),
                        describe(pose)
                    )
                }
                PointError::Rejected(Rejection::NoSolution) => {
                    format!("no solution for {}", describe(pose))
                }
            }));
        }
        if s.path.is_full() {
            s.path
                .flush(&s.machine, &mut s.kin, &mut s.wheel, &mut s.emitter, false)?;
        }
        Ok(())
    }
}

/// The machine's axes as a dialect writes them, then its pressure word, if
/// it has a pressure axis.
pub fn axis_specs(machine: &Machine) -> Vec<AxisSpec> {
    machine
        .axes
        .iter()
        .map(|a| AxisSpec {
            name: a.name.clone(),
            rotary: a.is_rotary(),
            fixed: a.fixed.is_some(),
            endless: a.is_endless(),
            pressure: false,
        })
        .chain(pressure_spec(machine))
        .collect()
}

/// The linear axes named X, Y and Z, which carry the tool point in
/// tool-centre-point output; the dialect must be able to switch it on.
fn tcp_axes(machine: &Machine, dialect: &Dialect) -> Result<[usize; 3], PostError> {
    let mut found = [usize::MAX; 3];
    for (k, name) in ["X", "Y", "Z"].iter().enumerate() {
        found[k] = machine
            .axes
            .iter()
            .position(|a| !a.is_rotary() && a.is_free() && a.name.eq_ignore_ascii_case(name))
            .ok_or_else(|| {
                PostError::Setup(format!(
                    "tool-centre-point output needs free linear axes named X, Y and Z; machine `{}` has no {name}",
                    machine.name
                ))
            })?;
    }
    if dialect.kind() != DialectKind::Csv && dialect.template(TemplateKind::TcpOn).is_none() {
        return Err(PostError::Setup(format!(
            "dialect `{}` has no `tcp_on` template: it cannot switch tool-centre-point control on",
            dialect.name()
        )));
    }
    Ok(found)
}

/// The machine's own header or footer: written for the machine's default
/// dialect only (it is in that controller's language); other dialects use
/// their own.
fn machine_template<'a>(
    machine: &Machine,
    dialect: &Dialect,
    template: &'a Option<String>,
) -> Option<&'a str> {
    match &machine.post.dialect {
        Some(d) if d.eq_ignore_ascii_case(dialect.name()) => template.as_deref(),
        _ => None,
    }
}

pub(crate) fn write_pending<W: Write>(
    writer: &mut NcWriter<W>,
    p: Pending,
) -> Result<(), PostError> {
    let written = match p.output {
        Output::Comment(text) => writer.comment(&text),
        Output::ToolChange(number, name) => writer.tool_change(number, &name),
        Output::Spindle(state) => writer.spindle(state),
        Output::Coolant(mode) => writer.coolant(mode.as_deref()),
        Output::Insert(text) => writer.insert(&text),
    };
    written.map_err(|e| match e {
        NcError::Io(e) => PostError::Io(e),
        other => PostError::Input(Box::new(Diagnostic {
            message: other.to_string(),
            ..*p.at
        })),
    })
}

/// Puts the kinematics of the written pressure `pressure` (NaN: none) in
/// `kin`, on a machine with a pressure axis.
pub(crate) fn select(kin: &mut Kinematics, wheel: &mut Option<Wheel>, pressure: f64) {
    if let Some(w) = wheel {
        w.select(kin, pressure);
    }
}

/// Which remarks on reference directions were made (each once a file).
#[derive(Default)]
struct Remarked {
    ignored: bool,
    skew: bool,
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
    // Off perpendicular by more than a tenth of a degree.
    let off = (axis.dot(r) / (axis.norm() * r.norm()))
        .clamp(-1.0, 1.0)
        .asin();
    (off.abs() > 0.1f64.to_radians() && !std::mem::replace(&mut remarked.skew, true)).then(|| {
        format!(
            "the reference direction is {:.3}° off perpendicular to the tool axis: only its part perpendicular to it is used (further ones are not reported)",
            off.abs().to_degrees()
        )
    })
}

/// The pose as a user reads it in a message.
pub(crate) fn describe(pose: &Pose) -> String {
    let (p, a) = (pose.point, pose.axis);
    format!(
        "point ({}, {}, {}) axis ({:.7}, {:.7}, {:.7})",
        Mm(p.x),
        Mm(p.y),
        Mm(p.z),
        a.x,
        a.y,
        a.z
    )
}

/// A length or angle in a message: four decimals, or in exponent notation
/// where that would print hundreds of digits (`GOTO/1e300,…`).
pub(crate) struct Mm(pub f64);

impl std::fmt::Display for Mm {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0.abs() < 1e12 || !self.0.is_finite() {
            write!(f, "{:.4}", self.0)
        } else {
            write!(f, "{:.4e}", self.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Mm;

    #[test]
    fn huge_lengths_are_written_with_an_exponent() {
        assert_eq!(Mm(12.345_67).to_string(), "12.3457");
        assert_eq!(Mm(-999_999_999_999.0).to_string(), "-999999999999.0000");
        assert_eq!(Mm(1e300).to_string(), "1.0000e300");
        assert_eq!(Mm(-1e12).to_string(), "-1.0000e12");
        assert_eq!(Mm(f64::NAN).to_string(), "NaN");
    }
}
