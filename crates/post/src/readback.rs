//! The read-back stage: the program as written is read again with the
//! dialect's own reader, and every block read must carry the values the
//! check passed, rounded as written. It proves that the writer and the
//! reader agree on the text, for the tests and for whoever wants the proof.

use std::io::Write;

use kinpost_diag::Diagnostic;
use kinpost_nc::{AxisSpec, Block, BlockError, Dialect, NcWriter, ProgramInfo, read_program};

use crate::check::BlockSink;
use crate::command::Pending;
use crate::error::PostError;
use crate::sink::ProgramWriter;

/// Why a program read back differs from what was written.
#[derive(Debug, thiserror::Error)]
pub enum ReadBackError {
    /// The dialect's reader refuses the program.
    #[error("the program does not read back: {0}")]
    Unreadable(Box<Diagnostic>),
    /// A written block is not read back at its line.
    #[error("block {index} (program line {line}) does not read back as a block")]
    Missing {
        /// 0-based index among the blocks written.
        index: usize,
        /// Its line in the program.
        line: usize,
    },
    /// A block reads back with another value or motion.
    #[error("block {index} (program line {line}) reads back as {read}, written as {written}")]
    Block {
        /// 0-based index among the blocks.
        index: usize,
        /// Its line in the program.
        line: usize,
        /// What was written.
        written: String,
        /// What was read.
        read: String,
    },
}

/// The output of a program, kept as it is written, with its lines counted.
struct Tee<W> {
    out: W,
    text: Vec<u8>,
    lines: usize,
}

impl<W: Write> Write for Tee<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.out.write(buf)?;
        self.text.extend_from_slice(&buf[..n]);
        self.lines += buf[..n].iter().filter(|&&b| b == b'\n').count();
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// An NC writer whose program is read back at [`ProgramWriter::finish`]
/// (see the module's documentation).
pub struct ReadBack<W: Write> {
    writer: NcWriter<Tee<W>>,
    dialect: Dialect,
    axes: Vec<AxisSpec>,
    /// The blocks as written: their program line, their values rounded as
    /// written (NaN: no value, e.g. no pressure programmed), their arc's
    /// centre offset too.
    written: Vec<Block<Vec<f64>>>,
}

/// The program `text` read with `dialect`'s reader against the blocks the
/// writer wrote into it: each written block must read back, at its line,
/// with its motion and every value it carries (other lines, e.g. a
/// header's, are not the writer's blocks; a value the dialect never writes,
/// a locked axis, reads back as none).
pub fn compare_read_back(
    dialect: &Dialect,
    axes: &[AxisSpec],
    written: &[Block<Vec<f64>>],
    text: &str,
) -> Result<(), ReadBackError> {
    let read = read_program(dialect, axes, "read-back", text)
        .map_err(|d| ReadBackError::Unreadable(Box::new(d)))?;
    let mut at = read.iter().peekable();
    for (index, w) in written.iter().enumerate() {
        let line = w.line.unwrap_or(0);
        while at.next_if(|r| r.line < Some(line)).is_some() {}
        let Some(r) = at.next_if(|r| r.line == Some(line)) else {
            return Err(ReadBackError::Missing { index, line });
        };
        if !reads_as_written(w, r) {
            return Err(ReadBackError::Block {
                index,
                line,
                written: format!("{:?} {:?} {:?}", w.motion, w.axes, w.arc),
                read: format!("{:?} {:?} {:?}", r.motion, r.axes, r.arc),
            });
        }
    }
    Ok(())
}

/// Whether block `r` as read carries what `w` wrote: the motion, every
/// value (an axis the dialect never writes, a locked one, reads back as no
/// value), the arc's plane, sense and the two centre words of its plane.
fn reads_as_written(w: &Block<Vec<f64>>, r: &Block<Vec<Option<f64>>>) -> bool {
    let same_values = w.axes.iter().zip(&r.axes).all(|(w, r)| match r {
        Some(r) => w.to_bits() == r.to_bits(),
        None => true,
    });
    let same_arc = match (&w.arc, &r.arc) {
        (None, None) => true,
        (Some(w), Some(r)) => {
            let [a, b, _] = w.plane.axes();
            w.plane == r.plane
                && w.clockwise == r.clockwise
                && [a, b]
                    .iter()
                    .all(|&k| w.centre_offset[k].to_bits() == r.centre_offset[k].to_bits())
        }
        _ => false,
    };
    w.motion == r.motion && same_values && same_arc
}

