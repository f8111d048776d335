//! Comparison with the design: a part against itself, a slot against the
//! uncut design, a mesh stock against its box.

use kinpost_stock::{Design, Mesh, Stock, Tool, ToolPose, compare};
use kinpost_surface::grid::read_grid;
use kinpost_surface::{FitOptions, Surface};
use nalgebra::{Point3, Vector3};

fn corners() -> (Point3<f64>, Point3<f64>) {
    (Point3::new(0.0, 0.0, 0.0), Point3::new(40.0, 20.0, 10.0))
}

/// The box of [`corners`] at 0.25 mm with a slot of a 4 mm flat end mill
/// `depth` deep below its top, x 10…30 at y 10, cut by move `id`.
fn slotted(depth: f64, id: u32) -> Stock {
    let (lo, hi) = corners();
    let mut s = Stock::from_box(lo, hi, 0.25).unwrap();
    let tool = Tool::FlatEnd {
        diameter: 4.0,
        flute_length: 20.0,
        shank: None,
    };
    let z = hi.z - depth;
    let a = ToolPose::new(Point3::new(10.0, 10.0, z), Vector3::z());
    let b = ToolPose::new(Point3::new(30.0, 10.0, z), Vector3::z());
    s.cut_move(&tool, &a, &b, id).unwrap();
    s
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
    let s = slotted(0.3, 41);
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

/// A cubic B-spline surface through a grid of `f(x, y)` over x0..x1, y0..y1
/// (rows along x, columns along y: S_u × S_v = +Z for a graph).
fn graph_surface(x: (f64, f64), y: (f64, f64), f: impl Fn(f64, f64) -> f64) -> Surface {
    let mut csv = String::from("row,col,x,y,z\n");
    let n = 25;
    for r in 0..n {
        for c in 0..n {
            let (px, py) = (
                x.0 + (x.1 - x.0) * r as f64 / (n - 1) as f64,
                y.0 + (y.1 - y.0) * c as f64 / (n - 1) as f64,
            );
            csv.push_str(&format!("{r},{c},{px},{py},{}\n", f(px, py)));
        }
    }
    Surface::fit(
        &read_grid(&csv, "graph.csv").unwrap(),
        &FitOptions::default(),
    )
    .unwrap()
}

#[test]
fn the_shell_of_a_design_surface_is_its_allowance_over_a_region() {
    // The plane z = 10 over x 0..40, y 0..20; its middle (a quarter of the
    // domain cut off on each side along u, nothing along v) grown 0.1 mm
    // out and 2 mm in: a 20 × 20 × 2.1 mm slab from z = 8 to 10.1.
    let plane = graph_surface((0.0, 40.0), (0.0, 20.0), |_, _| 10.0);
    let (u0, u1) = plane.u_range();
    let (v0, v1) = plane.v_range();
    let region = [u0 + 0.25 * (u1 - u0), u0 + 0.75 * (u1 - u0), v0, v1];
    let shell = Design::shell_of_surface(&plane, region, 0.001, false, 0.1, 2.0).unwrap();
    assert!(
        (shell.signed_volume6() / 6.0 - 20.0 * 20.0 * 2.1).abs() < 1e-6,
        "a closed shell facing out: {}",
        shell.signed_volume6() / 6.0
    );
    let (lo, hi) = shell.bounds().unwrap();
    assert!((lo - Point3::new(10.0, 0.0, 8.0)).norm() < 1e-9, "{lo}");
    assert!((hi - Point3::new(30.0, 20.0, 10.1)).norm() < 1e-9, "{hi}");
    let stock = Stock::from_mesh(&shell, 0.1).unwrap();
    // Compared with the region it grew from, the uncut stock stands 0.1 mm
    // proud everywhere, exactly along the rays.
    let design = Design::from_surface_region(&plane, region, 0.001, false).unwrap();
    let c = compare(&stock, &design, 0.01).unwrap();
    let [lo, hi] = c.deviation_range_mm.unwrap();
    assert!(
        (lo - 0.1).abs() < 1e-9 && (hi - 0.1).abs() < 1e-9,
        "{lo} {hi}"
    );
    assert_eq!(c.residual_regions.len(), 1);
    assert!((c.residual_regions[0].area_mm2 - 400.0).abs() < 400.0 * 0.01);
    // Turned over, the material is above the surface: 0.1 mm below it out
    // to 2 mm above.
    let over = Design::shell_of_surface(&plane, region, 0.001, true, 0.1, 2.0).unwrap();
    let (lo, hi) = over.bounds().unwrap();
    assert!((lo.z - 9.9).abs() < 1e-9 && (hi.z - 12.0).abs() < 1e-9);
    assert!(over.signed_volume6() > 0.0);
}

#[test]
fn a_curved_shell_offsets_along_the_normal() {
    // A cylinder of radius 50 about the y axis (z = √(50² − x²) − 40), x
    // within ±20: its shell 0.2 mm out, compared with it, stands 0.2 mm
    // proud along the normal (the tessellation's 0.001 mm chord and the
    // offset grid's chords aside).
    let r = 50.0;
    let cylinder = graph_surface((-20.0, 20.0), (0.0, 30.0), |x, _| {
        (r * r - x * x).sqrt() - 40.0
    });
    let (u0, u1) = cylinder.u_range();
    let (v0, v1) = cylinder.v_range();
    let region = [u0, u1, v0, v1];
    let shell = Design::shell_of_surface(&cylinder, region, 0.001, false, 0.2, 1.0).unwrap();
    let stock = Stock::from_mesh(&shell, 0.05).unwrap();
    let design = Design::from_surface(&cylinder, 0.001, false).unwrap();
    let c = compare(&stock, &design, 0.01).unwrap();
    let [lo, hi] = c.deviation_range_mm.unwrap();
    assert!(lo > 0.2 - 0.003 && hi < 0.2 + 0.003, "{lo} {hi}");
    // A shell as deep as the radius would fold over itself: refused.
    assert!(matches!(
        Design::shell_of_surface(&cylinder, region, 0.001, false, 0.2, 50.0),
        Err(kinpost_stock::DesignError::Surface(_))
    ));
    // A region outside the domain is refused.
    assert!(matches!(
        Design::from_surface_region(&cylinder, [u0, u1 + 1.0, v0, v1], 0.001, false),
        Err(kinpost_stock::DesignError::Region(_))
    ));
}

#[test]
fn the_deviation_map_sees_every_measured_ray() {
    // A 0.4 mm slot in a plate measured against its top: the map seen along
    // Z holds the slot's depth where the slot is and 0 elsewhere.
    let plane = graph_surface((0.0, 40.0), (0.0, 20.0), |_, _| 10.0);
    let design = Design::from_surface(&plane, 0.001, false).unwrap();
    let s = slotted(0.4, 3);
    let c = compare(&s, &design, 0.01).unwrap();
    let map = c.maps.iter().max_by_key(|m| m.measured_rays).unwrap();
    assert_eq!(map.axis, 2);
    assert_eq!(map.measured_rays, 160 * 80);
    assert_eq!(map.size, [160, 80]);
    let at = |x: f64, y: f64| {
        let (i, j) = (
            ((x - map.origin[0]) / map.cell_mm) as usize,
            ((y - map.origin[1]) / map.cell_mm) as usize,
        );
        map.cells[j * map.size[0] + i].unwrap()
    };
    assert!((f64::from(at(20.0, 10.0)) + 0.4).abs() < 1e-6);
    assert!(f64::from(at(5.0, 3.0)).abs() < 1e-6);
    let [lo, hi] = c.deviation_range_mm.unwrap();
    assert!((lo + 0.4).abs() < 1e-9 && hi.abs() < 1e-9);
}
