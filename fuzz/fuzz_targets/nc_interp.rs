//! Fuzz target: any bytes read by the NC interpreter of every controller
//! family give steps or a located diagnostic, never a panic, an endless
//! loop or unbounded recursion (small limits: 20 000 executed blocks, 16
//! nested calls). The first byte picks the family the others are run
//! with first. Run with `cargo +nightly fuzz run nc_interp`, the corpus
//! seeded with `data/linuxcnc/*.ngc`, `data/qiao2022/figure28b-verbatim.mpf`
//! and programs in each dialect (see `crates/nc/tests/interp_*.rs`).

#![no_main]

use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Event, Family, Options, Step, run};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let text = String::from_utf8_lossy(rest);
    let axes = [
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C"),
        AxisSpec::pressure_word("H1"),
    ];
    let options = Options {
        max_executed_blocks: 20_000,
        max_call_depth: 16,
        ..Options::default()
    };
    let families = [Family::Sinumerik, Family::Fanuc, Family::LinuxCnc, Family::Heidenhain, Family::Csv];
    let start = usize::from(first) % families.len();
    for k in 0..families.len() {
        let family = families[(start + k) % families.len()];
        let mut moves = 0u64;
        let mut count = |s: &Step| {
            if matches!(s.event, Event::Move(_)) {
                moves += 1;
            }
        };
        match run(&text, family, &axes, &options, "fuzz", &mut count) {
            Ok(report) => assert_eq!(report.moves, moves),
            Err(d) => {
                let _ = d.to_string();
            }
        }
    }
});
