//! Exact intersections of a line with the tools' convex pieces and with
//! their sweeps along a straight move.
//!
//! A line is `o + t·d` (`d` unit). Every function returns the span of `t`
//! inside the solid, or `None`: the solids are convex, so the span is one
//! interval.
//!
//! Sweeps (pure translation by `v`, constant axis) are Minkowski sums of the
//! piece with the segment [0, v]:
//! * a sphere sweeps a capsule: the hull of the spans of the two end spheres
//!   and of the cylinder around the segment;
//! * a cylinder (a disc D of radius r, normal w, swept along its axis over
//!   [z0, z1]) sweeps D ⊕ P, P the parallelogram spanned by the axis segment
//!   and v. With v = v_a·w + L·û (û ⟂ w) and ê = w × û, a point (u, z, e) is
//!   in D ⊕ P iff |e| ≤ r and some β ∈ [0, 1] with z − β·v_a ∈ [z0, z1] has
//!   |u − β·L| ≤ ρ(e) = √(r² − e²). The admissible β form an interval
//!   [β_lo(z), β_hi(z)] (clamped linear functions of z), so the condition is
//!   z within [min(z0, z0 + v_a), max(z1, z1 + v_a)] and the four
//!   inequalities u − L ≤ ρ, −u ≤ ρ, u − L·ℓ_hi(z) ≤ ρ, L·ℓ_lo(z) − u ≤ ρ with
//!   ℓ linear. Along the line each is `a(t) ≤ √(r² − b(t)²)` with a, b
//!   linear: a convex set of (a, b) (a disc grown towards −a), so an interval
//!   given by one quadratic and two linear inequalities ([`half_disc`]).
//!   The span is the intersection of the five intervals: closed form, exact
//!   to rounding.
//!
//! The cone frustum (drill point) and the rounded disc (bull-nose corner,
//! wheel edge) have closed-form or convex-iteration spans at one pose; their
//! sweeps are sampled (see `SAMPLE_STEP_FRACTION`).

use nalgebra::Vector3;

use crate::tolerance::ROOT_MM;
use crate::tool::Piece;

/// A closed interval of the line parameter, possibly unbounded.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Span {
    /// Lower end.
    pub lo: f64,
    /// Upper end.
    pub hi: f64,
}

const ALL: Span = Span {
    lo: f64::NEG_INFINITY,
    hi: f64::INFINITY,
};

impl Span {
    fn new(lo: f64, hi: f64) -> Option<Span> {
        (lo <= hi).then_some(Span { lo, hi })
    }
    fn meet(self, o: Span) -> Option<Span> {
        Span::new(self.lo.max(o.lo), self.hi.min(o.hi))
    }
}

fn meet(a: Option<Span>, b: Option<Span>) -> Option<Span> {
    a?.meet(b?)
}

/// The hull of two optional spans.
pub fn hull(a: Option<Span>, b: Option<Span>) -> Option<Span> {
    match (a, b) {
        (Some(a), Some(b)) => Some(Span {
            lo: a.lo.min(b.lo),
            hi: a.hi.max(b.hi),
        }),
        (a, None) => a,
        (None, b) => b,
    }
}

/// `t` with `a0 + a1·t ≤ 0`.
fn linear_le0(a0: f64, a1: f64) -> Option<Span> {
    if a1 > 0.0 {
        Some(Span {
            lo: f64::NEG_INFINITY,
            hi: -a0 / a1,
        })
    } else if a1 < 0.0 {
        Some(Span {
            lo: -a0 / a1,
            hi: f64::INFINITY,
        })
    } else {
        (a0 <= 0.0).then_some(ALL)
    }
}

/// `t` with `lo ≤ z0 + dz·t ≤ hi`.
pub(crate) fn slab(z0: f64, dz: f64, lo: f64, hi: f64) -> Option<Span> {
    meet(linear_le0(lo - z0, -dz), linear_le0(z0 - hi, dz))
}

