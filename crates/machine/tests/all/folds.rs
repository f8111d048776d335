//! The folds of machines whose two rotary axes are not at the angle the tool
//! axis makes with the inner one (`Kinematics::folds`), checked against the
//! forward kinematics: every reachable tool axis lies in the band the folds
//! bound, and at a fold the two branches of the inverse kinematics meet.

use kinpost_machine::{Kinematics, Machine, Pose, builtin, machine_from_toml};
use nalgebra::Vector3;

fn machine(file: &str) -> Machine {
    let path = format!("{}/tests/machines/{file}", env!("CARGO_MANIFEST_DIR"));
    machine_from_toml(&std::fs::read_to_string(&path).unwrap(), &path).unwrap()
}

fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

#[test]
fn right_angles_have_poles_only() {
    for name in builtin::names() {
        let m = builtin::load(name).unwrap().unwrap();
        assert_eq!(Kinematics::new(&m).folds(), None, "{name}");
    }
}

#[test]
fn a_nutating_head_folds_where_the_tool_lies_flat() {
    // B at 45° to the C axis, the tool along C at home: the tool axis makes
    // 0 to 90° with C (up to flat); 0° is the pole, 90° a fold.
    let m = machine("nutating-45.toml");
    let kin = Kinematics::new(&m);
    let folds = kin.folds().expect("a fold");
    let edges: Vec<f64> = folds
        .edges
        .iter()
        .filter(|e| !e.is_nan())
        .map(|e| e.to_degrees())
        .collect();
    assert_eq!(edges.len(), 1);
    assert!((edges[0] - 90.0).abs() < 1e-9, "{edges:?}");
    let (ib, ic) = (m.axis_index("B").unwrap(), m.axis_index("C").unwrap());
    let mut q = vec![0.0; m.axes.len()];
    // Every reachable axis points up or flat, never below (the band), and
    // its distance to the fold is its elevation.
    for k in 0..=72 {
        q[ib] = -180.0 + 5.0 * f64::from(k);
        q[ic] = 7.0 * f64::from(k);
        let axis = kin.fk(&q).axis;
        assert!(axis.z >= -1e-12, "B {}: {axis:?}", q[ib]);
        let elevation = axis.z.asin().to_degrees();
        assert!(
            (folds.distance(&axis).to_degrees() - elevation).abs() < 1e-9,
            "B {}: {} vs {elevation}",
            q[ib],
            folds.distance(&axis).to_degrees()
        );
    }
    // B half a turn lays the tool flat, on the fold. Towards it the two
    // branches of the inverse kinematics close in on each other, as the
    // square root of the distance to the fold: a tenth of the distance, a
    // third of the separation.
    let mut last = (f64::INFINITY, f64::INFINITY);
    for b in [170.0, 179.0, 179.9, 179.99] {
        q[ib] = b;
        q[ic] = 30.0;
        let pose: Pose = kin.fk(&q);
        let distance = folds.distance(&pose.axis).to_degrees();
        let mut out = Vec::new();
        kin.ik(&pose, None, &mut out).unwrap();
        let valid: Vec<_> = out.iter().filter(|s| s.is_valid()).collect();
        let mut apart = f64::INFINITY;
        for s in &valid {
            let back = kin.fk(&s.joints[..m.axes.len()]);
            assert!(angle(&back.axis, &pose.axis) < 1e-9);
            for t in valid.iter().filter(|t| t.branch != s.branch) {
                // (Angles, not travel: B near ±180° is one angle.)
                let turn = |a: f64, b: f64| ((a - b).rem_euclid(360.0) - 180.0).abs();
                let d = (180.0 - turn(s.joints[ib], t.joints[ib]))
                    .max(180.0 - turn(s.joints[ic], t.joints[ic]));
                apart = apart.min(d);
            }
        }
        assert!(apart.is_finite(), "B {b}: both branches");
        assert!(
            distance < last.0 && apart < last.1,
            "B {b}: {distance}, {apart}"
        );
        if last.0.is_finite() {
            let ratio = (apart / last.1) / (distance / last.0).sqrt();
            assert!((0.8..1.25).contains(&ratio), "B {b}: {ratio}");
        }
        last = (distance, apart);
    }
    assert!(last.1 < 1.0, "{last:?}");
}

