//! Cross-check with LinuxCNC's `xyzac-trt-kins` (tilting rotary table: A
//! cradle about X, C table on the cradle), inverse kinematics of
//! `src/emc/kinematics/trtfuncs.c` (`xyzacKinematicsInverse`, LinuxCNC
//! 2.9). The formula below is re-derived from the machine it describes, not
//! copied:
//!
//! LinuxCNC's world coordinates are the part frame, which coincides with the
//! machine frame at A = C = 0; the joints X, Y, Z are where the tool tip
//! stands in the machine frame; A and C turn the *table*: a part point p is
//! carried first by C, +C degrees about the Z line through the rotation
//! point (x_r, y_r), then by A, +A degrees about the X line through
//! (0, y_r + D_y, z_r + D_z) (right-hand rule both; D_y, D_z are the
//! `y-offset` and `z-offset` pins, and LinuxCNC adds its `tool-offset` pin to
//! D_z, zero here). The tool tip must be where p went:
//!
//! ```text
//! (X, Y, Z) = Rx(A) · (Rz(C) · (p − r) − d) + d + r,   r = (x_r, y_r, z_r), d = (0, D_y, D_z)
//! ```
//!
//! (the Z line through (x_r, y_r) also passes through r, and the X line
//! through r + d). Multiplied out this is the three lines of
//! `xyzacKinematicsInverse`. In kinpost's terms it is a machine file with
//! X, Y, Z on the tool side and A, C on the workpiece side, written below.

