//! The belt-grinding process model against Preston's law in closed form.

use std::f64::consts::PI;

use kinpost_stock::{Conditions, ProcessModel, Stock, Tool, ToolPose, Trace, calibrate};
use nalgebra::{Point3, Vector3};

const FILE: &str = r#"
[force]
axis = "H1"
newtons = [[3000, 300.0], [3300, 150.0], [3600, 0.0]]

[wheel]
preston_mm2_per_n = 1.0e-6
stiffness_n_per_mm3 = 3.0
"#;

fn model() -> ProcessModel {
    ProcessModel::from_toml(FILE, "p.toml").unwrap()
}

/// Depth at the middle of a pass over a flat, read from the Z ray there.
fn ground_depth(force_n: f64, rpm: f64, feed_mm_min: f64) -> f64 {
    let mut s = Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(100.0, 40.0, 10.0),
        0.1,
    )
    .unwrap();
    let tool = Tool::ContactWheel {
        radius: 50.0,
        width: 25.0,
        edge_radius: 0.0,
    };
    let a =
        ToolPose::new(Point3::new(10.0, 20.05, 10.0), Vector3::z()).with_reference(Vector3::x());
    let b =
        ToolPose::new(Point3::new(90.0, 20.05, 10.0), Vector3::z()).with_reference(Vector3::x());
    let c = Conditions {
        force_n,
        spindle_rpm: rpm,
        feed_mm_min,
        curvature_per_mm: 0.0,
    };
    let stats = s.grind_move(&model(), &tool, &a, &b, &c, 5).unwrap();
    assert!(stats.rays > 0);
    let f = s.family(2);
    let ray = f.ray(500, 200); // x = 50.05, y = 20.05
    assert_eq!(ray[0].hi_move, 5);
    // Outside the belt's width nothing is ground.
    assert_eq!(f.ray(500, 200 + 126)[0].hi, 10.0);
    10.0 - ray[0].hi
}

#[test]
fn preston_removal_on_a_flat_is_the_closed_form() {
    for (force, rpm, feed) in [
        (200.0, 1000.0, 600.0),
        (400.0, 1000.0, 600.0),
        (200.0, 2000.0, 600.0),
        (200.0, 1000.0, 1200.0),
    ] {
        let belt = 2.0 * PI * rpm / 60.0 * 50.0;
        let expected = 1.0e-6 * belt * force / (feed / 60.0 * 25.0);
        let got = ground_depth(force, rpm, feed);
        assert!(
            (got - expected).abs() < 1e-9 * expected.max(1.0),
            "F {force} rpm {rpm} feed {feed}: {got} vs {expected}"
        );
    }
    // Linear in force and belt speed, inverse in feed.
    let base = ground_depth(200.0, 1000.0, 600.0);
    assert!((ground_depth(400.0, 1000.0, 600.0) / base - 2.0).abs() < 1e-9);
    assert!((ground_depth(200.0, 2000.0, 600.0) / base - 2.0).abs() < 1e-9);
    assert!((ground_depth(200.0, 1000.0, 1200.0) / base - 0.5).abs() < 1e-9);
}

#[test]
fn force_table_interpolates_and_clamps() {
    let m = model();
    assert_eq!(m.force_n(2000.0), 300.0);
    assert_eq!(m.force_n(3150.0), 225.0);
    assert_eq!(m.force_n(3600.0), 0.0);
    assert_eq!(m.force_n(9000.0), 0.0);
}

