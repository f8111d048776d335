//! The interpreter never panics (nor loops without end, nor recurses
//! without bound): on random bytes, on random programs made of the words of
//! every family, and on random edits of real programs (LinuxCNC's samples,
//! Qiao et al. 2022 Figure 28(b), the tests' hand-written programs). Every
//! outcome is steps or a located diagnostic. The stable-Rust side of the
//! `nc_interp` fuzz target.

use std::path::Path;

use kinpost_nc::AxisSpec;
use kinpost_nc::interp::{Family, Options, Step, run};
use proptest::prelude::*;

const FAMILIES: [Family; 5] = [
    Family::Sinumerik,
    Family::Fanuc,
    Family::LinuxCnc,
    Family::Heidenhain,
    Family::Csv,
];

fn axes() -> Vec<AxisSpec> {
    vec![
        AxisSpec::linear("X"),
        AxisSpec::endless("A"),
        AxisSpec::linear("Y"),
        AxisSpec::linear("Z"),
        AxisSpec::rotary("B"),
        AxisSpec::rotary("C"),
        AxisSpec::pressure_word("H1"),
    ]
}

fn options() -> Options {
    Options {
        max_executed_blocks: 20_000,
        max_call_depth: 16,
        ..Options::default()
    }
}

/// Runs every family; a diagnostic must point into the text.
fn check(text: &str) {
    for family in FAMILIES {
        let mut n = 0usize;
        let r = run(text, family, &axes(), &options(), "p", &mut |_: &Step| {
            n += 1
        });
        if let Err(d) = r {
            assert!(d.line <= text.lines().count().max(1), "{family:?}: {d}");
            let _ = d.to_string();
        }
    }
}

fn data(path: &str) -> String {
    std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../data")
            .join(path),
    )
    .unwrap()
}

/// Words of the four languages, to build programs from.
const WORDS: &[&str] = &[
    "G0",
    "G1",
    "G2",
    "G3",
    "G17",
    "G18",
    "G19",
    "G20",
    "G21",
    "G70",
    "G71",
    "G90",
    "G91",
    "G93",
    "G94",
    "G81",
    "G83",
    "G73",
    "G98",
    "G99",
    "G80",
    "G43.4",
    "G49",
    "G53",
    "G54",
    "G10 L2 P1",
    "G28",
    "G92",
    "X10",
    "Y-5.5",
    "Z2",
    "A=DC(5)",
    "C=ACP(10)",
    "X=IC(2)",
    "I5",
    "J-3",
    "K1",
    "R5",
    "R-7",
    "P2",
    "Q1.5",
    "F100",
    "F=R1",
    "S1000",
    "M3",
    "M6",
    "T1",
    "M30",
    "M99",
    "M98 P100",
    "#1=5",
    "#1=[#1+1]",
    "#<a>=2",
    "X#1",
    "X[#1*2]",
    "R1=R1+1",
    "IF R1<3 GOTOB L1",
    "L1:",
    "GOTOF L1",
    "WHILE R1<5",
    "ENDWHILE",
    "FOR R2=1 TO 3",
    "ENDFOR",
    "REPEAT",
    "UNTIL R1>2",
    "LOOP",
    "ENDLOOP",
    "DEF REAL V=1",
    "V=V*2",
    "MSG(\"m\")",
    "TRAORI",
    "CIP I1=1 J1=1",
    "CT",
    "CR=5",
    "TURN=1",
    "MCALL CYCLE81(10,0,2,-5)",
    "MCALL",
    "o100 sub",
    "o100 endsub",
    "o100 call [1]",
    "o1 while [#1 LT 3]",
    "o1 endwhile",
    "o2 if [1]",
    "o2 else",
    "o2 endif",
    "o3 repeat [2]",
    "o3 endrepeat",
    "o4 do",
    "o4 while [0]",
    "IF [#1 EQ 1] GOTO 10",
    "N10",
    "WHILE [1] DO 1",
    "END 1",
    "G65 P100 A1",
    "O100",
    "L X+10 R0 FMAX",
    "L IX+1 F100",
    "CC X+0 Y+0",
    "C X+1 Y+0 DR+",
    "CR X+2 Y+2 R+5 DR-",
    "LP PR+5 PA+30",
    "CP IPA+90 DR+",
    "LBL 1",
    "LBL 0",
    "CALL LBL 1 REP 2",
    "CALL LBL 1",
    "FN 0: Q1 = +1",
    "FN 12: IF +Q1 LT +3 GOTO LBL 1",
    "Q2 = Q1 * 2",
    "CYCL DEF 200 DRILLING",
    "Q200=2",
    "Q201=-5",
    "Q206=100",
    "CYCL CALL",
    "M99",
    "TOOL CALL 1 Z S100",
    "BEGIN PGM X MM",
    "END PGM X MM",
    "(MSG, hi)",
    "; note",
    "%",
    "/",
    "H1=3000",
];

