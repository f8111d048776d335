//! The replay never panics: random programs of motion words (rapids,
//! feeds, arcs in every plane, feed modes, the pressure word, spindle and
//! dwell words) on a machine with solids and a pressure axis (`mts1600`)
//! and on `trunnion-ac`, with a CL to compare with. Every outcome is a
//! report or a located error.

use kinpost_machine::builtin;
use kinpost_nc::interp::{Family, Options};
use kinpost_sim::{ClPath, SimOptions, simulate};
use proptest::prelude::*;

const CL: &str =
    "GOTO/-416,70.5,16.53,0,0,1\nGOTO/-416,70.3931,11.3684\nGOTO/-400,60,10,0,0.1,0.995\n";

fn word() -> impl Strategy<Value = String> {
    let value = prop_oneof![-2000.0f64..2000.0, Just(0.0), -1.0f64..1.0, Just(1e-9),];
    let letter = prop::sample::select(vec![
        "X", "Y", "Z", "A", "B", "C", "I", "J", "K", "R", "F", "S", "H1=",
    ]);
    let code = prop::sample::select(vec![
        "G0", "G1", "G2", "G3", "G17", "G18", "G19", "G90", "G91", "G93", "G94", "G95", "G4 P0.5",
        "M3", "M5", "G20", "G21", "TRAORI", "TRAFOOF", "M428", "M429",
    ]);
    prop_oneof![
        (letter, value).prop_map(|(l, v)| format!("{l}{v:.4}")),
        code.prop_map(str::to_string),
    ]
}

fn program() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::collection::vec(word(), 1..6), 1..25).prop_map(|lines| {
        lines
            .iter()
            .map(|l| l.join(" "))
            .collect::<Vec<_>>()
            .join("\n")
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn random_programs_give_a_report_or_an_error(text in program(), pressure_offset: bool) {
        for (machine, family) in [("mts1600", Family::Sinumerik), ("trunnion-ac", Family::LinuxCnc)] {
            let m = builtin::load(machine).unwrap().unwrap();
            let options = SimOptions {
                interp: Options { max_executed_blocks: 10_000, ..Options::default() },
                pressure_offset,
                collisions: true,
            };
            let cl = ClPath::read(CL.as_bytes(), "t.cls").unwrap();
            match simulate(&text, family, "p", &m, &options, Some(cl), &mut |_| {}) {
                Ok(r) => {
                    prop_assert!(r.duration_s >= 0.0, "{}", r.duration_s);
                    let _ = r.to_json();
                    let _ = r.summary();
                }
                Err(e) => {
                    let _ = e.to_string();
                }
            }
        }
    }
}
