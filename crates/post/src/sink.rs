//! The end of the pipeline: where checked blocks and commands go
//! ([`BlockSink`]). The NC writer is one; a test collects them in a
//! [`Recorded`] list instead.

use std::io::Write;

use kinpost_nc::{AxisSpec, Block, BlockError, Dialect, NcWriter, ProgramInfo};

use crate::check::BlockSink;
use crate::command::{Command, Pending};
use crate::error::PostError;

impl<W: Write> BlockSink for NcWriter<W> {
    #[inline]
    fn round(&mut self, values: &[f64], written: &mut [f64]) {
        self.quantize_axes(values, written);
    }

    // (Inlined into the check as before native arcs: the GOTO-only post
    // keeps its speed.)
    #[inline(always)]
    fn block(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        NcWriter::block(self, block)
    }

    fn command(&mut self, p: Pending) -> Result<(), PostError> {
        let written = match &p.command {
            Command::Comment(text) => self.comment(text),
            Command::ToolChange(number, name, register) => {
                self.tool_change_with_register(*number, name, *register)
            }
            Command::Spindle(state) => self.spindle(*state),
            Command::Coolant(mode) => self.coolant(mode.as_deref()),
            Command::Insert(text) => self.insert(text),
            Command::Stop { optional } => self.stop(*optional),
            Command::Dwell(seconds) => self.dwell(*seconds),
            Command::CutterCompensation(on) => self.cutter_compensation(*on),
            // The closed-loop check acts on these; nothing to write.
            Command::ArcBegin { .. }
            | Command::ArcEnd
            | Command::HoleBegin { .. }
            | Command::HoleEnd => Ok(()),
        };
        written.map_err(|e| p.locate(e).into())
    }

    fn inverse_time(&mut self, on: bool) -> Result<(), PostError> {
        Ok(NcWriter::inverse_time(self, on)?)
    }

    #[inline]
    fn feed_rounds_to_zero(&self, word: f64) -> bool {
        NcWriter::feed_rounds_to_zero(self, word)
    }

    fn writes_arcs(&self) -> bool {
        NcWriter::writes_arcs(self)
    }

    fn writes_arc(&self, plane: kinpost_nc::ArcPlane, helix: bool) -> bool {
        NcWriter::writes_arc(self, plane, helix)
    }

    fn round_centre(&self, offset: [f64; 3]) -> [f64; 3] {
        [0, 1, 2].map(|k| self.quantized_centre(k, offset[k]))
    }

    fn writes_cycles(&self) -> bool {
        NcWriter::writes_cycles(self)
    }

    fn hole(&mut self, hole: &kinpost_nc::Hole) -> Result<bool, kinpost_nc::NcError> {
        NcWriter::hole(self, hole)
    }
}

/// What a [`Recorded`] sink received, in order.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A block as handed over: its values unrounded, the pressure last
    /// if any.
    Block(Block<Vec<f64>>),
    /// A command.
    Command(Command),
    /// Inverse time on or off.
    InverseTime(bool),
}

/// A block sink that keeps everything in a list, for tests of the stages:
/// values are rounded to `decimals` as a dialect would write them.
#[derive(Debug, Clone, Default)]
pub struct Recorded {
    /// Decimals of every value (a dialect's word format).
    pub decimals: u32,
    /// What was received.
    pub events: Vec<Event>,
}

impl Recorded {
    /// An empty list, rounding to `decimals`.
    pub fn new(decimals: u32) -> Recorded {
        Recorded {
            decimals,
            events: Vec::new(),
        }
    }

    /// The blocks received, in order.
    pub fn blocks(&self) -> impl Iterator<Item = &Block<Vec<f64>>> + '_ {
        self.events.iter().filter_map(|e| match e {
            Event::Block(b) => Some(b),
            _ => None,
        })
    }
}

impl BlockSink for Recorded {
    fn round(&mut self, values: &[f64], written: &mut [f64]) {
        let scale = 10f64.powi(self.decimals as i32);
        for (w, v) in written.iter_mut().zip(values) {
            *w = (v * scale).round() / scale;
        }
    }

    fn block(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        self.events
            .push(Event::Block(block.map_axes(|a| a.to_vec())));
        Ok(())
    }

    fn command(&mut self, pending: Pending) -> Result<(), PostError> {
        self.events.push(Event::Command(pending.command));
        Ok(())
    }

    fn inverse_time(&mut self, on: bool) -> Result<(), PostError> {
        self.events.push(Event::InverseTime(on));
        Ok(())
    }

    fn feed_rounds_to_zero(&self, word: f64) -> bool {
        word * 10f64.powi(self.decimals as i32) < 0.5
    }
}

/// What the pipeline writes a whole program with: a [`BlockSink`] that also
/// writes the header and footer and switches tool-centre-point control.
/// The NC writer of a dialect; [`ReadBack`](crate::ReadBack) around one.
pub trait ProgramWriter: BlockSink + Sized {
    /// Where the program goes.
    type Out;
    /// What [`ProgramWriter::finish`] hands back.
    type Finished;

    /// The writer of a program in `dialect` for a machine with `axes`.
    fn open(dialect: &Dialect, axes: &[AxisSpec], out: Self::Out) -> Self;

    /// CSV: a last column says what each feed row's feed is.
    fn add_feed_mode_column(&mut self);

    /// The header (`template` replaces the dialect's).
    fn header(&mut self, info: &ProgramInfo, template: Option<&str>) -> Result<(), PostError>;

    /// Tool-centre-point control on or off.
    fn tcp(&mut self, on: bool) -> Result<(), PostError>;

    /// The footer (`template` replaces the dialect's).
    fn footer(&mut self, info: &ProgramInfo, template: Option<&str>) -> Result<(), PostError>;

    /// Motion blocks written.
    fn blocks_written(&self) -> u64;

    /// Flushes and hands the output back.
    fn finish(self) -> Result<Self::Finished, PostError>;
}

impl<W: Write> ProgramWriter for NcWriter<W> {
    type Out = W;
    type Finished = W;

    fn open(dialect: &Dialect, axes: &[AxisSpec], out: W) -> Self {
        NcWriter::new(dialect, axes, out)
    }

    fn add_feed_mode_column(&mut self) {
        NcWriter::add_feed_mode_column(self);
    }

    fn header(&mut self, info: &ProgramInfo, template: Option<&str>) -> Result<(), PostError> {
        Ok(NcWriter::header(self, info, template)?)
    }

    fn tcp(&mut self, on: bool) -> Result<(), PostError> {
        Ok(NcWriter::tcp(self, on)?)
    }

    fn footer(&mut self, info: &ProgramInfo, template: Option<&str>) -> Result<(), PostError> {
        Ok(NcWriter::footer(self, info, template)?)
    }

    fn blocks_written(&self) -> u64 {
        NcWriter::blocks_written(self)
    }

    fn finish(self) -> Result<W, PostError> {
        Ok(NcWriter::finish(self)?)
    }
}
