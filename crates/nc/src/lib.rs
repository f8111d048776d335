//! NC dialects for kinpost: data-driven writers and readers of CNC programs.
//!
//! A [`Dialect`] is data, loaded from a TOML file (the built-in ones are
//! embedded, see [`Dialect::builtin_names`]; the format is documented in
//! `docs/dialects.md`). [`NcWriter`] writes a program in a dialect: header and
//! footer templates, tool changes, comments and — on the hot path — motion
//! blocks, formatted without allocation. [`read_program`] reads such a program
//! back into blocks of axis values, for closed-loop checks. [`interp`] is the
//! interpreter of real programs for the four controller families (Sinumerik,
//! Fanuc, LinuxCNC, Heidenhain) and the CSV table: expressions, variables,
//! control flow, arcs and drilling cycles resolved into a stream of typed
//! steps for the virtual machine (`INTERPRETER.md`).
//!
//! ```
//! use kinpost_nc::{AxisSpec, Block, Dialect, Motion, NcWriter};
//! let dialect = Dialect::builtin("sinumerik").unwrap();
//! let axes = [AxisSpec::linear("X"), AxisSpec::endless("A"), AxisSpec::linear("Y"),
//!             AxisSpec::linear("Z"), AxisSpec::rotary("B"), AxisSpec::rotary("C").fixed()];
//! let mut w = NcWriter::new(&dialect, &axes, Vec::new());
//! let axis_values = [459.0, 0.0, 8.80694, 361.36839, 0.0, 0.0];
//! w.block(&Block::feed(&axis_values[..], 250.0).with_cl_line(16)).unwrap();
//! let text = String::from_utf8(w.finish().unwrap()).unwrap();
//! assert_eq!(text, "X=459.000 Y=8.807 Z361.368 B0.000 A=DC(0.000) F250\n");
//! ```

#![deny(missing_docs)]

use std::collections::BTreeMap;

mod block;
mod dialect;
pub mod interp;
mod reader;
mod sanitize;
mod template;
mod writer;

pub use block::{ArcMotion, ArcPlane, Block, Hole, HoleKind, Motion};
pub use dialect::{
    ArcWords, BlockFormat, CYCLE_VARIABLES, CommentSyntax, CycleRetract, CycleWords, Dialect,
    DialectKind, FeedFormat, MAX_DIALECT_FILE_BYTES, MotionWords, Numbering, TemplateKind,
    WordFormat, check_template,
};
pub use kinpost_diag::{Diagnostic, Diagnostics, Severity};
pub use kinpost_number::{FormatError, MAX_DECIMALS, NumberError, NumberFormat, TrailingZeros};
pub use minijinja::Value;
pub use reader::{ReadProgram, read_program, read_program_full};
pub use template::{
    MAX_TEMPLATE_OUTPUT_BYTES, TEMPLATE_FUEL, TEMPLATE_RECURSION_LIMIT, TemplateError,
    template_span_in_toml,
};
pub use writer::{MAX_DWELL_SECONDS, MAX_SPINDLE_RPM, MAX_TOOL_NUMBER, NcWriter, Spindle};

/// One machine axis as the writer and reader need it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AxisSpec {
    /// Axis name as in the machine file (`X`, `A`, `H1`).
    pub name: String,
    /// Rotary (degrees) or linear (mm).
    pub rotary: bool,
    /// Locked by the machine (e.g. C in 5-axis mode).
    pub fixed: bool,
    /// A rotary axis that turns without end (a modulo axis on the
    /// controller): dialects may write it with shortest-path words such as
    /// Sinumerik's `DC(…)` (the `[endless]` word format).
    pub endless: bool,
    /// Not an axis but the process pressure of the machine (belt grinding
    /// `H1`): formatted by the dialect's `[pressure]` table, written on a
    /// line of its own before the first motion block that has a new value,
    /// read back as a modal word. A block value of NaN means no pressure
    /// is programmed: nothing is written (an empty CSV field).
    pub pressure: bool,
}

impl AxisSpec {
    /// A free linear axis.
    pub fn linear(name: &str) -> AxisSpec {
        AxisSpec {
            name: name.to_string(),
            rotary: false,
            fixed: false,
            endless: false,
            pressure: false,
        }
    }

    /// A free rotary axis.
    pub fn rotary(name: &str) -> AxisSpec {
        AxisSpec {
            name: name.to_string(),
            rotary: true,
            fixed: false,
            endless: false,
            pressure: false,
        }
    }

