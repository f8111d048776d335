//! Analytic tests of arcs and NURBS curves: closed forms, an independent
//! rotation (Rodrigues' formula), exact rational circles, Bernstein
//! polynomials, and the chord tolerance measured on dense points.

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI, TAU};

use proptest::prelude::*;

use super::*;

fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
    norm(sub(a, b)) <= tol
}

/// `v` turned by `angle` about the unit `axis` (Rodrigues' formula),
/// written out here independently of the code under test.
fn rotate(v: Vec3, axis: Vec3, angle: f64) -> Vec3 {
    let (s, c) = angle.sin_cos();
    let k = axis;
    let kxv = [
        k[1] * v[2] - k[2] * v[1],
        k[2] * v[0] - k[0] * v[2],
        k[0] * v[1] - k[1] * v[0],
    ];
    let kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    [
        v[0] * c + kxv[0] * s + k[0] * kv * (1.0 - c),
        v[1] * c + kxv[1] * s + k[1] * kv * (1.0 - c),
        v[2] * c + kxv[2] * s + k[2] * kv * (1.0 - c),
    ]
}

#[test]
fn quarter_circle_counter_clockwise_about_z() {
    let a = Arc::new([1., 0., 0.], [0., 1., 0.], [0.; 3], [0., 0., 1.], 1).unwrap();
    assert!((a.sweep_rad() - FRAC_PI_2).abs() < 1e-15);
    assert!((a.length_mm() - FRAC_PI_2).abs() < 1e-15);
    assert_eq!(a.radius_mm(), 1.0);
    assert!(close(
        a.point_at(0.5),
        [FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.],
        1e-15
    ));
    assert!(close(a.tangent_at(0.0), [0., 1., 0.], 1e-15));
    assert!(close(a.tangent_at(1.0), [-1., 0., 0.], 1e-15));
    assert!(!a.is_helix());
    // The ends are the points given, exactly.
    assert_eq!(a.point_at(0.0), [1., 0., 0.]);
    assert_eq!(a.point_at(1.0), [0., 1., 0.]);
    assert_eq!(a.point_at(-3.0), [1., 0., 0.]);
    assert_eq!(a.point_at(7.0), [0., 1., 0.]);
}

#[test]
fn the_same_ends_clockwise_is_three_quarters() {
    // About -Z the way from (1,0) to (0,1) is the long one.
    let a = Arc::new([1., 0., 0.], [0., 1., 0.], [0.; 3], [0., 0., -1.], 1).unwrap();
    assert!((a.sweep_rad() - 3.0 * FRAC_PI_2).abs() < 1e-15);
    let half = 0.75 * PI; // half of 270°, clockwise from 0°
    assert!(close(a.point_at(0.5), [half.cos(), -half.sin(), 0.], 1e-15));
    assert!(close(a.tangent_at(0.0), [0., -1., 0.], 1e-15));
}

#[test]
fn start_equal_to_end_is_a_full_circle_and_turns_add_whole_turns() {
    let c = [5., -2., 1.];
    let s = [8., -2., 1.];
    let a = Arc::new(s, s, c, [0., 0., 2.], 1).unwrap();
    assert_eq!(a.sweep_rad(), TAU);
    assert!(close(a.point_at(0.25), [5., 1., 1.], 1e-14));
    assert!(close(a.point_at(0.5), [2., -2., 1.], 1e-14));
    let two = Arc::new(s, s, c, [0., 0., 1.], 2).unwrap();
    assert_eq!(two.sweep_rad(), 2.0 * TAU);
    assert!(close(two.point_at(0.125), [5., 1., 1.], 1e-14));
    // A rounding away from the start (1 µm and less) is still a full
    // circle; 2 µm is a tiny arc.
    let near = Arc::new(s, [8., -2. + 0.9e-3, 1.], c, [0., 0., 1.], 1).unwrap();
    assert!(near.sweep_rad() > TAU - 1e-3);
    let tiny = Arc::new(s, [8., -2. + 2e-3, 1.], c, [0., 0., 1.], 1).unwrap();
    assert!(tiny.sweep_rad() < 1e-3);
    // TIMES 2 on a partial arc: the end is reached the second time.
    let a = Arc::new([1., 0., 0.], [0., 1., 0.], [0.; 3], [0., 0., 1.], 2).unwrap();
    assert!((a.sweep_rad() - (FRAC_PI_2 + TAU)).abs() < 1e-14);
}

