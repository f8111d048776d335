//! The planner stage on its own, its decisions collected in a `Vec` sink:
//! points and commands come out in order, every decided configuration
//! reaches its pose (checked by the forward kinematics), a pass across the
//! singular pole of an A/C trunnion is planned without a flip, and a point
//! no configuration reaches is an error at once.

use kinpost_diag::Located;
use kinpost_machine::{Joints, Kinematics, KinematicsAtPressure, Machine, Pose, builtin};
use kinpost_nc::Motion;
use kinpost_plan::{Costs, PathPoint, PlanError, PlanSink, Planned, Planner, Trellis};
use nalgebra::Vector3;

/// What the sink received.
#[derive(Debug)]
#[allow(clippy::large_enum_variant)] // (a test's list)
enum Out {
    Point {
        line: usize,
        joints: Joints,
        pose: Pose,
        reached: Pose,
        continuous: bool,
        cut: bool,
    },
    Command(&'static str),
}

#[derive(Default)]
struct VecSink(Vec<Out>);

impl PlanSink<&'static str> for VecSink {
    type Error = Located<PlanError>;

    fn point(&mut self, kin: &Kinematics, p: &Planned<'_>) -> Result<(), Self::Error> {
        let n = kin.axis_count();
        self.0.push(Out::Point {
            line: p.site.line,
            joints: p.node.joints,
            pose: p.node.pose,
            reached: kin.fk(&p.node.joints[..n]),
            continuous: p.continuous,
            cut: p.cut,
        });
        Ok(())
    }

    fn command(&mut self, c: &'static str) -> Result<(), Self::Error> {
        self.0.push(Out::Command(c));
        Ok(())
    }
}

fn trunnion() -> Machine {
    builtin::load("trunnion-ac").unwrap().unwrap()
}

fn planner(m: &Machine, lag: usize) -> (Planner<&'static str>, KinematicsAtPressure) {
    let kin = Kinematics::new(m);
    let costs = Costs::new(m, 0.5, kin.singularity().map(|s| s.axis));
    let planner = Planner::new(m, &kin, Trellis::new(costs, lag), 0.5, "test.cls");
    (planner, KinematicsAtPressure::new(m, kin, true))
}

/// A feed point at `point` with tool axis tilted `tilt_deg` from +Z about
/// the direction at `heading_deg` in the XY plane.
fn point(line: usize, point: [f64; 3], tilt_deg: f64, heading_deg: f64) -> PathPoint {
    let (t, h) = (tilt_deg.to_radians(), heading_deg.to_radians());
    PathPoint {
        pose: Pose {
            point: Vector3::from(point),
            axis: Vector3::new(t.sin() * h.cos(), t.sin() * h.sin(), t.cos()),
            reference: None,
        },
        motion: Motion::Feed,
        line,
        feed: Some(500.0),
        pressure: f64::NAN,
    }
}

#[test]
fn points_and_commands_come_out_in_order_and_reach_their_poses() {
    let m = trunnion();
    for lag in [1, 7, 1 << 15] {
        let (mut p, mut kin) = planner(&m, lag);
        let mut sink = VecSink::default();
        p.push_command("start");
        // A pass that tilts the tool from 10° to 40° while turning it half
        // way round the part.
        for k in 0..40 {
            let line = 10 + k;
            let f = k as f64 / 39.0;
            let q = point(
                line,
                [20.0 - 40.0 * f, 5.0, 3.0],
                10.0 + 30.0 * f,
                180.0 * f,
            );
            p.push_point(&mut kin, q, format!("GOTO {line}").as_bytes())
                .unwrap();
            if k == 19 {
                p.push_command("half way");
            }
            if p.is_full() {
                p.flush(&mut kin, &mut sink, false).unwrap();
            }
        }
        p.push_command("end");
        p.flush(&mut kin, &mut sink, true).unwrap();
        let order: Vec<String> = sink
            .0
            .iter()
            .map(|o| match o {
                Out::Point { line, .. } => line.to_string(),
                Out::Command(c) => c.to_string(),
            })
            .collect();
        let mut want = vec!["start".to_string()];
        want.extend((10..30).map(|l| l.to_string()));
        want.push("half way".into());
        want.extend((30..50).map(|l| l.to_string()));
        want.push("end".into());
        assert_eq!(order, want, "lag {lag}");
        let mut previous: Option<Joints> = None;
        for o in &sink.0 {
            let Out::Point {
                joints,
                pose,
                reached,
                continuous,
                cut,
                ..
            } = o
            else {
                continue;
            };
            assert!((reached.point - pose.point).norm() < 1e-9);
            assert!(reached.axis.angle(&pose.axis) < 1e-9);
            assert!(*continuous);
            // The first point starts the path; the others cut on from it,
            // each rotary axis moving by a few degrees at most.
            assert_eq!(*cut, previous.is_some());
            if let Some(q) = previous {
                for i in [3, 4] {
                    assert!((joints[i] - q[i]).abs() < 10.0, "{i}: {q:?} -> {joints:?}");
                }
            }
            previous = Some(*joints);
        }
    }
}

/// A pass over the pole of the A/C trunnion (tool axis along C at A = 0):
/// the points inside the singular cone are solved between their decided
/// neighbours, C does not flip, and the run is reported.
#[test]
fn a_pass_over_the_pole_keeps_the_free_angle_continuous() {
    let m = trunnion();
    let (mut p, mut kin) = planner(&m, 1 << 15);
    let mut sink = VecSink::default();
    for k in 0..=20 {
        let f = k as f64 / 20.0;
        // From 5° tilt towards -X, through vertical, to 5° towards +X, a
        // little off the pole's plane.
        let tilt = (10.0 * f - 5.0).abs();
        let heading = if f < 0.5 { 180.0 + 3.0 } else { 3.0 };
        p.push_point(
            &mut kin,
            point(k + 1, [10.0 * f, 0.0, 0.0], tilt, heading),
            b"GOTO",
        )
        .unwrap();
    }
    p.flush(&mut kin, &mut sink, true).unwrap();
    assert!(
        !p.stretches().is_empty(),
        "the vertical point is in the cone"
    );
    let c: Vec<f64> = sink
        .0
        .iter()
        .filter_map(|o| match o {
            Out::Point { joints, .. } => Some(joints[4]),
            Out::Command(_) => None,
        })
        .collect();
    assert_eq!(c.len(), 21);
    let biggest = c
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .fold(0.0, f64::max);
    assert!(
        biggest < 90.0,
        "C swings by {biggest}° between points: {c:?}"
    );
}

#[test]
fn a_point_out_of_reach_is_an_error_at_once() {
    let m = trunnion();
    let (mut p, mut kin) = planner(&m, 1 << 15);
    // A tilted 60° beyond its -30° limit side: no solution inside the
    // travel of A (−30° .. 120°) points the tool down.
    let e = p
        .push_point(&mut kin, point(3, [0.0, 0.0, 0.0], 179.0, 90.0), b"GOTO")
        .unwrap_err();
    assert!(
        matches!(e, PlanError::OutsideTravel { .. } | PlanError::Ik { .. }),
        "{e}"
    );
}
