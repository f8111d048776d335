//! Fuzz target: any bytes (as lossy UTF-8) fed to the dialect-file loader
//! must give a dialect or located diagnostics, never a panic; a dialect that
//! loads must write a few blocks and read them back. Run with
//! `cargo +nightly fuzz run dialect_file` (seed the corpus with
//! `crates/nc/dialects/*.toml`).

#![no_main]

use kinpost_nc::{
    ArcMotion, ArcPlane, AxisSpec, Block, Dialect, Motion, NcWriter, ProgramInfo, read_program,
};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let Ok(dialect) = Dialect::from_toml(&text, "fuzz.toml") else {
        return;
    };
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::rotary("B"),
        AxisSpec::pressure_word("H1"),
    ];
    let mut w = NcWriter::new(&dialect, &axes, Vec::new());
    let _ = w.header(&ProgramInfo::default(), None);
    for (k, motion) in [Motion::Rapid, Motion::Feed, Motion::Feed].into_iter().enumerate() {
        let v = [k as f64 * 1.5, -400.0 + k as f64, 12.25, 3000.0 + 10.0 * k as f64];
        let _ = w.block(&Block { cl_line: Some(k + 1), motion, ..Block::feed(&v[..], 250.0) });
    }
    // A circular block, written where the dialect has [arc] words.
    let circle = ArcMotion { plane: ArcPlane::Zx, clockwise: true, centre_offset: [1.0, 0.0, -0.5] };
    let end = [3.0, -396.0, 12.25, 3030.0];
    let _ = w.block(&Block { arc: Some(circle), ..Block::feed(&end[..], 200.0) });
    let _ = w.comment("fuzz (comment)");
    let _ = w.footer(&ProgramInfo::default(), None);
    if let Ok(out) = w.finish() {
        let _ = read_program(&dialect, &axes, "fuzz.nc", &String::from_utf8_lossy(&out));
    }
});
