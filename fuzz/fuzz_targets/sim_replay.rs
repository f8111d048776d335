//! Fuzz target: any bytes replayed by the virtual machine (`kinpost-sim`)
//! on `mts1600` (solids, a pressure axis) and `trunnion-ac`, with a CL to
//! compare with, give a report or an error, never a panic (small limits:
//! 20 000 executed blocks). The first byte picks the controller family
//! and whether the pressure word moves the wheel. Run with `cargo +nightly
//! fuzz run sim_replay`, seeded like `nc_interp`.

#![no_main]

use kinpost_machine::builtin;
use kinpost_nc::interp::{Family, Options};
use kinpost_sim::{ClPath, SimOptions, simulate};
use libfuzzer_sys::fuzz_target;

const CL: &str = "GOTO/-416,70.5,16.53,0,0,1\nGOTO/-416,70.3931,11.3684\n";

fuzz_target!(|data: &[u8]| {
    let Some((&first, rest)) = data.split_first() else {
        return;
    };
    let text = String::from_utf8_lossy(rest);
    let families = [Family::Sinumerik, Family::Fanuc, Family::LinuxCnc, Family::Heidenhain, Family::Csv];
    let family = families[usize::from(first) % families.len()];
    let options = SimOptions {
        interp: Options {
            max_executed_blocks: 20_000,
            max_call_depth: 16,
            ..Options::default()
        },
        pressure_offset: first & 0x80 != 0,
        collisions: true,
    };
    for name in ["mts1600", "trunnion-ac"] {
        let machine = builtin::load(name).unwrap().unwrap();
        let cl = ClPath::read(CL.as_bytes(), "f.cls").unwrap();
        match simulate(&text, family, "f", &machine, &options, Some(cl), &mut |_| {}) {
            Ok(r) => {
                assert!(r.duration_s >= 0.0);
                let _ = r.to_json();
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
});