#[test]
fn a_tool_pointing_the_other_way_folds_alike() {
    // The nutating head with the tool along −C at home: the band is the
    // mirror image (down to flat), the fold is still where the tool lies
    // flat. Here γ + β passes half a turn: the edge is 360° − γ − β.
    for tool in [Vector3::z(), -Vector3::z()] {
        let mut m = machine("nutating-45.toml");
        m.tool.axis = tool;
        let folds = Kinematics::new(&m).folds().expect("a fold");
        for flat in [Vector3::x(), Vector3::y(), Vector3::new(-0.6, 0.8, 0.0)] {
            assert!(
                folds.distance(&flat) < 1e-12,
                "{tool:?} {flat:?}: {folds:?}"
            );
        }
        assert!((folds.distance(&tool).to_degrees() - 90.0).abs() < 1e-9);
    }
}

#[test]
fn an_arc_reaches_the_fold_where_its_points_do() {
    // Arcs between random tool axes against the angle from the fold
    // direction sampled along them: where the samples pass an edge by more
    // than the sampling can miss, the arc reaches it; where they stay that
    // far from every edge, it does not.
    // The tool tilted on the nutating head: edges away from 90°, where a
    // short arc may reach one between two points on the same side.
    let mut m = machine("nutating-45.toml");
    m.tool.axis = Vector3::new(0.3, 0.5, 0.8).normalize();
    let folds = Kinematics::new(&m).folds().unwrap();
    assert!(
        folds
            .edges
            .iter()
            .all(|e| (e.to_degrees() - 90.0).abs() > 5.0),
        "{folds:?}"
    );
    let (mut reached, mut missed) = (0, 0);
    for (a, b) in random_arcs() {
        let (lo, hi, miss) = sampled_angles(&folds.direction, &a, &b);
        let edges = folds.edges.iter().filter(|e| !e.is_nan());
        let inside = edges.clone().any(|&e| e > lo + miss && e < hi - miss);
        let outside = edges
            .clone()
            .all(|&e| e < lo - 2.0 * miss || e > hi + 2.0 * miss);
        let got = folds.reached(&a, &b, 0.0);
        if inside {
            assert!(got, "{a:?} → {b:?}: [{lo}, {hi}]");
            reached += 1;
        }
        if outside {
            assert!(!got, "{a:?} → {b:?}: [{lo}, {hi}]");
            missed += 1;
        }
        // Either way round.
        assert_eq!(folds.reached(&b, &a, 0.0), got);
    }
    assert!(reached > 60 && missed > 60, "{reached} {missed}");
}

#[test]
fn an_arc_comes_as_near_the_pole_as_its_points_do() {
    // The least distance to the singular direction (or its opposite) along
    // arcs between random tool axes, against samples along them.
    let m = builtin::load("head-head-bc").unwrap().unwrap();
    let s = Kinematics::new(&m).singularity().unwrap();
    let (mut inner, mut at_ends) = (0, 0);
    for (a, b) in random_arcs() {
        let (lo, hi, miss) = sampled_angles(&s.direction, &a, &b);
        let want = lo.min(std::f64::consts::PI - hi);
        let got = s.arc_distance(&a, &b);
        assert!(
            got <= want + 1e-12 && got >= want - miss,
            "{a:?} → {b:?}: {got} vs sampled {want}"
        );
        assert!((s.arc_distance(&b, &a) - got).abs() < 1e-12);
        let ends = s.distance(&a).min(s.distance(&b));
        if got < ends - 1e-3 {
            inner += 1;
        } else {
            at_ends += 1;
        }
    }
    assert!(inner > 30 && at_ends > 60, "{inner} {at_ends}");
}

