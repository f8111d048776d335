//! Fuzz target: any bytes (as lossy UTF-8) read as an NC program by every
//! built-in dialect's reader give blocks or a located diagnostic, never a
//! panic. Run with `cargo +nightly fuzz run nc_program` (seed the corpus
//! with `crates/post/tests/all/snapshots/*.snap` and
//! `data/linuxcnc/*.ngc`).

#![no_main]

use kinpost_nc::{AxisSpec, Dialect, read_program};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C").fixed(),
        AxisSpec::pressure_word("H1"),
    ];
    for name in Dialect::builtin_names() {
        let dialect = Dialect::builtin(name).expect("listed");
        if let Err(d) = read_program(&dialect, &axes, "fuzz.nc", &text) {
            let _ = d.to_string();
        }
    }
});
