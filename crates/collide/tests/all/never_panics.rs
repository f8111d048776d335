//! The collision world never panics: built from machine files whose solid
//! numbers are replaced by extreme values (those that load), from meshes
//! of any indices and coordinates, and checked at any joint values,
//! non-finite ones too.

use kinpost_collide::{Motion, World};
use kinpost_machine::{Body, Mesh, Role, Shape, Solid, builtin, machine_from_toml};
use proptest::prelude::*;
use std::sync::Arc;

const VALUES: &[&str] = &[
    "0", "-0", "1e-300", "5e-324", "1e-9", "1", "-1", "1e5", "999999", "-999999", "nan", "inf",
];

/// Byte ranges of the numbers after the first `[[solid]]` of `text`.
fn solid_numbers(text: &str) -> Vec<(usize, usize)> {
    let from = text.find("[[solid]]").unwrap_or(text.len());
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = from;
    while i < b.len() {
        if b[i].is_ascii_digit() && !b[i - 1].is_ascii_alphanumeric() {
            let start = if b[i - 1] == b'-' { i - 1 } else { i };
            let mut end = i;
            while end < b.len() && matches!(b[end], b'0'..=b'9' | b'.' | b'e') {
                end += 1;
            }
            out.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

/// Builds the world of `text` if it loads, and checks it at `poses`.
fn exercise(text: &str, poses: &[Vec<f64>]) {
    let Ok(m) = machine_from_toml(text, "fuzz.toml") else {
        return;
    };
    let Ok(world) = World::new(&m) else {
        return;
    };
    for q in poses {
        for motion in [Motion::Feed, Motion::Rapid] {
            for c in world.check_pose(q, motion) {
                assert!(c.distance_mm >= 0.0 || c.distance_mm.is_nan(), "{c:?}");
            }
        }
    }
    if let [a, b, ..] = poses {
        let _ = world.check_move(a, b, Motion::Rapid);
    }
}

fn poses(n: usize) -> Vec<Vec<f64>> {
    let mut out = vec![vec![0.0; n], vec![10.0; n], vec![-400.0; n]];
    for v in [f64::NAN, f64::INFINITY, -1e300, 1e12] {
        out.push(vec![v; n]);
    }
    out
}

#[test]
fn every_solid_number_replaced_by_extreme_values() {
    for name in ["mts1600", "htm40100h", "trunnion-ac"] {
        let text = builtin::source(name).unwrap();
        let n = machine_from_toml(text, name).unwrap().axes.len();
        let found = solid_numbers(text);
        assert!(found.len() > 20, "{name}");
        // Every third number (the whole set is slow to build in debug).
        for &(start, end) in found.iter().step_by(3) {
            for v in VALUES {
                let mutated = format!("{}{v}{}", &text[..start], &text[end..]);
                exercise(&mutated, &poses(n)[..3]);
            }
        }
        exercise(text, &poses(n));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Meshes of any indices and coordinates are refused or checked.
    #[test]
    fn any_mesh_is_refused_or_checked(
        vertices in proptest::collection::vec(proptest::array::uniform3(-1e3..1e3f64), 0..12),
        triangles in proptest::collection::vec(proptest::array::uniform3(0u32..14), 0..16),
        nan in any::<bool>(),
        q in proptest::collection::vec(-500.0..500.0f64, 6),
    ) {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let mut world = World::new(&m).unwrap();
        let mut vertices = vertices;
        if nan && !vertices.is_empty() {
            vertices[0][1] = f64::NAN;
        }
        let mesh = Mesh { source: "random".into(), vertices, triangles };
        let added = world.add_part("part", mesh.clone());
        let as_tool = world.add_solid(Solid {
            name: "tool-mesh".into(),
            on: Body::Tool,
            shape: Shape::Mesh(Arc::new(mesh)),
            home: nalgebra::Isometry3::identity(),
            group: "tool-mesh".into(),
            role: Role::Cutter,
        });
        if added.is_ok() || as_tool.is_ok() {
            let _ = world.check_pose(&q, Motion::Rapid);
            let _ = world.check_move(&q, &m.home_joints(), Motion::Rapid);
        }
    }
}
