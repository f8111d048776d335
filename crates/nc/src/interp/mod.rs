//! The NC interpreter: real programs of the four controller families
//! (Sinumerik 840D, Fanuc, LinuxCNC rs274ngc, Heidenhain TNC conversational)
//! and kinpost's CSV tables, turned into a stream of typed, fully resolved
//! [`Step`]s for the virtual machine.
//!
//! What the interpreter resolves (so that the replay never has to):
//! - every motion block's END value of every machine axis, in machine order,
//!   as an absolute value in the work coordinate system in force, in mm and
//!   degrees: incremental words (`G91`, `IC()`, Heidenhain `IX`) are added,
//!   inch programs (`G20`, `G70`, `BEGIN PGM … INCH`) converted, rotary
//!   `DC`/`ACP`/`ACN`/`AC` resolved to the position the controller reaches,
//!   endless axes ([`AxisSpec::endless`]) reported in `[0, 360)` with the
//!   signed way they turned in [`Move::travel`];
//! - arcs with their plane, absolute centre, helical component and full
//!   turns; canned cycles expanded into their real moves;
//! - expressions, variables and control flow (jumps, loops, subprograms),
//!   bounded by [`Options::max_executed_blocks`] and
//!   [`Options::max_call_depth`].
//!
//! What it reports but does not apply (the virtual machine's business): the
//! work offset in force (its values when the program or the options set
//! them), tool length compensation, cutter radius compensation (`G41`/`G42`,
//! `RL`/`RR`: the programmed contour is reported, the cutter centre path is
//! NOT offset), tool-centre-point control.
//!
//! Anything a program asks for that the interpreter does not model is an
//! error naming the file, line and column with the source line; M-codes it
//! does not know are warnings (machines define their own) and pass through
//! as [`Event::MCode`]. Machine inputs (`$A_IN[n]`, `#<_hal[…]>`, `M66`)
//! come from [`Options::inputs`]; an input the options do not give reads 0,
//! and the run says so in [`Report::assumed`].
//!
//! ```
//! use kinpost_nc::AxisSpec;
//! use kinpost_nc::interp::{Event, Family, MotionKind, Options, read_all};
//! let axes = [AxisSpec::linear("X"), AxisSpec::linear("Y"), AxisSpec::linear("Z")];
//! let text = "G21 G90 G17\nG0 X10 Y5\n#1 = 2.5\nG91 G1 X#1 F200\nM2\n";
//! let (steps, _report) = read_all(text, Family::LinuxCnc, &axes, &Options::default(), "p.ngc").unwrap();
//! let moves: Vec<_> = steps.iter().filter_map(|s| match &s.event {
//!     Event::Move(m) => Some((s.line, m.kind.clone(), m.axes()[0])),
//!     _ => None,
//! }).collect();
//! assert_eq!(moves, [(2, MotionKind::Rapid, 10.0), (4, MotionKind::Linear, 12.5)]);
//! ```

use std::collections::BTreeMap;

use kinpost_diag::Diagnostic;

use crate::dialect::{Dialect, DialectKind};
use crate::{ArcMotion, ArcPlane, AxisSpec, Block, Motion};

mod arc;
mod csv;
mod cycle;
mod expr;
mod heidenhain;
mod machine;
mod num;
mod rs274;
mod sinumerik;
mod source;

pub use machine::Tolerances;

/// Most machine axes an interpreter handles (LinuxCNC's nine and room for a
/// pressure word and auxiliary axes).
pub const MAX_AXES: usize = 12;

/// The controller family whose language a program is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Family {
    /// Siemens Sinumerik 840D (ISO dialect off: `X=`, `R1=`, `DEF`, `GOTOF`).
    Sinumerik,
    /// Fanuc 0i/30i ISO code with custom macro B (`#1`, `IF [..] GOTO`, `G65`).
    Fanuc,
    /// LinuxCNC rs274ngc (`#<name>`, O-words).
    LinuxCnc,
    /// Heidenhain TNC conversational (Klartext: `L X+10 R0 FMAX`).
    Heidenhain,
    /// kinpost's own CSV table (one row per motion block).
    Csv,
}

