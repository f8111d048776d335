//! The text encodings a CL file may come in. The reader takes UTF-8; a file
//! in ISO 8859-1 (Latin-1: the accented comments CATIA V5 writes on
//! Western European systems) is read through [`Latin1`], which gives the
//! same text as UTF-8. Columns in diagnostics count characters, so they
//! are the same in both.

use std::io::{self, Read};

/// Reads ISO 8859-1 text as UTF-8: every byte is the code point of the same
/// value (ISO/IEC 8859-1 is the first 256 code points of Unicode), so bytes
/// below 0x80 pass unchanged and the others become two bytes,
/// `0xC0 | b >> 6` and `0x80 | b & 0x3F`.
#[derive(Debug)]
pub struct Latin1<R> {
    inner: R,
    raw: Vec<u8>,
    /// The second byte of a character that did not fit the last read.
    pending: Option<u8>,
}

impl<R: Read> Latin1<R> {
    /// Latin-1 text from `inner`, read as UTF-8.
    pub fn new(inner: R) -> Latin1<R> {
        Latin1 {
            inner,
            raw: Vec::new(),
            pending: None,
        }
    }
}

impl<R: Read> Read for Latin1<R> {
    fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
        if out.is_empty() {
            return Ok(0);
        }
        if let Some(b) = self.pending.take() {
            out[0] = b;
            return Ok(1);
        }
        // Each byte read gives at most two: read half of what fits (one
        // byte when only one fits, its second half kept for the next read).
        let want = (out.len() / 2).max(1);
        self.raw.resize(want, 0);
        let got = self.inner.read(&mut self.raw[..want])?;
        let mut n = 0;
        for &b in &self.raw[..got] {
            if b < 0x80 {
                out[n] = b;
                n += 1;
            } else {
                out[n] = 0xC0 | (b >> 6);
                n += 1;
                let second = 0x80 | (b & 0x3F);
                if n < out.len() {
                    out[n] = second;
                    n += 1;
                } else {
                    self.pending = Some(second);
                }
            }
        }
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads everything through reads of at most `chunk` bytes.
    fn read_in(chunk: usize, bytes: &[u8]) -> Vec<u8> {
        let mut r = Latin1::new(bytes);
        let (mut all, mut buf) = (Vec::new(), vec![0u8; chunk]);
        loop {
            let n = r.read(&mut buf).unwrap();
            if n == 0 {
                return all;
            }
            all.extend_from_slice(&buf[..n]);
        }
    }

    #[test]
    fn every_byte_becomes_its_code_point() {
        let bytes: Vec<u8> = (0..=255u8).collect();
        // Independent of the code: Rust's own char conversion.
        let expected: String = bytes.iter().map(|&b| char::from(b)).collect();
        for chunk in [1, 2, 3, 7, 64, 4096] {
            assert_eq!(read_in(chunk, &bytes), expected.as_bytes(), "chunk {chunk}");
        }
    }

    #[test]
    fn a_catia_comment_reads_as_its_accents() {
        // "PPRINT/Opération de perçage" in ISO 8859-1.
        let latin1 = b"PPRINT/Op\xe9ration de per\xe7age\n";
        let text = String::from_utf8(read_in(5, latin1)).unwrap();
        assert_eq!(text, "PPRINT/Opération de perçage\n");
    }
}
