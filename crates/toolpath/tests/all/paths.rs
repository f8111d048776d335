//! Paths on surfaces with known answers: the scallop between passes on a
//! cylinder against the analytic cusp height, the requested scallop and
//! chord tolerance held, and the CL file read back by kinpost's own reader.

use std::f64::consts::PI;

use kinpost_cl::{ClEvent, ClReader, Motion};
use kinpost_surface::grid::Grid;
use kinpost_surface::{FitOptions, Surface};
use kinpost_toolpath::cl::{ClOptions, write_cl};
use kinpost_toolpath::{Direction, PathOptions, Side, Spacing, Wheel, plan};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};

const RHO: f64 = 60.0;
const ARC: f64 = PI / 3.0;

/// Cylinder of radius 60 about z: rows the angle (60°), columns the height
/// (0..100): r_u × r_v points outwards.
fn cylinder() -> Surface {
    let (m, n) = (181, 21);
    let mut points = Vec::new();
    for i in 0..m {
        for j in 0..n {
            let t = ARC * i as f64 / (m - 1) as f64;
            points.push([
                RHO * t.cos(),
                RHO * t.sin(),
                100.0 * j as f64 / (n - 1) as f64,
            ]);
        }
    }
    Surface::fit(
        &Grid {
            rows: m,
            cols: n,
            points,
        },
        &FitOptions::default(),
    )
    .unwrap()
}

fn angle_of(p: &Vector3<f64>) -> f64 {
    p.y.atan2(p.x)
}

/// Passes along the cylinder's axis on its convex outside: the wheel's
/// straight generator lies across the pass, so the cusp between passes
/// Δθ apart is the circle's: ρ (sec(Δθ/2) − 1).
#[test]
fn scallop_on_a_cylinder_is_the_analytic_cusp() {
    let s = cylinder();
    for h in [0.002, 0.01, 0.05] {
        let options = PathOptions {
            wheel: Wheel {
                radius: 40.0,
                width: 25.0,
            },
            direction: Direction::V,
            side: Side::Plus,
            spacing: Spacing::Scallop(h),
            overlap: 0.1,
            region: [0.1, 0.9, 0.0, 1.0],
            ..PathOptions::default()
        };
        let path = plan(&s, &options).unwrap();
        let r = &path.report;
        assert!(r.scallop_max <= h, "scallop {} over {h}", r.scallop_max);
        assert!(
            r.scallop_max > 0.5 * h,
            "scallop {} far under {h}",
            r.scallop_max
        );
        assert!(
            r.interference_max < 1e-6,
            "interference {}",
            r.interference_max
        );
        // Every gap against the analytic cusp of its own angle.
        for (k, g) in r.gaps.iter().enumerate() {
            let a = angle_of(&path.passes[k].points[0].point);
            let b = angle_of(&path.passes[k + 1].points[0].point);
            let half = (b - a).abs() / 2.0;
            let cusp = RHO * (1.0 / half.cos() - 1.0);
            assert!(
                (g.scallop - cusp).abs() < 1e-5 * cusp + 1e-9,
                "gap {k}: {} vs analytic {cusp}",
                g.scallop
            );
            let chord = 2.0 * RHO * half.sin();
            assert!(
                (g.stepover - chord).abs() < 1e-6,
                "{} vs {chord}",
                g.stepover
            );
        }
        // The passes lie along the axis (straight): five CL points each
        // (a pass has at least four segments),
        // the tool axis the outward normal, the reference +z.
        for p in &path.passes {
            assert_eq!(p.points.len(), 5);
            for c in &p.points {
                let radial = Vector3::new(c.point.x, c.point.y, 0.0).normalize();
                assert!((c.axis - radial).norm() < 1e-6);
                assert!((c.reference - Vector3::z()).norm() < 1e-9);
            }
        }
    }
}

/// Passes around the cylinder (along u): the chord tolerance sets the
/// point spacing, √(8·tol·ρ) apart; the straight wheel across the pass
/// leaves no scallop on the straight generators.
#[test]
fn chord_tolerance_sets_the_point_spacing() {
    let s = cylinder();
    for tol in [0.001, 0.01, 0.1] {
        let options = PathOptions {
            direction: Direction::U,
            chord_tolerance: tol,
            max_angle_deg: 45.0,
            spacing: Spacing::Stepover(10.0),
            ..PathOptions::default()
        };
        let path = plan(&s, &options).unwrap();
        let r = &path.report;
        assert!(r.chord_error_max <= tol);
        let step = (8.0 * tol * RHO).sqrt();
        let expected = (ARC * RHO / step).ceil() as usize + 1;
        for p in &path.passes {
            // Sagitta of each segment: ρ(1 − cos(α/2)) ≤ tol, checked
            // independently of the sampler's own estimate.
            for w in p.points.windows(2) {
                let alpha = (angle_of(&w[1].point) - angle_of(&w[0].point)).abs();
                let sagitta = RHO * (1.0 - (alpha / 2.0).cos());
                assert!(sagitta <= tol * (1.0 + 1e-6), "sagitta {sagitta} > {tol}");
            }
            assert!(
                p.points.len() >= expected && p.points.len() <= 2 * expected + 2,
                "{} points, about {expected} expected",
                p.points.len()
            );
        }
        assert!(r.scallop_max < 1e-9, "{}", r.scallop_max);
        // 100 mm of height at step-over ≤ 10 mm: 11 passes.
        assert_eq!(r.passes, 11);
        assert!((r.stepover_max - 10.0).abs() < 1e-6 && r.stepover_min <= 10.0 + 1e-9);
    }
}