impl Family {
    /// The family of a dialect: a built-in one by its name; a user dialect
    /// by its program file extension (`mpf`/`spf` Sinumerik, `nc`/`tap`
    /// Fanuc, `ngc` LinuxCNC, `h` Heidenhain) or its kind (CSV). `None` when
    /// neither tells.
    pub fn of_dialect(dialect: &Dialect) -> Option<Family> {
        if dialect.kind() == DialectKind::Csv {
            return Some(Family::Csv);
        }
        match dialect.name() {
            "sinumerik" => return Some(Family::Sinumerik),
            "fanuc" => return Some(Family::Fanuc),
            "linuxcnc" => return Some(Family::LinuxCnc),
            "heidenhain" => return Some(Family::Heidenhain),
            _ => {}
        }
        match dialect.extension().to_ascii_lowercase().as_str() {
            "mpf" | "spf" => Some(Family::Sinumerik),
            "nc" | "tap" | "iso" => Some(Family::Fanuc),
            "ngc" => Some(Family::LinuxCnc),
            "h" => Some(Family::Heidenhain),
            _ => None,
        }
    }
}

/// Axis values in machine order (the axes given to the interpreter); the
/// first [`AxisValues::len`] entries are meaningful.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisValues {
    values: [f64; MAX_AXES],
    len: u8,
}

impl AxisValues {
    /// `len` zeros.
    pub(crate) fn zeros(len: usize) -> AxisValues {
        AxisValues {
            values: [0.0; MAX_AXES],
            len: len.min(MAX_AXES) as u8,
        }
    }

    /// The values, one per machine axis.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..usize::from(self.len)]
    }

    pub(crate) fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.values[..usize::from(self.len)]
    }

    /// Number of axes.
    pub fn len(&self) -> usize {
        usize::from(self.len)
    }

    /// No axes.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }
}

impl std::ops::Index<usize> for AxisValues {
    type Output = f64;
    fn index(&self, i: usize) -> &f64 {
        &self.as_slice()[i]
    }
}

/// An arc (circular or helical interpolation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Arc {
    /// ArcPlane of the circle.
    pub plane: ArcPlane,
    /// Clockwise seen from the positive end of the plane's normal (`G2`,
    /// `DR-`), else counter-clockwise.
    pub clockwise: bool,
    /// Absolute centre in the work coordinate system, mm, as (X, Y, Z); the
    /// coordinate along the plane's normal is the start's.
    pub centre_mm: [f64; 3],
    /// Start point in the work coordinate system, mm, as (X, Y, Z).
    pub start_mm: [f64; 3],
    /// Radius at the start, mm.
    pub radius_mm: f64,
    /// Full turns before the last partial one (LinuxCNC `P2` → 1,
    /// Sinumerik `TURN=1` → 1); 0 for an ordinary arc. A full circle whose
    /// end is its start has `turns` 0 and `sweep_deg` 360.
    pub turns: u32,
    /// Angle swept in the plane, degrees, positive, full turns included.
    pub sweep_deg: f64,
    /// Travel along the plane's normal (helix), mm; 0 for a plane arc.
    pub helix_mm: f64,
}

/// How a motion block moves.
#[derive(Debug, Clone, PartialEq)]
pub enum MotionKind {
    /// Positioning at rapid traverse (`G0`, `FMAX`).
    Rapid,
    /// Linear interpolation at the feed (`G1`, `L`).
    Linear,
    /// Circular or helical interpolation.
    Arc(Arc),
}

/// Feed rate mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum FeedMode {
    /// mm/min (`G94`, Sinumerik `G94`, Heidenhain `F`).
    PerMinute,
    /// Inverse time: F = 1 / block time in minutes (`G93`).
    InverseTime,
    /// mm per spindle revolution (`G95`, Heidenhain `FU`).
    PerRevolution,
}

