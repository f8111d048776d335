//! Fuzz target: any bytes fed to the CL reader, with and without a default
//! tool axis, must never panic or loop, and every diagnostic must point into
//! the input. The fast paths (whole input in memory) must read exactly what
//! the general path (a one-byte buffer) reads, and the bytes read as
//! ISO 8859-1 what their UTF-8 text reads. Run with
//! `cargo +nightly fuzz run cl_reader fuzz/corpus/cl_reader
//! fuzz/seeds/cl_reader data/cl/nx data/cl/creo data/cl/solidworks --
//! -max_len=8192` from the repository root (the first folder is where
//! libFuzzer keeps what it finds; `fuzz/seeds/cl_reader` holds a file of
//! each CAM system's forms: arcs, NURBS, cycles, frames, inch files, the NX
//! listing frame; `-max_len` keeps the real files' starts, without it the
//! largest file sets the input size and the runs crawl).

#![no_main]

use std::io::BufRead;

use kinpost_cl::{ClEvent, ClReader, Units};
use libfuzzer_sys::fuzz_target;

/// Everything the reader gives, in order, as text.
fn transcript<R: BufRead>(mut reader: ClReader<R>) -> Vec<String> {
    let mut out = Vec::new();
    loop {
        let result = reader.next_statement();
        let end = matches!(result, Ok(None));
        out.push(format!("{result:?}"));
        out.extend(reader.take_warnings().iter().map(|w| format!("{w:?}")));
        if end || out.len() > 100_000 {
            return out;
        }
    }
}

fuzz_target!(|data: &[u8]| {
    assert_eq!(
        transcript(ClReader::new(data, "fuzz.cls")),
        transcript(ClReader::new(std::io::BufReader::with_capacity(1, data), "fuzz.cls")),
        "the fast paths read differently from the general path"
    );
    // Read as ISO 8859-1 (`--encoding latin1`), every byte is a character:
    // the same text the standard library makes of it.
    let latin1: String = data.iter().map(|&b| char::from(b)).collect();
    assert_eq!(
        transcript(ClReader::new(
            std::io::BufReader::with_capacity(3, kinpost_cl::encoding::Latin1::new(data)),
            "fuzz.cls"
        )),
        transcript(ClReader::new(latin1.as_bytes(), "fuzz.cls")),
        "Latin-1 read differently from its UTF-8 text"
    );
    let lines = data.split(|&b| b == b'\n').count();
    for (default_axis, units) in [(false, None), (true, None), (true, Some(Units::Inch))] {
        let mut reader = ClReader::new(data, "fuzz.cls").with_units(units);
        if default_axis {
            reader = reader.with_default_axis([0.0, 0.0, 1.0]);
        }
        // Every call consumes at least one line, but for Creo's further
        // points after an arc: each gives the circle again, then the point.
        let mut calls = 0;
        loop {
            calls += 1;
            assert!(calls <= 2 * lines + 1, "the reader does not advance");
            let result = reader.next_statement();
            for w in reader.take_warnings() {
                assert!(w.line >= 1 && w.line <= lines && w.column >= 1);
            }
            match result {
                Ok(None) => break,
                Ok(Some(statement)) => {
                    assert!(statement.line >= 1 && statement.line <= lines);
                    match statement.event {
                        ClEvent::Goto { point, axis, .. } => {
                            assert!(point.iter().all(|v| v.is_finite()));
                            let n: f64 = axis.iter().map(|v| v * v).sum();
                            assert!((n - 1.0).abs() < 1e-12);
                        }
                        ClEvent::Circle(c) => {
                            let n: f64 = c.axis.iter().map(|v| v * v).sum();
                            assert!((n - 1.0).abs() < 1e-12);
                            assert!(c.radius_mm > 0.0 && (1..=1000).contains(&c.turns));
                        }
                        ClEvent::Nurbs(curve) => {
                            let (a, b) = curve.domain();
                            assert!(a < b);
                            let _ = curve.point_at(0.5 * (a + b));
                        }
                        _ => {}
                    }
                }
                Err(e) => {
                    assert!(e.line >= 1 && e.line <= lines && e.column >= 1);
                    let _ = e.to_string();
                }
            }
        }
    }
});
