//! Streaming reader of cutter-location (CL) files: NX CLSF and APT text as
//! written by NX, CATIA, SolidWorks CAM and friends.
//!
//! [`ClReader`] reads one logical statement at a time from any
//! [`BufRead`](std::io::BufRead) and turns it into a [`Statement`]: the
//! 1-based line where the statement starts and a [`ClEvent`]. It keeps the
//! modal state a post-processor needs to interpret a CL file (the current tool
//! axis and reference direction, the one-shot `RAPID`, the units), so that
//! every [`ClEvent::Goto`] is complete on its own.
//!
//! Problems are reported as [`Diagnostic`]s that name the file, the line and
//! the column and carry the source line: errors are returned by
//! [`ClReader::next_statement`], warnings are collected and handed out by
//! [`ClReader::take_warnings`]. A caller that reads mostly moves can ask
//! [`ClReader::next_move`] instead: it writes the `GOTO` of a plain line into
//! a [`Move`] of the caller's and hands every other statement out as usual.
//!
//! # Example
//!
//! ```
//! use kinpost_cl::{ClEvent, ClReader, Motion};
//!
//! let cl = "\
//! TOOL PATH/ROUGH,TOOL,EM10
//! RAPID
//! GOTO/10,20,30,0,0,1
//! FEDRAT/MMPM,250
//! GOTO / 10, 25, 30 $$ CATIA spacing, trailing comment
//! FOO/1
//! ";
//! let mut reader = ClReader::new(cl.as_bytes(), "part.cls");
//! let mut gotos = Vec::new();
//! while let Some(statement) = reader.next_statement().unwrap() {
//!     if let ClEvent::Goto { point, axis, motion, .. } = statement.event {
//!         gotos.push((statement.line, point, axis, motion));
//!     }
//! }
//! assert_eq!(gotos[0], (3, [10.0, 20.0, 30.0], [0.0, 0.0, 1.0], Motion::Rapid));
//! assert_eq!(gotos[1], (5, [10.0, 25.0, 30.0], [0.0, 0.0, 1.0], Motion::Feed));
//!
//! // `FOO` is unknown: a warning naming line 6, not an error.
//! let warnings = reader.take_warnings();
//! assert_eq!(warnings.len(), 1);
//! assert_eq!(warnings[0].line, 6);
//! assert_eq!(warnings[0].message, "unknown statement `FOO` ignored");
//! ```
//!
//! # What is read
//!
//! | statement | event |
//! |---|---|
//! | `TOOL PATH/name,word,…` | [`ClEvent::ToolPath`] |
//! | `TLDATA/kind,v,…`, `CUTTER/v,…` | [`ClEvent::ToolData`] |
//! | `MSYS/x,y,z[,xi,xj,xk[,yi,yj,yk]]` | [`ClEvent::MachineSystem`]; a later `MSYS` that changes it is an error |
//! | `$$ text`, `PPRINT/text` | [`ClEvent::Comment`] |
//! | `RAPID`, `RAPID/` | no event: the next `GOTO` is a rapid move |
//! | `GOTO/x,y,z[,i,j,k[,u,v,w]]` | [`ClEvent::Goto`] |
//! | `GODLTA/dx,dy,dz`, `GODLTA/d` (along the tool axis) | [`ClEvent::Goto`] to the last point moved by that much |
//! | `TLAXIS/i,j,k` | no event: the tool axis of the three-value `GOTO`s that follow |
//! | `FEDRAT/[unit,]f`, `FEDRAT/f[,unit]` | [`ClEvent::Feedrate`]; it cancels a `RAPID` no move used (with a warning) |
//! | `LOAD/TOOL,n`, `LOADTL/n`, `SELECT/TOOL,n` | [`ClEvent::LoadTool`], [`ClEvent::SelectTool`] |
//! | `SPINDL/rpm,RPM,CLW`, `SPINDL/OFF` | [`ClEvent::Spindle`], [`ClEvent::SpindleOff`] |
//! | `COOLNT/mode` | [`ClEvent::Coolant`] |
//! | `INSERT/text` | [`ClEvent::Insert`] |
//! | `END-OF-PATH` | [`ClEvent::EndOfPath`] |
//! | `PARTNO/text`, `PARTNO text` | [`ClEvent::PartNo`] (one pair of enclosing quotes removed) |
//! | `UNITS/MM`, `UNIT/MM`, `UNITS/INCHES` | [`ClEvent::Units`] |
//! | `MULTAX[/ON\|/OFF]` | [`ClEvent::Multax`] |
//! | `PRESSURE/[word,]value` (kinpost extension) | [`ClEvent::Pressure`] |
//! | `FINI` | [`ClEvent::Fini`] |
//! | `PAINT/…`, `TRNTYP/…`, `CSI_…`, identity `CSYS/…`, `CUTCOM/OFF` | nothing (display-only or harmless) |
//! | `CUTCOM/LEFT\|RIGHT…` | nothing, with a warning (cutter compensation ignored) |
//! | `CIRCLE/…`, `NURBS…`, `CYCLE/…`, non-identity `CSYS/…`, `TLAXIS` other than `i,j,k` | error: not supported yet |
//! | anything else | nothing, with a warning (unknown statement ignored) |
//!
//! # Syntax
//!
//! * Keywords are case-insensitive; whitespace is allowed around `/` and `,`.
//! * Numbers are APT style: `.9625`, `25.`, `-3.`, `1E-3`, `+2`.
//! * A line whose text ends in `$` continues on the next line (the `$` is
//!   removed and the lines are joined). `$$` starts a comment: a line that
//!   starts with `$$` is a [`ClEvent::Comment`]; a `$$ …` after a statement is
//!   ignored (also inside `INSERT/` text). A comment line inside a continued
//!   statement is skipped.
//! * LF or CRLF line ends, blank lines, a UTF-8 byte-order mark at the start,
//!   any UTF-8 text in names. Invalid UTF-8 is an error naming the line.

