//! Writing CL files: the statements kinpost's own CL carries, in NX's
//! spelling, so that [`ClReader`](crate::ClReader) reads them back and any
//! post that reads NX CLSF reads them too.

use std::io::{self, Write};

use kinpost_number::{Formatter, NumberError, NumberFormat, TrailingZeros};

use crate::Vec3;

/// Why a CL statement cannot be written.
#[derive(Debug)]
pub enum WriteError {
    /// A value that is not finite or too large for its format.
    Value {
        /// The value.
        value: f64,
        /// Why.
        error: NumberError,
    },
    /// Writing failed.
    Io(io::Error),
}

impl std::fmt::Display for WriteError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WriteError::Value { value, error } => write!(f, "{value}: {error}"),
            WriteError::Io(e) => write!(f, "cannot write the CL file: {e}"),
        }
    }
}

impl std::error::Error for WriteError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            WriteError::Io(e) => Some(e),
            WriteError::Value { .. } => None,
        }
    }
}

impl From<io::Error> for WriteError {
    fn from(e: io::Error) -> Self {
        WriteError::Io(e)
    }
}

/// `decimals` digits after the point, all of them written (`12.500000`).
fn fixed(decimals: u8) -> NumberFormat {
    NumberFormat {
        decimals,
        trailing_zeros: TrailingZeros::Keep,
        leading_zero: true,
        plus_sign: false,
        modulo: None,
    }
}

/// Text that ends a statement or starts another (line breaks, `$`, which
/// continues or comments a line, and `,`, which separates fields) replaced,
/// so that a name or comment stays one field of one statement.
fn field(text: &str) -> String {
    text.replace([',', '\n', '\r', '$'], "_")
}

/// A writer of CL statements to `W` (wrap a file in a `BufWriter`).
pub struct ClWriter<W: Write> {
    out: W,
    line: Vec<u8>,
    /// Points, mm: six decimals.
    length: Formatter,
    /// Directions: nine decimals.
    direction: Formatter,
}

impl<W: Write> ClWriter<W> {
    /// A writer to `out`.
    pub fn new(out: W) -> Self {
        ClWriter {
            out,
            line: Vec::with_capacity(160),
            length: fixed(6).formatter(),
            direction: fixed(9).formatter(),
        }
    }

    /// A number with `decimals`, for the fields of a statement.
    pub fn number(value: f64, decimals: u8) -> Result<String, WriteError> {
        fixed(decimals)
            .format(value)
            .map_err(|error| WriteError::Value { value, error })
    }

    fn text(&mut self, s: &str) -> Result<(), WriteError> {
        self.out.write_all(s.as_bytes())?;
        Ok(self.out.write_all(b"\n")?)
    }

    /// `TOOL PATH/name,TOOL,tool`.
    pub fn tool_path(&mut self, name: &str, tool: &str) -> Result<(), WriteError> {
        self.text(&format!("TOOL PATH/{},TOOL,{}", field(name), field(tool)))
    }

    /// `TLDATA/MILL,diameter,corner radius,length,taper,tip` (NX's milling
    /// tool, mm and degrees).
    pub fn tldata_mill(&mut self, diameter: f64, length: f64) -> Result<(), WriteError> {
        let d = Self::number(diameter, 4)?;
        let l = Self::number(length, 4)?;
        self.text(&format!("TLDATA/MILL,{d},0.0000,{l},0.0000,0.0000"))
    }

    /// `MSYS/…` of the identity: the part frame is the machine coordinate
    /// system.
    pub fn msys_identity(&mut self) -> Result<(), WriteError> {
        self.text(
            "MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000",
        )
    }

    /// `$$ text` (line breaks become blanks).
    pub fn comment(&mut self, text: &str) -> Result<(), WriteError> {
        self.text(&format!("$$ {}", text.replace(['\n', '\r'], " ")))
    }

    /// `PRESSURE/word,value` (kinpost's extension: the contact pressure of
    /// belt grinding).
    pub fn pressure(&mut self, word: &str, value: f64) -> Result<(), WriteError> {
        let v = Self::number(value, 3)?;
        self.text(&format!("PRESSURE/{},{v}", field(word)))
    }