impl<W: Write> ReadBack<W> {
    /// Lines written so far (the writer writes whole lines at once).
    fn writer_lines(&self) -> usize {
        self.writer.get_ref().lines
    }
}

impl<W: Write> BlockSink for ReadBack<W> {
    fn round(&mut self, values: &[f64], written: &mut [f64]) {
        self.writer.round(values, written);
    }

    fn block(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError> {
        let values = block
            .axes
            .iter()
            .zip(&self.axes)
            .map(|(&v, a)| {
                if v.is_nan() {
                    v
                } else {
                    self.dialect.quantize(a, v)
                }
            })
            .collect();
        let before = self.writer_lines();
        self.writer.block(block)?;
        // A block that changes no word is not written.
        let after = self.writer_lines();
        if after > before {
            self.written.push(Block {
                line: Some(after),
                arc: block.arc.map(|mut arc| {
                    arc.centre_offset = self.writer.round_centre(arc.centre_offset);
                    arc
                }),
                ..block.map_axes(|_| values)
            });
        }
        Ok(())
    }

    fn command(&mut self, pending: Pending) -> Result<(), PostError> {
        self.writer.command(pending)
    }

    fn inverse_time(&mut self, on: bool) -> Result<(), PostError> {
        BlockSink::inverse_time(&mut self.writer, on)
    }

    fn feed_rounds_to_zero(&self, word: f64) -> bool {
        self.writer.feed_rounds_to_zero(word)
    }

    fn writes_arcs(&self) -> bool {
        self.writer.writes_arcs()
    }

    fn writes_arc(&self, plane: kinpost_nc::ArcPlane, helix: bool) -> bool {
        self.writer.writes_arc(plane, helix)
    }

    fn round_centre(&self, offset: [f64; 3]) -> [f64; 3] {
        self.writer.round_centre(offset)
    }

    fn writes_cycles(&self) -> bool {
        self.writer.writes_cycles()
    }

    fn hole(&mut self, hole: &kinpost_nc::Hole) -> Result<bool, kinpost_nc::NcError> {
        self.writer.hole(hole)
    }
}

impl<W: Write> ProgramWriter for ReadBack<W> {
    type Out = W;
    type Finished = Result<W, ReadBackError>;

    fn open(dialect: &Dialect, axes: &[AxisSpec], out: W) -> Self {
        ReadBack {
            writer: NcWriter::new(
                dialect,
                axes,
                Tee {
                    out,
                    text: Vec::new(),
                    lines: 0,
                },
            ),
            dialect: dialect.clone(),
            axes: axes.to_vec(),
            written: Vec::new(),
        }
    }

    fn add_feed_mode_column(&mut self) {
        self.writer.add_feed_mode_column();
    }

    fn header(&mut self, info: &ProgramInfo, template: Option<&str>) -> Result<(), PostError> {
        ProgramWriter::header(&mut self.writer, info, template)
    }

    fn tcp(&mut self, on: bool) -> Result<(), PostError> {
        ProgramWriter::tcp(&mut self.writer, on)
    }

    fn footer(&mut self, info: &ProgramInfo, template: Option<&str>) -> Result<(), PostError> {
        ProgramWriter::footer(&mut self.writer, info, template)
    }

    fn blocks_written(&self) -> u64 {
        self.writer.blocks_written()
    }

    /// The output, once the program reads back as written.
    fn finish(self) -> Result<Self::Finished, PostError> {
        let mut tee = ProgramWriter::finish(self.writer)?;
        tee.flush()?;
        let text = String::from_utf8_lossy(&tee.text);
        Ok(compare_read_back(&self.dialect, &self.axes, &self.written, &text).map(|()| tee.out))
    }
}