/// Cutter radius compensation (reported, not applied).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CutterComp {
    /// `G40`, `R0`.
    Off,
    /// `G41`, `RL`: tool left of the contour.
    Left,
    /// `G42`, `RR`: tool right of the contour.
    Right,
}

/// Spindle direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SpindleDir {
    /// Stopped (`M5`).
    Off,
    /// Clockwise (`M3`).
    Cw,
    /// Counter-clockwise (`M4`).
    Ccw,
}

/// The coordinate system block values are given in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum WorkOffset {
    /// None selected (Sinumerik `G500`, power-on state, a Heidenhain program
    /// without a preset or datum cycle).
    None,
    /// A numbered work offset: 1..=6 for `G54`..`G59`; `G54.1 P n` and
    /// Fanuc's `G54 P n` as 100 + n; LinuxCNC `G59.1`..`G59.3` as 7..=9;
    /// Sinumerik `G505`..`G599` as 5..=99; a Heidenhain preset (cycle 247)
    /// as 1000 + its number.
    Numbered(u16),
}

/// Where the tool-length and work-offset words in force leave the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModalState {
    /// Work offset in force.
    pub work_offset: WorkOffset,
    /// Values of the work offset and every shift in force (G5x + G92/G52,
    /// Sinumerik settable offset, Heidenhain datum shift), per axis, mm /
    /// degrees, as far as the program or [`Options::work_offsets`] set them
    /// (0 otherwise: see [`Report::assumed`]). machine = value + offset.
    pub offset: AxisValues,
    /// Tool length compensation in force: the offset number (`G43 H2` → 2,
    /// Sinumerik `D1` → 1, Heidenhain: the tool number); `None` after `G49`
    /// / `D0`.
    pub tool_length: Option<u32>,
    /// Cutter radius compensation (reported only).
    pub cutter_comp: CutterComp,
    /// Tool-centre-point control (`TRAORI`, `G43.4`, `M128`, `FUNCTION TCPM`).
    pub tcp: bool,
    /// Spindle direction.
    pub spindle: SpindleDir,
    /// Programmed spindle speed, 1/min (0 before the first `S`).
    pub spindle_speed: f64,
    /// Coolant: mist (`M7`).
    pub coolant_mist: bool,
    /// Coolant: flood (`M8`).
    pub coolant_flood: bool,
    /// Tool in the spindle (after the last tool change), if any.
    pub tool: Option<u32>,
    /// Working plane.
    pub plane: ArcPlane,
}

/// A drilling cycle a move belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct CycleRef {
    /// Cycle code: 81..=89, 73, 76 for G-code cycles; 81..=86 for Sinumerik
    /// `CYCLE81`..`CYCLE86`; 200..=208 for Heidenhain cycles.
    pub code: u16,
    /// 1-based NC line of the cycle call (the block that drilled this hole).
    pub line: usize,
}

/// One motion block, fully resolved.
#[derive(Debug, Clone, PartialEq)]
pub struct Move {
    /// How it moves.
    pub kind: MotionKind,
    /// END value of every machine axis, machine order, absolute, in the
    /// work coordinate system (see [`ModalState::offset`]); mm and degrees;
    /// endless axes in `[0, 360)`. The pressure word is carried here too.
    pub end: AxisValues,
    /// Signed change of every axis in this block (for an endless axis the
    /// way it turned, which its end value in `[0, 360)` cannot tell).
    pub travel: AxisValues,
    /// Machine axes whose value the block programmed (bit i = axis i).
    pub programmed: u32,
    /// The block's values of these axes (bit i) are machine coordinates
    /// (`G53`, Sinumerik `SUPA`/`G53`): `end` still gives work coordinates
    /// (the machine value minus [`ModalState::offset`]).
    pub machine_frame: bool,
    /// Feed value in force (mm/min, 1/min for inverse time, mm/rev), 0
    /// before the first; meaningless for rapids.
    pub feed: f64,
    /// Feed mode in force.
    pub feed_mode: FeedMode,
    /// The drilling cycle this move is a part of.
    pub cycle: Option<CycleRef>,
    /// Modal state in force for this block.
    pub state: ModalState,
}

