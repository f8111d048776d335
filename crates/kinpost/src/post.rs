//! The post-processing pipeline (DESIGN.md §1): CL statements → tool poses →
//! inverse kinematics (every branch) → planner → NC blocks, each block run
//! back through the forward kinematics before it is written.
//!
//! Everything streams: one statement is read, planned, checked and written
//! before the next is read, so memory does not grow with the program.

use std::io::{BufRead, Write};
use std::time::Instant;

use kinpost_cl::{ClEvent, ClReader, FeedUnit, Motion, SpindleDir, Units};
use kinpost_diag::{Diagnostic, Severity};
use kinpost_machine::{Kinematics, Machine, Pose, Solution};
use kinpost_nc::{AxisSpec, Block, Dialect, NcError, NcWriter, ProgramInfo, Spindle};
use kinpost_plan::{NearestPlanner, Planner, Rejection};
use nalgebra::Vector3;

use crate::check::{CheckStats, Tolerance, pose_error};
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

/// State of the program being written.
struct Job<'a, W: Write> {
    machine: &'a Machine,
    kin: Kinematics,
    planner: NearestPlanner,
    writer: NcWriter<W>,
    info: ProgramInfo,
    header_written: bool,
    /// Comments met before the header, written right after it.
    early_comments: Vec<String>,
    solutions: Vec<Solution>,
    written: [f64; kinpost_machine::MAX_AXES],
    /// The tolerance in force; grows to a block's own rounding bound where
    /// that is larger (see `within_block_bound`).
    tolerance: Tolerance,
    /// Set by `--tolerance`: never relaxed.
    tolerance_given: bool,
    /// One unit of the last written decimal, per axis.
    resolution: Vec<f64>,
    stats: CheckStats,
    feed: Option<f64>,
    /// Scale from CL units to mm.
    scale: f64,
    cl_points: u64,
    blocks: u64,
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
    let axes: Vec<AxisSpec> = machine
        .axes
        .iter()
        .map(|a| AxisSpec {
            name: a.name.clone(),
            rotary: a.is_rotary(),
            fixed: a.fixed.is_some(),
        })
        .collect();
    let writer = NcWriter::new(dialect, &axes, out);
    let resolution: Vec<f64> = axes
        .iter()
        .map(|a| 10f64.powi(-i32::from(dialect.word_format(a).number.decimals)))
        .collect();
    let tolerance = {
        let derived = Tolerance::from_resolution(machine, |i| resolution[i]);
        Tolerance {
            position_mm: options.tolerance_mm.unwrap_or(derived.position_mm),
            ..derived
        }
    };
    let stem = std::path::Path::new(&options.cl_file)
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .filter(|s| s != "-" && s != "<stdin>")
        .unwrap_or_else(|| "PROGRAM".to_string());
    let mut job = Job {
        machine,
        kin: Kinematics::new(machine),
        planner: NearestPlanner::new(machine),
        writer,
        info: ProgramInfo {
            program_name: options.program_name.clone().unwrap_or(stem),
            date: options.date.clone(),
            machine: machine.name.clone(),
            tool: String::new(),
            tool_number: 1,
            cl_file: options.cl_file.clone(),
            ..ProgramInfo::default()
        },
        header_written: false,
        early_comments: Vec::new(),
        solutions: Vec::with_capacity(16),
        written: [0.0; kinpost_machine::MAX_AXES],
        tolerance,
        tolerance_given: options.tolerance_mm.is_some(),
        resolution,
        stats: CheckStats::default(),
        feed: None,
        scale: 1.0,
        cl_points: 0,
        blocks: 0,
    };
    let mut named = options.program_name.is_some();
    let mut warnings = Vec::new();

    while let Some(statement) = reader.next_statement()? {
        let line = statement.line;
        match statement.event {
            ClEvent::Goto {
                point,
                axis,
                reference,
                motion,
            } => {
                job.start()?;
                let s = job.scale;
                let pose = Pose {
                    point: Vector3::new(point[0] * s, point[1] * s, point[2] * s),
                    axis: Vector3::from(axis),
                    reference: reference.map(Vector3::from),
                };
                job.motion(&pose, motion, line, &reader)?;
            }
            ClEvent::Feedrate { value, unit } => {
                job.feed = Some(match unit {
                    FeedUnit::Mmpm | FeedUnit::Mmpr => value,
                    FeedUnit::Ipm | FeedUnit::Ipr => value * 25.4,
                });
                if matches!(unit, FeedUnit::Mmpr | FeedUnit::Ipr) {
                    warnings.push(reader.statement_diagnostic(
                        Severity::Warning,
                        "feed per revolution is written as given; the dialect's feed word is per minute",
                    ));
                }
            }
            ClEvent::Units(units) => {
                job.scale = match units {
                    Units::Mm => 1.0,
                    Units::Inch => 25.4,
                };
            }
            ClEvent::PartNo(name) => {
                if !named && !name.trim().is_empty() {
                    job.info.program_name = name.trim().to_string();
                    named = true;
                }
            }
            ClEvent::ToolPath { name, words } => {
                if !named && !name.trim().is_empty() {
                    job.info.program_name = name.trim().to_string();
                    named = true;
                }
                if let Some(pos) = words.iter().position(|w| w.eq_ignore_ascii_case("TOOL"))
                    && let Some(tool) = words.get(pos + 1)
                {
                    job.info.tool = tool.clone();
                }
                job.break_segment();
                job.comment(&format!("TOOL PATH: {name}"))?;
            }
            ClEvent::Comment(text) => job.comment(text.trim())?,
            ClEvent::LoadTool { number } => {
                job.break_segment();
                if job.header_written {
                    let tool = job.info.tool.clone();
                    job.writer.tool_change(number, &tool)?;
                } else {
                    job.info.tool_number = number;
                    job.start()?;
                }
            }
            ClEvent::SelectTool { .. } => {}
            ClEvent::Spindle { rpm, dir } => {
                job.start()?;
                job.writer.spindle(match dir {
                    SpindleDir::Clockwise => Spindle::Cw(rpm),
                    SpindleDir::CounterClockwise => Spindle::Ccw(rpm),
                })?;
            }
            ClEvent::SpindleOff => {
                job.start()?;
                job.writer.spindle(Spindle::Off)?;
            }
            ClEvent::Coolant { on, mode } => {
                job.start()?;
                job.writer.coolant(on.then_some(mode.as_str()))?;
            }
            ClEvent::Insert(text) => {
                job.start()?;
                job.writer.insert(&text)?;
            }
            ClEvent::EndOfPath => job.break_segment(),
            ClEvent::Pressure { .. } => warnings.push(reader.statement_diagnostic(
                Severity::Warning,
                "PRESSURE ignored: this machine has no pressure axis",
            )),
            ClEvent::ToolData { .. } | ClEvent::MachineSystem { .. } | ClEvent::Multax(_) => {}
            ClEvent::Fini => break,
        }
    }
    job.start()?;
    let info = job.info.clone();
    job.writer
        .footer(&info, machine.post.footer.as_deref())
        .map_err(|e| PostError::Template(e.to_string()))?;
    job.writer.finish()?;

    warnings.extend(reader.take_warnings());
    warnings.sort_by_key(|w| (w.line, w.column));
    Ok(Summary {
        cl_points: job.cl_points,
        blocks: job.blocks,
        warnings,
        max_position_error_mm: job.stats.max_position_error_mm,
        max_axis_error_rad: job.stats.max_axis_error_rad,
        tolerance_mm: job.tolerance.position_mm,
        tolerance_rad: job.tolerance.axis_rad,
        seconds: started.elapsed().as_secs_f64(),
    })
}

