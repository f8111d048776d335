//! Every dialect's output of the same job, read back with that dialect's
//! reader (not with the values the post kept), runs through the forward
//! kinematics onto the CL within the closed-loop tolerance: joint and
//! tool-centre-point output, every built-in machine.

use crate::common;

use kinpost_post::machine::{Kinematics, OutputMode, Pose, builtin};
use kinpost_post::nc::{Dialect, read_program};
use kinpost_post::{PostOptions, post};
use nalgebra::Vector3;

/// The CL poses of a job, in order, as the reader sees them.
fn cl_poses(cl: &str) -> Vec<Pose> {
    cl.lines()
        .filter_map(|l| l.strip_prefix("GOTO/"))
        .map(|v| {
            let v: Vec<f64> = v.split(',').map(|x| x.parse().unwrap()).collect();
            Pose {
                point: Vector3::new(v[0], v[1], v[2]),
                axis: Vector3::new(v[3], v[4], v[5]).normalize(),
                reference: None,
            }
        })
        .collect()
}

#[test]
fn every_dialect_reads_back_onto_the_cl() {
    for name in builtin::names() {
        let machine = builtin::load(name).unwrap().unwrap();
        let kin = Kinematics::new(&machine);
        let cl = common::job(&machine);
        let poses = cl_poses(&cl);
        let axes = kinpost_post::axis_specs(&machine);
        for dialect_name in Dialect::builtin_names() {
            let dialect = Dialect::builtin(dialect_name).unwrap();
            for output in [OutputMode::Joint, OutputMode::Tcp] {
                let mut out = Vec::new();
                // One block per CL point (no linearization), so that block k
                // belongs to CL point k.
                let options = PostOptions {
                    output: Some(output),
                    lintol_mm: Some(0.0),
                    ..Default::default()
                };
                let summary = post(cl.as_bytes(), &machine, &dialect, &mut out, &options).unwrap();
                let text = String::from_utf8(out).unwrap();
                let blocks = read_program(&dialect, &axes, "job", &text)
                    .unwrap_or_else(|e| panic!("{name}/{dialect_name}: {e}\n{text}"));
                // A machine's own header may move axes too (mts1600: `G01
                // B0`): the job's blocks are the last ones.
                assert!(blocks.len() >= poses.len(), "{name}/{dialect_name}\n{text}");
                let blocks = &blocks[blocks.len() - poses.len()..];
                for (b, want) in blocks.iter().zip(&poses) {
                    let q: Vec<f64> = b
                        .axes
                        .iter()
                        .zip(&machine.axes)
                        .map(|(v, a)| v.or(a.fixed).expect("every free axis is written"))
                        .collect();
                    let mut got = kin.fk(&q);
                    if output == OutputMode::Tcp {
                        let at = |n: &str| q[machine.axis_index(n).unwrap()];
                        got.point = Vector3::new(at("X"), at("Y"), at("Z"));
                    }
                    let dp = (got.point - want.point).norm();
                    let da = got
                        .axis
                        .cross(&want.axis)
                        .norm()
                        .atan2(got.axis.dot(&want.axis));
                    // The CL itself is rounded to 4 / 7 decimals.
                    assert!(
                        dp <= summary.tolerance_mm + 1e-4 && da <= summary.tolerance_rad + 1e-6,
                        "{name}/{dialect_name}/{output:?} line {:?}: {dp} mm, {da} rad",
                        b.line
                    );
                }
            }
        }
    }
}
