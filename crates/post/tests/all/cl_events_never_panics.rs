//! The whole post of random CL programs made of the statements beyond
//! `GOTO` (arcs, splines, cycles, stops, dwells, home moves, compensation,
//! surface speeds, frames, inserts), with random and hostile numbers, in
//! every built-in dialect: a program and a summary or an error, never a
//! panic.

use kinpost_post::machine::builtin;
use kinpost_post::nc::Dialect;
use kinpost_post::{InsertMode, PostOptions, post};
use proptest::prelude::*;

fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        (-50.0..50.0f64).prop_map(|v| format!("{v:.3}")),
        Just("0".to_string()),
        Just("1E300".to_string()),
        Just("-1E-300".to_string()),
        (0u32..5).prop_map(|v| v.to_string()),
    ]
}

fn statement() -> impl Strategy<Value = String> {
    let n = number;
    prop_oneof![
        (n(), n(), n()).prop_map(|(x, y, z)| format!("GOTO/{x},{y},{z}")),
        (n(), n(), n()).prop_map(|(x, y, z)| format!("RAPID\nGOTO/{x},{y},{z},0,0,1")),
        (n(), n(), n(), n()).prop_map(|(x, y, z, r)| format!("CIRCLE/{x},{y},{z},0,0,1,{r}")),
        (n(), n(), n()).prop_map(|(x, y, z)| format!("CIRCLE/{x},{y},{z},0,0,1")),
        (n(), n(), n())
            .prop_map(|(d, r, s)| format!("CYCLE/DEEP,FEDTO,{d},RAPTO,{r},STEP,{s},MMPM,100")),
        (n(), n(), n()).prop_map(|(d, r, b)| format!(
            "CYCLE/BRKCHP,DEPTH,{d},CLEAR,{r},STEP,1,BACK,{b},TIMES,2"
        )),
        (n(), n()).prop_map(|(d, p)| format!("CYCLE/TAP,FEDTO,{d},RAPTO,2,PITCH,{p}")),
        (n(), n()).prop_map(|(d, t)| format!("CYCLE/BORE,FEDTO,{d},RAPTO,1,DWELL,{t},IPM,3")),
        Just("CYCLE/OFF".to_string()),
        n().prop_map(|t| format!("DELAY/{t}")),
        n().prop_map(|t| format!("DELAY/{t},REV")),
        Just("STOP".to_string()),
        Just("OPSTOP".to_string()),
        Just("END".to_string()),
        (n(), n(), n()).prop_map(|(x, y, z)| format!("FROM/{x},{y},{z}")),
        Just("GOHOME".to_string()),
        Just("CUTCOM/LEFT".to_string()),
        Just("CUTCOM/RIGHT,ZXPLAN,3".to_string()),
        Just("CUTCOM/OFF".to_string()),
        n().prop_map(|d| format!("CUTTER/{d}")),
        n().prop_map(|v| format!("SPINDL/SMM,{v},CLW,MAXRPM,5000,RANGE,2")),
        n().prop_map(|v| format!("SPINDL/{v},RPM,CCLW")),
        Just("SPINDL/OFF".to_string()),
        n().prop_map(|f| format!("FEDRAT/MMPM,{f}")),
        n().prop_map(|f| format!("FEDRAT/MMPR,{f}")),
        Just("LOAD/TOOL,3,ADJUST,13".to_string()),
        Just("CSYS/0,1,0,5,-1,0,0,0,0,0,1,0".to_string()),
        Just("CLAMP/ON,AAXIS".to_string()),
        n().prop_map(|x| format!("ORIGIN/{x},0,0")),
        Just("INSERT/G0 X10".to_string()),
        Just("NURBS/\nKNOT/1\nCNTRL/1,2,0\nCNTRL/3,2,0\nCNTRL/4,0,0".to_string()),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]
    #[test]
    fn random_cl_events_never_panic(
        statements in proptest::collection::vec(statement(), 1..24),
        insert in prop_oneof![
            Just(InsertMode::Verbatim),
            Just(InsertMode::Comment),
            Just(InsertMode::Drop)
        ],
    ) {
        let cl = format!("FEDRAT/MMPM,500\n{}\n", statements.join("\n"));
        let machine = builtin::load("trunnion-ac").unwrap().unwrap();
        let options = PostOptions {
            cl_file: "random.cls".into(),
            default_axis: Some([0.0, 0.0, 1.0]),
            insert,
            ..Default::default()
        };
        for name in Dialect::builtin_names() {
            let dialect = Dialect::builtin(name).unwrap();
            let mut out = Vec::new();
            if let Err(e) = post(cl.as_bytes(), &machine, &dialect, &mut out, &options) {
                // Every error of the input names its place.
                let _ = e.to_string();
            }
        }
    }
}
