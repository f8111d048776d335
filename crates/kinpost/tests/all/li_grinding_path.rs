//! Li (B-spline grinding) end to end: the 35 measured points → interpolation surface →
//! grinding path → posted on the `ac-grinder` (the paper's A/C machine).
//! Every posted block's A and C are the angles of the paper's eq. (30)
//! for the CL normal, and the paper's eq. (25), with the posted linear
//! axes, puts the CL point on the wheel's grinding point. The paper's side
//! is `crates/machine/tests/li_paper/mod.rs`, written from the printed
//! formulas, shared with the machine crate's eq. (30) test.

use crate::li_paper;

use std::path::Path;

use kinpost_post::cl::{ClEvent, ClReader};
use kinpost_post::machine::builtin;
use kinpost_post::{PostOptions, post};
use kinpost_surface::grid::read_grid;
use kinpost_surface::{FitOptions, Surface};
use kinpost_toolpath::cl::{ClOptions, write_cl};
use kinpost_toolpath::{Direction, PathOptions, Spacing, Wheel, plan};
use li_paper::{PHI, R_S1, eq25, eq30_angles_deg, same_angle_within};
use nalgebra::{Vector3, Vector4};

fn cl_text(direction: Direction) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data/li-bspline/points.csv");
    let grid = read_grid(&std::fs::read_to_string(&path).unwrap(), "points.csv").unwrap();
    let surface = Surface::fit(&grid, &FitOptions::default()).unwrap();
    let options = PathOptions {
        wheel: Wheel {
            radius: R_S1,
            width: 2.0,
        },
        direction,
        spacing: Spacing::Scallop(0.002),
        chord_tolerance: 0.001,
        lead: 3.0,
        ..PathOptions::default()
    };
    let path = plan(&surface, &options).unwrap();
    assert!(path.report.scallop_max <= 0.002);
    let mut out = Vec::new();
    let cl = ClOptions {
        name: "LI_FLANK".into(),
        feed: 600.0,
        pressure: None,
        reference: false,
        comments: Vec::new(),
    };
    write_cl(&path, &options, &cl, &mut out).unwrap();
    String::from_utf8(out).unwrap()
}

#[test]
fn posted_angles_are_those_of_eq_30() {
    let machine = builtin::load("ac-grinder").unwrap().unwrap();
    let dialect = kinpost_post::nc::Dialect::builtin("csv").unwrap();
    for direction in [Direction::U, Direction::V] {
        let cl = cl_text(direction);
        let mut csv = Vec::new();
        let summary = post(
            cl.as_bytes(),
            &machine,
            &dialect,
            &mut csv,
            &PostOptions::default(),
        )
        .unwrap();
        assert!(summary.warnings.is_empty(), "{:?}", summary.warnings);
        assert!(summary.max_position_error_mm <= summary.tolerance_mm);
        assert!(summary.max_axis_error_rad <= summary.tolerance_rad);

        // The CL poses, as the post read them.
        let mut poses = Vec::new();
        let mut reader = ClReader::new(cl.as_bytes(), "li-flank.cls");
        while let Some(s) = reader.next_statement().unwrap() {
            if let ClEvent::Goto { point, axis, .. } = s.event {
                poses.push((Vector3::from(point), Vector3::from(axis)));
            }
        }
        let csv = String::from_utf8(csv).unwrap();
        let mut rows = csv.lines();
        let header: Vec<&str> = rows.next().unwrap().split(',').collect();
        let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
        let (cx, cy, cz, ca, cc) = (col("X"), col("Y"), col("Z"), col("A"), col("C"));
        let rows: Vec<Vec<f64>> = rows
            .map(|r| {
                r.split(',')
                    .map(|v| v.parse().unwrap_or(f64::NAN))
                    .collect()
            })
            .collect();
        assert_eq!(rows.len(), poses.len());
        assert!(rows.len() > 30);
        let grinding_point = Vector4::new(R_S1 * PHI.sin(), 0.0, -R_S1 * PHI.cos(), 1.0); // eq. 27
        for (r, (p, n)) in rows.iter().zip(&poses) {
            let (a, c) = (r[ca], r[cc]);
            // The CSV writes 6 decimals: 5e-7° of rounding.
            assert!(
                eq30_angles_deg(n)
                    .iter()
                    .any(|&(ea, ec)| same_angle_within(a, ea, 360.0, 1e-6)
                        && same_angle_within(c, ec, 360.0, 1e-6)),
                "A {a} C {c} are not eq. 30's {:?} for n = {n}",
                eq30_angles_deg(n)
            );
            let xs = eq25(r[cx], r[cy], r[cz], a.to_radians(), c.to_radians())
                * Vector4::new(p.x, p.y, p.z, 1.0);
            assert!((xs - grinding_point).norm() < 1e-4, "eq. 25 gives {xs}");
        }
    }
}