use kinpost_machine::{Kinematics, Pose, machine_from_toml};
use nalgebra::{Matrix3, Vector3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

/// LinuxCNC's HAL parameters of `xyzac-trt-kins`.
#[derive(Debug, Clone, Copy)]
struct Trt {
    x_rot_point: f64,
    y_rot_point: f64,
    z_rot_point: f64,
    y_offset: f64,
    z_offset: f64,
}

/// The kinpost machine file equivalent to `xyzac-trt-kins` with these
/// parameters.
fn machine_file(t: &Trt) -> String {
    format!(
        r#"name = "linuxcnc-xyzac-trt"
description = "LinuxCNC xyzac-trt-kins equivalent"

[[axis]]
name = "X"
kind = "linear"
side = "tool"
direction = [1, 0, 0]

[[axis]]
name = "Y"
kind = "linear"
side = "tool"
direction = [0, 1, 0]

[[axis]]
name = "Z"
kind = "linear"
side = "tool"
direction = [0, 0, 1]

# The cradle: about X through (0, y_r + D_y, z_r + D_z).
[[axis]]
name = "A"
kind = "rotary"
side = "workpiece"
direction = [1, 0, 0]
point = [0, {ay}, {az}]
limits = [-120, 120]

# The table on the cradle: about Z through (x_r, y_r) at A = 0.
[[axis]]
name = "C"
kind = "rotary"
side = "workpiece"
direction = [0, 0, 1]
point = [{cx}, {cy}, 0]
limits = [-360, 360]

# World coordinates = part frame = machine frame at A = C = 0.
[workpiece]
origin = [0, 0, 0]
x = [1, 0, 0]
z = [0, 0, 1]

# The joints are the tool tip's position.
[tool]
point = [0, 0, 0]
axis = [0, 0, 1]
"#,
        ay = t.y_rot_point + t.y_offset,
        az = t.z_rot_point + t.z_offset,
        cx = t.x_rot_point,
        cy = t.y_rot_point,
    )
}

/// Right-hand rotation about +X by `a` radians.
fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Right-hand rotation about +Z by `c` radians.
fn rot_z(c: f64) -> Matrix3<f64> {
    let (s, co) = c.sin_cos();
    Matrix3::new(co, -s, 0.0, s, co, 0.0, 0.0, 0.0, 1.0)
}

/// LinuxCNC's inverse kinematics: joints X, Y, Z for the tool tip `p`
/// (world = part frame) at table angles `a`, `c` (degrees).
fn linuxcnc_inverse(t: &Trt, p: &Vector3<f64>, a: f64, c: f64) -> Vector3<f64> {
    let r = Vector3::new(t.x_rot_point, t.y_rot_point, t.z_rot_point);
    let d = Vector3::new(0.0, t.y_offset, t.z_offset);
    rot_x(a.to_radians()) * (rot_z(c.to_radians()) * (p - r) - d) + d + r
}

/// The tool axis in the part frame at table angles `a`, `c` (degrees): the
/// spindle's +Z carried back through the table rotations,
/// (Rx(A)·Rz(C))ᵀ · Z.
fn tool_axis(a: f64, c: f64) -> Vector3<f64> {
    (rot_x(a.to_radians()) * rot_z(c.to_radians())).transpose() * Vector3::z()
}

fn parameter_sets() -> [Trt; 3] {
    [
        // Rotation point and offsets all non-zero: the A and C lines miss
        // each other by D_y.
        Trt {
            x_rot_point: 12.5,
            y_rot_point: -20.0,
            z_rot_point: -35.0,
            y_offset: 1.75,
            z_offset: -60.0,
        },
        Trt {
            x_rot_point: -150.0,
            y_rot_point: 80.0,
            z_rot_point: 10.0,
            y_offset: -0.125,
            z_offset: 25.0,
        },
        // Intersecting lines through the world origin.
        Trt {
            x_rot_point: 0.0,
            y_rot_point: 0.0,
            z_rot_point: 0.0,
            y_offset: 0.0,
            z_offset: 0.0,
        },
    ]
}

#[test]
fn kinpost_ik_gives_linuxcnc_joints() {
    for t in parameter_sets() {
        let src = machine_file(&t);
        let m = machine_from_toml(&src, "linuxcnc-xyzac-trt.toml").unwrap();
        let kin = Kinematics::new(&m);
        let strategy = (
            prop_oneof![-120.0f64..-0.5, 0.5f64..120.0],
            -360.0f64..360.0,
            [-300.0f64..300.0, -300.0f64..300.0, -300.0f64..300.0],
        );
        let mut runner = TestRunner::new(Config::with_cases(3000));
        runner
            .run(&strategy, |(a, c, p)| {
                let mut sols = Vec::new();
                let p = Vector3::from(p);
                let want = linuxcnc_inverse(&t, &p, a, c);
                let pose = Pose {
                    point: p,
                    axis: tool_axis(a, c),
                    reference: None,
                };
                let hint = [want.x, want.y, want.z, a, c];
                kin.ik_all_branches(&pose, Some(&hint), &mut sols)
                    .map_err(|e| TestCaseError::fail(format!("{t:?}: {e}")))?;
                // The solution with LinuxCNC's A and C (IK gives both
                // branches and every 360° equivalent inside the limits).
                let s = sols
                    .iter()
                    .find(|s| (s.joints[3] - a).abs() < 1e-9 && (s.joints[4] - c).abs() < 1e-9)
                    .ok_or_else(|| {
                        TestCaseError::fail(format!("{t:?}: A{a} C{c} not among {sols:?}"))
                    })?;
                let got = Vector3::new(s.joints[0], s.joints[1], s.joints[2]);
                prop_assert!(
                    (got - want).norm() < 1e-9,
                    "{t:?} A{a} C{c} p {p}: kinpost {got} vs LinuxCNC {want}"
                );
                // And forward: kinpost's FK of LinuxCNC's joints is the pose.
                let back = kin.fk(&hint);
                prop_assert!((back.point - p).norm() < 1e-9);
                prop_assert!((back.axis - pose.axis).norm() < 1e-12);
                Ok(())
            })
            .unwrap();
    }
}

/// One pose worked by hand: A = 90°, C = 0, offsets (x_r, y_r, z_r) =
/// (0, 0, 0), D_y = 0, D_z = −100: the part point (0, 0, 0) sits 100 mm
/// above the A line; a quarter turn about +X carries it to y = −100 on the
/// line's height.
#[test]
fn hand_worked_quarter_turn() {
    let t = Trt {
        x_rot_point: 0.0,
        y_rot_point: 0.0,
        z_rot_point: 0.0,
        y_offset: 0.0,
        z_offset: -100.0,
    };
    let want = Vector3::new(0.0, -100.0, -100.0);
    let got = linuxcnc_inverse(&t, &Vector3::zeros(), 90.0, 0.0);
    assert!((got - want).norm() < 1e-12, "{got}");
    let m = machine_from_toml(&machine_file(&t), "t").unwrap();
    let kin = Kinematics::new(&m);
    let mut sols = Vec::new();
    let pose = Pose {
        point: Vector3::zeros(),
        axis: tool_axis(90.0, 0.0),
        reference: None,
    };
    kin.ik(&pose, None, &mut sols).unwrap();
    let s = sols
        .iter()
        .find(|s| (s.joints[3] - 90.0).abs() < 1e-9 && s.joints[4].abs() < 1e-9)
        .unwrap();
    assert!((Vector3::new(s.joints[0], s.joints[1], s.joints[2]) - want).norm() < 1e-9);
}