    /// A free rotary axis that turns without end.
    pub fn endless(name: &str) -> AxisSpec {
        AxisSpec {
            endless: true,
            ..AxisSpec::rotary(name)
        }
    }

    /// The process pressure word (e.g. `H1`; see the field `pressure`).
    pub fn pressure_word(name: &str) -> AxisSpec {
        AxisSpec {
            pressure: true,
            ..AxisSpec::linear(name)
        }
    }

    /// The same axis, locked.
    pub fn fixed(mut self) -> AxisSpec {
        self.fixed = true;
        self
    }
}

/// What the header and footer templates get to see.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ProgramInfo {
    /// Program name (`program_name`).
    pub program_name: String,
    /// Date as the caller wants it printed (`date`); passed in so output is
    /// deterministic.
    pub date: String,
    /// Machine name (`machine`).
    pub machine: String,
    /// Tool name (`tool`).
    pub tool: String,
    /// Tool number (`tool_number`), 0 when unknown.
    pub tool_number: u32,
    /// CL file the program was made from (`cl_file`).
    pub cl_file: String,
    /// The CL loads the header's tool (`tool_loaded`): only then does the
    /// header call it (`T… M06`).
    pub tool_loaded: bool,
    /// The tool length offset register of the header's tool
    /// (`length_register`: the CL's `ADJUST`, else the tool number).
    pub length_register: u32,
    /// The program is tool-centre-point output (`tcp_output`): the
    /// `tcp_on` template applies the tool length, not `G43`.
    pub tcp_output: bool,
    /// Further variables: each is available by its own name (unless it
    /// collides with a built-in one) and in the map `extra`.
    pub extra: BTreeMap<String, String>,
}

impl ProgramInfo {
    /// The names every template gets from [`ProgramInfo::template_vars`]
    /// (each extra key too, but those depend on the caller).
    pub const VARIABLES: [&'static str; 13] = [
        "program_name",
        "date",
        "machine",
        "tool",
        "tool_number",
        "cl_file",
        "dialect",
        "axes",
        "extra",
        "tcp",
        "tool_loaded",
        "length_register",
        "tcp_output",
    ];

    /// The template variables: `program_name`, `date`, `machine`, `tool`,
    /// `tool_number`, `cl_file`, `dialect`, `axes` (list of names), `extra`,
    /// `tcp` (false here: the writer sets it while tool-centre-point
    /// control is on) and every extra key.
    pub fn template_vars(&self, dialect: &str, axes: &[AxisSpec]) -> BTreeMap<String, Value> {
        let mut vars: BTreeMap<String, Value> = self
            .extra
            .iter()
            .map(|(k, v)| (k.clone(), Value::from(v.as_str())))
            .collect();
        let mut put = |k: &str, v: Value| {
            vars.insert(k.to_string(), v);
        };
        put("program_name", Value::from(self.program_name.as_str()));
        put("date", Value::from(self.date.as_str()));
        put("machine", Value::from(self.machine.as_str()));
        put("tool", Value::from(self.tool.as_str()));
        put("tool_number", Value::from(self.tool_number));
        put("cl_file", Value::from(self.cl_file.as_str()));
        put("dialect", Value::from(dialect));
        put("tcp", Value::from(false));
        put("tool_loaded", Value::from(self.tool_loaded));
        put("length_register", Value::from(self.length_register));
        put("tcp_output", Value::from(self.tcp_output));
        put(
            "axes",
            Value::from(
                axes.iter()
                    .map(|a| Value::from(a.name.as_str()))
                    .collect::<Vec<_>>(),
            ),
        );
        put(
            "extra",
            Value::from(
                self.extra
                    .iter()
                    .map(|(k, v)| (k.clone(), Value::from(v.as_str())))
                    .collect::<BTreeMap<String, Value>>(),
            ),
        );
        vars
    }
}