#[test]
fn a_helix_rises_in_proportion_to_the_angle() {
    // From (1,0,0) a quarter turn to (0,1,2): the rise is 2, the centre
    // given at another height on the axis.
    let a = Arc::new([1., 0., 0.], [0., 1., 2.], [0., 0., 7.], [0., 0., 1.], 1).unwrap();
    assert!((a.sweep_rad() - FRAC_PI_2).abs() < 1e-15);
    assert_eq!(a.rise_mm(), 2.0);
    assert!(a.is_helix());
    assert_eq!(a.centre(), [0., 0., 0.]);
    let p = a.point_at(0.5);
    assert!(close(p, [FRAC_1_SQRT_2, FRAC_1_SQRT_2, 1.0], 1e-15));
    assert!((a.length_mm() - FRAC_PI_2.hypot(2.0)).abs() < 1e-14);
    // Two full turns down by 3 (a helical ramp).
    let h = Arc::new([4., 0., 3.], [4., 0., 0.], [0.; 3], [0., 0., 1.], 2).unwrap();
    assert_eq!(h.sweep_rad(), 2.0 * TAU);
    assert!(close(h.point_at(0.5), [4., 0., 1.5], 1e-13));
    assert!(close(h.point_at(0.125), [0., 4., 2.625], 1e-13));
}

#[test]
fn a_radius_rounded_between_the_ends_is_followed_smoothly() {
    let a = Arc::new([10., 0., 0.], [0., 10.005, 0.], [0.; 3], [0., 0., 1.], 1).unwrap();
    assert_eq!(a.point_at(1.0), [0., 10.005, 0.]);
    assert!((norm(a.point_at(0.5)) - 10.0025).abs() < 1e-12);
}

#[test]
fn arcs_that_are_not_arcs_are_refused() {
    let o = [0.; 3];
    assert_eq!(
        Arc::new([1., 0., 0.], [0., 1., 0.], o, [0.; 3], 1),
        Err(ArcError::ZeroAxis)
    );
    assert!(matches!(
        Arc::new([0., 0., 5.], [0., 1., 0.], o, [0., 0., 1.], 1),
        Err(ArcError::StartOnAxis { .. })
    ));
    assert!(matches!(
        Arc::new([1., 0., 0.], [0., 1.02, 0.], o, [0., 0., 1.], 1),
        Err(ArcError::EndOffCircle { .. })
    ));
    assert_eq!(
        Arc::new([1., 0., 0.], [0., 1., 0.], o, [0., 0., 1.], 0),
        Err(ArcError::NoTurns)
    );
    assert_eq!(
        Arc::new([f64::NAN, 0., 0.], [0., 1., 0.], o, [0., 0., 1.], 1),
        Err(ArcError::NotFinite)
    );
}

/// The largest distance from the curve (densely sampled between the
/// parameters of each chord) to the chords through `points` from `start`.
fn chord_error(f: impl Fn(f64) -> Vec3, start: Vec3, params: &[f64], points: &[Vec3]) -> f64 {
    let mut worst: f64 = 0.0;
    let mut a = start;
    let mut t0 = 0.0;
    for (&t1, &b) in params.iter().zip(points) {
        for k in 1..200 {
            let t = t0 + (t1 - t0) * k as f64 / 200.0;
            worst = worst.max(distance_to_segment(f(t), a, b));
        }
        (a, t0) = (b, t1);
    }
    worst
}