/// `t` with `a·t² + 2b·t + c ≤ 0`, for `a ≥ 0` (a convex quadratic).
pub fn quadratic_le0(a: f64, b: f64, c: f64) -> Option<Span> {
    // Below this the quadratic term cannot move a root by more than rounding
    // over any line length a stock can have.
    if a <= 1e-15 * (b.abs() + c.abs()).max(1e-300) || a == 0.0 {
        return linear_le0(c, 2.0 * b);
    }
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    // Stable roots: q = −(b + sign(b)·√disc); roots q/a and c/q.
    let q = -(b + s.copysign(b));
    if q == 0.0 {
        return Some(Span { lo: 0.0, hi: 0.0 });
    }
    let (r1, r2) = (q / a, c / q);
    Some(Span {
        lo: r1.min(r2),
        hi: r1.max(r2),
    })
}

/// `t` with `a(t) ≤ √(r² − b(t)²)` (and |b(t)| ≤ r), `a = a0 + a1·t`,
/// `b = b0 + b1·t`: the preimage of the convex set {(a, b): a ≤ 0, |b| ≤ r}
/// ∪ {a² + b² ≤ r²}, hence an interval, the hull of the two parts.
pub fn half_disc(a0: f64, a1: f64, b0: f64, b1: f64, r: f64) -> Option<Span> {
    let strip = meet(linear_le0(a0, a1), slab(b0, b1, -r, r));
    let disc = quadratic_le0(
        a1 * a1 + b1 * b1,
        a0 * a1 + b0 * b1,
        a0 * a0 + b0 * b0 - r * r,
    );
    hull(strip, disc)
}

/// The line in a piece's frame: axial coordinate `z0 + dz·t`, radial
/// vector `p⊥ + t·d⊥`.
#[derive(Debug, Clone, Copy)]
pub struct Local {
    z0: f64,
    dz: f64,
    /// |d⊥|²
    a: f64,
    /// p⊥·d⊥
    b: f64,
    /// |p⊥|²
    c: f64,
}

impl Local {
    /// The line `o + t·d` seen from the frame at `origin` with unit `axis`.
    pub fn new(
        o: &Vector3<f64>,
        d: &Vector3<f64>,
        origin: &Vector3<f64>,
        axis: &Vector3<f64>,
    ) -> Local {
        let p = o - origin;
        let z0 = p.dot(axis);
        let dz = d.dot(axis);
        let pp = p - z0 * axis;
        let dp = d - dz * axis;
        Local {
            z0,
            dz,
            a: dp.norm_squared(),
            b: pp.dot(&dp),
            c: pp.norm_squared(),
        }
    }
}

impl Local {
    /// The line along axis `k` of the part frame through the point whose
    /// `u` and `v` coordinates are `pu`, `pv` (the stock's rays): the same
    /// as [`Local::new`] with d = e_k, in a third of the arithmetic.
    #[inline]
    pub fn along(
        k: usize,
        u: usize,
        v: usize,
        pu: f64,
        pv: f64,
        origin: &Vector3<f64>,
        axis: &Vector3<f64>,
    ) -> Local {
        let mut p = [0.0; 3];
        p[u] = pu - origin[u];
        p[v] = pv - origin[v];
        p[k] = -origin[k];
        let z0 = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
        let pp = [
            p[0] - z0 * axis[0],
            p[1] - z0 * axis[1],
            p[2] - z0 * axis[2],
        ];
        let dz = axis[k];
        // d⊥ = e_k − dz·w, and p⊥·w = 0, so p⊥·d⊥ = p⊥_k.
        Local {
            z0,
            dz,
            a: 1.0 - dz * dz,
            b: pp[k],
            c: pp[0] * pp[0] + pp[1] * pp[1] + pp[2] * pp[2],
        }
    }
}

/// The span of a line inside a piece at one pose.
pub fn piece_span(piece: &Piece, l: &Local) -> Option<Span> {
    match *piece {
        Piece::Cylinder { z0, z1, r } => cylinder(l, z0, z1, r),
        Piece::Sphere { zc, r } => {
            // |p⊥ + t d⊥|² + (z(t) − zc)² ≤ r²
            let zr = l.z0 - zc;
            quadratic_le0(l.a + l.dz * l.dz, l.b + zr * l.dz, l.c + zr * zr - r * r)
        }
        Piece::Cone { z0, r0, z1, r1 } => cone(l, z0, r0, z1, r1),
        Piece::RoundedDisc { zc, disc, r } => rounded_disc(l, zc, disc, r),
    }
}

fn cylinder(l: &Local, z0: f64, z1: f64, r: f64) -> Option<Span> {
    let axial = slab(l.z0, l.dz, z0, z1)?;
    let radial = quadratic_le0(l.a, l.b, l.c - r * r)?;
    axial.meet(radial)
}