#[test]
fn an_arc_leaves_the_band_as_far_as_its_points_do() {
    // How far arcs between random tool axes go outside the band of
    // reachable directions, against samples along them and the forward
    // kinematics: the tool tilted on the nutating head so that the band has
    // a fold at each edge (a cone it cannot point around the pole, and one
    // around its opposite).
    let mut m = machine("nutating-45.toml");
    m.tool.axis = Vector3::new(0.3, 0.5, 0.8).normalize();
    let kin = Kinematics::new(&m);
    let folds = kin.folds().unwrap();
    let [lower, upper] = folds.edges;
    assert!(lower > 0.1 && upper < 3.1, "{folds:?}");
    // Every tool axis the machine points lies in the band.
    let (ib, ic) = (m.axis_index("B").unwrap(), m.axis_index("C").unwrap());
    let mut q = vec![0.0; m.axes.len()];
    for k in 0..=360 {
        q[ib] = f64::from(k);
        q[ic] = 13.0 * f64::from(k);
        let t = angle(&folds.direction, &kin.fk(&q).axis);
        assert!(t >= lower - 1e-12 && t <= upper + 1e-12, "B {k}: {t}");
    }
    let (mut below, mut above, mut inside) = (0, 0, 0);
    // Random arcs, and the same drawn towards either cone (the one beyond
    // the upper fold is narrow).
    let d = folds.direction;
    let toward = |c: Vector3<f64>, w: f64| {
        random_arcs()
            .into_iter()
            .map(move |(a, b)| ((a + c * w).normalize(), (b + c * w).normalize()))
    };
    let arcs = random_arcs()
        .into_iter()
        .chain(toward(d, 1.0))
        .chain(toward(-d, 6.0));
    for (a, b) in arcs {
        let (lo, hi, miss) = sampled_angles(&d, &a, &b);
        let got = folds.arc_outside(&a, &b);
        let back = folds.arc_outside(&b, &a);
        assert_eq!(got.is_some(), back.is_some(), "either way round");
        if let (Some(x), Some(y)) = (got, back) {
            assert!((x.depth - y.depth).abs() < 1e-12 && x.cone_axis == y.cone_axis);
        }
        let want = (lower - lo).max(hi - upper);
        match got {
            None => {
                assert!(want <= miss, "{a:?} → {b:?}: sampled {want} outside");
                inside += 1;
            }
            Some(e) => {
                assert!(
                    e.depth >= want - 1e-12 && e.depth <= want + miss,
                    "{a:?} → {b:?}: {} vs sampled {want}",
                    e.depth
                );
                let (axis, half) = if lower - lo >= hi - upper {
                    below += 1;
                    (d, lower)
                } else {
                    above += 1;
                    (-d, std::f64::consts::PI - upper)
                };
                assert_eq!((e.cone_axis, e.half_angle), (axis, half));
            }
        }
    }
    assert!(
        below > 30 && above > 30 && inside > 30,
        "{below} {above} {inside}"
    );
}

/// Pairs of random unit tool axes: short arcs as well as long ones
/// (below 3.1 rad: the shorter arc is well defined).
fn random_arcs() -> Vec<(Vector3<f64>, Vector3<f64>)> {
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let mut arcs = Vec::new();
    for _ in 0..600 {
        let a = Vector3::new(next(), next(), next()).normalize();
        let b = (a + Vector3::new(next(), next(), next()) * next().abs().powi(3) * 2.0).normalize();
        if (1e-9..=3.1).contains(&angle(&a, &b)) {
            arcs.push((a, b));
        }
    }
    arcs
}

/// The least and largest angle from `d` over 2,001 points of the arc from
/// `a` to `b`, and how far the arc itself can stray beyond them between
/// samples.
fn sampled_angles(d: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> (f64, f64, f64) {
    let theta = angle(a, b);
    let u = (b - a * a.dot(b)).normalize();
    const SAMPLES: usize = 2000;
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for k in 0..=SAMPLES {
        let phi = theta * k as f64 / SAMPLES as f64;
        let t = angle(d, &(a * phi.cos() + u * phi.sin()));
        lo = lo.min(t);
        hi = hi.max(t);
    }
    // Between samples the angle strays from them by at most (Δφ)²/8 times
    // its curvature, 1/sin of the angle from ±d (which is at least the
    // nearest sample's less a step: the angle changes no faster than φ).
    let step = theta / SAMPLES as f64;
    let near = lo.min(std::f64::consts::PI - hi) - step;
    (lo, hi, step * step / (8.0 * near.max(step).sin()) + 1e-12)
}
