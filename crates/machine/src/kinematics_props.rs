//! The compiled chain against the definition: random machines (any sides,
//! chain orders, tilted part frames, rotary axes locked at a value, a locked
//! linear axis, three free rotary axes with a tool reference), their forward
//! kinematics checked against the product of exponentials written out with
//! nalgebra isometries (`W(q)⁻¹·T(q)`, docs/conventions.md), and the precomputed
//! linear solve against the general one.

use nalgebra::{
    Isometry3, Matrix3, Point3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3,
};
use proptest::prelude::*;
use proptest::test_runner::{RngAlgorithm, TestRng};

use super::*;
use crate::model::{Axis, PostSettings, Tool};

/// Random draws for building machines, from proptest's generator (a
/// failure is saved and replayed).
#[derive(Debug)]
struct Draw(TestRng);

impl Draw {
    /// Uniform in [0, 1).
    fn next(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn chance(&mut self, p: f64) -> bool {
        self.next() < p
    }
    /// Uniform on the unit sphere (Archimedes: z uniform in [−1, 1]).
    fn unit(&mut self) -> Vector3<f64> {
        let z = self.range(-1.0, 1.0);
        let (s, c) = self
            .range(-std::f64::consts::PI, std::f64::consts::PI)
            .sin_cos();
        let r = (1.0 - z * z).sqrt();
        Vector3::new(r * c, r * s, z)
    }
    fn point(&mut self, r: f64) -> Vector3<f64> {
        Vector3::new(self.range(-r, r), self.range(-r, r), self.range(-r, r))
    }
}

fn axis(name: &str, kind: AxisKind, side: Side, direction: Vector3<f64>) -> Axis {
    Axis {
        name: name.into(),
        kind,
        side,
        direction,
        point: Vector3::zeros(),
        limits: None,
        fixed: None,
        free_with_reference: false,
        wrap: crate::model::Wrap::None,
        prefer: None,
        max_velocity: None,
        machine_offset: 0.0,
    }
}

/// A random machine the kinematics must handle: three free linear axes,
/// two or three free rotary axes, sometimes a rotary axis locked at a value
/// and a linear axis locked at a value, in random chain order and sides.
fn random_machine(rng: &mut Draw) -> Machine {
    let sides = |rng: &mut Draw| {
        if rng.chance(0.5) {
            Side::Tool
        } else {
            Side::Workpiece
        }
    };
    let lin = loop {
        let l = [rng.unit(), rng.unit(), rng.unit()];
        if Matrix3::from_columns(&l).determinant().abs() > 0.3 {
            break l;
        }
    };
    let mut axes = Vec::new();
    for (k, d) in lin.iter().enumerate() {
        let mut a = axis(["X", "Y", "Z"][k], AxisKind::Linear, sides(rng), *d);
        if rng.chance(0.3) {
            a.limits = Some([-2000.0, 2000.0]);
        }
        axes.push(a);
    }
    let three = rng.chance(0.25);
    let rot = loop {
        let r = [rng.unit(), rng.unit(), rng.unit()];
        if r[0].cross(&r[1]).norm() > 0.3 && r[1].cross(&r[2]).norm() > 0.3 {
            break r;
        }
    };
    for (k, d) in rot.iter().enumerate().take(if three { 3 } else { 2 }) {
        let mut a = axis(["A", "B", "C"][k], AxisKind::Rotary, sides(rng), *d);
        a.point = rng.point(300.0);
        a.limits = match (rng.next() * 3.0) as u32 {
            0 => None,
            1 => Some([-400.0, 400.0]),
            _ => Some([-100.0, 120.0]),
        };
        axes.push(a);
    }
    if rng.chance(0.4) {
        let mut a = axis("U", AxisKind::Rotary, sides(rng), rng.unit());
        a.point = rng.point(300.0);
        a.fixed = Some(rng.range(-90.0, 90.0));
        axes.push(a);
    }
    if rng.chance(0.3) {
        let mut a = axis("W", AxisKind::Linear, sides(rng), rng.unit());
        a.fixed = Some(rng.range(-50.0, 50.0));
        axes.push(a);
    }
    // Random chain order (Fisher–Yates).
    for i in (1..axes.len()).rev() {
        let j = ((rng.next() * (i + 1) as f64) as usize).min(i);
        axes.swap(i, j);
    }
    let rotation =
        UnitQuaternion::from_axis_angle(&Unit::new_normalize(rng.unit()), rng.range(-3.0, 3.0))
            .to_rotation_matrix()
            .into_inner();
    let tool_axis = rng.unit();
    let reference = (three || rng.chance(0.5)).then(|| {
        let r = rng.unit();
        (r - tool_axis * tool_axis.dot(&r)).normalize()
    });
    Machine {
        name: "random".into(),
        description: String::new(),
        axes,
        workpiece_rotation: rotation,
        workpiece_origin: rng.point(100.0),
        tool: Tool {
            point: rng.point(200.0),
            axis: tool_axis,
            reference,
        },
        post: PostSettings::default(),
        pressure: None,
        solids: Vec::new(),
        collision: Default::default(),
    }
}

/// Joint values inside the limits, locked axes at their value.
fn random_joints(m: &Machine, rng: &mut Draw) -> Vec<f64> {
    m.axes
        .iter()
        .map(|a| match (a.fixed, a.limits, a.is_rotary()) {
            (Some(v), _, _) => v,
            (None, Some([lo, hi]), _) => rng.range(lo, hi),
            (None, None, true) => rng.range(-170.0, 170.0),
            (None, None, false) => rng.range(-500.0, 500.0),
        })
        .collect()
}

/// The motion `G_i(q)` of one axis in the machine frame.
fn motion(a: &Axis, q: f64) -> Isometry3<f64> {
    match a.kind {
        AxisKind::Linear => Isometry3::from_parts(
            Translation3::from(a.direction * q),
            UnitQuaternion::identity(),
        ),
        AxisKind::Rotary => {
            let r =
                UnitQuaternion::from_axis_angle(&Unit::new_normalize(a.direction), q.to_radians());
            // Turn about the line through `point`: p + R (x − p).
            Isometry3::from_parts(Translation3::from(a.point - r * a.point), r)
        }
    }
}

/// The definition: `W(q)⁻¹·T(q)` with `W = Π_workpiece G_i · W0` and
/// `T = Π_tool G_i`, both in machine-file order from the base outwards.
fn reference_fk(m: &Machine, q: &[f64]) -> Pose {
    let mut w = Isometry3::identity();
    let mut t = Isometry3::identity();
    for (a, &v) in m.axes.iter().zip(q) {
        let v = a.fixed.unwrap_or(v);
        match a.side {
            Side::Workpiece => w *= motion(a, v),
            Side::Tool => t *= motion(a, v),
        }
    }
    let w0 = Isometry3::from_parts(
        Translation3::from(m.workpiece_origin),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
            m.workpiece_rotation,
        )),
    );
    let part_to_tool = (w * w0).inverse() * t;
    Pose {
        point: (part_to_tool * Point3::from(m.tool.point)).coords,
        axis: part_to_tool * m.tool.axis,
        reference: m.tool.reference.map(|r| part_to_tool * r),
    }
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() <= tol * (1.0 + a.norm())
}