/// Frustum: ρ(t) ≤ g(t) = r0 + s·(z(t) − z0) on z ∈ [z0, z1]. Squaring
/// gives a quadratic whose zero set may be the two nappes of a double cone;
/// the frustum is convex, so its span is the hull of the sub-intervals
/// between the breakpoints (roots, slab ends, g = 0) where a midpoint
/// satisfies both ρ² ≤ g² and g ≥ 0.
fn cone(l: &Local, z0: f64, r0: f64, z1: f64, r1: f64) -> Option<Span> {
    let axial = slab(l.z0, l.dz, z0, z1)?;
    let s = (r1 - r0) / (z1 - z0);
    let (alpha, beta) = (r0 + s * (l.z0 - z0), s * l.dz);
    let (qa, qb, qc) = (l.a - beta * beta, l.b - alpha * beta, l.c - alpha * alpha);
    let inside = |t: f64| {
        let g = alpha + beta * t;
        g >= 0.0 && (l.a * t * t + 2.0 * l.b * t + l.c) <= g * g
    };
    // Bounded by the slab and by the cylinder of the larger radius.
    let rmax = r0.max(r1);
    let bounded = axial.meet(quadratic_le0(l.a, l.b, l.c - rmax * rmax)?)?;
    let (lo, hi) = (bounded.lo, bounded.hi);
    let mut cuts = [lo, hi, f64::NAN, f64::NAN, f64::NAN];
    let mut n = 2;
    if qa.abs() > 1e-15 {
        let disc = qb * qb - qa * qc;
        if disc >= 0.0 {
            let sq = disc.sqrt();
            cuts[n] = (-qb - sq) / qa;
            cuts[n + 1] = (-qb + sq) / qa;
            n += 2;
        }
    } else if qb != 0.0 {
        cuts[n] = -qc / (2.0 * qb);
        n += 1;
    }
    if beta != 0.0 {
        cuts[n] = -alpha / beta;
        n += 1;
    }
    let cuts = &mut cuts[..n];
    for c in cuts.iter_mut() {
        *c = c.clamp(lo, hi);
    }
    cuts.sort_by(f64::total_cmp);
    let mut span: Option<Span> = None;
    for w in cuts.windows(2) {
        if inside(0.5 * (w[0] + w[1])) {
            span = hull(span, Span::new(w[0], w[1]));
        }
    }
    if span.is_none() {
        // A span of zero length (the line touches the rim or the apex).
        span = cuts
            .iter()
            .find(|&&t| inside(t))
            .map(|&t| Span { lo: t, hi: t });
    }
    span
}

/// Points within `r` of the disc of radius `disc` at axial `zc`. The
/// squared distance to a convex set, D²(t), is convex and continuously
/// differentiable along the line, so f = D² − r² is found from each end of
/// the bounding sphere's span by Newton's method: from outside a convex
/// function's root, Newton's steps never pass it and converge to it
/// (quadratically where D² is smooth); a step that would go uphill means
/// the line misses the piece. Stops at `ROOT_MM`.
fn rounded_disc(l: &Local, zc: f64, disc: f64, r: f64) -> Option<Span> {
    let zr = l.z0 - zc;
    let big = disc + r;
    let bound = quadratic_le0(
        l.a + l.dz * l.dz,
        l.b + zr * l.dz,
        l.c + zr * zr - big * big,
    )?;
    let r2 = r * r;
    // f and f' at t.
    let eval = |t: f64| {
        let z = zr + l.dz * t;
        let rho = (l.a * t * t + 2.0 * l.b * t + l.c).max(0.0).sqrt();
        let out = (rho - disc).max(0.0);
        let mut d = 2.0 * z * l.dz;
        if out > 0.0 && rho > 0.0 {
            d += 2.0 * out * (l.a * t + l.b) / rho;
        }
        (z * z + out * out - r2, d)
    };
    let root = |start: f64, dir: f64| -> Option<f64> {
        let mut t = start;
        for _ in 0..200 {
            let (f, d) = eval(t);
            if f <= 0.0 {
                return Some(t);
            }
            if d * dir >= 0.0 {
                return None;
            }
            let step = -f / d;
            t += step;
            if step.abs() <= ROOT_MM {
                return Some(t);
            }
        }
        Some(t)
    };
    let lo = root(bound.lo, 1.0)?;
    let hi = root(bound.hi, -1.0)?;
    Span::new(lo, hi)
}

