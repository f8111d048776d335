//! The motion bound of conservative advancement holds on random machines,
//! the swept check finds whatever dense sampling finds (and reports only
//! poses truly in contact), and parallel checks give the sequential
//! result for any number of threads.

use crate::common;

use kinpost_collide::bound::MotionBound;
use kinpost_collide::{ContactKind, Motion, World};
use kinpost_machine::{
    Axis, AxisKind, Body, Kinematics, Machine, PostSettings, Side, Tool, Wrap, builtin,
};
use nalgebra::{Matrix3, Point3, Vector3};
use proptest::prelude::*;
use proptest::test_runner::TestRng;

/// Random draws from proptest's generator (a failure is saved and
/// replayed).
#[derive(Debug)]
struct Draw(TestRng);

impl Draw {
    fn next(&mut self) -> f64 {
        (self.0.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next()
    }
    fn chance(&mut self, p: f64) -> bool {
        self.next() < p
    }
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

fn rngs() -> impl Strategy<Value = Draw> {
    any::<()>().prop_perturb(|(), rng| Draw(rng))
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
        wrap: Wrap::None,
        prefer: None,
        max_velocity: None,
        machine_offset: 0.0,
    }
}

/// Three linear and two or three rotary axes, random sides, directions,
/// lines and order; sometimes a rotary axis locked at a value.
fn random_machine(rng: &mut Draw) -> Machine {
    let side = |rng: &mut Draw| {
        if rng.chance(0.5) {
            Side::Tool
        } else {
            Side::Workpiece
        }
    };
    let mut axes = Vec::new();
    let lin = loop {
        let l = [rng.unit(), rng.unit(), rng.unit()];
        if Matrix3::from_columns(&l).determinant().abs() > 0.3 {
            break l;
        }
    };
    for (k, d) in lin.iter().enumerate() {
        axes.push(axis(["X", "Y", "Z"][k], AxisKind::Linear, side(rng), *d));
    }
    let rotary = if rng.chance(0.3) { 3 } else { 2 };
    for k in 0..rotary {
        let mut a = axis(["A", "B", "C"][k], AxisKind::Rotary, side(rng), rng.unit());
        a.point = rng.point(300.0);
        if k == 2 {
            a.fixed = Some(rng.range(-90.0, 90.0));
        }
        axes.push(a);
    }
    for i in (1..axes.len()).rev() {
        let j = ((rng.next() * (i + 1) as f64) as usize).min(i);
        axes.swap(i, j);
    }
    Machine {
        name: "random".into(),
        description: String::new(),
        axes,
        workpiece_rotation: Matrix3::identity(),
        workpiece_origin: Vector3::zeros(),
        tool: Tool {
            point: rng.point(100.0),
            axis: Vector3::z(),
            reference: None,
        },
        post: PostSettings::default(),
        pressure: None,
        solids: Vec::new(),
        collision: Default::default(),
    }
}

fn random_joints(m: &Machine, rng: &mut Draw) -> Vec<f64> {
    m.axes
        .iter()
        .map(|a| match (a.fixed, a.is_rotary()) {
            (Some(v), _) => v,
            (None, true) => rng.range(-200.0, 200.0),
            (None, false) => rng.range(-500.0, 500.0),
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    /// No point of a solid's bounding ball travels farther, on a
    /// joint-linear move, than the bound says, over the whole move and
    /// over any stretch of it.
    #[test]
    fn no_point_moves_farther_than_the_bound(mut rng in rngs()) {
        let m = random_machine(&mut rng);
        let kin = Kinematics::new(&m);
        let bodies: Vec<Body> = [Body::Base, Body::Tool, Body::Workpiece]
            .into_iter()
            .chain((0..m.axes.len()).map(Body::Axis))
            .collect();
        for body in bodies {
            let centre = rng.point(400.0);
            let radius = rng.range(0.0, 150.0);
            let bound = MotionBound::new(&m, body, centre, radius);
            let from = random_joints(&m, &mut rng);
            // Small moves (a sampling step) and large ones.
            let scale = 10f64.powf(rng.range(-2.0, 0.0));
            let to: Vec<f64> = from
                .iter()
                .zip(&m.axes)
                .map(|(&v, a)| if a.fixed.is_some() { v } else { v + scale * rng.range(-300.0, 300.0) })
                .collect();
            let at = |t: f64| -> Vec<f64> { from.iter().zip(&to).map(|(a, b)| a + t * (b - a)).collect() };
            let points: Vec<Point3<f64>> = (0..8)
                .map(|_| Point3::from(centre + rng.unit() * radius * rng.next().cbrt()))
                .collect();
            let samples: Vec<Vec<Point3<f64>>> = (0..=64)
                .map(|k| {
                    let poses = kin.body_poses(&at(f64::from(k) / 64.0));
                    points.iter().map(|p| poses.of(body) * p).collect()
                })
                .collect();
            for (i, j) in [(0usize, 64usize), (0, 32), (16, 17), (40, 63), (5, 6)] {
                let d = bound.path_bound_mm(&at(i as f64 / 64.0), &at(j as f64 / 64.0));
                for k in i..=j {
                    for (p, q) in samples[i].iter().zip(&samples[k]) {
                        let moved = (q - p).norm();
                        prop_assert!(moved <= d * (1.0 + 1e-9) + 1e-9, "{body:?}: {moved} > {d} ({i}..{j} at {k})");
                    }
                }
            }
        }
    }
}

fn mts1600_world() -> (Machine, World) {
    let m = builtin::load("mts1600").unwrap().unwrap();
    let mut world = World::new(&m).unwrap();
    world
        .add_part("blank", common::flat_part_blank(2000, 0.3))
        .unwrap();
    (m, world)
}

/// A random move of mts1600 around its fixture and part.
fn random_move(m: &Machine, rng: &mut Draw) -> (Vec<f64>, Vec<f64>) {
    let pose = |rng: &mut Draw| {
        let mut q = m.home_joints();
        for (name, lo, hi) in [
            ("X", -100.0, 800.0),
            ("Y", -100.0, 93.0),
            ("Z", 300.0, 520.0),
            ("A", -180.0, 180.0),
            ("B", -45.0, 45.0),
        ] {
            q[m.axis_index(name).unwrap()] = rng.range(lo, hi);
        }
        q
    };
    let from = pose(rng);
    let mut to = pose(rng);
    // Short moves too, as sampled programs make.
    if rng.chance(0.5) {
        for (a, b) in to.iter_mut().zip(&from) {
            *a = b + 0.05 * (*a - b);
        }
    }
    (from, to)
}

/// Severity of a kind: collisions and rapids into stock above near misses.
fn severe(kind: ContactKind) -> u8 {
    u8::from(kind.is_error())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// What 4001 samples of a move find, the swept check finds, at least
    /// as severe; and every pose it reports is in contact.
    #[test]
    fn the_sweep_misses_nothing_dense_sampling_finds(mut rng in rngs()) {
        let (m, world) = mts1600_world();
        let motion = if rng.chance(0.5) { Motion::Rapid } else { Motion::Feed };
        let (from, to) = random_move(&m, &mut rng);
        let swept = world.check_move(&from, &to, motion);
        for c in &swept {
            let again = world.check_pose(&c.joints, motion);
            prop_assert!(again.iter().any(|d| d.indices == c.contact.indices && d.kind == c.contact.kind), "{c:?}");
        }
        let n = 4000;
        for k in 0..=n {
            let t = f64::from(k) / f64::from(n);
            let q: Vec<f64> = from.iter().zip(&to).map(|(a, b)| a + t * (b - a)).collect();
            for c in world.check_pose(&q, motion) {
                let s = swept.iter().find(|s| s.contact.indices == c.indices);
                prop_assert!(s.is_some(), "{c:?} at t = {t} not found by the sweep");
                let s = s.unwrap();
                prop_assert!(severe(s.contact.kind) >= severe(c.kind), "{c:?} at {t}, swept {s:?}");
                // No later than this sample's own step: at the very start of a
                // move parry's GJK distance of a pair may differ from the
                // sweep's first query by more than the pose difference
                // (found by this test), so ordering is held to the
                // sampling's resolution, not to the exact sample.
                if severe(s.contact.kind) == severe(c.kind) {
                    prop_assert!(s.fraction <= t + 1.0 / f64::from(n), "{c:?} at {t}, swept later {s:?}");
                }
            }
        }
    }
}

/// The random moves above are no empty test: many meet the machine or
/// the blank.
#[test]
fn random_moves_meet_the_machine() {
    let (m, world) = mts1600_world();
    let mut rng = Draw(TestRng::deterministic_rng(
        proptest::test_runner::RngAlgorithm::ChaCha,
    ));
    let mut meeting = 0;
    for _ in 0..48 {
        let (from, to) = random_move(&m, &mut rng);
        if !world.check_move(&from, &to, Motion::Rapid).is_empty() {
            meeting += 1;
        }
    }
    assert!((12..=44).contains(&meeting), "{meeting} of 48");
}

#[test]
fn parallel_checks_give_the_sequential_result_for_any_thread_count() {
    let (m, world) = mts1600_world();
    let mut rng = Draw(TestRng::deterministic_rng(
        proptest::test_runner::RngAlgorithm::ChaCha,
    ));
    let poses: Vec<Vec<f64>> = (0..3000).map(|_| random_move(&m, &mut rng).0).collect();
    let sequential: Vec<_> = poses
        .iter()
        .map(|q| world.check_pose(q, Motion::Rapid))
        .collect();
    assert!(sequential.iter().filter(|c| !c.is_empty()).count() > 100);
    for threads in [1, 2, 3, 7] {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let parallel = pool.install(|| world.check_poses(&poses, Motion::Rapid));
        assert!(parallel == sequential, "{threads} threads");
    }
}
