//! Golden programs: one small 5-axis job per built-in machine and built-in
//! dialect, kept as insta snapshots (`crates/kinpost/tests/snapshots/`),
//! reviewed by hand when they change (`cargo insta review`, or
//! `INSTA_UPDATE=always` and `git diff`).
//!
//! The job of a machine is made from joint values inside its travel, so
//! every machine can reach it: ten points along a line in joint space, run
//! through the machine's forward kinematics and written as CL.

use kinpost::machine::{Kinematics, Machine, builtin};
use kinpost::nc::Dialect;
use kinpost::{PostOptions, post};

/// Joint values a fraction `t` of the way between two corners well inside
/// the travel (23 % and 64 % of each range, rotary ranges cut to ±150° so
/// that no axis needs to unwind; ±100 mm / ±60° where none).
fn joints(m: &Machine, t: f64) -> Vec<f64> {
    m.axes
        .iter()
        .map(|a| match (a.fixed, a.limits) {
            (Some(v), _) => v,
            (None, Some([lo, hi])) => {
                let (lo, hi) = if a.is_rotary() {
                    (lo.max(-150.0), hi.min(150.0))
                } else {
                    (lo.max(-400.0), hi.min(400.0))
                };
                lo + (hi - lo) * (0.23 + 0.41 * t)
            }
            (None, None) if a.is_rotary() => -60.0 + 120.0 * (0.23 + 0.41 * t),
            (None, None) => -100.0 + 200.0 * (0.23 + 0.41 * t),
        })
        .collect()
}

fn job(m: &Machine) -> String {
    let kin = Kinematics::new(m);
    let mut cl = format!(
        "PARTNO/GOLDEN {}\nLOAD/TOOL,3\nSPINDL/3000,RPM,CLW\nCOOLNT/FLOOD\nRAPID\n",
        m.name
    );
    for k in 0..10 {
        let p = kin.fk(&joints(m, k as f64 / 9.0));
        if k == 1 {
            cl.push_str("FEDRAT/MMPM,400\n");
        }
        cl.push_str(&format!(
            "GOTO/{:.4},{:.4},{:.4},{:.7},{:.7},{:.7}\n",
            p.point.x, p.point.y, p.point.z, p.axis.x, p.axis.y, p.axis.z
        ));
    }
    cl.push_str("$$ end of the golden job\nCOOLNT/OFF\nSPINDL/OFF\nEND-OF-PATH\n");
    cl
}

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
