//! Golden programs: one small 5-axis job per built-in machine and built-in
//! dialect, kept as insta snapshots (`crates/post/tests/all/snapshots/`),
//! reviewed by hand when they change (`cargo insta review`, or
//! `INSTA_UPDATE=always` and `git diff`).
//!
//! The job of a machine is made from joint values inside its travel, so
//! every machine can reach it: ten points along a line in joint space, run
//! through the machine's forward kinematics and written as CL. The points
//! are far apart, so linearization is off here (it would bury the dialect
//! under inserted blocks); `tests/all/planning.rs` tests it.

use crate::common;

use common::job;
use kinpost_post::machine::builtin;
use kinpost_post::nc::Dialect;
use kinpost_post::{PostOptions, post};

#[test]
fn every_machine_in_every_dialect() {
    for name in builtin::names() {
        let machine = builtin::load(name).unwrap().unwrap();
        let cl = job(&machine);
        for dialect_name in Dialect::builtin_names() {
            let dialect = Dialect::builtin(dialect_name).unwrap();
            let mut out = Vec::new();
            let options = PostOptions {
                cl_file: format!("{name}.cls"),
                date: "2026-11-23".into(),
                lintol_mm: Some(0.0),
                ..Default::default()
            };
            let summary = post(cl.as_bytes(), &machine, &dialect, &mut out, &options)
                .unwrap_or_else(|e| panic!("{name} / {dialect_name}: {e}\n{cl}"));
            assert_eq!(summary.blocks, 10);
            assert!(summary.max_position_error_mm <= summary.tolerance_mm);
            let program = String::from_utf8(out).unwrap();
            insta::assert_snapshot!(format!("{name}__{dialect_name}"), program);
        }
    }
}

/// A repeated CL point writes no block in a dialect with modal axis words
/// (no bare `G00`), and the summary counts the blocks written: the lines of
/// motion of the program, the rows of a CSV table (which keeps the repeat),
/// every block of sinumerik (which writes every axis word every time).
#[test]
fn a_repeated_point_writes_no_block() {
    let cl = "TOOL PATH/D,TOOL,E\nRAPID\nGOTO/0,0,50,0,0,1\nFEDRAT/MMPM,100\nGOTO/0,0,10\n\
              GOTO/0,0,10\nGOTO/0,0,10.0001\nGOTO/0,0,10\nRAPID\nGOTO/0,0,10\n";
    let machine = builtin::load("trunnion-ac").unwrap().unwrap();
    for (dialect_name, blocks, motion) in [
        ("fanuc", 2, ["G00 X0.000", "G01 Z10.000 F100."].as_slice()),
        (
            "linuxcnc",
            4,
            &["G0 X0.0000", "G1 Z10.0000 F100", "Z10.0001", "Z10.0000"],
        ),
        ("heidenhain", 2, &["L X+0.000", "L Z+10.000 R0 F100"]),
        ("csv", 6, &[]),
        ("sinumerik", 6, &[]),
    ] {
        let dialect = Dialect::builtin(dialect_name).unwrap();
        let mut out = Vec::new();
        let summary = post(
            cl.as_bytes(),
            &machine,
            &dialect,
            &mut out,
            &PostOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{dialect_name}: {e}"));
        let program = String::from_utf8(out).unwrap();
        assert_eq!(
            summary.blocks, blocks,
            "{dialect_name}:\n{program}\n{summary:?}"
        );
        if motion.is_empty() {
            continue;
        }
        let moves: Vec<&str> = program
            .lines()
            .skip_while(|l| !l.contains("TOOL PATH"))
            .skip(1)
            .take_while(|l| !l.split_whitespace().any(|w| w.starts_with('M')))
            .collect();
        assert_eq!(moves.len(), motion.len(), "{dialect_name}:\n{program}");
        for (line, start) in moves.iter().zip(motion) {
            assert!(line.contains(start), "{dialect_name}: {line:?}\n{program}");
        }
    }
}