impl Move {
    /// The end values as a slice (machine order).
    pub fn axes(&self) -> &[f64] {
        self.end.as_slice()
    }

    /// The move as the block model has it (the type the post's writers
    /// take): rapid or feed, the end values, the feed in force on a feed
    /// move (`None` before the first feed word and on rapids), and an arc's
    /// plane, sense and centre relative to its start. Where it stands in
    /// the program is the [`Step`]'s ([`Step::block`]).
    pub fn block(&self) -> Block<&[f64]> {
        let rapid = self.kind == MotionKind::Rapid;
        Block {
            cl_line: None,
            line: None,
            number: None,
            motion: if rapid { Motion::Rapid } else { Motion::Feed },
            axes: self.axes(),
            feed: (!rapid && self.feed > 0.0).then_some(self.feed),
            arc: match &self.kind {
                MotionKind::Arc(arc) => Some(ArcMotion {
                    plane: arc.plane,
                    clockwise: arc.clockwise,
                    centre_offset: [0, 1, 2].map(|k| arc.centre_mm[k] - arc.start_mm[k]),
                }),
                _ => None,
            },
        }
    }
}

impl Step {
    /// The block of a motion step ([`Move::block`]); `None` for the other
    /// events.
    pub fn block(&self) -> Option<Block<&[f64]>> {
        match &self.event {
            Event::Move(m) => Some(Block {
                cl_line: self.cl_line,
                line: Some(self.line),
                number: self.number,
                ..m.block()
            }),
            _ => None,
        }
    }
}

/// Why a program stops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StopKind {
    /// Programmed stop (`M0`).
    Program,
    /// Optional stop (`M1`).
    Optional,
    /// End of program (`M2`, `M30`, `END PGM`, `M17`/`RET` of the main program).
    End,
}

/// Something the replay must see.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A motion block (boxed: the other events are small).
    Move(Box<Move>),
    /// Tool change (`M6`, `TOOL CALL`): the tool now in the spindle.
    ToolChange {
        /// Tool number.
        tool: u32,
    },
    /// Next tool selected (`T5` without a change).
    ToolSelect {
        /// Tool number.
        tool: u32,
    },
    /// Spindle direction and speed (`M3 S2000`, `S2000` alone).
    Spindle {
        /// Direction.
        dir: SpindleDir,
        /// Speed, 1/min.
        speed: f64,
    },
    /// Coolant state after `M7`/`M8`/`M9`.
    Coolant {
        /// Mist on.
        mist: bool,
        /// Flood on.
        flood: bool,
    },
    /// Dwell.
    Dwell {
        /// Seconds (revolutions are converted with the speed in force).
        seconds: f64,
    },
    /// Program stop or end.
    Stop(StopKind),
    /// Length units changed (`G20`/`G21`, `G70`/`G71`, `BEGIN PGM … INCH`):
    /// `true` for inch. Values in events stay mm.
    Units {
        /// Inch programming.
        inch: bool,
    },
    /// Work offset selection or values changed (`G54`, `G10 L2`, `G92`,
    /// Heidenhain datum cycles).
    WorkOffset(WorkOffset),
    /// Tool-centre-point control on or off.
    Tcp(bool),
    /// Tool length compensation changed: the offset number, `None` off.
    ToolLength(Option<u32>),
    /// Cutter radius compensation changed (reported only).
    CutterComp(CutterComp),
    /// Working plane changed.
    ArcPlane(ArcPlane),
    /// Feed mode changed.
    FeedMode(FeedMode),
    /// The pressure word was programmed (`H1=3000`): axis index and value.
    Pressure {
        /// Machine axis index of the pressure word.
        axis: usize,
        /// Value as programmed.
        value: f64,
    },
    /// A drilling cycle was defined or (modally) called; its holes follow
    /// as moves carrying [`Move::cycle`].
    Cycle {
        /// Cycle code (see [`CycleRef::code`]).
        code: u16,
    },
    /// Drilling cycle mode cancelled (`G80`, `MCALL` without a cycle).
    CycleOff,
    /// An operator message (`MSG("…")`, `(MSG,…)`, `(PRINT,…)`, `(DEBUG,…)`).
    Message(String),
    /// An M-code the interpreter has no meaning for (machine-specific,
    /// warned about): passed on for the replay.
    MCode(u32),
    /// Output of `M62`–`M65` (LinuxCNC digital outputs): number and state.
    DigitalOutput {
        /// Output number (`P`).
        index: u32,
        /// On.
        on: bool,
        /// Synchronized with the next motion (`M62`/`M63`) or at once.
        synced: bool,
    },
    /// The stock (Heidenhain `BLK FORM`): minimum and maximum corner, mm.
    BlankForm {
        /// Minimum corner (X, Y, Z).
        min_mm: [f64; 3],
        /// Maximum corner (X, Y, Z).
        max_mm: [f64; 3],
    },
}