#[test]
fn arc_samples_keep_the_chord_tolerance_with_the_fewest_chords() {
    for (r, sweep_deg, tol) in [
        (5.0, 90.0, 0.01),
        (50.0, 359.0, 0.001),
        (0.5, 30.0, 0.1),
        (200.0, 720.0, 0.005),
        (1.0, 180.0, 5.0),
    ] {
        let sweep = f64::to_radians(sweep_deg);
        let turns = if sweep > TAU { 2 } else { 1 };
        let end = [r * sweep.cos(), r * sweep.sin(), 3.0];
        let a = Arc::new([r, 0., 0.], end, [0.; 3], [0., 0., 1.], turns).unwrap();
        let points = a.sample(tol).unwrap();
        let n = points.len();
        assert_eq!(points[n - 1], end);
        let params: Vec<f64> = (1..=n).map(|k| k as f64 / n as f64).collect();
        let err = chord_error(|t| a.point_at(t), a.start(), &params, &points);
        assert!(
            err <= tol * (1.0 + 1e-9),
            "r {r} sweep {sweep_deg}: {err} > {tol}"
        );
        // One chord fewer would not do (unless one chord is all there is).
        if n > 1 {
            let fewer = sweep / (n - 1) as f64;
            let sagitta = r * (1.0 - (fewer / 2.0).cos());
            assert!(
                sagitta > tol || fewer > PI,
                "r {r}: {n} chords where {} do",
                n - 1
            );
        }
    }
    assert!(matches!(
        Arc::new([1., 0., 0.], [0., 1., 0.], [0.; 3], [0., 0., 1.], 1)
            .unwrap()
            .sample(0.0),
        Err(SampleError::Tolerance(_))
    ));
    // A tolerance a million times finer than the radius's rounding would
    // ask for more points than anyone can use: refused.
    let helix = Arc::new(
        [1., 0., 0.],
        [1., 0., 5.],
        [0.; 3],
        [0., 0., 1.],
        MAX_ARC_TURNS,
    )
    .unwrap();
    assert_eq!(
        helix.sample(1e-15),
        Err(SampleError::TooManyPoints {
            tolerance_mm: 1e-15
        })
    );
    assert_eq!(
        Arc::new(
            [1., 0., 0.],
            [1., 0., 5.],
            [0.; 3],
            [0., 0., 1.],
            MAX_ARC_TURNS + 1
        ),
        Err(ArcError::TooManyTurns {
            turns: MAX_ARC_TURNS + 1
        })
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    /// Arcs about any axis match an independent rotation of the start.
    #[test]
    fn arcs_about_any_axis_are_rotations_of_the_start(
        ax in -1.0..1.0f64, ay in -1.0..1.0f64, az in -1.0..1.0f64,
        angle in 0.01..(TAU - 0.01),
        r in 0.01..500.0f64,
        cx in -100.0..100.0f64, cy in -100.0..100.0f64, cz in -100.0..100.0f64,
        seed in -1.0..1.0f64,
        rise in -50.0..50.0f64,
    ) {
        let n = norm([ax, ay, az]);
        prop_assume!(n > 0.1);
        let axis = [ax / n, ay / n, az / n];
        // A direction across the axis.
        let helper = if axis[0].abs() < 0.9 { [1., 0., 0.] } else { [0., 1., 0.] };
        let u0 = cross(axis, helper);
        let u = rotate(scale(u0, 1.0 / norm(u0)), axis, seed * PI);
        let centre = [cx, cy, cz];
        let start = add(centre, scale(u, r));
        let end = add(add(centre, scale(rotate(u, axis, angle), r)), scale(axis, rise));
        let a = Arc::new(start, end, centre, axis, 1).unwrap();
        prop_assert!((a.sweep_rad() - angle).abs() < 1e-9 * (1.0 + 1.0 / r));
        prop_assert!((a.rise_mm() - rise).abs() < 1e-9 * (1.0 + rise.abs()));
        for t in [0.1, 0.37, 0.5, 0.9] {
            let want = add(add(centre, scale(rotate(u, axis, angle * t), r)), scale(axis, rise * t));
            prop_assert!(close(a.point_at(t), want, 1e-9 * (1.0 + r + rise.abs())));
        }
    }
}

/// A rational quadratic quarter circle (Piegl & Tiller, §7.2): every
/// point is on the unit circle.
fn quarter_circle() -> Nurbs {
    Nurbs::new(
        2,
        vec![0., 0., 0., 1., 1., 1.],
        vec![[1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
        vec![1., FRAC_1_SQRT_2, 1.],
    )
    .unwrap()
}

#[test]
fn a_rational_quarter_circle_is_exact() {
    let c = quarter_circle();
    assert_eq!(c.domain(), (0.0, 1.0));
    for k in 0..=100 {
        let p = c.point_at(k as f64 / 100.0);
        assert!((norm(p) - 1.0).abs() < 1e-15, "{p:?}");
    }
    // By symmetry the middle parameter is the middle of the arc.
    assert!(close(
        c.point_at(0.5),
        [FRAC_1_SQRT_2, FRAC_1_SQRT_2, 0.],
        1e-15
    ));
    assert_eq!(c.point_at(0.0), [1., 0., 0.]);
    assert_eq!(c.point_at(1.0), [0., 1., 0.]);
}

#[test]
fn a_cubic_bezier_matches_the_bernstein_polynomials() {
    let p = [[0., 0., 0.], [1., 3., 0.], [4., 3., 1.], [5., 0., 2.]];
    let c = Nurbs::new(
        3,
        vec![0., 0., 0., 0., 2., 2., 2., 2.],
        p.to_vec(),
        vec![1.; 4],
    )
    .unwrap();
    for k in 0..=20 {
        let u = 2.0 * k as f64 / 20.0;
        let t = u / 2.0;
        let b = [
            (1. - t).powi(3),
            3. * t * (1. - t).powi(2),
            3. * t * t * (1. - t),
            t.powi(3),
        ];
        let want = [0, 1, 2].map(|i| (0..4).map(|j| b[j] * p[j][i]).sum::<f64>());
        assert!(close(c.point_at(u), want, 1e-14), "{u}");
    }
}

#[test]
fn a_degree_one_spline_is_the_polyline_and_spans_are_found() {
    let p = vec![[0., 0., 0.], [2., 0., 0.], [2., 2., 0.], [4., 2., 0.]];
    let c = Nurbs::new(1, vec![0., 0., 1., 3., 4., 4.], p, vec![1.; 4]).unwrap();
    assert!(close(c.point_at(0.5), [1., 0., 0.], 1e-15));
    assert!(close(c.point_at(1.0), [2., 0., 0.], 1e-15));
    assert!(close(c.point_at(2.0), [2., 1., 0.], 1e-15));
    assert!(close(c.point_at(3.5), [3., 2., 0.], 1e-15));
    assert_eq!(c.point_at(4.0), [4., 2., 0.]);
}

#[test]
fn nurbs_data_are_checked() {
    let p = vec![[0.; 3]; 3];
    assert_eq!(
        Nurbs::new(0, vec![0., 1., 2., 3.], p.clone(), vec![1.; 3]),
        Err(NurbsError::ZeroDegree)
    );
    assert!(matches!(
        Nurbs::new(2, vec![0.; 5], p.clone(), vec![1.; 3]),
        Err(NurbsError::KnotCount { knots: 5, .. })
    ));
    assert!(matches!(
        Nurbs::new(2, vec![0., 0., 0., 1., 0.5, 1.], p.clone(), vec![1.; 3]),
        Err(NurbsError::KnotsDecrease { index: 4, .. })
    ));
    assert!(matches!(
        Nurbs::new(2, vec![0., 0., 0., 1., 1., 1.], p.clone(), vec![1., 0., 1.]),
        Err(NurbsError::BadWeight { index: 1, .. })
    ));
    assert_eq!(
        Nurbs::new(2, vec![1.; 6], p.clone(), vec![1.; 3]),
        Err(NurbsError::EmptyDomain)
    );
    assert!(matches!(
        Nurbs::new(3, vec![0.; 7], p, vec![1.; 3]),
        Err(NurbsError::TooFewPoints { .. })
    ));
}

#[test]
fn nurbs_samples_keep_the_chord_tolerance() {
    let c = quarter_circle();
    for tol in [0.1, 0.01, 1e-4] {
        let points = c.sample(tol).unwrap();
        assert_eq!(*points.last().unwrap(), [0., 1., 0.]);
        // The parameters of the points: their angles (the curve is a circle
        // and the parameter grows with the angle).
        let angle = |p: Vec3| p[1].atan2(p[0]);
        let params: Vec<f64> = points.iter().map(|&p| angle(p)).collect();
        let on_circle = |a: f64| [a.cos(), a.sin(), 0.];
        let err = chord_error(on_circle, [1., 0., 0.], &params, &points);
        assert!(err <= tol, "{err} > {tol}");
        // Not far more points than a circle needs.
        let needed = FRAC_PI_2 / (2.0 * (1.0 - tol).acos());
        assert!(
            (points.len() as f64) < 4.0 * needed + 8.0,
            "{} points",
            points.len()
        );
    }
}
