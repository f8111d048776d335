//! Property tests: random bytes and random edits of valid STL files never
//! make the STL loader, the stock built from what loads, a cut, the
//! comparison or the part mesh panic; random text never makes the
//! process-file reader panic, and its diagnostics point into the text.

use std::io::Cursor;

use kinpost_stock::{Design, Mesh, ProcessModel, Stock, Tool, ToolPose, compare, contour};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

/// Everything a loaded mesh goes through, at a resolution that keeps the
/// lattice small.
fn exercise(bytes: &[u8]) {
    let Ok(mesh) = Mesh::read_stl(Cursor::new(bytes), "fuzz.stl") else {
        return;
    };
    let Some((lo, hi)) = mesh.bounds() else {
        return;
    };
    // 16 rays across the longest extent, and no finer than a micrometre.
    let extent = (hi - lo).amax();
    let h = if extent.is_finite() {
        (extent / 16.0).max(1e-3)
    } else {
        1.0
    };
    if let Ok(mut s) = Stock::from_mesh(&mesh, h) {
        let tool = Tool::BallEnd {
            diameter: 4.0 * h,
            flute_length: 8.0 * h,
            shank: None,
        };
        let mid = lo + (hi - lo) / 2.0;
        let a = ToolPose::new(mid, Vector3::z());
        let b = ToolPose::new(mid + Vector3::new(h, h, -h), Vector3::new(0.1, 0.0, 1.0));
        let _ = s.cut_move(&tool, &a, &b, 1);
        let _ = contour(&s);
        if let Ok(d) = Design::from_mesh(mesh.clone()) {
            let _ = compare(&s, &d, 0.01);
        }
    }
    let _ = Stock::from_mesh_offset(&mesh, h, h);
}

fn ascii_cube() -> String {
    let m = Mesh::cuboid(Point3::new(0.0, 0.0, 0.0), Point3::new(2.0, 1.0, 1.0));
    let mut s = String::from("solid cube\n");
    for t in &m.triangles {
        s.push_str("facet normal 0 0 0\nouter loop\n");
        for &i in t {
            let p = m.vertices[i as usize];
            s.push_str(&format!("vertex {} {} {}\n", p.x, p.y, p.z));
        }
        s.push_str("endloop\nendfacet\n");
    }
    s.push_str("endsolid cube\n");
    s
}

const PROCESS: &str = "[force]\naxis = \"H1\"\nnewtons = [[3000, 300.0], [3600, 0.0]]\n[wheel]\npreston_mm2_per_n = 1e-6\nstiffness_n_per_mm3 = 3.0\n";

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn random_bytes(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        exercise(&bytes);
    }

    #[test]
    fn binary_stl_with_random_payload(count in 0u32..20, payload in prop::collection::vec(any::<u8>(), 0..1200)) {
        let mut bytes = vec![0u8; 80];
        bytes.extend(count.to_le_bytes());
        bytes.extend(payload);
        exercise(&bytes);
    }

    #[test]
    fn edited_ascii_stl(pos in 0usize..2000, cut in 0usize..40, insert in "[ -~\n]{0,12}") {
        let mut s = ascii_cube();
        let pos = pos.min(s.len());
        let end = (pos + cut).min(s.len());
        s.replace_range(pos..end, &insert);
        exercise(s.as_bytes());
    }

    #[test]
    fn process_file_edits(pos in 0usize..200, cut in 0usize..20, insert in "[ -~\n]{0,10}") {
        let mut s = PROCESS.to_string();
        let pos = pos.min(s.len());
        let end = (pos + cut).min(s.len());
        s.replace_range(pos..end, &insert);
        if let Err(d) = ProcessModel::from_toml(&s, "p.toml") {
            prop_assert!(d.line <= s.split('\n').count());
        }
    }
}

#[test]
fn the_unedited_cube_loads_and_cuts() {
    let s = ascii_cube();
    let mesh = Mesh::read_stl(Cursor::new(s.as_bytes()), "cube.stl").unwrap();
    assert_eq!(mesh.triangles.len(), 12);
    exercise(s.as_bytes());
    assert!(ProcessModel::from_toml(PROCESS, "p.toml").is_ok());
}
