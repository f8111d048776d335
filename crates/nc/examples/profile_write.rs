//! Writes N motion blocks (default 50,000) the way the post does (one
//! `quantize_axes`, then `block`) into a sink, for instruction-counting
//! profilers: `valgrind --tool=callgrind target/release/examples/profile_write
//! [sinumerik|csv|...] [N]`. The criterion benchmark `benches/write.rs` is
//! the measurement of record.

use std::io;

use kinpost_nc::{Dialect, NcWriter};

#[path = "../benches/write_gen.rs"]
mod write_gen;
use write_gen::{axes, write_block};

fn main() {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "sinumerik".into());
    let n: usize = std::env::args()
        .nth(2)
        .and_then(|a| a.parse().ok())
        .unwrap_or(50_000);
    let dialect = Dialect::builtin(&name).expect("a built-in dialect");
    let axes = axes();
    let mut w = NcWriter::new(&dialect, &axes, io::sink());
    // The path first, so that a profile of the loop is the writer's alone.
    let path: Vec<[f64; 6]> = (0..n)
        .map(|k| {
            let t = k as f64 / n as f64;
            let s = (k % 1000) as f64 / 1000.0;
            [
                -400.0 + 50.0 * s,
                10.0 * (std::f64::consts::TAU * t).sin(),
                60.0 - 40.0 * t,
                350.0 + 3.0 * (7.0 * s).sin(),
                -20.0 + 40.0 * s,
                0.0,
            ]
        })
        .collect();
    write_path(&mut w, &path);
    eprintln!("{} blocks", w.blocks_written());
}

/// The profiled loop (`--toggle-collect=*write_path*` counts it alone).
#[inline(never)]
fn write_path<W: io::Write>(w: &mut NcWriter<W>, path: &[[f64; 6]]) {
    for (k, v) in path.iter().enumerate() {
        write_block(w, k + 4, v, 2000.0);
    }
}
