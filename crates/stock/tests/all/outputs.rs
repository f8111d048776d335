//! The part mesh is watertight and close to the dexels; the files read back.

use std::collections::HashMap;

use kinpost_stock::{
    BlockRef, Design, Mesh, PartMesh, Report, Stock, Tool, ToolPose, compare, contour, write_ply,
    write_stl, write_svg,
};
use nalgebra::{Point3, Vector3};

fn cut_part(h: f64) -> Stock {
    let mut s =
        Stock::from_box(Point3::new(0.0, 0.0, 0.0), Point3::new(20.0, 12.0, 6.0), h).unwrap();
    let ball = Tool::BallEnd {
        diameter: 4.0,
        flute_length: 10.0,
        shank: None,
    };
    let a = ToolPose::new(Point3::new(2.0, 4.0, 4.5), Vector3::z());
    let b = ToolPose::new(Point3::new(18.0, 8.0, 4.5), Vector3::z());
    s.cut_move(&ball, &a, &b, 0).unwrap();
    let wheel = Tool::ContactWheel {
        radius: 30.0,
        width: 8.0,
        edge_radius: 1.0,
    };
    let axis = Vector3::new(0.2, 0.0, 1.0).normalize();
    let p = ToolPose::new(Point3::new(10.0, 3.0, 5.7), axis).with_reference(Vector3::x());
    let q = ToolPose::new(Point3::new(12.0, 3.5, 5.6), Vector3::z()).with_reference(Vector3::x());
    s.cut_move(&wheel, &p, &q, 1).unwrap();
    s
}

/// Every undirected edge in exactly two triangles, once in each direction.
fn assert_watertight(m: &PartMesh) {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &m.triangles {
        assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
        for i in 0..3 {
            *directed.entry((t[i], t[(i + 1) % 3])).or_default() += 1;
        }
    }
    for (&(a, b), &n) in &directed {
        assert_eq!(n, 1, "directed edge {a}->{b} used {n} times");
        assert_eq!(
            directed.get(&(b, a)),
            Some(&1),
            "edge {a}-{b} not shared by exactly two triangles"
        );
    }
}

fn volume(m: &PartMesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| Vector3::from(m.vertices[i as usize]));
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

#[test]
fn part_mesh_is_watertight_and_encloses_the_dexel_volume() {
    let s = cut_part(0.1);
    let m = contour(&s);
    assert!(m.triangles.len() > 1000);
    assert_watertight(&m);
    let (v, expected) = (volume(&m), s.volume_mm3());
    // Within a layer of half a ray spacing over the surface (area ≈ 900 mm²).
    assert!(
        (v - expected).abs() < 0.5 * 0.1 * 900.0,
        "{v} vs {expected}"
    );
    // Every vertex within √3·h of the lattice box.
    for p in &m.vertices {
        for i in 0..3 {
            assert!(p[i] >= -0.2 && p[i] <= [20.0, 12.0, 6.0][i] + 0.2);
        }
    }
}

#[test]
fn a_box_meshes_to_its_exact_faces() {
    let s = Stock::from_box(Point3::new(0.0, 0.0, 0.0), Point3::new(3.0, 2.0, 1.0), 0.25).unwrap();
    let m = contour(&s);
    assert_watertight(&m);
    // Vertices on edges across a face are snapped onto it exactly.
    let on_face = m
        .vertices
        .iter()
        .filter(|p| {
            p[0] == 0.0 || p[0] == 3.0 || p[1] == 0.0 || p[1] == 2.0 || p[2] == 0.0 || p[2] == 1.0
        })
        .count();
    assert!(
        on_face * 2 > m.vertices.len(),
        "{on_face} of {}",
        m.vertices.len()
    );
}

#[test]
fn files_read_back() {
    let s = cut_part(0.2);
    let m = contour(&s);
    let mut stl = Vec::new();
    write_stl(&m, &mut stl).unwrap();
    let back = Mesh::read_stl(std::io::Cursor::new(&stl), "part.stl").unwrap();
    assert_eq!(back.triangles.len(), m.triangles.len());
    // The written STL is itself a closed solid: a stock from it has the volume.
    let again = Stock::from_mesh(&back, 0.2).unwrap();
    assert!((again.volume_mm3() - s.volume_mm3()).abs() < 0.05 * s.volume_mm3());

    let design = Design::from_mesh(Mesh::cuboid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(20.0, 12.0, 5.5),
    ))
    .unwrap();
    let cmp = compare(&s, &design, 0.01).unwrap();
    let mut ply = Vec::new();
    write_ply(&m, &cmp, 0.2, &mut ply).unwrap();
    let header_end = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let header = std::str::from_utf8(&ply[..header_end]).unwrap();
    assert!(header.contains(&format!("element vertex {}", m.vertices.len())));
    assert_eq!(
        ply.len() - header_end,
        m.vertices.len() * 19 + m.triangles.len() * 13
    );

    let mut svg = Vec::new();
    write_svg(&s, &cmp, &mut svg).unwrap();
    let svg = String::from_utf8(svg).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert!(svg.contains("gouge") && svg.contains("residual"));

    let blocks = vec![
        BlockRef {
            block: Some("N10".into()),
            line: 3,
        },
        BlockRef {
            block: Some("N20".into()),
            line: 4,
        },
    ];
    let r = Report::new("box 0,0,0 20,12,6", &s, &cmp, &blocks);
    assert!(r.gouge_max_mm > 0.4 && r.residual_max_mm > 0.4, "{r:?}");
    assert!(r.gouge_regions.iter().all(|g| g.line.is_some()));
    let json = serde_json::to_string(&r).unwrap();
    assert!(json.contains("\"gouge_regions\""));
}
