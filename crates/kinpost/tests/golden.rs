//! Golden programs: one small 5-axis job per built-in machine and built-in
//! dialect, kept as insta snapshots (`crates/kinpost/tests/snapshots/`),
//! reviewed by hand when they change (`cargo insta review`, or
//! `INSTA_UPDATE=always` and `git diff`).
//!
//! The job of a machine is made from joint values inside its travel, so
//! every machine can reach it: ten points along a line in joint space, run
//! through the machine's forward kinematics and written as CL. The points
//! are far apart, so linearization is off here (it would bury the dialect
//! under inserted blocks); `tests/planning.rs` tests it.

mod common;

use common::job;
use kinpost::machine::builtin;
use kinpost::nc::Dialect;
use kinpost::{PostOptions, post};

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