#![deny(missing_docs)]

mod number;
mod reader;
mod words;
mod writer;

pub use kinpost_diag::{Diagnostic, Severity};
pub use number::parse_number;
pub use reader::{ClReader, MAX_STATEMENT_BYTES, MAX_STATEMENT_LINES};
pub use writer::{ClWriter, WriteError};

/// A point or a direction: `[x, y, z]`.
pub type Vec3 = [f64; 3];

/// How the tool moves to a [`ClEvent::Goto`] point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Motion {
    /// Positioning move at the machine's rapid rate (the statement before the
    /// `GOTO` was `RAPID`).
    Rapid,
    /// Cutting move at the current feed rate.
    #[default]
    Feed,
}

/// The unit of a [`ClEvent::Feedrate`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FeedUnit {
    /// Millimetres per minute (`MMPM`).
    Mmpm,
    /// Inches per minute (`IPM`).
    Ipm,
    /// Millimetres per revolution (`MMPR`).
    Mmpr,
    /// Inches per revolution (`IPR`).
    Ipr,
}

/// Length units of a CL file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Units {
    /// Millimetres (`UNITS/MM`), the default.
    Mm,
    /// Inches (`UNITS/INCHES`).
    Inch,
}

/// Spindle rotation direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SpindleDir {
    /// `CLW`, M3.
    Clockwise,
    /// `CCLW`, M4.
    CounterClockwise,
}

