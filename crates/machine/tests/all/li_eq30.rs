//! The built-in `ac-grinder` against Li (B-spline grinding), section 5: posting a
//! surface normal gives exactly the A and C angles of eq. (30), and the whole
//! pose of every solution, run through the paper's own transformation chain
//! (eq. 17-25), puts the CL point on the wheel's grinding point.
//!
//! Everything on the paper's side is written here from the printed formulas,
//! independently of kinpost's chain:
//!
//! ```text
//! eq. 25:  x_s = T1 T2 T3 T4 T5 T6 T7 T8 · x_g         (part frame → wheel frame)
//! eq. 26:  n_s = T2 T6 T7 T8 · n_g                      (rotation parts)
//! eq. 29:  n_s = C0 · n_d,  n_d = (0, −1, 0)            (eq. 28)
//! eq. 30:  θa = arctan(n_xg / n_yg)
//!          −n_xg sin θa sin θc − n_yg cos θa sin θc + n_zg cos θc = 0
//! ```
//!
//! The paper leaves the sign of C0 open (eq. 30 holds for both); the machine
//! file takes C0 > 0 (the CL tool axis, the part's outward normal, lies on
//! +n_d), and so does this test. The installation offsets L_x, L_y, L_z, the
//! wheel radius r_s1 and the angle φ of the grinding point (eq. 27) are the
//! assumed values stated in `machines/ac-grinder.toml`.

use kinpost_machine::{Kinematics, Pose, builtin};
use nalgebra::{Vector3, Vector4};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

use crate::li_paper;

use li_paper::{PHI, R_S1, eq25, eq26, eq30, eq30_angles_deg, eq30_residual, same_angle};

/// A unit normal from two uniform numbers (uniform on the sphere), and a
/// point near the measured points of Li (B-spline grinding) (Tables 1-5).
fn cases() -> impl Strategy<Value = (f64, f64, [f64; 3])> {
    (
        -1.0f64..1.0,
        0.0f64..std::f64::consts::TAU,
        [60.0f64..75.0, -10.0f64..5.0, -20.0f64..0.0],
    )
}

#[test]
fn posting_a_normal_gives_the_angles_of_eq_30() {
    let m = builtin::load("ac-grinder").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let idx = |n: &str| m.axis_index(n).unwrap();
    let (ix, iy, iz, ia, ic) = (idx("X"), idx("Y"), idx("Z"), idx("A"), idx("C"));
    let grinding_point = Vector4::new(R_S1 * PHI.sin(), 0.0, -R_S1 * PHI.cos(), 1.0); // eq. 27
    let mut runner = TestRunner::new(Config::with_cases(5000));
    runner
        .run(&cases(), |(z, phi, p)| {
            let mut sols = Vec::new();
            let rho = (1.0 - z * z).sqrt();
            let n = Vector3::new(rho * phi.cos(), rho * phi.sin(), z);
            // Normals on the cutter's own axis z_g leave θa undetermined
            // (eq. 30 divides 0 by 0).
            prop_assume!(rho > 1e-3 && n.y.abs() > 1e-9);
            let p = Vector3::from(p);
            let pose = Pose {
                point: p,
                axis: n,
                reference: None,
            };
            kin.ik_all_branches(&pose, None, &mut sols)
                .map_err(|e| TestCaseError::fail(format!("{e} for n = {n}")))?;
            prop_assert!(sols.iter().any(|s| s.is_valid()));

            // Every solution kinpost gives (inside the travel or not: the
            // angles do not depend on it) satisfies eq. 30 and eq. 26 with
            // C0 = +1, and eq. 25 puts the CL point on the grinding point.
            let (ta, _) = eq30(&n);
            let mut pairs: Vec<(f64, f64)> = Vec::new();
            for s in &sols {
                let j = &s.joints;
                let (a, c) = (j[ia], j[ic]);
                prop_assert!(
                    same_angle(a, ta.to_degrees(), 180.0),
                    "A = {a} vs arctan(nx/ny) = {}",
                    ta.to_degrees()
                );
                let res = eq30_residual(&n, a.to_radians(), c.to_radians());
                prop_assert!(res.abs() < 1e-12, "eq. 30 residual {res}");
                let ns = eq26(&n, a.to_radians(), c.to_radians());
                prop_assert!(
                    (ns - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12,
                    "n_s = {ns}"
                );
                let xs = eq25(j[ix], j[iy], j[iz], a.to_radians(), c.to_radians())
                    * Vector4::new(p.x, p.y, p.z, 1.0);
                prop_assert!(
                    (xs - grinding_point).norm() < 1e-9,
                    "eq. 25 gives {xs} for the CL point"
                );
                if !pairs
                    .iter()
                    .any(|&(a2, c2)| same_angle(a, a2, 360.0) && same_angle(c, c2, 360.0))
                {
                    pairs.push((a, c));
                }
            }

            // Eq. 30's own angles (θc or θc + 180°, whichever gives C0 > 0:
            // both solve the second line) are among them, and so is the
            // other branch (θa + 180°, 180° − θc): exactly two orientations.
            for (a, c) in eq30_angles_deg(&n) {
                prop_assert!(
                    pairs
                        .iter()
                        .any(|&(a2, c2)| same_angle(a, a2, 360.0) && same_angle(c, c2, 360.0)),
                    "A {a} C {c} not among {pairs:?}"
                );
            }
            prop_assert_eq!(pairs.len(), 2);
            Ok(())
        })
        .unwrap();
}

/// The home pose of the machine file is the paper's geometry at
/// l = 0, θ = 0: the grinding point, in part coordinates, and the normal
/// that eq. 26 maps onto n_d.
#[test]
fn home_pose_is_the_paper_chain_at_zero() {
    let m = builtin::load("ac-grinder").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let home = kin.fk(&m.home_joints());
    let to_part = eq25(0.0, 0.0, 0.0, 0.0, 0.0).try_inverse().unwrap();
    let n = to_part * Vector4::new(R_S1 * PHI.sin(), 0.0, -R_S1 * PHI.cos(), 1.0);
    assert!(
        (home.point - n.xyz()).norm() < 1e-12,
        "{} vs {}",
        home.point,
        n
    );
    let ns = eq26(&home.axis, 0.0, 0.0);
    assert!((ns - Vector3::new(0.0, -1.0, 0.0)).norm() < 1e-12, "{ns}");
}