/// Inside a cylinder (side −), passes along the axis: the straight wheel
/// across a concave section touches at its edges under the surface; the
/// interference is the sagitta of half the wheel width.
#[test]
fn concave_section_reports_wheel_edge_interference() {
    let s = cylinder();
    let options = PathOptions {
        wheel: Wheel {
            radius: 30.0,
            width: 20.0,
        },
        direction: Direction::V,
        side: Side::Minus,
        spacing: Spacing::Overlap(0.5),
        region: [0.2, 0.8, 0.0, 1.0],
        ..PathOptions::default()
    };
    // The bound is the sagitta of the full half width, along the normal.
    let bound = RHO - (RHO * RHO - 100.0f64).sqrt();
    // Every wheel reaches that deep at its edges, however close the
    // passes: with a step below half the width the edges lie beyond the
    // neighbouring passes, and are looked at there too (before, only the
    // points between two passes were, and the figure shrank with the step).
    for overlap in [0.5, 0.8, 0.95] {
        let options = PathOptions {
            spacing: Spacing::Overlap(overlap),
            ..options
        };
        let path = plan(&s, &options).unwrap();
        let r = &path.report;
        assert_eq!(r.scallop_max, 0.0);
        assert!(
            r.interference_max > 0.95 * bound && r.interference_max <= bound * 1.05,
            "overlap {overlap}: {} vs {bound}",
            r.interference_max
        );
    }
}

#[test]
fn cl_file_reads_back_with_leads_rapids_references_and_pressure() {
    let s = cylinder();
    let placement = Isometry3::from_parts(
        Translation3::new(-500.0, 10.0, 20.0),
        UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 0.3),
    );
    let options = PathOptions {
        direction: Direction::V,
        lead: 7.0,
        placement,
        ..PathOptions::default()
    };
    let path = plan(&s, &options).unwrap();
    let cl_options = ClOptions {
        name: "CYL".into(),
        feed: 1500.0,
        pressure: Some(("H1".into(), 3000.0)),
        reference: true,
        comments: vec!["test".into()],
    };
    let mut out = Vec::new();
    write_cl(&path, &options, &cl_options, &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert!(text.starts_with(
        "TOOL PATH/CYL,TOOL,WHEEL_R50.000_W20.000\nTLDATA/MILL,100.0000,0.0000,20.0000"
    ));
    assert!(text.contains("\nPRESSURE/H1,3000.000\n"));
    let mut reader = ClReader::new(text.as_bytes(), "cyl.cls");
    let mut gotos = Vec::new();
    let mut feeds = Vec::new();
    let mut pressure = None;
    while let Some(st) = reader.next_statement().unwrap() {
        match st.event {
            ClEvent::Goto {
                point,
                axis,
                reference,
                motion,
            } => gotos.push((point, axis, reference.unwrap(), motion)),
            ClEvent::Feedrate { value, .. } => feeds.push(value),
            ClEvent::Pressure { word, value } => pressure = Some((word, value)),
            _ => {}
        }
    }
    assert!(reader.take_warnings().is_empty());
    assert_eq!(feeds, [1500.0]);
    assert_eq!(pressure, Some((Some("H1".to_string()), 3000.0)));
    let expected: usize = path.passes.iter().map(|p| p.points.len() + 2).sum();
    assert_eq!(gotos.len(), expected);
    let mut k = 0;
    for pass in &path.passes {
        // Rapid to the lead-in point, feed down, along, and up.
        assert_eq!(gotos[k].3, Motion::Rapid);
        let first = &pass.points[0];
        let lead_in = placement * nalgebra::Point3::from(first.point + first.axis * 7.0);
        assert!((Vector3::from(gotos[k].0) - lead_in.coords).norm() < 1e-5);
        for (m, c) in pass.points.iter().enumerate() {
            let g = &gotos[k + 1 + m];
            assert_eq!(g.3, Motion::Feed);
            let p = placement * nalgebra::Point3::from(c.point);
            assert!((Vector3::from(g.0) - p.coords).norm() < 1e-5);
            assert!((Vector3::from(g.1) - placement * c.axis).norm() < 1e-8);
            assert!((Vector3::from(g.2) - placement * c.reference).norm() < 1e-8);
        }
        assert_eq!(gotos[k + pass.points.len() + 1].3, Motion::Feed);
        k += pass.points.len() + 2;
    }
    // Zig-zag: consecutive passes run opposite ways, the reference stays.
    let z0 = path.passes[0].points[0].point.z;
    let z1 = path.passes[1].points[0].point.z;
    assert!(z0 < 1e-9 && (z1 - 100.0).abs() < 1e-9);
}

#[test]
fn bad_options_are_errors() {
    let s = cylinder();
    let bad = |o: PathOptions| plan(&s, &o).unwrap_err().to_string();
    assert!(
        bad(PathOptions {
            spacing: Spacing::Stepover(30.0),
            ..PathOptions::default()
        })
        .contains("larger than the wheel width")
    );
    assert!(
        bad(PathOptions {
            wheel: Wheel {
                radius: -1.0,
                width: 10.0
            },
            ..PathOptions::default()
        })
        .contains("radius")
    );
    assert!(
        bad(PathOptions {
            region: [0.5, 0.4, 0.0, 1.0],
            ..PathOptions::default()
        })
        .contains("region")
    );
}
