//! The read-back stage: the program as written is read again with the
//! dialect's own reader, and every block read must carry the values the
//! check passed, rounded as written. It proves that the writer and the
//! reader agree on the text, for the tests and for whoever wants the proof.

use std::io::Write;

use kinpost_diag::Diagnostic;
use kinpost_nc::{
    AxisSpec, Block, BlockError, Dialect, Motion, NcWriter, ProgramInfo, read_program,
};

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
    /// Another number of motion blocks.
    #[error("{written} blocks written, {read} read back")]
    Count {
        /// Blocks written.
        written: usize,
        /// Blocks read.
        read: usize,
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

/// The output of a program, kept as it is written.
struct Tee<W> {
    out: W,
    text: Vec<u8>,
}

impl<W: Write> Write for Tee<W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.out.write(buf)?;
        self.text.extend_from_slice(&buf[..n]);
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.out.flush()
    }
}

/// A block as written: its motion and its rounded values.
struct Written {
    motion: Motion,
    values: Vec<f64>,
}

/// An NC writer whose program is read back at [`ProgramWriter::finish`]
/// (see the module's documentation).
pub struct ReadBack<W: Write> {
    writer: NcWriter<Tee<W>>,
    dialect: Dialect,
    axes: Vec<AxisSpec>,
    written: Vec<Written>,
}

/// The blocks read back from `text` against those `written`: every block
/// the writer wrote (a block that changes no word is not written), with its
/// values as rounded.
fn compare(
    dialect: &Dialect,
    axes: &[AxisSpec],
    written: &[Written],
    text: &str,
) -> Result<(), ReadBackError> {
    let read = read_program(dialect, axes, "read-back", text)
        .map_err(|d| ReadBackError::Unreadable(Box::new(d)))?;
    // Blocks that repeat the one before are not written.
    let mut expected: Vec<&Written> = Vec::new();
    for w in written {
        if expected.last().is_none_or(|l| l.values != w.values) {
            expected.push(w);
        }
    }
    if expected.len() != read.len() {
        return Err(ReadBackError::Count {
            written: expected.len(),
            read: read.len(),
        });
    }
    for (index, (w, r)) in expected.iter().zip(&read).enumerate() {
        let same = w.motion == r.motion
            && w.values.iter().zip(&r.axes).all(|(w, r)| match r {
                Some(r) => w.to_bits() == r.to_bits() || (w.is_nan() && r.is_nan()),
                None => true,
            });
        if !same {
            return Err(ReadBackError::Block {
                index,
                line: r.line,
                written: format!("{:?} {:?}", w.motion, w.values),
                read: format!("{:?} {:?}", r.motion, r.axes),
            });
        }
    }
    Ok(())
}

impl<W: Write> BlockSink for ReadBack<W> {
    fn round(&mut self, values: &[f64], written: &mut [f64]) {
        self.writer.round(values, written);
    }

    fn block(&mut self, block: &Block) -> Result<(), BlockError> {
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
        self.writer.block(block)?;
        self.written.push(Written {
            motion: block.motion,
            values,
        });
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
        Ok(compare(&self.dialect, &self.axes, &self.written, &text).map(|()| tee.out))
    }
}
