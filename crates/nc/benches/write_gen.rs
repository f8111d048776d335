//! What the writing benchmark and `examples/profile_write.rs` share: the
//! axes of `mts1600` and one block written the way the post writes it.

use std::hint::black_box;
use std::io;

use kinpost_nc::{AxisSpec, Block, Motion, NcWriter};

/// The axes of `mts1600` in machine order (C locked).
pub fn axes() -> [AxisSpec; 6] {
    [
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
    ]
}

/// One feed block as the post writes it: the values rounded for the
/// closed-loop check (`quantize_axes`), then the block.
#[inline(always)]
pub fn write_block<W: io::Write>(
    w: &mut NcWriter<W>,
    cl_line: usize,
    values: &[f64; 6],
    feed: f64,
) {
    let mut written = [0.0; 6];
    w.quantize_axes(black_box(values), &mut written);
    w.block(&Block {
        line: None,
        number: None,
        arc: None,
        cl_line: Some(cl_line),
        motion: Motion::Feed,
        axes: black_box(values),
        feed: Some(feed),
    })
    .unwrap();
    black_box(&written);
}