/// Same point, axis and reference (the reference only where `reference`
/// says: the inverse kinematics controls it with three free rotary axes).
fn same_pose(want: &Pose, got: &Pose, reference: bool) -> bool {
    close(&want.point, &got.point, 1e-9)
        && close(&want.axis, &got.axis, 1e-9)
        && match (want.reference, got.reference) {
            (Some(a), Some(b)) => !reference || close(&a, &b, 1e-9),
            (a, b) => a.is_none() && b.is_none(),
        }
}

fn rngs() -> impl Strategy<Value = Draw> {
    any::<()>().prop_perturb(|(), rng| Draw(rng))
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// The compiled chain (constants carried to the tool, hand-written
    /// products) is the product of exponentials.
    #[test]
    fn fk_is_the_product_of_exponentials(mut rng in rngs()) {
        let m = random_machine(&mut rng);
        let kin = Kinematics::new(&m);
        for _ in 0..4 {
            let q = random_joints(&m, &mut rng);
            let want = reference_fk(&m, &q);
            let got = kin.fk(&q);
            prop_assert!(same_pose(&want, &got, true), "{want:?}\n{got:?}\n{m:?}");
        }
    }

    /// The bodies of the virtual machine move as the kinematics does: the
    /// tool point, axis and reference at home moved by the tool body, seen
    /// from the part frame, are `fk(q)` (and the definition); each axis body
    /// is its side's product of axis motions up to that axis.
    #[test]
    fn body_poses_carry_the_tool_to_fk(mut rng in rngs()) {
        let m = random_machine(&mut rng);
        let kin = Kinematics::new(&m);
        for _ in 0..4 {
            let q = random_joints(&m, &mut rng);
            let bodies = kin.body_poses(&q);
            let part_to_tool = bodies.part_frame().inverse() * bodies.tool;
            let got = Pose {
                point: (part_to_tool * Point3::from(m.tool.point)).coords,
                axis: part_to_tool * m.tool.axis,
                reference: m.tool.reference.map(|r| part_to_tool * r),
            };
            prop_assert!(same_pose(&kin.fk(&q), &got, true), "{:?}\n{got:?}\n{m:?}", kin.fk(&q));
            prop_assert!(same_pose(&reference_fk(&m, &q), &got, true));
            for (i, a) in m.axes.iter().enumerate() {
                let mut want = Isometry3::identity();
                for (b, &v) in m.axes[..=i].iter().zip(&q) {
                    if b.side == a.side {
                        want *= motion(b, b.fixed.unwrap_or(v));
                    }
                }
                let got = bodies.of(crate::Body::Axis(i));
                let x = Point3::from(rng.point(500.0));
                prop_assert!(close(&(want * x).coords, &(got * x).coords, 1e-9));
            }
        }
    }

    /// The chord bound (module `chord`) holds: the tool point at the middle
    /// of a straight joint motion, by the definition, is within
    /// `midpoint_bound` of the middle of the chord; the lever at the end is
    /// within `lever_over` of the lever at the start, either way round.
    #[test]
    fn the_chord_bound_holds(mut rng in rngs()) {
        let m = random_machine(&mut rng);
        let kin = Kinematics::new(&m);
        for _ in 0..4 {
            let a = random_joints(&m, &mut rng);
            // Steps from hundredths of a degree (fine CL) to tens.
            let scale = 10f64.powf(rng.range(-2.0, 1.5));
            let b: Vec<f64> = a
                .iter()
                .zip(&m.axes)
                .map(|(&v, ax)| match (ax.fixed, ax.is_rotary()) {
                    (Some(_), _) => v,
                    (None, true) => v + scale * rng.range(-1.0, 1.0),
                    (None, false) => v + 5.0 * scale * rng.range(-1.0, 1.0),
                })
                .collect();
            let mid: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.5 * (x + y)).collect();
            let (pa, pb, pm) = (reference_fk(&m, &a), reference_fk(&m, &b), reference_fk(&m, &mid));
            let deviation = (pm.point - 0.5 * (pa.point + pb.point)).norm();
            let (_, lever_a) = kin.fk_lever(&a, &mut crate::angle::SinCosMemo::default(), false);
            let (_, lever_b) = kin.fk_lever(&b, &mut crate::angle::SinCosMemo::default(), false);
            let (w, v) = kin.joint_travel(&a, &b);
            let bound = midpoint_bound(lever_a, w, v);
            prop_assert!(deviation <= bound + 1e-9, "{deviation} > {bound} (w {w}, v {v}, lever {lever_a})\n{m:?}");
            // The same configurations, reached the short way round.
            let near: Vec<f64> = a
                .iter()
                .zip(&b)
                .zip(&m.axes)
                .map(|((&x, &y), ax)| if ax.is_rotary() { x + wrap180(y - x) } else { y })
                .collect();
            let (wp, vp) = kin.joint_travel(&a, &near);
            prop_assert!(lever_b <= lever_over(lever_a, wp, vp) + 1e-9);
            prop_assert!(lever_a <= lever_over(lever_b, wp, vp) + 1e-9);
        }
    }

    /// Every branch the inverse kinematics gives reaches the pose by the
    /// definition, `q` is among them, and the precomputed linear solve gives
    /// what the general one gives.
    #[test]
    fn ik_solutions_reach_the_pose_and_the_fast_linear_solve_agrees(mut rng in rngs()) {
        let m = random_machine(&mut rng);
        let kin = Kinematics::new(&m);
        let mut general = kin.clone();
        general.linear_solve = LinearSolve::General;
        let n = m.axes.len();
        let three = m.free_rotary_count() == 3;
        let (mut fast, mut slow) = (Vec::new(), Vec::new());
        for _ in 0..4 {
            let q = random_joints(&m, &mut rng);
            let pose = reference_fk(&m, &q);
            kin.ik_all_branches(&pose, Some(&q), &mut fast)
                .map_err(|e| TestCaseError::fail(format!("{e} at {q:?}\n{m:?}")))?;
            for s in &fast {
                // Double precision reaches the pose relative to the values
                // involved: a branch whose linear axes lie near a direction
                // they lose (random chains have such poses, and no travel
                // limits) solves to values of 1e8 mm, exact to their size.
                let size: f64 = m.axes.iter().enumerate().filter(|(_, a)| !a.is_rotary()).map(|(i, _)| s.joints[i].abs()).sum();
                let mut got = reference_fk(&m, &s.joints[..n]);
                if size > 1e6 {
                    prop_assert!((got.point - pose.point).norm() <= 1e-9 * size, "{s:?}\n{m:?}");
                    got.point = pose.point;
                }
                prop_assert!(same_pose(&pose, &got, three), "{s:?}\n{m:?}");
            }
            // `q` is among them: its angles (the linear values follow from
            // the pose, which every solution reaches; compared directly they
            // would test the conditioning of random chains at random poses).
            let same_angles = |s: &Solution| {
                m.axes.iter().enumerate().all(|(i, a)| !a.is_rotary() || (s.joints[i] - q[i]).abs() < 1e-6)
            };
            prop_assert!(fast.iter().any(same_angles), "{q:?} not among {fast:?}");
            general.ik_all_branches(&pose, Some(&q), &mut slow).unwrap();
            prop_assert_eq!(fast.len(), slow.len());
            for (f, s) in fast.iter().zip(&slow) {
                prop_assert_eq!((f.branch, f.singular), (s.branch, s.singular));
                prop_assert_eq!(f.violation.map(|v| v.axis), s.violation.map(|v| v.axis));
                for (a, b) in f.joints.iter().zip(&s.joints) {
                    prop_assert!((a - b).abs() <= 1e-9 * (1.0 + a.abs()), "{f:?} vs {s:?}");
                }
            }
        }
    }

    /// The travel test of the precomputed linear solve (its three axes
    /// written out) finds what the general one finds, for values inside,
    /// outside and at the edges of the travel.
    #[test]
    fn linear_violation_of_the_precomputed_solve_is_the_general_one(mut rng in rngs()) {
        // A machine with the precomputed solve.
        let (m, kin) = loop {
            let m = random_machine(&mut rng);
            let kin = Kinematics::new(&m);
            if matches!(kin.linear_solve, LinearSolve::Constant { .. }) {
                break (m, kin);
            }
        };
        let mut general = kin.clone();
        general.linear_solve = LinearSolve::General;
        for _ in 0..16 {
            let mut q = [0.0; MAX_AXES];
            for v in &mut q[..m.axes.len()] {
                let edge = if rng.chance(0.5) { 2000.0 } else { -2000.0 };
                *v = match (rng.next() * 3.0) as u32 {
                    0 => rng.range(-2500.0, 2500.0),
                    1 => edge + rng.range(-2e-9, 2e-9),
                    _ => rng.range(-1000.0, 1000.0),
                };
            }
            prop_assert_eq!(kin.linear_violation(&q), general.linear_violation(&q));
        }
    }

    /// `wrap180` skips its turn inside (−180°, 180°): the same bits as by
    /// the turn, there and an ulp or two either side of the edges.
    #[test]
    fn wrap180_shortcut_is_the_turn(deg in -200.0..200.0f64, edge in 0usize..3, ulps in -3i64..=3) {
        let deg = match edge {
            0 => deg,
            1 => f64::from_bits((180.0f64.to_bits() as i64 + ulps) as u64),
            _ => -f64::from_bits((180.0f64.to_bits() as i64 + ulps) as u64),
        };
        for d in [deg, deg * 1e-300, deg / 360.0] {
            prop_assert_eq!(wrap180(d).to_bits(), wrap180_by_turns(d).to_bits(), "{}", d);
        }
    }

    /// The arc test never contradicts the turn count it stands in for.
    #[test]
    fn arc_test_agrees_with_turn_range(
        lo in -400.0..200.0f64,
        width in 0.0..361.0f64,
        deg in -180.0..180.0f64,
        edge in 0usize..3,
        nudge in -3i32..=3,
    ) {
        let hi = lo + width;
        // Angles right at the limits (and an ulp or a slack away) too.
        let deg = match edge {
            0 => deg,
            e => {
                let limit = if e == 1 { lo - 1e-9 } else { hi + 1e-9 };
                wrap180(limit) + f64::from(nudge) * 1e-10
            }
        };
        let (s, c) = deg.to_radians().sin_cos();
        let (first, last) = turn_range(lo, hi, wrap180(deg));
        if let Some(inside) = Arc::new(lo, hi).contains(c, s) {
            prop_assert_eq!(inside, first <= last, "{} in [{}, {}]", deg, lo, hi);
        }
    }
}

#[test]
fn the_random_machines_cover_both_linear_solves() {
    let mut counts = [0usize; 2];
    let mut rng = Draw(TestRng::deterministic_rng(RngAlgorithm::ChaCha));
    for _ in 0..400 {
        let kin = Kinematics::new(&random_machine(&mut rng));
        counts[usize::from(matches!(kin.linear_solve, LinearSolve::General))] += 1;
    }
    assert!(counts[0] > 50 && counts[1] > 50, "{counts:?}");
}