/// One event with the place in the program it comes from.
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// 1-based line of the program.
    pub line: usize,
    /// Block number of that line (`N120`, Heidenhain's leading number).
    pub number: Option<u64>,
    /// CSV: the CL line column; `None` otherwise.
    pub cl_line: Option<usize>,
    /// What happens.
    pub event: Event,
}

/// Receives the steps of a run, in program order.
pub trait Sink {
    /// One step. The reference is only valid during the call (the
    /// interpreter reuses its buffers).
    fn step(&mut self, step: &Step);
}

impl<F: FnMut(&Step)> Sink for F {
    fn step(&mut self, step: &Step) {
        self(step)
    }
}

/// Options of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Values of external inputs by name, as the program spells them
    /// without case (`$A_IN[5]`, `#<_hal[pin.name]>` as `_hal[pin.name]`,
    /// `M66 P2` as `M66[2]`, Fanuc system variables as `#1000`).
    pub inputs: BTreeMap<String, f64>,
    /// Skip blocks that start with `/` (block delete switch on).
    pub block_delete: bool,
    /// Axis positions at the start (NC values, machine order); zeros when
    /// `None` (as LinuxCNC's interpreter starts).
    pub start: Option<Vec<f64>>,
    /// Values of work offsets the controller holds (keyed like
    /// [`WorkOffset::Numbered`]), NC values per machine axis; offsets not
    /// given are zero and the run says so when the program selects one.
    pub work_offsets: BTreeMap<u16, Vec<f64>>,
    /// M-codes that switch tool-centre-point control on and off in this
    /// machine's configuration (LinuxCNC's sample configurations remap
    /// `M428`/`M429`; the built-in `linuxcnc` dialect writes them).
    pub tcp_mcodes: Option<(u32, u32)>,
    /// Fanuc: address values without a decimal point are in the least
    /// input increment (`X1` = 0.001 mm) unless this is set (parameter
    /// DPI, "calculator-type" input).
    pub fanuc_calculator_input: bool,
    /// Fanuc `G73` retract and `G83` clearance, mm (parameters 5114 and 5115
    /// of the machine; 0.5 mm here when not given).
    pub fanuc_peck_clearance_mm: Option<f64>,
    /// Most blocks executed (jumps and loops count every pass) before the
    /// run stops with an error, and most moves canned cycles make (their
    /// repeat counts and pecks multiply them): 500 million by default.
    pub max_executed_blocks: u64,
    /// Deepest nesting of subprogram / macro calls: 64 by default.
    pub max_call_depth: usize,
    /// Tolerances of the geometry checks.
    pub tolerances: Tolerances,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            inputs: BTreeMap::new(),
            block_delete: false,
            start: None,
            work_offsets: BTreeMap::new(),
            tcp_mcodes: None,
            fanuc_calculator_input: false,
            fanuc_peck_clearance_mm: None,
            max_executed_blocks: 500_000_000,
            max_call_depth: 64,
            tolerances: Tolerances::default(),
        }
    }
}

