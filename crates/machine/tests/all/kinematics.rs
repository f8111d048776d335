//! Properties of the kinematics over every built-in machine and the test
//! machines in `tests/machines/`: `fk(ik(pose)) == pose` for every branch and
//! `ik(fk(q))` contains `q`; plus the numbers of Qiao et al. 2022 and the paper's
//! orientation law as independent checks.

use kinpost_machine::{Kinematics, Machine, Pose, builtin, machine_from_toml};
use nalgebra::Vector3;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};

fn test_machines() -> Vec<Machine> {
    let mut out: Vec<Machine> = builtin::names()
        .map(|n| builtin::load(n).unwrap().unwrap())
        .collect();
    // Built-ins whose locked axes free up with reference directions, in
    // their 6-axis form too.
    let six: Vec<Machine> = out
        .iter()
        .filter(|m| m.unlocks_with_reference())
        .map(|m| m.with_reference_axes_free())
        .collect();
    assert!(!six.is_empty());
    out.extend(six);
    // Built-ins with a pressure axis, with the wheel held at both ends of
    // its calibration (the tool point moved by the wheel offset).
    let pressed: Vec<Machine> = out
        .iter()
        .filter_map(|m| m.pressure.as_ref().map(|p| (m, p.range())))
        .flat_map(|(m, [lo, hi])| [m.at_pressure(lo), m.at_pressure(hi)])
        .collect();
    assert!(!pressed.is_empty());
    out.extend(pressed);
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/machines");
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for f in files {
        let src = std::fs::read_to_string(&f).unwrap();
        out.push(machine_from_toml(&src, &f.display().to_string()).unwrap());
    }
    assert!(out.len() >= 5);
    out
}

/// Random joint values inside the limits (±170° / ±500 mm where none).
fn joints(m: &Machine) -> impl Strategy<Value = Vec<f64>> {
    let ranges: Vec<_> = m
        .axes
        .iter()
        .map(|a| match (a.fixed, a.limits, a.is_rotary()) {
            (Some(v), _, _) => v..=v,
            (None, Some([lo, hi]), _) => lo..=hi,
            (None, None, true) => -170.0..=170.0,
            (None, None, false) => -500.0..=500.0,
        })
        .collect();
    ranges
}

