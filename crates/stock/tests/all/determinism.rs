//! Same input, same bytes, for any thread count.

use kinpost_stock::{Design, Mesh, Stock, Tool, ToolPose, compare, contour, write_ply, write_stl};
use nalgebra::{Point3, Vector3};

/// Every ray's intervals and move ids, as bytes.
fn bytes(s: &Stock) -> Vec<u8> {
    let mut out = Vec::new();
    for k in 0..3 {
        for ray in &s.family(k).rays {
            out.extend((ray.len() as u32).to_le_bytes());
            for seg in ray {
                out.extend(seg.lo.to_bits().to_le_bytes());
                out.extend(seg.hi.to_bits().to_le_bytes());
                out.extend(seg.lo_move.to_le_bytes());
                out.extend(seg.hi_move.to_le_bytes());
            }
        }
    }
    out
}

fn simulate() -> (Vec<u8>, Vec<u8>, Vec<u8>, String) {
    let mut s = Stock::from_box(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(30.0, 20.0, 10.0),
        0.2,
    )
    .unwrap();
    let wheel = Tool::ContactWheel {
        radius: 25.0,
        width: 10.0,
        edge_radius: 1.0,
    };
    let mut id = 0;
    for i in 0..20 {
        let x = 2.0 + i as f64;
        let lean = 0.1 * (i as f64).sin();
        let a = ToolPose::new(Point3::new(x, 8.0, 9.8), Vector3::new(lean, 0.0, 1.0))
            .with_reference(Vector3::x());
        let b = ToolPose::new(
            Point3::new(x + 1.0, 8.5, 9.7),
            Vector3::new(-lean, 0.05, 1.0),
        )
        .with_reference(Vector3::x());
        s.cut_move(&wheel, &a, &b, id).unwrap();
        id += 1;
    }
    let bull = Tool::BullNose {
        diameter: 6.0,
        corner_radius: 1.0,
        flute_length: 12.0,
        shank: None,
    };
    let ball = Tool::BallEnd {
        diameter: 4.0,
        flute_length: 12.0,
        shank: None,
    };
    for (tool, y) in [(bull, 15.0), (ball, 4.0)] {
        let a = ToolPose::new(Point3::new(1.0, y, 8.5), Vector3::z());
        let b = ToolPose::new(Point3::new(29.0, y + 1.0, 8.0), Vector3::z());
        s.cut_move(&tool, &a, &b, id).unwrap();
        id += 1;
    }
    let design = Design::from_mesh(Mesh::cuboid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(30.0, 20.0, 9.0),
    ))
    .unwrap();
    let cmp = compare(&s, &design, 0.01).unwrap();
    let m = contour(&s);
    let mut stl = Vec::new();
    write_stl(&m, &mut stl).unwrap();
    let mut ply = Vec::new();
    write_ply(&m, &cmp, 0.2, &mut ply).unwrap();
    (bytes(&s), stl, ply, format!("{cmp:?}"))
}

#[test]
fn the_result_is_the_same_bytes_for_1_2_and_4_threads() {
    let run = |n: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
            .install(simulate)
    };
    let one = run(1);
    assert!(one.0.len() > 50_000);
    for n in [2, 4] {
        let other = run(n);
        assert!(one.0 == other.0, "stock differs with {n} threads");
        assert!(one.1 == other.1, "STL differs with {n} threads");
        assert!(one.2 == other.2, "PLY differs with {n} threads");
        assert_eq!(one.3, other.3, "comparison differs with {n} threads");
    }
}