impl Options {
    /// Sets an input from a `NAME=VALUE` argument (`--input '$A_IN[5]=1'`).
    pub fn parse_input(&mut self, arg: &str) -> Result<(), InputError> {
        let Some((name, value)) = arg.split_once('=') else {
            return Err(InputError::NoValue(arg.to_string()));
        };
        let v: f64 = value.trim().parse().map_err(|_| InputError::NotANumber {
            arg: arg.to_string(),
            value: value.to_string(),
        })?;
        self.inputs.insert(normalize_input(name), v);
        Ok(())
    }
}

/// Why an `--input NAME=VALUE` argument cannot be used.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InputError {
    /// No `=`.
    NoValue(String),
    /// The value is not a number.
    NotANumber {
        /// The argument.
        arg: String,
        /// Its value part.
        value: String,
    },
}

impl std::fmt::Display for InputError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InputError::NoValue(arg) => write!(f, "`{arg}`: expected NAME=VALUE"),
            InputError::NotANumber { arg, value } => {
                write!(f, "`{arg}`: `{value}` is not a number")
            }
        }
    }
}

impl std::error::Error for InputError {}

/// Input names compare without case and blanks.
pub(crate) fn normalize_input(name: &str) -> String {
    name.chars()
        .filter(|c| !c.is_whitespace())
        .flat_map(char::to_uppercase)
        .collect()
}

/// What a run says besides its steps.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// Warnings (unknown M-codes, axis words of axes the machine lacks),
    /// each at its line.
    pub warnings: Vec<Diagnostic>,
    /// Values the run had to assume, one sentence each (an input read as
    /// 0, a work offset taken as zero), in the order they were first needed.
    pub assumed: Vec<String>,
    /// Motion blocks emitted.
    pub moves: u64,
    /// Blocks executed (lines interpreted, loops counted per pass).
    pub executed_blocks: u64,
}

/// Runs `text` through the interpreter of `family` for a machine with
/// `axes`, calling `sink` for every step. `file` names the program in
/// diagnostics. Stops at the first error.
pub fn run(
    text: &str,
    family: Family,
    axes: &[AxisSpec],
    options: &Options,
    file: &str,
    sink: &mut dyn Sink,
) -> Result<Report, Diagnostic> {
    if axes.len() > MAX_AXES {
        return Err(Diagnostic::error(
            file,
            0,
            0,
            0,
            "",
            format!(
                "the machine has {} axes; the interpreter handles at most {MAX_AXES}",
                axes.len()
            ),
        ));
    }
    match family {
        Family::Csv => csv::run(text, axes, options, file, sink),
        Family::Sinumerik => sinumerik::run(text, axes, options, file, sink),
        Family::Fanuc => rs274::run(text, rs274::Flavour::Fanuc, axes, options, file, sink),
        Family::LinuxCnc => rs274::run(text, rs274::Flavour::LinuxCnc, axes, options, file, sink),
        Family::Heidenhain => heidenhain::run(text, axes, options, file, sink),
    }
}

/// [`run`] collecting every step (for tests and small programs).
pub fn read_all(
    text: &str,
    family: Family,
    axes: &[AxisSpec],
    options: &Options,
    file: &str,
) -> Result<(Vec<Step>, Report), Diagnostic> {
    let mut steps = Vec::new();
    let report = run(text, family, axes, options, file, &mut |s: &Step| {
        steps.push(s.clone())
    })?;
    Ok((steps, report))
}
