//! Tight bounds of a tool piece within the stock's box, so a cut visits
//! only the rays that can meet the piece where material can be.
//!
//! For a convex piece K and a box B = ∩ slabs S_j, bbox(K ∩ B) ⊆ B ∩
//! bbox(K) ∩_j bbox(K ∩ S_j). For a cylinder the extreme points of K ∩ S_j
//! lie on its rim discs clipped to S_j (rim arcs and the chords' ends) or
//! on the sections of its lateral surface by the slab's planes (ellipse
//! arcs within the cylinder's length, extreme where a sinusoid is): all
//! closed form. A wheel pressed 0.05 mm into a flat is thus bounded by its 4.5 mm
//! contact cap, not by its 100 mm diameter. Other pieces keep their own
//! bounds, cut to the box.

use nalgebra::{Point3, Vector3};

use crate::tool::Piece;

/// Axis-aligned bounds.
pub type Aabb = ([f64; 3], [f64; 3]);

fn meet(a: Aabb, b: Aabb) -> Aabb {
    (
        std::array::from_fn(|i| a.0[i].max(b.0[i])),
        std::array::from_fn(|i| a.1[i].min(b.1[i])),
    )
}

/// Whether the bounds are empty.
pub fn is_empty(b: &Aabb) -> bool {
    (0..3).any(|i| !(b.0[i] <= b.1[i]))
}

struct Grow {
    lo: [f64; 3],
    hi: [f64; 3],
    any: bool,
}

impl Grow {
    fn new() -> Self {
        Grow {
            lo: [f64::INFINITY; 3],
            hi: [f64::NEG_INFINITY; 3],
            any: false,
        }
    }
    fn add(&mut self, p: [f64; 3]) {
        for i in 0..3 {
            self.lo[i] = self.lo[i].min(p[i]);
            self.hi[i] = self.hi[i].max(p[i]);
        }
        self.any = true;
    }
}

/// Two unit vectors across the axis.
fn frame(w: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let a = if w.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let e1 = w.cross(&a).normalize();
    (e1, w.cross(&e1))
}

/// Points of the disc (centre c, radius r, in the plane of e1, e2) that can
/// be extreme in K ∩ {lo ≤ x_j ≤ hi}: the rim's extremes along every axis
/// when inside the slab, and where the rim crosses the slab's planes.
#[allow(clippy::too_many_arguments)]
fn disc_in_slab(
    c: &Vector3<f64>,
    r: f64,
    e1: &Vector3<f64>,
    e2: &Vector3<f64>,
    j: usize,
    lo: f64,
    hi: f64,
    g: &mut Grow,
) {
    let at = |phi: f64| (c + r * (phi.cos() * e1 + phi.sin() * e2)).into();
    let inside = |p: &[f64; 3]| p[j] >= lo - 1e-12 && p[j] <= hi + 1e-12;
    for i in 0..3 {
        let phi = (r * e2[i]).atan2(r * e1[i]);
        for p in [at(phi), at(phi + std::f64::consts::PI)] {
            if inside(&p) {
                g.add(p);
            }
        }
    }
    // Rim ∩ planes x_j = P: r·(cos φ e1_j + sin φ e2_j) = P − c_j.
    let (a, b) = (r * e1[j], r * e2[j]);
    let amp = a.hypot(b);
    if amp > 0.0 {
        let psi = b.atan2(a);
        for plane in [lo, hi] {
            let q = (plane - c[j]) / amp;
            if q.abs() <= 1.0 {
                let d = q.acos();
                g.add(at(psi + d));
                g.add(at(psi - d));
            }
        }
    }
}

