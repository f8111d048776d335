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
//! Every length and feed an event carries is in mm, whatever the file's
//! units (see *Units* below). The meaning of each statement, what each CAM
//! system writes and the sources are in the repository's
//! `docs/cl-statements.md`.
//!
//! | statement | event |
//! |---|---|
//! | `TOOL PATH/name,word,…` | [`ClEvent::ToolPath`] |
//! | `TLDATA/kind[,kind2…],v,…`, `CUTTER/d[,r,e,f,α,β,h]` | [`ClEvent::ToolData`] ([`ToolData`]) |
//! | `MSYS/x,y,z[,xi,xj,xk,yi,yj,yk]` | [`ClEvent::MachineSystem`], checked orthonormal ([`FRAME_TOLERANCE`]); a cut-short record: warning |
//! | `CSYS/` 3 × 4 matrix | [`ClEvent::CoordinateSystem`] ([`Frame::from_rows`], checked orthonormal) |
//! | `$$ text` (Creo `$$->` continued with `$` joined), `PPRINT/text` | [`ClEvent::Comment`] |
//! | `RAPID`, `RAPID/` | no event: the next `GOTO` is a rapid move |
//! | `GOTO/x,y,z[,i,j,k[,u,v,w]]`, Creo's further points on lines of their own | [`ClEvent::Goto`] |
//! | `CIRCLE/x,y,z,i,j,k[,r[,t,f,d,e]][,TIMES,n]` (SOLIDWORKS CAM 6, Creo 7, NX 11 values) | [`ClEvent::Circle`] ([`Circle`]): the next `GOTO` ends the arc; axis made right-handed |
//! | `NURBS/` with `KNOT/…` and `CNTRL/…` records (NX) | [`ClEvent::Nurbs`] ([`Nurbs`]) |
//! | `GODLTA/dx,dy,dz`, `GODLTA/d` (along the tool axis) | [`ClEvent::Goto`] to the last point moved by that much |
//! | `FROM/x,y,z[,i,j,k]` | [`ClEvent::From`] (also the current point and, if given, the tool axis) |
//! | `GOHOME[/x,y,z[,i,j,k]]` | [`ClEvent::GoHome`] |
//! | `TLAXIS/i,j,k` | no event: the tool axis of the three-value `GOTO`s that follow; other forms are APT part-program geometry: error |
//! | `FEDRAT/[unit,]f`, `FEDRAT/f[,unit]` (`MMPM`, `IPM`, `MMPR`, `IPR`) | [`ClEvent::Feedrate`] in mm; it cancels a `RAPID` no move used (with a warning) |
//! | `CYCLE/kind[,kind2],keyword,value,…` (NX, Creo, SOLIDWORKS CAM couplets) | [`ClEvent::Cycle`] ([`Cycle`]) |
//! | `CYCLE/OFF` | [`ClEvent::CycleOff`] |
//! | `CYCLE/INIT`, `CYCLE/CLEAR` (SOLIDWORKS CAM, no values) | nothing: they announce the `CYCLE` that follows |
//! | `LOAD/TOOL,n[,ADJUST,m]`, `LOADTL/n[,ADJUST,m]` | [`ClEvent::LoadTool`] |
//! | `SELECT/TOOL,n` | [`ClEvent::SelectTool`] |
//! | `SPINDL/[RPM,]n[,RPM\|SFM\|SMM][,CLW\|CCLW][,RANGE,r][,MAXRPM,m]`, `SPINDL/ON` | [`ClEvent::Spindle`] ([`SpindleSpeed`]) |
//! | `SPINDL/OFF` | [`ClEvent::SpindleOff`] |
//! | `COOLNT/FLOOD\|MIST\|THRU\|AIR\|ON\|OFF…` | [`ClEvent::Coolant`] |
//! | `CUTCOM/LEFT\|RIGHT\|OFF[,XYPLAN\|YZPLAN\|ZXPLAN][,n]` | [`ClEvent::CutterCompensation`] |
//! | `DELAY/t[,REV]`, `DWELL/t` | [`ClEvent::Dwell`] |
//! | `STOP`, `OPSTOP`, `END` | [`ClEvent::Stop`], [`ClEvent::OptionalStop`], [`ClEvent::End`] |
//! | `MACHIN/name,…` | [`ClEvent::Machine`] |
//! | `OPNAME/name` | [`ClEvent::OperationName`] |
//! | `CLAMP/[ON\|OFF,]words` | [`ClEvent::Clamp`] |
//! | `ORIGIN/x,y,z` | [`ClEvent::Origin`] |
//! | `TMARK[/…]` | [`ClEvent::TapeMark`] |
//! | `SETUP/START,n`, `SETUP/END,n` (SOLIDWORKS CAM) | [`ClEvent::Setup`] |
//! | `INSERT/text` | [`ClEvent::Insert`] |
//! | `END-OF-PATH` | [`ClEvent::EndOfPath`] |
//! | `PARTNO/text`, `PARTNO text` | [`ClEvent::PartNo`] (one pair of enclosing quotes removed) |
//! | `UNITS/MM`, `UNIT/MM`, `UNITS/INCHES` | [`ClEvent::Units`] |
//! | `MULTAX[/ON\|/OFF]` | [`ClEvent::Multax`] |
//! | `PRESSURE/[word,]value` (kinpost extension) | [`ClEvent::Pressure`] |
//! | `FINI` | [`ClEvent::Fini`] |
//! | `PAINT/…` (NX display records), `TRNTYP/…` (SOLIDWORKS CAM's transformation type, informational), `CSI_…` | nothing (display-only or informational) |
//! | NX's "Information listing created by…" header with its `Date`, `Current work part`, `Node name` lines; "Tool Path Listing has N lines." | nothing (the listing around an NX CLSF) |
//! | `KNOT/`, `CNTRL/` not after a `NURBS/` | error |
//! | anything else | nothing, with a warning (unknown statement ignored) |
//!
//! # Units
//!
//! The reader converts every length to mm with one multiplication by
//! [`MM_PER_INCH`] when the file is in inches (`UNITS/INCHES`, or
//! [`ClReader::with_units`] given `Some(Units::Inch)`, the command's
//! `--units inch`); [`ClReader::units`] says which. An inch feed (`IPM`,
//! `IPR`) in a file that never declares its units and without
//! [`ClReader::with_units`] is an error that names `--units`: the file's
//! lengths would otherwise be read as mm. A `UNITS` statement that
//! contradicts [`ClReader::with_units`] is an error too.
//!
//! # Arcs, curves and cycles
//!
//! [`ClEvent::Circle`] and [`ClEvent::Nurbs`] describe the motion to the
//! next point: build it with [`Circle::arc`] (an [`Arc`]) or use the
//! [`Nurbs`]; both sample to a chord tolerance. A [`ClEvent::Cycle`] stays
//! on until [`ClEvent::CycleOff`]: the reader does not mark the `GOTO`s in
//! between, a post treats each as a hole.
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