fn angle_between(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

fn assert_same_pose(m: &Machine, want: &Pose, got: &Pose) -> Result<(), TestCaseError> {
    prop_assert!(
        (want.point - got.point).norm() < 1e-9,
        "{}: point {} vs {}",
        m.name,
        want.point,
        got.point
    );
    prop_assert!(
        angle_between(&want.axis, &got.axis) < 1e-9,
        "{}: axis",
        m.name
    );
    // The reference is controlled only with three free rotary axes.
    if m.free_rotary_count() == 3
        && let (Some(a), Some(b)) = (want.reference, got.reference)
    {
        prop_assert!(angle_between(&a, &b) < 1e-9, "{}: reference", m.name);
    }
    Ok(())
}

#[test]
fn fk_of_ik_is_the_pose_for_every_branch_and_ik_of_fk_contains_q() {
    for m in test_machines() {
        let kin = Kinematics::new(&m);
        let mut runner = TestRunner::new(Config::with_cases(2000));
        let two_branches = std::cell::Cell::new(0usize);
        runner
            .run(&joints(&m), |q| {
                let mut sols = Vec::new();
                let pose = kin.fk(&q);
                kin.ik_all_branches(&pose, Some(&q), &mut sols)
                    .map_err(|e| TestCaseError::fail(format!("{}: {e} at {q:?}", m.name)))?;
                let mut contains = false;
                for s in &sols {
                    let j = &s.joints[..m.axes.len()];
                    assert_same_pose(&m, &pose, &kin.fk(j))?;
                    if s.is_valid() {
                        for (i, a) in m.axes.iter().enumerate() {
                            prop_assert!(a.accepts(j[i]), "{}: {} outside limits", m.name, a.name);
                        }
                    }
                    if j.iter().zip(&q).all(|(a, b)| (a - b).abs() < 1e-7) {
                        contains = true;
                    }
                }
                prop_assert!(contains, "{}: q {q:?} not among {:?}", m.name, sols);
                // The fast form leaves out only branches outside the rotary
                // travel: q (inside every limit) is still there, and every
                // solution it gives is one of the full list.
                let mut fast = Vec::new();
                kin.ik(&pose, Some(&q), &mut fast).unwrap();
                prop_assert!(fast.iter().all(|f| sols.contains(f)));
                let has_q = fast.iter().any(|s| {
                    s.joints[..q.len()]
                        .iter()
                        .zip(&q)
                        .all(|(a, b)| (a - b).abs() < 1e-7)
                });
                prop_assert!(has_q, "{}: fast ik lost q", m.name);
                if sols.iter().any(|s| s.branch == 1) {
                    two_branches.set(two_branches.get() + 1);
                }
                Ok(())
            })
            .unwrap();
        // Both closed-form branches are exercised, not only the one that
        // contains q.
        assert!(
            two_branches.get() > 100,
            "{}: second branch seen {} times",
            m.name,
            two_branches.get()
        );
    }
}

#[test]
fn singular_pose_keeps_the_hinted_angle_and_is_exact() {
    // Tool axis along the trunnion's C axis: A = 0, C is free.
    let src = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/machines/trunnion-ac-offset.toml"
    ))
    .unwrap();
    let m = machine_from_toml(&src, "t").unwrap();
    let kin = Kinematics::new(&m);
    let q = [10.0, -20.0, 30.0, 0.0, 37.5];
    let pose = kin.fk(&q);
    let mut sols = Vec::new();
    kin.ik(&pose, Some(&q), &mut sols).unwrap();
    assert!(sols.iter().all(|s| s.singular));
    let s = sols
        .iter()
        .find(|s| (s.joints[4] - 37.5).abs() < 1e-9)
        .expect("hint kept");
    assert!((kin.fk(&s.joints[..5]).point - pose.point).norm() < 1e-9);
}

#[test]
fn an_axis_without_limits_takes_the_turns_within_210_degrees_of_the_hint() {
    // The built-in A/C trunnion: C turns without end. At A 20°, C 100° the
    // other branch is A −20°, C 280° (half a turn away).
    let m = builtin::load("trunnion-ac").unwrap().unwrap();
    let (ia, ic) = (m.axis_index("A").unwrap(), m.axis_index("C").unwrap());
    let kin = Kinematics::new(&m);
    let mut q = vec![0.0; m.axes.len()];
    q[ia] = 20.0;
    q[ic] = 100.0;
    let pose = kin.fk(&q);
    let turns = |hint_c: f64| {
        let mut hint = q.clone();
        hint[ic] = hint_c;
        let mut sols = Vec::new();
        kin.ik(&pose, Some(&hint), &mut sols).unwrap();
        let mut got: Vec<(i64, i64)> = sols
            .iter()
            .map(|s| (s.joints[ia].round() as i64, s.joints[ic].round() as i64))
            .collect();
        got.sort();
        got
    };
    // On the hint: that turn of its branch; the other branch, half a turn
    // away, in both turns.
    assert_eq!(turns(100.0), [(-20, -80), (-20, 280), (20, 100)]);
    // 200° from the hint: both turns within 210°.
    assert_eq!(turns(300.0), [(-20, 280), (20, 100), (20, 460)]);
    // Beyond 210° a turn is left out: 100 is 215° from −115.
    assert_eq!(turns(-115.0), [(-20, -80), (20, -260)]);
}

