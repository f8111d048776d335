//! The NC output of a CL statement other than a point (a comment, a tool
//! change, …): it passes through every stage in its place among the points
//! and is written by the block sink.

use kinpost_diag::{Diagnostic, Located};
use kinpost_nc::{NcError, Spindle};

/// What a CL statement other than a point asks the program to say.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// A comment (`$$ text`, `PPRINT`, an operation's name).
    Comment(String),
    /// A tool change: number, name and length offset register (the CL's
    /// `ADJUST`, else the number).
    ToolChange(u32, String, u32),
    /// Spindle on (speed and direction) or off.
    Spindle(Spindle),
    /// Coolant on in a mode (`FLOOD`, `MIST`, …), or off.
    Coolant(Option<String>),
    /// Text for the controller, verbatim (`INSERT`).
    Insert(String),
    /// A program stop (`STOP`, `END`) or an optional stop (`OPSTOP`:
    /// `true`).
    Stop {
        /// Optional stop (M01).
        optional: bool,
    },
    /// A dwell, seconds (`DELAY`, a cycle's dwell).
    Dwell(f64),
    /// Cutter radius compensation on (`Some((left, register))`) or off
    /// (`CUTCOM`).
    CutterCompensation(Option<(bool, u32)>),
    /// The blocks up to the next [`Command::ArcEnd`] lie on this arc (part
    /// frame): the closed-loop check writes them as one circular block
    /// where the machine can (see [`crate::native_arc`]), else as they
    /// are. Never written itself.
    ArcBegin {
        /// The arc.
        arc: Box<kinpost_cl::Arc>,
        /// Only a G17 (XY) block may be written: cutter radius
        /// compensation is on, in the XY plane, and a controller does not
        /// change planes under it.
        xy_only: bool,
    },
    /// The end of the blocks of a [`Command::ArcBegin`].
    ArcEnd,
    /// The blocks and commands up to the next [`Command::HoleEnd`] are the
    /// moves of one hole of this canned cycle: the closed-loop check
    /// writes them as the dialect's cycle where they are exactly its moves
    /// (see [`crate::native_cycle`]), else as they are. Never written
    /// itself.
    HoleBegin {
        /// The cycle, resolved.
        cycle: Box<crate::cycle::HoleCycle>,
        /// The spindle speed in force, rpm.
        rpm: Option<f64>,
        /// The spindle turns counter-clockwise.
        ccw: bool,
    },
    /// The end of the blocks of a [`Command::HoleBegin`].
    HoleEnd,
}

/// A command with its CL statement: it is written after the reader has
/// moved on, and a template that fails on it names that statement.
#[derive(Debug, Clone)]
pub struct Pending {
    /// The command.
    pub command: Command,
    /// Its CL statement (a diagnostic whose message is filled in when a
    /// template fails on it).
    pub at: Box<Diagnostic>,
}

impl Pending {
    /// A tool change: the machine goes where it changes tools, and where it
    /// is after that is not known.
    pub fn changes_tool(&self) -> bool {
        matches!(self.command, Command::ToolChange(..))
    }

    /// `error` of writing this command, at its CL statement.
    pub fn locate(&self, error: NcError) -> Located<NcError> {
        Located {
            diagnostic: Box::new(Diagnostic {
                message: error.to_string(),
                ..(*self.at).clone()
            }),
            error,
        }
    }
}