/// The span of the capsule swept by a sphere of radius `r` from `c0` to
/// `c0 + v`.
pub fn capsule_span(
    o: &Vector3<f64>,
    d: &Vector3<f64>,
    c0: &Vector3<f64>,
    v: &Vector3<f64>,
    r: f64,
) -> Option<Span> {
    let sphere = |c: &Vector3<f64>| {
        let oc = o - c;
        quadratic_le0(1.0, oc.dot(d), oc.norm_squared() - r * r)
    };
    let len = v.norm();
    let mut span = hull(sphere(c0), sphere(&(c0 + v)));
    if len > 0.0 {
        let w = v / len;
        let l = Local::new(o, d, c0, &w);
        span = hull(span, cylinder(&l, 0.0, len, r));
    }
    span
}

/// The span of the solid swept by the cylinder piece (radius `r`, axial
/// [z0, z1] about `origin` + z·`axis`) translated by `v` (see the module doc).
#[allow(clippy::too_many_arguments)]
pub fn cylinder_sweep_span(
    o: &Vector3<f64>,
    d: &Vector3<f64>,
    origin: &Vector3<f64>,
    axis: &Vector3<f64>,
    z0: f64,
    z1: f64,
    r: f64,
    v: &Vector3<f64>,
) -> Option<Span> {
    let va = v.dot(axis);
    let vp = v - va * axis;
    let len = vp.norm();
    let (zlo, zhi) = (z0.min(z0 + va), z1.max(z1 + va));
    if len <= 1e-12 * (1.0 + v.norm()) {
        let l = Local::new(o, d, origin, axis);
        return cylinder(&l, zlo, zhi, r);
    }
    let u = vp / len;
    let e = axis.cross(&u);
    let p = o - origin;
    let (u0, u1) = (p.dot(&u), d.dot(&u));
    let (w0, w1) = (p.dot(axis), d.dot(axis));
    let (e0, e1) = (p.dot(&e), d.dot(&e));
    let mut span = slab(w0, w1, zlo, zhi);
    span = meet(span, half_disc(u0 - len, u1, e0, e1, r));
    span = meet(span, half_disc(-u0, -u1, e0, e1, r));
    if va != 0.0 {
        // ℓ_hi(z) = (z − z_hi_end)/v_a, ℓ_lo(z) = (z − z_lo_end)/v_a with the
        // ends by the sign of v_a (β_hi from z − β·v_a ≥ z0 when v_a > 0).
        let (for_hi, for_lo) = if va > 0.0 { (z0, z1) } else { (z1, z0) };
        let k = len / va;
        // a = u − L·(w − for_hi)/v_a
        span = meet(
            span,
            half_disc(u0 - k * (w0 - for_hi), u1 - k * w1, e0, e1, r),
        );
        // a = L·(w − for_lo)/v_a − u
        span = meet(
            span,
            half_disc(k * (w0 - for_lo) - u0, k * w1 - u1, e0, e1, r),
        );
    }
    span
}

/// The span of the points within `a` of the triangle (p0, p1, p2): the
/// triangle grown by a ball is convex, the hull of the capsules of its
/// edges and of the prism {|n̂·(x − p0)| ≤ a} over the triangle (three edge
/// planes through n̂).
pub fn triangle_offset_span(
    o: &Vector3<f64>,
    d: &Vector3<f64>,
    p: [Vector3<f64>; 3],
    a: f64,
) -> Option<Span> {
    let mut span = None;
    for i in 0..3 {
        let (s, e) = (p[i], p[(i + 1) % 3]);
        span = hull(span, capsule_span(o, d, &s, &(e - s), a));
    }
    let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
    let len = n.norm();
    if len > 0.0 {
        let n = n / len;
        let rel = o - p[0];
        let mut prism = slab(rel.dot(&n), d.dot(&n), -a, a);
        for i in 0..3 {
            let (s, e) = (p[i], p[(i + 1) % 3]);
            // Inward normal of the edge plane (triangle counter-clockwise about n).
            let m = n.cross(&(e - s));
            let r = o - s;
            prism = meet(prism, linear_le0(-r.dot(&m), -d.dot(&m)));
        }
        span = hull(span, prism);
    }
    span
}