/// Qiao et al. 2022, Figure 28: the CL points and the NC values the authors' post
/// printed, to the printed decimals.
#[test]
fn qiao_figure28_points() {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    let cases = [
        ([-416.0, 70.3931, 11.3684], [459.000, 8.807, 361.368]),
        ([-416.0, 70.0741, 9.7648], [459.000, 9.126, 359.765]),
        ([-416.0, 58.0000, 0.5000], [459.000, 21.200, 350.500]),
    ];
    let mut sols = Vec::new();
    for (p, nc) in cases {
        let pose = Pose {
            point: Vector3::from(p),
            axis: Vector3::z(),
            reference: None,
        };
        kin.ik(&pose, None, &mut sols).unwrap();
        let s = sols
            .iter()
            .filter(|s| s.is_valid())
            .min_by(|a, b| {
                let r = |s: &kinpost_machine::Solution| s.joints[1].abs() + s.joints[4].abs();
                r(a).total_cmp(&r(b))
            })
            .unwrap();
        let got = [s.joints[0], s.joints[2], s.joints[3]];
        for k in 0..3 {
            assert!(
                (got[k] - nc[k]).abs() <= 0.0005 + 1e-12,
                "{got:?} vs {nc:?}"
            );
        }
        assert!(s.joints[1].abs() < 1e-9 && s.joints[4].abs() < 1e-9);
    }
}

/// Qiao et al. 2022 eq. 3.18: the tool axis in the part frame is
/// (sin B, −sin A·cos B, cos A·cos B), written here independently of the chain.
#[test]
fn mts1600_orientation_law_of_eq_3_18() {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let kin = Kinematics::new(&m);
    for a in [-170.0f64, -33.0, 0.0, 12.5, 90.0, 300.0] {
        for b in [-45.0f64, -10.0, 0.0, 7.5, 45.0] {
            let q = [100.0, a, 5.0, 7.0, b, 0.0];
            let got = kin.fk(&q).axis;
            let (ar, br) = (a.to_radians(), b.to_radians());
            let want = Vector3::new(br.sin(), -ar.sin() * br.cos(), ar.cos() * br.cos());
            assert!((got - want).norm() < 1e-12, "A{a} B{b}: {got} vs {want}");
        }
    }
}

/// Within 10⁻¹²…10⁻³ rad of the singular direction (either sense), every
/// branch the inverse kinematics gives points the tool axis where it was
/// asked to 10⁻¹² rad, as far from the pole. Subproblem 2 once took its
/// height from `1 − a² − b²`, a difference of numbers near 1: 10⁻⁶ ° from
/// htm40100h's pole the axis came back 2.4·10⁻⁹ rad off.
#[test]
fn near_the_pole_every_branch_is_as_accurate_as_anywhere() {
    for m in test_machines() {
        let kin = Kinematics::new(&m);
        let Some(s) = kin.singularity() else {
            continue;
        };
        let point = kin.fk(&m.home_joints()).point;
        let other = if s.direction.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let n1 = s.direction.cross(&other).normalize();
        let n2 = s.direction.cross(&n1);
        let solved = std::cell::Cell::new(0usize);
        let mut runner = TestRunner::new(Config::with_cases(400));
        runner
            .run(
                &(-12.0..-3.0f64, 0.0..std::f64::consts::TAU, any::<bool>()),
                |(log_delta, phi, flip)| {
                    let d = if flip { -s.direction } else { s.direction };
                    let (sd, cd) = 10f64.powf(log_delta).sin_cos();
                    let axis = (d * cd + (n1 * phi.cos() + n2 * phi.sin()) * sd).normalize();
                    let pose = Pose {
                        point,
                        axis,
                        reference: None,
                    };
                    let mut sols = Vec::new();
                    // Beyond a fold, a sense of the pole may be out of reach.
                    if kin.ik_all_branches(&pose, None, &mut sols).is_err() {
                        return Ok(());
                    }
                    for sol in &sols {
                        let got = kin.fk(&sol.joints[..m.axes.len()]);
                        let err = angle_between(&axis, &got.axis);
                        prop_assert!(
                            err < 1e-12,
                            "{}: {err:e} rad at 10^{log_delta} rad from the pole",
                            m.name
                        );
                        prop_assert!((point - got.point).norm() < 1e-9, "{}: point", m.name);
                    }
                    solved.set(solved.get() + 1);
                    Ok(())
                },
            )
            .unwrap();
        assert!(
            solved.get() > 100,
            "{}: {} poses solved",
            m.name,
            solved.get()
        );
    }
}
