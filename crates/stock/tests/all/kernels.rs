//! The closed-form spans against brute force: dense sampling of the sweep
//! parameter and point-membership tests written here from the definitions.

use kinpost_stock::Piece;
use kinpost_stock::clip::piece_in_box;
use kinpost_stock::kernel::{Local, capsule_span, cylinder_sweep_span, piece_span};
use nalgebra::{Point3, Vector3};
use proptest::prelude::*;

fn unit(a: f64, b: f64) -> Vector3<f64> {
    // Spherical angles → unit vector.
    Vector3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos())
}

/// Whether x is in the piece (from the definitions, not the library).
fn inside(piece: &Piece, origin: &Vector3<f64>, axis: &Vector3<f64>, x: &Vector3<f64>) -> bool {
    let p = x - origin;
    let z = p.dot(axis);
    let rho = (p - z * axis).norm();
    match *piece {
        Piece::Cylinder { z0, z1, r } => z >= z0 && z <= z1 && rho <= r,
        Piece::Sphere { zc, r } => (p - zc * axis).norm() <= r,
        Piece::Cone { z0, r0, z1, r1 } => {
            z >= z0 && z <= z1 && rho <= r0 + (r1 - r0) * (z - z0) / (z1 - z0)
        }
        Piece::RoundedDisc { zc, disc, r } => {
            ((z - zc).powi(2) + (rho - disc).max(0.0).powi(2)).sqrt() <= r
        }
    }
}

/// The hull of the points of the line inside the piece, sampled.
fn sampled(
    piece: &Piece,
    origin: &Vector3<f64>,
    axis: &Vector3<f64>,
    o: &Vector3<f64>,
    d: &Vector3<f64>,
    n: usize,
) -> Option<(f64, f64)> {
    let mut out: Option<(f64, f64)> = None;
    for i in 0..=n {
        let t = -40.0 + 80.0 * i as f64 / n as f64;
        if inside(piece, origin, axis, &(o + t * d)) {
            out = Some(out.map_or((t, t), |(a, b)| (a.min(t), b.max(t))));
        }
    }
    out
}