pub mod curve;
pub mod encoding;
pub mod frame;
mod number;
mod reader;
mod vector;
mod words;
mod writer;

pub use curve::{Arc, ArcError, MAX_ARC_TURNS, MAX_SAMPLE_POINTS, Nurbs, NurbsError, SampleError};
pub use frame::{FRAME_TOLERANCE, Frame, FrameError};
pub use kinpost_diag::{Diagnostic, Severity};
pub use number::parse_number;
pub use reader::{ClReader, MAX_STATEMENT_BYTES, MAX_STATEMENT_LINES};
pub use writer::{ClWriter, WriteError};

/// A point or a direction: `[x, y, z]`.
pub type Vec3 = [f64; 3];

/// Millimetres in an inch.
pub const MM_PER_INCH: f64 = 25.4;

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

/// The unit of a feed rate. The reader converts inch feeds to mm: events
/// carry `Mmpm` or `Mmpr`; `Ipm` and `Ipr` name what a file wrote.
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

impl FeedUnit {
    /// Whether the feed is per spindle revolution.
    pub fn per_revolution(self) -> bool {
        matches!(self, FeedUnit::Mmpr | FeedUnit::Ipr)
    }

    /// Whether the unit is an inch unit.
    pub fn is_inch(self) -> bool {
        matches!(self, FeedUnit::Ipm | FeedUnit::Ipr)
    }
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

/// A `CIRCLE/` statement: the motion from the current point to the point of
/// the **next** [`ClEvent::Goto`] follows this circle (or helix). Whatever
/// the CAM system wrote, `axis` is given so that the motion is
/// counter-clockwise about it (right-hand rule); build the path with
/// [`Circle::arc`].
#[derive(Debug, Clone, PartialEq)]
pub struct Circle {
    /// Centre (mm).
    pub centre: Vec3,
    /// Unit axis; the tool moves counter-clockwise about it.
    pub axis: Vec3,
    /// Radius (mm): as written, or (SOLIDWORKS CAM writes none) the start
    /// point's distance from the axis.
    pub radius_mm: f64,
    /// The end point is reached for the `turns`-th time (NX `TIMES,n`;
    /// otherwise 1).
    pub turns: u32,
    /// NX: the total tolerance `t` (inside plus outside, mm) the arc was
    /// cut with.
    pub tolerance_mm: Option<f64>,
    /// NX: the tool diameter `d` (mm).
    pub tool_diameter_mm: Option<f64>,
    /// NX: the tool's corner radius `e` (mm).
    pub tool_corner_radius_mm: Option<f64>,
}

impl Circle {
    /// The arc from `start` (the current point) to `end` (the next `GOTO`).
    pub fn arc(&self, start: Vec3, end: Vec3) -> Result<Arc, ArcError> {
        Arc::new(start, end, self.centre, self.axis, self.turns)
    }
}

/// The kind of a canned cycle.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum CycleKind {
    /// Drilling (G81): `DRILL`.
    Drill,
    /// Peck drilling, retracting out of the hole (G83): `DEEP`, NX
    /// `DRILL,DEEP`, SOLIDWORKS CAM `DEEP2` (first and later pecks).
    Deep,
    /// Chip-breaking peck drilling (G73): `BRKCHP`.
    BreakChip,
    /// Tapping (G84): `TAP`.
    Tap,
    /// Boring (G85/G86/G89): `BORE`.
    Bore,
    /// Reaming: `REAM`.
    Ream,
    /// Facing / spot facing: `FACE`.
    Face,
    /// Countersinking: `CSINK`.
    Countersink,
    /// Drilling through (Creo `THRU`).
    Thru,
    /// Another kind word, as written (upper case).
    Other(String),
}