fn word_program() -> impl Strategy<Value = String> {
    proptest::collection::vec(proptest::collection::vec(0..WORDS.len(), 1..5), 1..40).prop_map(
        |lines| {
            lines
                .iter()
                .map(|l| l.iter().map(|&k| WORDS[k]).collect::<Vec<_>>().join(" "))
                .collect::<Vec<_>>()
                .join("\n")
        },
    )
}

fn mutated(text: &str, edits: &[(usize, u8, u8)]) -> String {
    let mut bytes = text.as_bytes().to_vec();
    for &(at, kind, byte) in edits {
        if bytes.is_empty() {
            break;
        }
        let at = at % bytes.len();
        match kind % 3 {
            0 => bytes[at] = byte,
            1 => {
                bytes.remove(at);
            }
            _ => bytes.insert(at, byte),
        }
    }
    String::from_utf8_lossy(&bytes).into_owned()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn random_bytes(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        check(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn random_word_programs(text in word_program()) {
        check(&text);
    }

    #[test]
    fn edited_real_programs(which in 0usize..3, edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..12)) {
        let text = match which {
            0 => data("qiao2022/figure28b-verbatim.mpf"),
            1 => data("linuxcnc/xyzab-tdr-demo.ngc"),
            _ => data("linuxcnc/boat-xyzbc.ngc").lines().take(200).collect::<Vec<_>>().join("\n"),
        };
        check(&mutated(&text, &edits));
    }

    #[test]
    fn huge_numbers_and_deep_nesting(depth in 1usize..400, exp in 0i32..400) {
        let deep = format!("G0 X{}1{}\n", "[".repeat(depth), "]".repeat(depth));
        check(&deep);
        let big = format!("G1 X1e{exp} F1\nG0 X{} Y-{}\n", "9".repeat(exp as usize), "9".repeat(exp as usize));
        check(&big);
        let paren = format!("R1={}1{}\n", "(".repeat(depth), ")".repeat(depth));
        check(&paren);
    }
}

/// Endless loops and recursion end at the limits, with an error.
#[test]
fn loops_and_recursion_are_bounded() {
    for (family, text) in [
        (Family::Sinumerik, "L1: G0 X1\nGOTOB L1\n"),
        (Family::Fanuc, "N1 G0 X1.\nGOTO 1\n"),
        (Family::LinuxCnc, "o1 while [1]\nG0 X1\no1 endwhile\nM2\n"),
        (
            Family::LinuxCnc,
            "o100 sub\no100 call\no100 endsub\no100 call\nM2\n",
        ),
        (Family::Fanuc, "O1\nM98 P1\nM30\n"),
        (
            Family::Heidenhain,
            "1 LBL 1\n2 L X+1 FMAX\n3 FN 9: IF +0 EQU +0 GOTO LBL 1\n",
        ),
    ] {
        let e = run(text, family, &axes(), &options(), "l", &mut |_: &Step| {}).unwrap_err();
        assert!(
            e.message.contains("blocks executed") || e.message.contains("nested deeper"),
            "{family:?}: {e}"
        );
    }
}