fn piece_strategy() -> impl Strategy<Value = Piece> {
    prop_oneof![
        (0.1f64..5.0, 0.1f64..5.0, 0.2f64..6.0).prop_map(|(a, l, r)| Piece::Cylinder {
            z0: -a,
            z1: l,
            r
        }),
        (-3.0f64..3.0, 0.2f64..6.0).prop_map(|(zc, r)| Piece::Sphere { zc, r }),
        (0.0f64..3.0, 0.2f64..6.0, 0.1f64..5.0).prop_map(|(r0, r1, l)| Piece::Cone {
            z0: -1.0,
            r0,
            z1: l,
            r1
        }),
        (-2.0f64..2.0, 0.0f64..5.0, 0.1f64..2.0).prop_map(|(zc, disc, r)| Piece::RoundedDisc {
            zc,
            disc,
            r
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn piece_spans_match_point_membership(
        piece in piece_strategy(),
        (a, b) in (0.0f64..6.3, 0.0f64..3.15),
        (c, e) in (0.0f64..6.3, 0.0f64..3.15),
        off in prop::array::uniform3(-6.0f64..6.0),
    ) {
        let axis = unit(a, b);
        let d = unit(c, e);
        let origin = Vector3::new(0.3, -0.2, 0.1);
        let o = Vector3::from(off);
        let n = 40_000;
        let step = 80.0 / n as f64;
        let span = piece_span(&piece, &Local::new(&o, &d, &origin, &axis));
        let brute = sampled(&piece, &origin, &axis, &o, &d, n);
        match (span, brute) {
            (Some(s), Some((lo, hi))) => {
                prop_assert!(s.lo <= lo + 1e-7 && s.hi >= hi - 1e-7, "{s:?} vs {lo}..{hi}");
                prop_assert!(s.lo >= lo - step - 1e-7 && s.hi <= hi + step + 1e-7, "{s:?} vs {lo}..{hi}");
            }
            (Some(s), None) => prop_assert!(s.hi - s.lo <= step + 1e-7, "{s:?} but no sample inside"),
            (None, Some((lo, hi))) => prop_assert!(false, "missed {lo}..{hi}"),
            (None, None) => {}
        }
    }

    #[test]
    fn the_stock_rays_fast_frame_gives_the_same_spans(
        piece in piece_strategy(),
        (a, b) in (0.0f64..6.3, 0.0f64..3.15),
        k in 0usize..3,
        (pu, pv) in (-6.0f64..6.0, -6.0f64..6.0),
    ) {
        let axis = unit(a, b);
        let origin = Vector3::new(0.3, -0.2, 0.1);
        let (u, v) = match k { 0 => (1, 2), 1 => (0, 2), _ => (0, 1) };
        let mut o = Vector3::zeros();
        o[u] = pu;
        o[v] = pv;
        let mut d = Vector3::zeros();
        d[k] = 1.0;
        let slow = piece_span(&piece, &Local::new(&o, &d, &origin, &axis));
        let fast = piece_span(&piece, &Local::along(k, u, v, pu, pv, &origin, &axis));
        match (slow, fast) {
            (Some(s), Some(f)) => prop_assert!((s.lo - f.lo).abs() < 1e-7 && (s.hi - f.hi).abs() < 1e-7, "{s:?} {f:?}"),
            (None, None) => {}
            (s, f) => prop_assert!(s.or(f).unwrap().hi - s.or(f).unwrap().lo < 1e-6, "{s:?} {f:?}"),
        }
    }

    #[test]
    fn sweeps_match_dense_sampling(
        cyl in any::<bool>(),
        (z0, z1, r) in (-3.0f64..0.0, 0.1f64..4.0, 0.3f64..4.0),
        (a, b) in (0.0f64..6.3, 0.0f64..3.15),
        (c, e) in (0.0f64..6.3, 0.0f64..3.15),
        vv in prop::array::uniform3(-3.0f64..3.0),
        off in prop::array::uniform3(-5.0f64..5.0),
    ) {
        let axis = unit(a, b);
        let d = unit(c, e);
        let origin = Vector3::new(0.1, 0.2, -0.3);
        let v = Vector3::from(vv);
        let o = Vector3::from(off);
        let piece = if cyl { Piece::Cylinder { z0, z1, r } } else { Piece::Sphere { zc: z1, r } };
        let exact = if cyl {
            cylinder_sweep_span(&o, &d, &origin, &axis, z0, z1, r, &v)
        } else {
            capsule_span(&o, &d, &(origin + z1 * axis), &v, r)
        };
        // The union over 2001 positions along the move, each exact.
        let n = 2000;
        let mut hull: Option<(f64, f64)> = None;
        for i in 0..=n {
            let org = origin + v * (i as f64 / n as f64);
            if let Some(s) = piece_span(&piece, &Local::new(&o, &d, &org, &axis)) {
                hull = Some(hull.map_or((s.lo, s.hi), |(l, h)| (l.min(s.lo), h.max(s.hi))));
            }
        }
        // Between two positions the boundary moves by at most |v|/n.
        let slack = 4.0 * v.norm() / n as f64 + 1e-7;
        match (exact, hull) {
            (Some(s), Some((lo, hi))) => {
                prop_assert!(s.lo <= lo + 1e-7 && s.hi >= hi - 1e-7, "{s:?} vs {lo}..{hi}");
                prop_assert!(s.lo >= lo - slack && s.hi <= hi + slack, "{s:?} vs {lo}..{hi}");
            }
            (Some(s), None) => prop_assert!(s.hi - s.lo <= slack, "{s:?} but no sampled position meets the line"),
            (None, Some((lo, hi))) => prop_assert!(false, "missed {lo}..{hi}"),
            (None, None) => {}
        }
    }

    #[test]
    fn clipped_bounds_hold_every_point_of_the_piece_in_the_box(
        piece in piece_strategy(),
        (a, b) in (0.0f64..6.3, 0.0f64..3.15),
        lo in prop::array::uniform3(-4.0f64..0.0),
        size in prop::array::uniform3(0.01f64..5.0),
        seed in any::<u64>(),
    ) {
        let axis = unit(a, b);
        let origin = Point3::new(0.2, -0.1, 0.3);
        let hi: [f64; 3] = std::array::from_fn(|i| lo[i] + size[i]);
        let bounds = piece_in_box(&piece, &origin, &axis, &(lo, hi));
        let mut state = seed | 1;
        let mut next = || { state ^= state << 13; state ^= state >> 7; state ^= state << 17; (state >> 11) as f64 / (1u64 << 53) as f64 };
        // Random points of the piece's bounding cube, kept when inside it.
        for _ in 0..20000 {
            let p = Vector3::new(lo[0] + size[0] * next(), lo[1] + size[1] * next(), lo[2] + size[2] * next());
            if inside(&piece, &origin.coords, &axis, &p) {
                let Some((blo, bhi)) = bounds else { return Err(TestCaseError::fail(format!("{p:?} in the piece and the box but no bounds"))) };
                for i in 0..3 {
                    prop_assert!(p[i] >= blo[i] - 1e-9 && p[i] <= bhi[i] + 1e-9, "{p:?} outside {blo:?}..{bhi:?}");
                }
            }
        }
    }
}