/// A dwell: time or spindle revolutions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Dwell {
    /// Seconds.
    Seconds(f64),
    /// Spindle revolutions.
    Revolutions(f64),
}

/// A feed rate in mm per minute or per revolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feed {
    /// Value in `unit`.
    pub value: f64,
    /// `Mmpm` or `Mmpr`.
    pub unit: FeedUnit,
}

/// A canned cycle (`CYCLE/…`): each following [`ClEvent::Goto`] is a hole,
/// its point the top of the hole, until [`ClEvent::CycleOff`]. The reader
/// does not mark the holes: a post keeps the cycle and treats the `GOTO`s
/// after it as holes. Distances are in mm along the tool axis, measured
/// from the hole point; see `docs/cl-statements.md` for how each CAM
/// system's words map to them.
#[derive(Debug, Clone, PartialEq)]
pub struct Cycle {
    /// What the cycle does.
    pub kind: CycleKind,
    /// How deep to feed below the hole point (`FEDTO`, `DEPTH`), positive.
    pub depth_mm: Option<f64>,
    /// Height above the hole point where the rapid approach ends and the
    /// feed starts (`RAPTO` of NX and SOLIDWORKS CAM; Creo `CLEAR` less its
    /// `RAPTO`).
    pub feed_start_mm: Option<f64>,
    /// Height above the hole point the tool returns to after each hole
    /// (`RTRCTO`, Creo `RETURN`); `None`: to the feed start.
    pub retract_mm: Option<f64>,
    /// Depth of the first peck (`STEP`, `INCR`, `1STPECK`).
    pub peck_mm: Option<f64>,
    /// Depth of the later pecks (a second `STEP` value, `SUBPECK`); `None`:
    /// as the first.
    pub next_peck_mm: Option<f64>,
    /// Dwell at the bottom.
    pub dwell: Option<Dwell>,
    /// The cycle's feed rate, if it has its own.
    pub feed: Option<Feed>,
    /// Tapping pitch (mm per revolution), if given.
    pub pitch_mm: Option<f64>,
    /// Chip breaking: how far the tool backs off after each peck (Creo
    /// `BACK`), if given.
    pub back_off_mm: Option<f64>,
    /// Chip breaking: the tool leaves the hole after every this many pecks
    /// (Creo `TIMES`), if given.
    pub full_retract_every: Option<u32>,
}

