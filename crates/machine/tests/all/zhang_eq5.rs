//! The built-in `htm40100h` against Zhang et al. (impeller) (Zhang, Li, Dong), the
//! post-processing model of the HTM40100h turn-mill centre.
//!
//! Eq. (5), as printed: the cutter axis in the workpiece frame is
//!
//! ```text
//! u = (cos q_C · cos q_B, −sin q_C · cos q_B, −sin q_B)
//! ```
//!
//! Sign conventions that make kinpost's forward kinematics give exactly
//! this (documented in `machines/htm40100h.toml`): the cutter axis points
//! along +X at home; B turns the head by +q_B about +Y (right-hand rule), so
//! the axis goes to (cos q_B, 0, −sin q_B); C turns the table, and with it
//! the part, by +q_C about +Z (right-hand rule), so in the part frame the
//! head appears turned by −q_C: R_Z(−q_C) in eq. (3) and (4).
//!
//! Eq. (6) and (7) are checked in their corrected form (the printed ones have
//! m_y for m_x in eq. 6 and lose + L cos q_B in eq. 7's X; see the machine
//! file), with the assumed L = 200 mm and (m_x, m_y) = (0, 0) of the machine
//! file.

use kinpost_machine::{Kinematics, Pose, builtin};
use nalgebra::Vector3;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

const L: f64 = 200.0;
const M_X: f64 = 0.0;
const M_Y: f64 = 0.0;

/// Eq. 5 (angles in degrees).
fn eq5(b: f64, c: f64) -> Vector3<f64> {
    let (sb, cb) = b.to_radians().sin_cos();
    let (sc, cc) = c.to_radians().sin_cos();
    Vector3::new(cc * cb, -sc * cb, -sb)
}

/// Eq. 6 with the m_x slip corrected: the tool point in the part frame.
fn eq6(x: f64, y: f64, z: f64, b: f64, c: f64) -> Vector3<f64> {
    let (sb, cb) = b.to_radians().sin_cos();
    let (sc, cc) = c.to_radians().sin_cos();
    let reach = x + L - L * cb - M_X;
    Vector3::new(
        cc * reach + sc * (y - M_Y) + M_X,
        -sc * reach + cc * (y - M_Y) + M_Y,
        z + L * sb,
    )
}

/// Eq. 7 with + L cos q_B restored in X: the linear axes for a tool point.
fn eq7(p: &Vector3<f64>, b: f64, c: f64) -> [f64; 3] {
    let (sb, cb) = b.to_radians().sin_cos();
    let (sc, cc) = c.to_radians().sin_cos();
    [
        M_X - L + L * cb - sc * (p.y - M_Y) + cc * (p.x - M_X),
        M_Y + cc * (p.y - M_Y) + sc * (p.x - M_X),
        -sb * L + p.z,
    ]
}

/// Whether two angles in degrees differ by whole turns.
fn same_angle(a: f64, b: f64) -> bool {
    let d = (a - b) / 360.0;
    (d - d.round()).abs() * 360.0 < 1e-7
}

fn strategy() -> impl Strategy<Value = [f64; 5]> {
    [
        -300.0f64..500.0,
        -150.0f64..150.0,
        -100.0f64..1000.0,
        -120.0f64..120.0,
        -360.0f64..360.0,
    ]
}

#[test]
fn fk_tool_axis_is_eq_5() {
    let m = builtin::load("htm40100h").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let names: Vec<&str> = m.axes.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["X", "Y", "Z", "B", "C"]);
    // Home: cutter axis along +X, tool point on the part origin (Fig. 1).
    let home = kin.fk(&m.home_joints());
    assert!((home.axis - Vector3::x()).norm() < 1e-15);
    assert!(home.point.norm() < 1e-12);
    let mut runner = TestRunner::new(Config::with_cases(5000));
    runner
        .run(&strategy(), |q| {
            let got = kin.fk(&q);
            let want = eq5(q[3], q[4]);
            prop_assert!(
                (got.axis - want).norm() < 1e-12,
                "B{} C{}: {} vs eq. 5 {}",
                q[3],
                q[4],
                got.axis,
                want
            );
            let want = eq6(q[0], q[1], q[2], q[3], q[4]);
            prop_assert!(
                (got.point - want).norm() < 1e-9,
                "eq. 6: {} vs {want}",
                got.point
            );
            Ok(())
        })
        .unwrap();
}

/// The IK solution of the pose at `q` (tool point scaled down into the
/// travel) has the linear axes of eq. 7.
fn linear_axes_are_eq_7(kin: &Kinematics, q: [f64; 5]) -> Result<(), TestCaseError> {
    let mut sols = Vec::new();
    let (b, c) = (q[3], q[4]);
    let p = Vector3::new(q[0], q[1], q[2]) * 0.2;
    let pose = Pose {
        point: p,
        axis: eq5(b, c),
        reference: None,
    };
    // Every branch, inside the travel or not (a branch outside it is
    // reported with one equivalent only: compare modulo 360°).
    kin.ik_all_branches(&pose, Some(&q), &mut sols).unwrap();
    let s = sols
        .iter()
        .find(|s| same_angle(s.joints[3], b) && same_angle(s.joints[4], c))
        .ok_or_else(|| TestCaseError::fail(format!("B{b} C{c} not among {sols:?}")))?;
    // Eq. 7 at the angles the IK found: next to the C axis (B near ±90°)
    // subproblem 2 finds B only to about ε/(2·distance) rad (its
    // g = √(|p|² − a² − b²) cancels), which moves X by L·sin B times that;
    // the linear solve itself is exact.
    let want = eq7(&p, s.joints[3], s.joints[4]);
    for (k, w) in want.iter().enumerate() {
        prop_assert!(
            (s.joints[k] - w).abs() < 1e-9,
            "axis {k}: {} vs eq. 7 {w}",
            s.joints[k]
        );
    }
    Ok(())
}

#[test]
fn ik_linear_axes_are_eq_7() {
    let m = builtin::load("htm40100h").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    // Found by the random run: B 2e-4° from the C axis, where X was 2.2e-9
    // mm off eq. 7 at the sampled (not the solved) angles.
    linear_axes_are_eq_7(&kin, [0.0, 0.0, 0.0, -90.0001980981887, 0.0]).unwrap();
    let mut runner = TestRunner::new(Config::with_cases(3000));
    runner
        .run(&strategy(), |q| linear_axes_are_eq_7(&kin, q))
        .unwrap();
}