/// Errors of the template-driven parts of the writer.
#[derive(Debug)]
pub enum NcError {
    /// Writing failed.
    Io(std::io::Error),
    /// Block numbers ran out.
    Numbers(NumbersRunOut),
    /// A template could not be compiled or rendered.
    Template {
        /// `header`, `footer`, `tool_change`, ... or `template` for an override.
        template: String,
        /// 1-based line in the template, when known.
        line: Option<usize>,
        /// Byte range in the template, when known.
        range: Option<std::ops::Range<usize>>,
        /// What went wrong.
        message: String,
    },
    /// A value that cannot stand in a program: one that would be written as
    /// 0 or is too large to write (a spindle speed, a tool number).
    Value {
        /// What it is (`spindle speed`).
        what: &'static str,
        /// The value as given.
        value: String,
        /// Why it cannot be written, and what can be.
        reason: String,
    },
    /// A line longer than the dialect's `max_line_length` that is not a
    /// comment to shorten (a CL `INSERT`, a template line).
    LineTooLong {
        /// What wrote it: `INSERT`, `template `header``, ….
        source: String,
        /// The line, without its line end.
        text: String,
        /// Its length in bytes, line end included.
        length: usize,
        /// The dialect's `max_line_length`.
        max: usize,
    },
    /// The program asks for something the dialect has no template for (a
    /// dwell, a stop, cutter compensation): never left out in silence.
    MissingTemplate {
        /// The template's key (`dwell`, `cutcom_on`, …).
        template: &'static str,
        /// The dialect's name.
        dialect: String,
    },
}

impl std::fmt::Display for NcError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NcError::Io(e) => write!(f, "cannot write the NC program: {e}"),
            NcError::Template {
                template,
                line,
                message,
                ..
            } => {
                write!(f, "template `{template}`")?;
                if let Some(l) = line {
                    write!(f, " line {l}")?;
                }
                write!(f, ": {message}")
            }
            NcError::Value {
                what,
                value,
                reason,
            } => write!(f, "cannot write the {what} {value}: {reason}"),
            NcError::Numbers(e) => e.fmt(f),
            NcError::MissingTemplate { template, dialect } => write!(
                f,
                "dialect `{dialect}` has no `{template}` template: add one to its [templates] to post this statement"
            ),
            NcError::LineTooLong {
                source,
                text,
                length,
                max,
            } => {
                let start: String = text.chars().take(40).collect();
                let more = if start.len() < text.len() { "…" } else { "" };
                write!(
                    f,
                    "{source}: the line `{start}{more}` has {length} bytes with its line end, \
                     more than the dialect's max_line_length of {max}"
                )
            }
        }
    }
}

impl std::error::Error for NcError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            NcError::Io(e) => Some(e),
            NcError::Template { .. }
            | NcError::Value { .. }
            | NcError::Numbers(_)
            | NcError::LineTooLong { .. }
            | NcError::MissingTemplate { .. } => None,
        }
    }
}

impl From<std::io::Error> for NcError {
    fn from(e: std::io::Error) -> Self {
        NcError::Io(e)
    }
}

/// Why a motion block cannot be written.
#[derive(Debug)]
pub enum BlockError {
    /// The block has another number of values than the writer has axes.
    AxisCount {
        /// Values in the block.
        got: usize,
        /// Axes of the writer.
        want: usize,
    },
    /// A value that is not finite, or too large for the word's format.
    Value {
        /// The word's axis name, or `feed`.
        word: String,
        /// The value.
        value: f64,
        /// Why it cannot be written.
        error: NumberError,
    },
    /// The block's line is longer than the dialect's `max_line_length`.
    TooLong {
        /// The line, without its line end.
        text: String,
        /// The CL line of the block (`None`: a block the post added).
        cl_line: Option<usize>,
        /// Its length in bytes, line end included.
        length: usize,
        /// The dialect's `max_line_length`.
        max: usize,
    },
    /// A pressure is programmed, and the dialect has no pressure word.
    NoPressureWord {
        /// The dialect.
        dialect: String,
        /// The machine's pressure word.
        word: String,
    },
    /// The dialect's `pressure` template, written with a new pressure word,
    /// failed.
    Template(NcError),
    /// A pressure asked for that the dialect's decimals write as 0.
    PressureRoundsToZero {
        /// The pressure word.
        word: String,
        /// The pressure.
        value: f64,
    },
    /// Block numbers ran out.
    Numbers(NumbersRunOut),
    /// An arc block for a dialect without `[arc]` words.
    NoArcWords {
        /// The dialect.
        dialect: String,
    },
    /// An arc whose dialect writes its centre in absolute coordinates
    /// (Heidenhain `CC`) before any block wrote the plane's axes: where it
    /// starts is not known.
    ArcStartUnknown {
        /// The CL line of the block (`None`: a block the post added).
        cl_line: Option<usize>,
    },
    /// An arc in a plane, or a helix, that the dialect does not write as an
    /// arc (its `[arc]` `native_planes` and `helix`): the controller would
    /// take it in another plane.
    ArcNotWritable {
        /// The dialect.
        dialect: String,
        /// The arc's plane.
        plane: ArcPlane,
        /// Whether it rises along the plane's normal.
        helix: bool,
    },
    /// An arc on a rapid block (circles are interpolated at a feed).
    RapidArc {
        /// The CL line of the block (`None`: a block the post added).
        cl_line: Option<usize>,
    },
    /// Writing failed.
    Io(std::io::Error),
}

