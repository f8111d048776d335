//! Analytic cuts: slots, grooves and footprints whose shape is known in
//! closed form, checked along the rays.

use kinpost_stock::dexel::UNCUT;
use kinpost_stock::{Stock, Tool, ToolPose};
use nalgebra::{Point3, Vector3};

fn boxed(h: f64) -> Stock {
    Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(100.0, 50.0, 20.0),
        h,
    )
    .unwrap()
}

/// Index of the lattice node nearest to `c` along axis `i`.
fn node(s: &Stock, i: usize, c: f64) -> usize {
    ((c - s.origin()[i]) / s.resolution_mm() - 0.5).round() as usize
}

#[test]
fn flat_end_slot_has_its_depth_along_the_rays_and_its_width() {
    let mut s = boxed(0.1);
    let tool = Tool::FlatEnd {
        diameter: 10.0,
        flute_length: 30.0,
        shank: None,
    };
    let d = 2.5;
    let a = ToolPose::new(Point3::new(10.0, 25.0, 20.0 - d), Vector3::z());
    let b = ToolPose::new(Point3::new(90.0, 25.0, 20.0 - d), Vector3::z());
    let cut = s.cut_move(&tool, &a, &b, 7).unwrap();
    assert!(cut.analytic);
    // Z rays: the floor at 20 − d inside the slot, untouched outside.
    let f = s.family(2);
    let mut inside = 0;
    for iu in 0..f.nu {
        for iv in 0..f.nv {
            let (x, y) = (s.coordinate(0, iu), s.coordinate(1, iv));
            let ray = f.ray(iu, iv);
            assert_eq!(ray.len(), 1);
            // Distance from (x, y) to the segment of tool centres.
            let dx = if x < 10.0 {
                10.0 - x
            } else if x > 90.0 {
                x - 90.0
            } else {
                0.0
            };
            let dist = dx.hypot(y - 25.0);
            if dist < 5.0 - 1e-9 {
                assert!(
                    (ray[0].hi - (20.0 - d)).abs() < 1e-6,
                    "floor at ({x}, {y}): {}",
                    ray[0].hi
                );
                assert_eq!(ray[0].hi_move, 7);
                inside += 1;
            } else if dist > 5.0 + 1e-9 {
                assert_eq!(ray[0].hi, 20.0);
                assert_eq!(ray[0].hi_move, UNCUT);
            }
        }
    }
    assert!(inside > 0);
    // Y rays above the floor at the middle of the slot: the walls at
    // y = 25 ± 5, exact along the ray.
    let fy = s.family(1);
    let (ix, iz) = (node(&s, 0, 50.0), node(&s, 2, 19.0));
    let ray = fy.ray(ix, iz);
    assert_eq!(ray.len(), 2);
    assert!((ray[0].hi - 20.0).abs() < 1e-6 && (ray[1].lo - 30.0).abs() < 1e-6);
    assert_eq!((ray[0].hi_move, ray[1].lo_move), (7, 7));
    // Width from the Z rays: within the resolution.
    let cut_rays = (0..f.nv).filter(|&iv| f.ray(ix, iv)[0].hi < 20.0).count();
    let width = cut_rays as f64 * s.resolution_mm();
    assert!((width - 10.0).abs() <= s.resolution_mm(), "width {width}");
    // Removed volume: the stadium of the slot times its depth.
    let expected = (80.0 * 10.0 + std::f64::consts::PI * 25.0) * d;
    assert!((s.removed_volume_mm3() - expected).abs() / expected < 5e-3);
}

#[test]
fn ball_end_groove_has_the_circular_profile() {
    let mut s = boxed(0.1);
    let tool = Tool::BallEnd {
        diameter: 10.0,
        flute_length: 25.0,
        shank: None,
    };
    let tip = 17.0; // 3 mm deep; the ball's centre at z = 22
    let a = ToolPose::new(Point3::new(-10.0, 25.0, tip), Vector3::z());
    let b = ToolPose::new(Point3::new(110.0, 25.0, tip), Vector3::z());
    s.cut_move(&tool, &a, &b, 3).unwrap();
    let f = s.family(2);
    let ix = node(&s, 0, 50.0);
    for iv in 0..f.nv {
        let y = s.coordinate(1, iv);
        let dy = y - 25.0;
        let top = f.ray(ix, iv)[0].hi;
        let expected = if dy.abs() < 5.0 {
            (22.0 - (25.0 - dy * dy).sqrt()).min(20.0)
        } else {
            20.0
        };
        assert!(
            (top - expected).abs() < 1e-6,
            "y = {y}: {top} vs {expected}"
        );
    }
    // Y rays at heights 17.5 .. 19.5: the groove's sides at 25 ± √(25 − (z − 22)²).
    let fy = s.family(1);
    for z in [17.55, 18.05, 19.05, 19.95] {
        let iz = node(&s, 2, z);
        let zc = s.coordinate(2, iz);
        let w = (25.0 - (zc - 22.0) * (zc - 22.0)).sqrt();
        let ray = fy.ray(ix, iz);
        assert_eq!(ray.len(), 2, "z = {zc}");
        assert!((ray[0].hi - (25.0 - w)).abs() < 1e-6 && (ray[1].lo - (25.0 + w)).abs() < 1e-6);
    }
}