    /// `RAPID`: the next `GOTO` is a rapid move.
    pub fn rapid(&mut self) -> Result<(), WriteError> {
        self.text("RAPID")
    }

    /// `FEDRAT/MMPM,feed`.
    pub fn feedrate_mmpm(&mut self, feed: f64) -> Result<(), WriteError> {
        let f = Self::number(feed, 4)?;
        self.text(&format!("FEDRAT/MMPM,{f}"))
    }

    /// `GOTO/x,y,z,i,j,k[,u,v,w]`: a point (six decimals), its tool axis
    /// and, for 6-axis machines, the reference direction (nine decimals).
    pub fn goto(
        &mut self,
        point: Vec3,
        axis: Vec3,
        reference: Option<Vec3>,
    ) -> Result<(), WriteError> {
        self.line.clear();
        self.line.extend_from_slice(b"GOTO/");
        for (k, v) in point.into_iter().enumerate() {
            if k > 0 {
                self.line.push(b',');
            }
            self.length
                .write(&mut self.line, v)
                .map_err(|error| WriteError::Value { value: v, error })?;
        }
        for v in axis.into_iter().chain(reference.into_iter().flatten()) {
            self.line.push(b',');
            self.direction
                .write(&mut self.line, v)
                .map_err(|error| WriteError::Value { value: v, error })?;
        }
        self.line.push(b'\n');
        Ok(self.out.write_all(&self.line)?)
    }

    /// `END-OF-PATH`.
    pub fn end_of_path(&mut self) -> Result<(), WriteError> {
        self.text("END-OF-PATH")
    }

    /// Flushes and hands the output back.
    pub fn finish(mut self) -> Result<W, WriteError> {
        self.out.flush()?;
        Ok(self.out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ClEvent, ClReader, Motion};

    /// What the writer writes, the reader reads back to the last bit of
    /// the written decimals.
    #[test]
    fn written_statements_read_back() {
        let mut w = ClWriter::new(Vec::new());
        w.tool_path("PASS, ONE\n", "WHEEL").unwrap();
        w.comment("two\nlines").unwrap();
        w.pressure("H1", 3000.0).unwrap();
        w.rapid().unwrap();
        w.goto([1.0, -2.5, 1e-7], [0.0, 0.0, 1.0], None).unwrap();
        w.feedrate_mmpm(250.0).unwrap();
        w.goto([1.0, 2.0, 3.0], [0.0, 0.6, 0.8], Some([1.0, 0.0, 0.0]))
            .unwrap();
        w.end_of_path().unwrap();
        let text = String::from_utf8(w.finish().unwrap()).unwrap();
        assert!(
            text.starts_with("TOOL PATH/PASS_ ONE_,TOOL,WHEEL\n$$ two lines\n"),
            "{text}"
        );
        assert!(
            text.contains("GOTO/1.000000,-2.500000,0.000000,0.000000000,0.000000000,1.000000000\n")
        );
        let mut r = ClReader::new(text.as_bytes(), "w.cls");
        let mut gotos = Vec::new();
        while let Some(s) = r.next_statement().unwrap() {
            if let ClEvent::Goto {
                point,
                axis,
                reference,
                motion,
            } = s.event
            {
                gotos.push((point, axis, reference, motion));
            }
        }
        assert_eq!(
            gotos[0],
            ([1.0, -2.5, 0.0], [0.0, 0.0, 1.0], None, Motion::Rapid)
        );
        assert_eq!(
            gotos[1],
            (
                [1.0, 2.0, 3.0],
                [0.0, 0.6, 0.8],
                Some([1.0, 0.0, 0.0]),
                Motion::Feed
            )
        );
        assert!(matches!(
            ClWriter::new(Vec::new()).goto([f64::NAN, 0.0, 0.0], [0.0, 0.0, 1.0], None),
            Err(WriteError::Value { .. })
        ));
    }
}
