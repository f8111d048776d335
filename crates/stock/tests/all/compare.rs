//! Comparison with the design: a part against itself, a slot against the
//! uncut design, a mesh stock against its box.

use kinpost_stock::{Design, Mesh, Stock, Tool, ToolPose, compare};
use nalgebra::{Point3, Vector3};

fn corners() -> (Point3<f64>, Point3<f64>) {
    (Point3::new(0.0, 0.0, 0.0), Point3::new(40.0, 20.0, 10.0))
}

#[test]
fn cuboid_mesh_faces_out_and_bounds_the_box() {
    let (lo, hi) = corners();
    let m = Mesh::cuboid(lo, hi);
    assert!((m.signed_volume6() / 6.0 - 8000.0).abs() < 1e-9);
    let s = Stock::from_mesh(&m, 0.5).unwrap();
    let b = Stock::from_box(lo, hi, 0.5).unwrap();
    for k in 0..3 {
        assert_eq!(s.family(k).rays, b.family(k).rays, "family {k}");
    }
}

#[test]
fn a_stock_compared_with_itself_as_design_has_no_gouge_or_residual() {
    let (lo, hi) = corners();
    let s = Stock::from_box(lo, hi, 0.25).unwrap();
    let d = Design::from_mesh(Mesh::cuboid(lo, hi)).unwrap();
    let c = compare(&s, &d, 0.01).unwrap();
    assert!(c.measured > 0);
    assert!(
        c.beyond.is_empty(),
        "{:?}",
        &c.beyond[..c.beyond.len().min(3)]
    );
    assert!(c.gouge_regions.is_empty() && c.residual_regions.is_empty());
    assert_eq!(c.gouge_volume_mm3, 0.0);
    assert_eq!(c.residual_volume_mm3, 0.0);
    // Every face measured once: the box's area over h².
    let area = 2.0 * (40.0 * 20.0 + 20.0 * 10.0 + 40.0 * 10.0);
    assert!(
        (c.histogram[4].area_mm2 - area).abs() < 1e-6 * area,
        "{:?}",
        c.histogram
    );
}

#[test]
fn a_slot_below_the_design_is_a_gouge_of_its_depth_made_by_its_move() {
    let (lo, hi) = corners();
    let mut s = Stock::from_box(lo, hi, 0.25).unwrap();
    let tool = Tool::FlatEnd {
        diameter: 4.0,
        flute_length: 20.0,
        shank: None,
    };
    let a = ToolPose::new(Point3::new(10.0, 10.0, 9.7), Vector3::z());
    let b = ToolPose::new(Point3::new(30.0, 10.0, 9.7), Vector3::z());
    s.cut_move(&tool, &a, &b, 41).unwrap();
    let d = Design::from_mesh(Mesh::cuboid(lo, hi)).unwrap();
    let c = compare(&s, &d, 0.01).unwrap();
    assert_eq!(c.gouge_regions.len(), 1, "{:?}", c.gouge_regions);
    let g = &c.gouge_regions[0];
    assert!((g.deviation_mm + 0.3).abs() < 1e-9);
    assert_eq!(g.move_id, Some(41));
    // The slot's footprint, within a ray's area on its rim.
    let area = 20.0 * 4.0 + std::f64::consts::PI * 4.0;
    assert!(
        (g.area_mm2 - area).abs() < 2.0 * 0.25 * (40.0 + 2.0 * std::f64::consts::PI * 2.0),
        "{}",
        g.area_mm2
    );
    assert!(c.residual_regions.is_empty());
    assert!((c.gouge_max().unwrap().deviation_mm + 0.3).abs() < 1e-9);
    assert!((c.gouge_volume_mm3 - area * 0.3).abs() < 0.05 * area * 0.3);
}

#[test]
fn a_design_with_an_allowance_leaves_that_residual() {
    let (lo, hi) = corners();
    let design = Mesh::cuboid(lo, hi);
    let s = Stock::from_mesh_offset(&design, 0.2, 0.25).unwrap();
    let c = compare(&s, &Design::from_mesh(design).unwrap(), 0.01).unwrap();
    assert!(c.gouge_regions.is_empty());
    // Six faces, each one region of +0.2 mm.
    assert_eq!(c.residual_regions.len(), 6, "{:?}", c.residual_regions);
    for r in &c.residual_regions {
        assert!((r.deviation_mm - 0.2).abs() < 1e-9, "{r:?}");
    }
}

#[test]
fn a_bspline_design_surface_is_measured_along_its_normal() {
    use kinpost_surface::grid::read_grid;
    use kinpost_surface::{FitOptions, Surface};
    // The plane z = 10 over x 5..35, y 2..18, as a fitted B-spline surface
    // (rows along x, columns along y: S_u × S_v = +Z, out of the material).
    let mut csv = String::from("row,col,x,y,z\n");
    for r in 0..4 {
        for c in 0..4 {
            csv.push_str(&format!(
                "{r},{c},{},{},10\n",
                5.0 + 10.0 * r as f64,
                2.0 + 16.0 / 3.0 * c as f64
            ));
        }
    }
    let surface = Surface::fit(
        &read_grid(&csv, "plane.csv").unwrap(),
        &FitOptions::default(),
    )
    .unwrap();
    let design = Design::from_surface(&surface, 0.001, false).unwrap();
    assert!(!design.is_closed());
    let (lo, hi) = corners();
    let mut s = Stock::from_box(lo, hi, 0.25).unwrap();
    let c = compare(&s, &design, 0.01).unwrap();
    assert!(c.beyond.is_empty());
    assert!(
        (c.histogram[4].area_mm2 - 30.0 * 16.0).abs() < 1.0,
        "{:?}",
        c.histogram
    );
    let tool = Tool::FlatEnd {
        diameter: 4.0,
        flute_length: 20.0,
        shank: None,
    };
    let a = ToolPose::new(Point3::new(10.0, 10.0, 9.6), Vector3::z());
    let b = ToolPose::new(Point3::new(30.0, 10.0, 9.6), Vector3::z());
    s.cut_move(&tool, &a, &b, 3).unwrap();
    let c = compare(&s, &design, 0.01).unwrap();
    assert_eq!(c.gouge_regions.len(), 1);
    assert!((c.gouge_regions[0].deviation_mm + 0.4).abs() < 1e-9);
    // Turned over, the same surface faces into the material: the uncut top
    // is then measured from the other side and is all beyond tolerance.
    let flipped = Design::from_surface(&surface, 0.001, true).unwrap();
    assert!(!compare(&s, &flipped, 0.01).unwrap().beyond.is_empty());
}