#[test]
fn tilted_wheel_pressed_into_a_plane_leaves_the_elliptical_footprint() {
    let mut s = Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(100.0, 60.0, 40.0),
        0.1,
    )
    .unwrap();
    let (r, width) = (20.0, 30.0);
    let tool = Tool::ContactWheel {
        radius: r,
        width,
        edge_radius: 0.0,
    };
    let theta = 30f64.to_radians();
    // Rotation axis tilted 30° from Z in the XZ plane; the plane z = H
    // through the wheel centre cuts the cylinder in an ellipse of semi-axes
    // R / cos θ (along X) and R (along Y), inside the width since
    // R·tan θ = 11.5 < 15.
    let rot = Vector3::new(theta.sin(), 0.0, theta.cos());
    let iz = node(&s, 2, 30.0);
    let h = s.coordinate(2, iz);
    let centre = Point3::new(50.0, 30.0, h);
    let axis = Vector3::y(); // contact point → centre
    let pose = ToolPose::new(centre - r * axis, axis).with_reference(axis.cross(&rot));
    s.cut_pose(&tool, &pose, 1).unwrap();
    let f = s.family(0);
    let (a, b) = (r / theta.cos(), r);
    let mut rows = 0;
    for iy in 0..f.nu {
        let y = s.coordinate(1, iy);
        let ray = f.ray(iy, iz);
        let q = 1.0 - ((y - 30.0) / b).powi(2);
        if q > 1e-9 {
            let half = a * q.sqrt();
            assert_eq!(ray.len(), 2, "y = {y}");
            assert!(
                (ray[0].hi - (50.0 - half)).abs() < 1e-6,
                "y = {y}: {} vs {}",
                ray[0].hi,
                50.0 - half
            );
            assert!((ray[1].lo - (50.0 + half)).abs() < 1e-6);
            rows += 1;
        } else if q < -1e-9 {
            assert_eq!(ray.len(), 1);
        }
    }
    assert!(rows > 300);
}

#[test]
fn bad_stocks_are_errors_not_allocations() {
    use kinpost_stock::StockError;
    let (lo, hi) = (Point3::new(0.0, 0.0, 0.0), Point3::new(250.0, 80.0, 40.0));
    assert!(matches!(
        Stock::from_box(lo, hi, 0.001),
        Err(StockError::TooManyRays { .. })
    ));
    assert!(matches!(
        Stock::from_box(lo, hi, 0.0),
        Err(StockError::Resolution(_))
    ));
    assert!(matches!(
        Stock::from_box(hi, lo, 0.1),
        Err(StockError::EmptyBox)
    ));
    assert!(matches!(
        Stock::from_box(lo, Point3::new(f64::NAN, 1.0, 1.0), 0.1),
        Err(StockError::EmptyBox)
    ));
    // The default resolution of the brief's block: 0.05 mm.
    assert_eq!(kinpost_stock::default_resolution(lo, hi), 0.05);
}

#[test]
fn the_disc_wheel_grinds_with_its_face_around_its_centre() {
    // Li (B-spline grinding), §5: the face normal is the tool axis, the
    // contact point on the face's rim; the reference points to the centre.
    let mut s = Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(60.0, 60.0, 10.0),
        0.1,
    )
    .unwrap();
    let tool: Tool =
        toml::from_str("kind = \"disc-wheel\"\nradius = 20.0\nthickness = 5.0").unwrap();
    let pose =
        ToolPose::new(Point3::new(10.05, 30.05, 9.9), Vector3::z()).with_reference(Vector3::x());
    s.cut_pose(&tool, &pose, 2).unwrap();
    let f = s.family(2);
    // The face centre at (30.05, 30.05): the top lowered to the face.
    let centre = f.ray(300, 300);
    assert!((centre[0].hi - 9.9).abs() < 1e-12 && centre[0].hi_move == 2);
    // 19.9 mm from the centre still under the face, 20.1 mm outside it.
    assert!((f.ray(300 + 199, 300)[0].hi - 9.9).abs() < 1e-12);
    assert_eq!(f.ray(300 + 201, 300)[0].hi, 10.0);
    // Without a reference the disc's place is unknown: an error, not a guess.
    let bare = ToolPose::new(Point3::new(10.0, 30.0, 9.9), Vector3::z());
    assert!(s.cut_pose(&tool, &bare, 3).is_err());
}