/// What one CL statement means.
#[derive(Debug, Clone, PartialEq)]
pub enum ClEvent {
    /// `TOOL PATH/name,word,…`: start of an operation. `name` is the first
    /// field, `words` the others, all trimmed, any UTF-8.
    ToolPath {
        /// Operation name.
        name: String,
        /// The remaining fields (e.g. `TOOL`, the tool name).
        words: Vec<String>,
    },
    /// `TLDATA/kind,values…` (`kind` as written, e.g. `MILL`; empty when the
    /// first field is already a number) or `CUTTER/values…` (`kind` is
    /// `"CUTTER"`).
    ToolData {
        /// Tool kind.
        kind: String,
        /// The numeric fields, in order.
        values: Vec<f64>,
    },
    /// `MSYS/x,y,z,xi,xj,xk,yi,yj,yk`: the machine coordinate system (origin
    /// and the directions of its X and Y axes, as written). A cut-short `MSYS`
    /// gives a warning and keeps what is there.
    MachineSystem {
        /// Origin.
        origin: Vec3,
        /// Direction of the X axis, if given.
        x: Option<Vec3>,
        /// Direction of the Y axis, if given.
        y: Option<Vec3>,
    },
    /// `$$ text` on a line of its own (text trimmed), or `PPRINT/text`.
    Comment(String),
    /// `GOTO/…`: a move. Always complete: a three-value `GOTO` repeats the
    /// current tool axis and reference direction.
    Goto {
        /// Tool tip point.
        point: Vec3,
        /// Tool axis, unit length.
        axis: Vec3,
        /// Reference direction (kinpost extension: nine-value `GOTO`), unit
        /// length, if one was ever given.
        reference: Option<Vec3>,
        /// Rapid if the previous motion statement was `RAPID`.
        motion: Motion,
    },
    /// `FEDRAT/…`: feed rate, always positive.
    Feedrate {
        /// Feed value.
        value: f64,
        /// Its unit (`FEDRAT/250` without a unit: `Mmpm`, or `Ipm` after
        /// `UNITS/INCHES`).
        unit: FeedUnit,
    },
    /// `LOAD/TOOL,n`: tool change.
    LoadTool {
        /// Tool number.
        number: u32,
    },
    /// `SELECT/TOOL,n`: pre-select the next tool.
    SelectTool {
        /// Tool number.
        number: u32,
    },
    /// `SPINDL/rpm,RPM,CLW|CCLW` (also `SPINDL/RPM,rpm,…`, and `SPINDL/ON`
    /// to restart the last speed).
    Spindle {
        /// Speed in revolutions per minute, positive.
        rpm: f64,
        /// Direction (`CLW` when not given).
        dir: SpindleDir,
    },
    /// `SPINDL/OFF`.
    SpindleOff,
    /// `COOLNT/FLOOD|MIST|THRU|ON|OFF|…`.
    Coolant {
        /// False for `COOLNT/OFF`.
        on: bool,
        /// The first word other than `ON` and `OFF`, upper case (`"MIST"`
        /// for `COOLNT/ON,MIST`); else the first word (`"ON"` for a bare
        /// `COOLNT`).
        mode: String,
    },
    /// `INSERT/text`: the text after the first `/`, verbatim (trailing
    /// whitespace and a trailing `$$` comment removed).
    Insert(String),
    /// `END-OF-PATH`.
    EndOfPath,
    /// `PARTNO/text` or `PARTNO text` (text trimmed).
    PartNo(String),
    /// `UNITS/MM`, `UNIT/MM`, `UNITS/INCHES`.
    Units(Units),
    /// `MULTAX` or `MULTAX/ON` (true), `MULTAX/OFF` (false).
    Multax(bool),
    /// kinpost extension: `PRESSURE/H1,3000` or `PRESSURE/3000` (contact
    /// pressure for belt grinding; not negative).
    Pressure {
        /// The optional word before the value (`H1`), as written.
        word: Option<String>,
        /// The value.
        value: f64,
    },
    /// `FINI`: end of the CL file.
    Fini,
}

/// A `GOTO` written by [`ClReader::next_move`]: the fields of
/// [`ClEvent::Goto`] and the line of the statement.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Move {
    /// 1-based line of the statement.
    pub line: usize,
    /// Tool tip point.
    pub point: Vec3,
    /// Tool axis, unit length.
    pub axis: Vec3,
    /// Reference direction, unit length, if one was ever given.
    pub reference: Option<Vec3>,
    /// Rapid if the previous motion statement was `RAPID`.
    pub motion: Motion,
}

impl From<Move> for Statement {
    fn from(m: Move) -> Statement {
        Statement {
            line: m.line,
            event: ClEvent::Goto {
                point: m.point,
                axis: m.axis,
                reference: m.reference,
                motion: m.motion,
            },
        }
    }
}

/// What [`ClReader::next_move`] found.
#[derive(Debug, Clone, PartialEq)]
pub enum Next {
    /// A `GOTO`, written into the caller's [`Move`].
    Move,
    /// Any other statement (a `GOTO` too, when its line is not plain).
    Statement(Statement),
    /// The end of the input.
    End,
}

/// One logical CL statement (possibly several physical lines).
#[derive(Debug, Clone, PartialEq)]
pub struct Statement {
    /// 1-based line where the statement starts.
    pub line: usize,
    /// What it means.
    pub event: ClEvent,
}

#[cfg(test)]
mod tests;