/// The side of cutter radius compensation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CutcomSide {
    /// `LEFT` (G41).
    Left,
    /// `RIGHT` (G42).
    Right,
    /// `OFF` (G40).
    Off,
}

/// A principal plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Plane {
    /// `XYPLAN` (G17).
    Xy,
    /// `YZPLAN` (G19).
    Yz,
    /// `ZXPLAN` (G18).
    Zx,
}

/// `TLDATA/…` or `CUTTER/…`: the tool's shape.
#[derive(Debug, Clone, PartialEq)]
pub struct ToolData {
    /// `"CUTTER"` for `CUTTER/`, else the first word of `TLDATA` (`MILL`,
    /// `DRILL`, `LATHE`, …; empty when the first field is a number).
    pub kind: String,
    /// Further leading words (NX `TLDATA/DRILL,MILL,…`: `["MILL"]`).
    pub words: Vec<String>,
    /// The numbers as written (in the file's units).
    pub values: Vec<f64>,
    /// Diameter (mm): the first number of every known form.
    pub diameter_mm: Option<f64>,
    /// Corner radius (mm): `TLDATA/MILL` and `CUTTER` second number.
    pub corner_radius_mm: Option<f64>,
    /// Length (mm): `TLDATA/MILL` third number, `CUTTER` seventh.
    pub length_mm: Option<f64>,
}