impl<W: Write> Job<'_, W> {
    /// Writes the header before the first NC output.
    fn start(&mut self) -> Result<(), PostError> {
        if self.header_written {
            return Ok(());
        }
        self.header_written = true;
        self.writer
            .header(&self.info, self.machine.post.header.as_deref())?;
        for c in std::mem::take(&mut self.early_comments) {
            self.writer.comment(&c)?;
        }
        Ok(())
    }

    fn comment(&mut self, text: &str) -> Result<(), PostError> {
        if self.header_written {
            self.writer.comment(text)?;
        } else {
            self.early_comments.push(text.to_string());
        }
        Ok(())
    }

    /// With the derived tolerance, a block beyond the machine-wide bound is
    /// still right if its error is what rounding causes at its own levers;
    /// the summary then reports the larger tolerance.
    fn within_block_bound(&mut self, want: &Pose, got: &Pose, n: usize) -> bool {
        if self.tolerance_given {
            return false;
        }
        let resolution = &self.resolution;
        let block = Tolerance::at_block(self.machine, &self.kin, &self.written[..n], |i| {
            resolution[i]
        });
        let (p, a) = pose_error(want, got);
        if p > block.position_mm || a > block.axis_rad {
            return false;
        }
        self.tolerance.position_mm = self.tolerance.position_mm.max(p);
        self.tolerance.axis_rad = self.tolerance.axis_rad.max(a);
        true
    }

    fn break_segment(&mut self) {
        self.planner.break_segment();
    }

    /// One CL point: solve, choose, round, check, write.
    fn motion<R: BufRead>(
        &mut self,
        pose: &Pose,
        motion: Motion,
        line: usize,
        reader: &ClReader<R>,
    ) -> Result<(), PostError> {
        self.cl_points += 1;
        if motion == Motion::Rapid {
            self.planner.break_segment();
        }
        let hint = self.planner.current().copied();
        let n = self.machine.axes.len();
        let at = |message: String| -> PostError {
            reader.statement_diagnostic(Severity::Error, message).into()
        };
        if let Err(e) = self
            .kin
            .ik(pose, hint.as_ref().map(|h| &h[..n]), &mut self.solutions)
        {
            return Err(at(format!("{e}: {}", describe(pose))));
        }
        let chosen = match self.planner.choose(&self.solutions) {
            Ok(i) => self.solutions[i],
            Err(Rejection::OutsideLimits(v)) => {
                let a = &self.machine.axes[v.axis];
                let [lo, hi] = a.limits.unwrap_or([f64::NAN, f64::NAN]);
                return Err(at(format!(
                    "no solution inside the travel: {} would be {:.4} (limits {lo} .. {hi}) for {}",
                    a.name,
                    v.value,
                    describe(pose)
                )));
            }
            Err(Rejection::NoSolution) => {
                return Err(at(format!("no solution for {}", describe(pose))));
            }
        };
        for i in 0..n {
            self.written[i] = self.writer.quantized(i, chosen.joints[i]);
        }
        let reached = self.kin.fk(&self.written[..n]);
        if !self.stats.record(pose, &reached, line, &self.tolerance)
            && !self.within_block_bound(pose, &reached, n)
        {
            let (p, a) = pose_error(pose, &reached);
            return Err(at(format!(
                "closed-loop check failed: the block as written puts the tool {p:.6} mm and {a:.3e} rad \
                 from the CL pose (tolerance {:.6} mm, {:.3e} rad); {}",
                self.tolerance.position_mm,
                self.tolerance.axis_rad,
                describe(pose)
            )));
        }
        let feed = match motion {
            Motion::Rapid => None,
            Motion::Feed if self.feed.is_none() => {
                return Err(at(
                    "feed move before any FEDRAT: the controller has no feed rate for it".into(),
                ));
            }
            Motion::Feed => self.feed,
        };
        self.writer.block(&Block {
            cl_line: Some(line),
            motion: match motion {
                Motion::Rapid => kinpost_nc::Motion::Rapid,
                Motion::Feed => kinpost_nc::Motion::Feed,
            },
            axes: &chosen.joints[..n],
            feed,
        })?;
        self.blocks += 1;
        Ok(())
    }
}

/// The pose as a user reads it in a message.
fn describe(pose: &Pose) -> String {
    let (p, a) = (pose.point, pose.axis);
    format!(
        "point ({:.4}, {:.4}, {:.4}) axis ({:.7}, {:.7}, {:.7})",
        p.x, p.y, p.z, a.x, a.y, a.z
    )
}