/// Block numbers ran out: the number after `last` does not fit in 64 bits
/// (a dialect's numbering without `wrap_after`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NumbersRunOut {
    /// The last number written.
    pub last: u64,
}

impl std::fmt::Display for NumbersRunOut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "block numbers run out: the number after {} does not fit in 64 bits \
             (give the dialect's [numbering] a wrap_after, or a smaller start or step)",
            self.last
        )
    }
}

impl std::error::Error for NumbersRunOut {}

impl From<NumbersRunOut> for BlockError {
    fn from(e: NumbersRunOut) -> Self {
        BlockError::Numbers(e)
    }
}

impl From<NumbersRunOut> for NcError {
    fn from(e: NumbersRunOut) -> Self {
        NcError::Numbers(e)
    }
}

impl std::fmt::Display for BlockError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            BlockError::AxisCount { got, want } => {
                write!(
                    f,
                    "block has {got} axis values, the machine has {want} axes"
                )
            }
            // (A value too large to write is shown in exponent form, not
            // in hundreds of digits.)
            BlockError::Value { word, value, error } if value.abs() >= 1e15 => {
                write!(f, "cannot write {word} = {value:e}: {error}")
            }
            BlockError::Value { word, value, error } => {
                write!(f, "cannot write {word} = {value}: {error}")
            }
            BlockError::TooLong {
                text,
                cl_line,
                length,
                max,
            } => {
                write!(f, "the line `{text}` for ")?;
                match cl_line {
                    Some(l) => write!(f, "CL line {l}")?,
                    None => f.write_str("a block the post added")?,
                }
                write!(
                    f,
                    " has {length} bytes with its line end, more than the dialect's max_line_length of {max}"
                )
            }
            BlockError::NoPressureWord { dialect, word } => write!(
                f,
                "dialect `{dialect}` cannot write the pressure word `{word}`: it has no [pressure] table"
            ),
            BlockError::Template(e) => e.fmt(f),
            BlockError::NoArcWords { dialect } => write!(
                f,
                "dialect `{dialect}` has no [arc] words: its arcs are written as lines"
            ),
            BlockError::ArcNotWritable {
                dialect,
                plane,
                helix,
            } => write!(
                f,
                "dialect `{dialect}` does not write {} in the {plane:?} plane as an arc block: write it as lines",
                if *helix { "a helix" } else { "an arc" }
            ),
            BlockError::ArcStartUnknown { cl_line } => {
                write!(f, "an arc block before any block wrote its plane's axes")?;
                if let Some(l) = cl_line {
                    write!(f, " (CL line {l})")?;
                }
                write!(f, ": its absolute centre cannot be written")
            }
            BlockError::RapidArc { cl_line } => {
                write!(f, "an arc block at rapid traverse")?;
                match cl_line {
                    Some(l) => write!(f, " (CL line {l}): circles are interpolated at a feed"),
                    None => write!(f, ": circles are interpolated at a feed"),
                }
            }
            BlockError::PressureRoundsToZero { word, value } => write!(
                f,
                "cannot write {word} = {value}: it would be written as 0 with the dialect's decimals"
            ),
            BlockError::Numbers(e) => e.fmt(f),
            BlockError::Io(e) => write!(f, "cannot write the NC program: {e}"),
        }
    }
}

impl std::error::Error for BlockError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            BlockError::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<std::io::Error> for BlockError {
    fn from(e: std::io::Error) -> Self {
        BlockError::Io(e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The names the dialect loader accepts are the names templates get.
    #[test]
    fn template_vars_are_the_documented_variables() {
        let vars = ProgramInfo::default().template_vars("d", &[AxisSpec::linear("X")]);
        let names: Vec<&str> = vars.keys().map(String::as_str).collect();
        let mut documented = ProgramInfo::VARIABLES.to_vec();
        documented.sort_unstable();
        assert_eq!(names, documented);
    }
}