/// A spindle speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpindleSpeed {
    /// Revolutions per minute.
    Rpm(f64),
    /// Constant surface speed, metres per minute (`SMM`, or `SFM` converted).
    SurfaceMetresPerMinute(f64),
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
    /// `TLDATA/…` or `CUTTER/…`.
    ToolData(Box<ToolData>),
    /// `MSYS/x,y,z,xi,xj,xk,yi,yj,yk`: the machine coordinate system (NX's
    /// MCS) of the `GOTO`s that follow, in the absolute frame: origin and
    /// the directions of its X and Y axes, as written. A cut-short `MSYS`
    /// gives a warning and keeps what is there; `frame` is the checked frame
    /// when the origin and both axes are given.
    MachineSystem {
        /// Origin (mm).
        origin: Vec3,
        /// Direction of the X axis, if given.
        x: Option<Vec3>,
        /// Direction of the Y axis, if given.
        y: Option<Vec3>,
        /// The frame, when complete (checked orthonormal).
        frame: Option<Box<Frame>>,
    },
    /// `CSYS/` with a 3 × 4 matrix: a coordinate frame ([`Frame::from_rows`]).
    CoordinateSystem(Frame),
    /// `$$ text` on a line of its own (text trimmed; a Creo `$$->` comment
    /// continued with `$` is joined into one), or `PPRINT/text`.
    Comment(String),
    /// `GOTO/…`: a move. Always complete: a three-value `GOTO` repeats the
    /// current tool axis and reference direction.
    Goto {
        /// Tool tip point (mm).
        point: Vec3,
        /// Tool axis, unit length.
        axis: Vec3,
        /// Reference direction (kinpost extension: nine-value `GOTO`), unit
        /// length, if one was ever given.
        reference: Option<Vec3>,
        /// Rapid if the previous motion statement was `RAPID`.
        motion: Motion,
    },
    /// `CIRCLE/…`: the next `GOTO` is reached along this circle.
    Circle(Box<Circle>),
    /// `NURBS/` with its `KNOT/` and `CNTRL/` records: the tool follows the
    /// curve from the current point (its first control point) to its end
    /// (the last control point), at the current feed.
    Nurbs(Nurbs),
    /// `FROM/x,y,z[,i,j,k]`: the tool's start point (and axis).
    From {
        /// Point (mm).
        point: Vec3,
        /// Tool axis, if given (unit length).
        axis: Option<Vec3>,
    },
    /// `GOHOME[/x,y,z[,i,j,k]]`: return to the home point (`None`: no
    /// point written and no `FROM` before: the machine's home).
    GoHome {
        /// The point, as written or the last `FROM` point (mm).
        point: Option<Vec3>,
        /// Tool axis, if written (unit length).
        axis: Option<Vec3>,
    },
    /// `FEDRAT/…`: feed rate, always positive, in mm.
    Feedrate {
        /// Feed value.
        value: f64,
        /// `Mmpm` or `Mmpr` (inch feeds are converted).
        unit: FeedUnit,
    },
    /// `CYCLE/…`: a canned cycle starts (or its parameters change).
    Cycle(Box<Cycle>),
    /// `CYCLE/OFF`: the canned cycle ends.
    CycleOff,
    /// `LOAD/TOOL,n[,ADJUST,m]`, `LOADTL/n[,ADJUST,m]`: tool change.
    LoadTool {
        /// Tool number.
        number: u32,
        /// Length offset register (`ADJUST`), if given.
        adjust: Option<u32>,
    },
    /// `SELECT/TOOL,n`: pre-select the next tool.
    SelectTool {
        /// Tool number.
        number: u32,
    },
    /// `SPINDL/rpm,RPM,CLW|CCLW` (also `SPINDL/RPM,rpm,…`, `SPINDL/ON` to
    /// restart the last speed), with an optional `RANGE,n` and `MAXRPM,m`.
    Spindle {
        /// Speed: revolutions per minute, or a constant surface speed
        /// (`SFM`, `SMM`).
        speed: SpindleSpeed,
        /// Direction (`CLW` when not given).
        dir: SpindleDir,
        /// Gear range, if given.
        range: Option<u32>,
        /// Speed limit in rpm (`MAXRPM`), if given.
        max_rpm: Option<f64>,
    },
    /// `SPINDL/OFF`.
    SpindleOff,
    /// `COOLNT/FLOOD|MIST|THRU|AIR|ON|OFF|…`.
    Coolant {
        /// False for `COOLNT/OFF`.
        on: bool,
        /// The first word other than `ON` and `OFF`, upper case (`"MIST"`
        /// for `COOLNT/ON,MIST`); else the first word (`"ON"` for a bare
        /// `COOLNT`).
        mode: String,
    },
    /// `CUTCOM/LEFT|RIGHT|OFF[,XYPLAN|YZPLAN|ZXPLAN][,n]`: cutter radius
    /// compensation; the `GOTO`s are then the part contour, not tool centre
    /// positions.
    CutterCompensation {
        /// Side, or off.
        side: CutcomSide,
        /// Plane, if given.
        plane: Option<Plane>,
        /// Offset register, if given.
        register: Option<u32>,
    },
    /// `DELAY/t[,REV]`, `DWELL/t`: wait.
    Dwell(Dwell),
    /// `STOP`: program stop (M00).
    Stop,
    /// `OPSTOP`: optional stop (M01).
    OptionalStop,
    /// `END`: end of a program section (stop; spindle and coolant off).
    End,
    /// `MACHIN/name,…`: the post-processor / machine the CAM system chose.
    Machine {
        /// First field.
        name: String,
        /// The other fields, as written.
        args: Vec<String>,
    },
    /// `OPNAME/name`: operation name.
    OperationName(String),
    /// `CLAMP/…`: clamp or release an axis.
    Clamp {
        /// False for `OFF`.
        on: bool,
        /// The other words (axis names), as written.
        words: Vec<String>,
    },
    /// `ORIGIN/x,y,z`: the program origin moves to this point (mm).
    Origin(Vec3),
    /// `TMARK[/…]`: tape mark.
    TapeMark,
    /// SOLIDWORKS CAM `SETUP/START,n` and `SETUP/END,n`.
    Setup {
        /// True at `START`.
        start: bool,
        /// Setup number.
        number: u32,
    },
    /// `INSERT/text`: the text after the first `/`, verbatim (trailing
    /// whitespace and a trailing `$$` comment removed).
    Insert(String),
    /// `END-OF-PATH`.
    EndOfPath,
    /// `PARTNO/text` or `PARTNO text` (text trimmed).
    PartNo(String),
    /// `UNITS/MM`, `UNIT/MM`, `UNITS/INCHES`: the file's length units (the
    /// reader converts to mm).
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