/// Bounds of a cylinder piece within the slab `lo ≤ x_j ≤ hi`.
#[allow(clippy::too_many_arguments)]
fn cylinder_in_slab(
    o: &Vector3<f64>,
    w: &Vector3<f64>,
    z0: f64,
    z1: f64,
    r: f64,
    j: usize,
    lo: f64,
    hi: f64,
) -> Option<Aabb> {
    let (e1, e2) = frame(w);
    let mut g = Grow::new();
    for z in [z0, z1] {
        disc_in_slab(&(o + z * w), r, &e1, &e2, j, lo, hi, &mut g);
    }
    if w[j].abs() > 1e-12 {
        for plane in [lo, hi] {
            // The plane's section of the lateral surface: the ellipse
            // φ ↦ O + s(φ)·w + r·(cos φ e1 + sin φ e2) with s(φ) from
            // x_j = plane, kept where s is within [z0, z1] (where it leaves
            // that range it meets the rims, whose crossings are added
            // above). Along axis i it is A + B cos φ + C sin φ, extreme at
            // φ = atan2(C, B) and its opposite.
            let base = (plane - o[j]) / w[j];
            let s_of = |phi: f64| base - r * (phi.cos() * e1[j] + phi.sin() * e2[j]) / w[j];
            for i in 0..3 {
                let k = w[i] / w[j];
                let (bi, ci) = (r * (e1[i] - e1[j] * k), r * (e2[i] - e2[j] * k));
                let phi = ci.atan2(bi);
                for ph in [phi, phi + std::f64::consts::PI] {
                    let s = s_of(ph);
                    if s >= z0 - 1e-12 && s <= z1 + 1e-12 {
                        g.add((o + s * w + r * (ph.cos() * e1 + ph.sin() * e2)).into());
                    }
                }
            }
        }
    }
    if !g.any {
        // The whole piece inside the slab has its extremes on the rims
        // (added above); nothing added means it misses the slab.
        return None;
    }
    Some((g.lo, g.hi))
}

/// Bounds of a sphere within the slab `lo ≤ x_j ≤ hi`: its own extent
/// where its extreme points are inside, else the circle of the nearer
/// plane.
fn sphere_in_slab(c: &Vector3<f64>, r: f64, j: usize, lo: f64, hi: f64) -> Option<Aabb> {
    let (a, b) = ((c[j] - r).max(lo), (c[j] + r).min(hi));
    if a > b {
        return None;
    }
    // Across j, the widest section is at the slab point nearest the centre.
    let near = c[j].clamp(a, b);
    let half = (r * r - (near - c[j]).powi(2)).max(0.0).sqrt();
    let mut out = (c.map(|x| x - half).into(), c.map(|x| x + half).into());
    let (lo_b, hi_b): &mut ([f64; 3], [f64; 3]) = &mut out;
    lo_b[j] = a;
    hi_b[j] = b;
    Some(out)
}

/// Bounds of the piece at `origin` along `axis`, within the box.
pub fn piece_in_box(
    piece: &Piece,
    origin: &Point3<f64>,
    axis: &Vector3<f64>,
    boxed: &Aabb,
) -> Option<Aabb> {
    let (lo, hi) = piece.bounds(origin, axis);
    let mut b = meet(([lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]), *boxed);
    if is_empty(&b) {
        return None;
    }
    for j in 0..3 {
        let (lo, hi) = (boxed.0[j], boxed.1[j]);
        let s = match *piece {
            Piece::Cylinder { z0, z1, r } => {
                cylinder_in_slab(&origin.coords, axis, z0, z1, r, j, lo, hi)?
            }
            Piece::Sphere { zc, r } => sphere_in_slab(&(origin.coords + zc * axis), r, j, lo, hi)?,
            Piece::RoundedDisc { zc, disc, r } => {
                // (disc ⊕ ball) ∩ slab ⊆ (disc ∩ slab grown by r) ⊕ ball.
                let (e1, e2) = frame(axis);
                let mut g = Grow::new();
                disc_in_slab(
                    &(origin.coords + zc * axis),
                    disc,
                    &e1,
                    &e2,
                    j,
                    lo - r,
                    hi + r,
                    &mut g,
                );
                if !g.any {
                    return None;
                }
                (g.lo.map(|c| c - r), g.hi.map(|c| c + r))
            }
            Piece::Cone { .. } => continue,
        };
        b = meet(b, s);
        if is_empty(&b) {
            return None;
        }
    }
    Some(b)
}

/// Bounds of the piece swept by `v` within the box: the piece within the
/// box reached back by v, swept forward by v (x in the box and on the
/// sweep has x − s·v in the piece and in the box − s·v).
pub fn swept_in_box(
    piece: &Piece,
    origin: &Point3<f64>,
    axis: &Vector3<f64>,
    v: &Vector3<f64>,
    boxed: &Aabb,
) -> Option<Aabb> {
    let back: Aabb = (
        std::array::from_fn(|i| boxed.0[i] - v[i].max(0.0)),
        std::array::from_fn(|i| boxed.1[i] - v[i].min(0.0)),
    );
    let b = piece_in_box(piece, origin, axis, &back)?;
    let grown: Aabb = (
        std::array::from_fn(|i| b.0[i] + v[i].min(0.0)),
        std::array::from_fn(|i| b.1[i] + v[i].max(0.0)),
    );
    let m = meet(grown, *boxed);
    (!is_empty(&m)).then_some(m)
}