/// Indentation of a Winkler wheel for a force, found by bisection on the
/// force integral computed with Simpson's rule (independent of the
/// library's closed form).
fn indentation(force: f64, k: f64, r: f64, w: f64) -> f64 {
    let load = |d: f64| {
        let a = (2.0 * r * d).sqrt();
        let n = 2000;
        let h = 2.0 * a / n as f64;
        let p = |x: f64| k * (d - x * x / (2.0 * r)).max(0.0);
        let mut s = p(-a) + p(a);
        for i in 1..n {
            s += p(-a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        w * s * h / 3.0
    };
    let (mut lo, mut hi) = (0.0, 10.0);
    for _ in 0..200 {
        let m = 0.5 * (lo + hi);
        if load(m) < force { lo = m } else { hi = m }
    }
    0.5 * (lo + hi)
}

#[test]
fn winkler_contact_carries_the_force() {
    let c = model().contact(250.0, 50.0, 25.0, 0.0).unwrap();
    let d = indentation(250.0, 3.0, 50.0, 25.0);
    assert!(
        (c.indentation_mm - d).abs() < 1e-9 * d.max(1e-3),
        "{} vs {d}",
        c.indentation_mm
    );
    assert!((c.half_length_mm - (2.0 * 50.0 * d).sqrt()).abs() < 1e-6);
    assert!((c.cumulative(c.half_length_mm) * 25.0 - 250.0).abs() < 1e-9);
}

#[test]
fn calibration_recovers_preston_and_stiffness() {
    let (kp, k) = (2.5e-6, 4.0);
    let mut traces = Vec::new();
    for (force, belt, feed) in [
        (100.0, 3000.0, 5.0),
        (250.0, 4000.0, 10.0),
        (300.0, 5000.0, 20.0),
    ] {
        traces.push(Trace::Pass {
            force_n: force,
            belt_mm_s: belt,
            feed_mm_s: feed,
            width_mm: 25.0,
            depth_mm: kp * belt * force / (feed * 25.0),
        });
    }
    for (force, dwell) in [(150.0, 2.0), (300.0, 1.0)] {
        let peak = kp * 3000.0 * dwell * k * indentation(force, k, 50.0, 25.0);
        traces.push(Trace::Dwell {
            force_n: force,
            belt_mm_s: 3000.0,
            dwell_s: dwell,
            width_mm: 25.0,
            radius_mm: 50.0,
            depth_mm: peak,
        });
    }
    let c = calibrate(&traces).unwrap();
    assert!((c.preston_mm2_per_n / kp - 1.0).abs() < 1e-9);
    assert!(
        (c.stiffness_n_per_mm3.unwrap() / k - 1.0).abs() < 1e-6,
        "{c:?}"
    );
    assert!(c.rms_mm < 1e-9);
    // Without dwells the stiffness is not identified.
    assert_eq!(calibrate(&traces[..3]).unwrap().stiffness_n_per_mm3, None);
    assert!(calibrate(&traces[3..]).is_err());
}

#[test]
fn a_bad_process_file_is_located() {
    let bad = FILE.replace("stiffness_n_per_mm3 = 3.0", "stiffness_n_per_mm3 = -3.0");
    let e = ProcessModel::from_toml(&bad, "p.toml").unwrap_err();
    assert_eq!((e.file.as_str(), e.line), ("p.toml", 8));
    let e = ProcessModel::from_toml(
        "[force]\naxis = \"H1\"\nnewtons = [[1, 2]]\n[wheel]\npreston = 1\n",
        "q.toml",
    )
    .unwrap_err();
    assert_eq!(e.line, 5, "{e:?}");
}

#[test]
fn the_shipped_mts1600_process_file_loads() {
    let src = include_str!("../../process/mts1600.toml");
    let m = ProcessModel::from_toml(src, "mts1600.toml").unwrap();
    assert_eq!(m.force.axis, "H1");
    assert_eq!(m.force_n(3000.0), 300.0);
    // The comment's claim: 0.02 mm a pass at 100 N, 20 m/s, 10 mm/s, 25 mm.
    assert!((m.pass_depth_mm(100.0, 20_000.0, 10.0, 25.0) - 0.02).abs() < 1e-12);
}

#[test]
fn the_grinding_summary_names_blocks_and_the_depth_range() {
    use kinpost_stock::{BlockRef, GrindingSummary};
    let mut s = Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(60.0, 40.0, 10.0),
        0.2,
    )
    .unwrap();
    let tool = Tool::ContactWheel {
        radius: 50.0,
        width: 25.0,
        edge_radius: 0.0,
    };
    let m = model();
    let mut stats = Vec::new();
    for (id, h1) in [(0u32, 3000.0), (1, 3300.0)] {
        let y = 10.0 + 20.0 * id as f64;
        let a = ToolPose::new(Point3::new(5.0, y, 10.0), Vector3::z()).with_reference(Vector3::x());
        let b =
            ToolPose::new(Point3::new(55.0, y, 10.0), Vector3::z()).with_reference(Vector3::x());
        let c = Conditions {
            force_n: m.force_n(h1),
            spindle_rpm: 1000.0,
            feed_mm_min: 600.0,
            curvature_per_mm: 0.0,
        };
        stats.push((id, s.grind_move(&m, &tool, &a, &b, &c, id).unwrap()));
    }
    let blocks = vec![
        BlockRef {
            block: Some("N10".into()),
            line: 2,
        },
        BlockRef {
            block: Some("N20".into()),
            line: 3,
        },
    ];
    let g = GrindingSummary::new(&stats, &blocks);
    assert_eq!(g.blocks.len(), 2);
    assert_eq!(g.blocks[1].line, Some(3));
    // The deeper block is the one at the higher force (H1 = 3000: 300 N).
    let full = |f: f64| 1.0e-6 * 2.0 * PI * 1000.0 / 60.0 * 50.0 * f / (10.0 * 25.0);
    assert!((g.depth_range_mm[1] - full(300.0)).abs() < 1e-12);
    assert!((g.blocks[1].pass_depth_mm - full(150.0)).abs() < 1e-12);
    assert!(g.depth_range_mm[0] > 0.0 && g.depth_range_mm[0] < full(150.0));
}
