//! The fast removal along one row of rays.
//!
//! [`crate::stock`]'s fast removal hands each row of rays (one family, one
//! `v` index) to [`cut_row`]. The solids are visited one after the other,
//! last first; for each, every ray within its bounds gets a *skip test*
//! (does the span this solid would compute there certainly start at or above
//! the ray's level m?) and the rays that fail it get their exact span, which
//! lowers m where it reaches the ray's top. Both passes are plain loops over
//! the rays of the solid's range, written without branches so that the
//! compiler vectorizes them; [`cut_row`] runs them compiled for AVX2 when the
//! processor has it (the same operations in the same order: the same bits on
//! every processor, see [`exact`]).
//!
//! Why skipping such a span changes nothing, bit for bit: the subtraction of
//! a union of spans from a ray depends only on the union within the ray's
//! material (first, last) (pieces that miss it are no-ops in
//! [`crate::dexel::subtract`], a piece that reaches past an end acts as if it
//! ended there), and a span that starts at or above m adds nothing there: m
//! is the ray's top, or the start of a span found that reaches the top.

use nalgebra::Vector3;

use crate::dexel::{Ray, remove_spans};
use crate::kernel::{Span, quadratic_lo_at_least, slab_lo_at_least};

/// A solid prepared for the rays along axis `K` of one family: the
/// constants of its span, taken from the same expressions as
/// [`crate::kernel`]'s functions.
#[derive(Debug, Clone, Copy)]
pub(crate) enum RowSolid {
    /// A cylinder piece (`Local::along` and `cylinder`).
    Cylinder {
        /// Frame origin and unit axis.
        origin: [f64; 3],
        axis: [f64; 3],
        z0: f64,
        z1: f64,
        r: f64,
    },
    /// A sphere piece (`Local::along` and the sphere of `piece_span`).
    Sphere {
        origin: [f64; 3],
        axis: [f64; 3],
        zc: f64,
        r: f64,
    },
    /// A sphere swept along a segment (`capsule_span`).
    Capsule(Capsule),
    /// No batch kernel: the scalar span, no skip test.
    Other,
}

/// The constants of `capsule_span` for rays along one axis.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Capsule {
    c0: [f64; 3],
    c1: [f64; 3],
    r: f64,
    /// The segment's length, its unit direction w, and for the ray
    /// direction d: d·w, d − (d·w)·w and |d − (d·w)·w|².
    len: f64,
    w: [f64; 3],
    dz: f64,
    dp: [f64; 3],
    a: f64,
    d: [f64; 3],
}

impl Capsule {
    /// The capsule of a sphere of radius `r` from `c0` to `c0 + v`, for rays
    /// along the unit vector `d` (the same expressions as `capsule_span`).
    pub(crate) fn new(c0: &Vector3<f64>, v: &Vector3<f64>, r: f64, d: &Vector3<f64>) -> Capsule {
        let c1 = c0 + v;
        let len = v.norm();
        // Only used when len > 0, as in `capsule_span`.
        let w = v / len;
        let dz = d.dot(&w);
        let dp = d - dz * w;
        Capsule {
            c0: (*c0).into(),
            c1: c1.into(),
            r,
            len,
            w: w.into(),
            dz,
            dp: dp.into(),
            a: dp.norm_squared(),
            d: (*d).into(),
        }
    }
}

/// What a row needs beyond its solids: where its rays are.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RowFrame {
    /// Ray axis and the two others (u the row's index).
    pub k: usize,
    pub u: usize,
    pub v: usize,
    /// Lattice origin along u, spacing, and the row's v coordinate.
    pub origin_u: f64,
    pub h: f64,
    pub pv: f64,
}

#[inline(always)]
fn sel(c: bool, a: f64, b: f64) -> f64 {
    if c { a } else { b }
}

/// A span as three values: ends and whether it exists.
#[derive(Clone, Copy)]
struct Opt {
    lo: f64,
    hi: f64,
    some: bool,
}

/// `kernel::linear_le0`, without branches.
#[inline(always)]
fn linear_le0(a0: f64, a1: f64) -> Opt {
    let q = -a0 / a1;
    let (pos, neg) = (a1 > 0.0, a1 < 0.0);
    Opt {
        lo: sel(neg, q, f64::NEG_INFINITY),
        hi: sel(pos, q, f64::INFINITY),
        some: pos | neg | (a0 <= 0.0),
    }
}

/// `Span::meet` of two optional spans (`kernel::meet`).
#[inline(always)]
fn meet(a: Opt, b: Opt) -> Opt {
    let lo = a.lo.max(b.lo);
    let hi = a.hi.min(b.hi);
    Opt {
        lo,
        hi,
        some: a.some & b.some & (lo <= hi),
    }
}

/// `kernel::hull`.
#[inline(always)]
fn hull(a: Opt, b: Opt) -> Opt {
    let both = a.some & b.some;
    Opt {
        lo: sel(both, a.lo.min(b.lo), sel(a.some, a.lo, b.lo)),
        hi: sel(both, a.hi.max(b.hi), sel(a.some, a.hi, b.hi)),
        some: a.some | b.some,
    }
}

/// `kernel::slab`.
#[inline(always)]
fn slab(z0: f64, dz: f64, lo: f64, hi: f64) -> Opt {
    meet(linear_le0(lo - z0, -dz), linear_le0(z0 - hi, dz))
}

/// `kernel::quadratic_le0`, without branches.
#[inline(always)]
fn quadratic_le0(a: f64, b: f64, c: f64) -> Opt {
    let lin = (a <= 1e-15 * (b.abs() + c.abs()).max(1e-300)) | (a == 0.0);
    let l = linear_le0(c, 2.0 * b);
    let disc = b * b - a * c;
    let s = disc.sqrt();
    let q = -(b + s.copysign(b));
    let qz = q == 0.0;
    let (r1, r2) = (q / a, c / q);
    Opt {
        lo: sel(lin, l.lo, sel(qz, 0.0, r1.min(r2))),
        hi: sel(lin, l.hi, sel(qz, 0.0, r1.max(r2))),
        some: (lin & l.some) | (!lin & !(disc < 0.0)),
    }
}

/// `kernel::cylinder` on the line (z0, dz, a, b, c) of `Local`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn cylinder(z0: f64, dz: f64, a: f64, b: f64, c: f64, zlo: f64, zhi: f64, r: f64) -> Opt {
    let axial = slab(z0, dz, zlo, zhi);
    let radial = quadratic_le0(a, b, c - r * r);
    meet(axial, radial)
}

/// `Local::along` for the ray through `pu` (axis `U`), `pv` (axis `V`)
/// along `K`: (z0, b, c); dz = axis[K] and a = 1 − dz² are constants.
#[inline(always)]
fn along<const K: usize, const U: usize, const V: usize>(
    pu: f64,
    pv: f64,
    origin: &[f64; 3],
    axis: &[f64; 3],
) -> (f64, f64, f64) {
    let mut p = [0.0; 3];
    p[U] = pu - origin[U];
    p[V] = pv - origin[V];
    p[K] = -origin[K];
    let z0 = p[0] * axis[0] + p[1] * axis[1] + p[2] * axis[2];
    let pp = [
        p[0] - z0 * axis[0],
        p[1] - z0 * axis[1],
        p[2] - z0 * axis[2],
    ];
    (z0, pp[K], pp[0] * pp[0] + pp[1] * pp[1] + pp[2] * pp[2])
}

/// The ray's origin o (o[K] = 0) as `stock` builds it.
#[inline(always)]
fn ray_origin<const K: usize, const U: usize, const V: usize>(pu: f64, pv: f64) -> [f64; 3] {
    let mut o = [0.0; 3];
    o[U] = pu;
    o[V] = pv;
    o
}

/// `a + b + c` as nalgebra's 3-vector dot product sums it.
#[inline(always)]
fn dot(x: &[f64; 3], y: &[f64; 3]) -> f64 {
    x[0] * y[0] + x[1] * y[1] + x[2] * y[2]
}

/// The sphere of `capsule_span`: the quadratic's (b, c).
#[inline(always)]
fn capsule_sphere(o: &[f64; 3], c: &[f64; 3], d: &[f64; 3], r: f64) -> (f64, f64) {
    let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
    (dot(&oc, d), dot(&oc, &oc) - r * r)
}

/// The cylinder part of `capsule_span`: `Local::new(o, d, c0, w)` → (z0, b, c).
#[inline(always)]
fn capsule_line(o: &[f64; 3], k: &Capsule) -> (f64, f64, f64) {
    let p = [o[0] - k.c0[0], o[1] - k.c0[1], o[2] - k.c0[2]];
    let z0 = dot(&p, &k.w);
    let pp = [p[0] - z0 * k.w[0], p[1] - z0 * k.w[1], p[2] - z0 * k.w[2]];
    (z0, dot(&pp, &k.dp), dot(&pp, &pp))
}

/// Scratch buffers of a row, kept by each thread from row to row.
#[derive(Default)]
pub(crate) struct Scratch {
    pu: Vec<f64>,
    first: Vec<f64>,
    last: Vec<f64>,
    m: Vec<f64>,
    q: Coefficients,
    flags: Vec<bool>,
    need: Vec<u32>,
    out: Vec<Opt>,
    found: Vec<(u32, Span)>,
    spans: Vec<Span>,
}

/// A solid that meets a row: its index and its first and last ray (row
/// indices, within the solid's bounds).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Active {
    pub solid: usize,
    pub a: usize,
    pub b: usize,
}

/// What [`cut_row`] needs of the solids: the prepared kernels, each
/// solid's extent along the rays, and the scalar span of the others.
pub(crate) struct RowSolids<'a> {
    pub prepared: &'a [RowSolid],
    /// Each solid's bounds along the rays (lo, hi).
    pub along: &'a [(f64, f64)],
    /// The span of solid `i` on the ray at (`pu`, `pv`), for
    /// [`RowSolid::Other`].
    pub other: &'a (dyn Fn(usize, f64, f64) -> Option<Span> + Sync),
}

/// Cuts one row: the rays `row[a..=b]` of every active solid (visited in
/// the order given), then subtracts from each ray the union of the spans it
/// kept, as the reference removal does.
pub(crate) fn cut_row(
    frame: &RowFrame,
    row: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    id: u32,
    scratch: &mut Scratch,
) {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2 (checked just above), the one
            // requirement of `cut_row_avx2`.
            unsafe { cut_row_avx2(frame, row, active, solids, id, scratch) };
            return;
        }
    }
    cut_row_any(frame, row, active, solids, id, scratch);
}

/// [`cut_row`] compiled for AVX2: the same operations, four lanes wide.
/// Rust never fuses a product and a sum, so the lanes round as the scalar
/// code does and the stock's bits do not depend on the processor.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn cut_row_avx2(
    frame: &RowFrame,
    row: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    id: u32,
    scratch: &mut Scratch,
) {
    cut_row_any(frame, row, active, solids, id, scratch);
}

#[inline(always)]
fn cut_row_any(
    frame: &RowFrame,
    row: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    id: u32,
    scratch: &mut Scratch,
) {
    match frame.k {
        0 => cut_row_k::<0, 1, 2>(frame, row, active, solids, id, scratch),
        1 => cut_row_k::<1, 0, 2>(frame, row, active, solids, id, scratch),
        _ => cut_row_k::<2, 0, 1>(frame, row, active, solids, id, scratch),
    }
}

/// The coefficients of one solid on the rays of its range.
#[inline(always)]
fn coefficients<const K: usize, const U: usize, const V: usize>(
    s: &RowSolid,
    pu: &[f64],
    pv: f64,
    q: &mut Coefficients,
) {
    let n = pu.len();
    q.resize(n);
    match *s {
        RowSolid::Cylinder {
            origin, axis, r, ..
        } => {
            for j in 0..n {
                let (lz, b, c) = along::<K, U, V>(pu[j], pv, &origin, &axis);
                (q.z[j], q.b[j], q.c[j]) = (lz, b, c - r * r);
            }
        }
        RowSolid::Sphere {
            origin,
            axis,
            zc,
            r,
        } => {
            let dz = axis[K];
            for j in 0..n {
                let (lz, b, c) = along::<K, U, V>(pu[j], pv, &origin, &axis);
                let zr = lz - zc;
                (q.b[j], q.c[j]) = (b + zr * dz, c + zr * zr - r * r);
            }
        }
        RowSolid::Capsule(ref k) => {
            for j in 0..n {
                let o = ray_origin::<K, U, V>(pu[j], pv);
                (q.b0[j], q.c0[j]) = capsule_sphere(&o, &k.c0, &k.d, k.r);
                (q.b1[j], q.c1[j]) = capsule_sphere(&o, &k.c1, &k.d, k.r);
                let (lz, b, c) = capsule_line(&o, k);
                (q.z[j], q.b[j], q.c[j]) = (lz, b, c - k.r * k.r);
            }
        }
        RowSolid::Other => {}
    }
}

/// Per-ray coefficients of a solid: for a piece, `Local`'s z0 (cylinder),
/// b and c of its quadratic (c already less r²); for a capsule, the two
/// spheres' (b, c) and the segment cylinder's (z0, b, c − r²).
#[derive(Default)]
struct Coefficients {
    z: Vec<f64>,
    b: Vec<f64>,
    c: Vec<f64>,
    b0: Vec<f64>,
    c0: Vec<f64>,
    b1: Vec<f64>,
    c1: Vec<f64>,
}

impl Coefficients {
    fn resize(&mut self, n: usize) {
        for v in [
            &mut self.z,
            &mut self.b,
            &mut self.c,
            &mut self.b0,
            &mut self.c0,
            &mut self.b1,
            &mut self.c1,
        ] {
            v.clear();
            v.resize(n, 0.0);
        }
    }
}

/// Whether each ray of the range needs the solid's span: within the
/// solid's extent along the ray (the reference's test) and not certainly
/// starting at or above the ray's m.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn flag<const K: usize>(
    s: &RowSolid,
    q: &Coefficients,
    (lo_k, hi_k): (f64, f64),
    first: &[f64],
    last: &[f64],
    m: &[f64],
    flags: &mut [bool],
) {
    let n = flags.len();
    let gate = |j: usize| !(hi_k <= first[j] || lo_k >= last[j]);
    match *s {
        RowSolid::Cylinder {
            axis, z0, z1, ..
        } => {
            let dz = axis[K];
            let a = 1.0 - dz * dz;
            for j in 0..n {
                let skip = slab_lo_at_least(q.z[j], dz, z0, z1, m[j])
                    | quadratic_lo_at_least(a, q.b[j], q.c[j], m[j]);
                flags[j] = gate(j) & !skip;
            }
        }
        RowSolid::Sphere { axis, .. } => {
            let dz = axis[K];
            let a = 1.0 - dz * dz + dz * dz;
            for j in 0..n {
                flags[j] = gate(j) & !quadratic_lo_at_least(a, q.b[j], q.c[j], m[j]);
            }
        }
        RowSolid::Capsule(ref k) => {
            for j in 0..n {
                // The hull starts at the lowest of its parts.
                let spheres = quadratic_lo_at_least(1.0, q.b0[j], q.c0[j], m[j])
                    & quadratic_lo_at_least(1.0, q.b1[j], q.c1[j], m[j]);
                let line = !(k.len > 0.0)
                    | slab_lo_at_least(q.z[j], k.dz, 0.0, k.len, m[j])
                    | quadratic_lo_at_least(k.a, q.b[j], q.c[j], m[j]);
                flags[j] = gate(j) & !(spheres & line);
            }
        }
        RowSolid::Other => {
            for j in 0..n {
                flags[j] = gate(j);
            }
        }
    }
}

/// The exact spans of the rays `need` (indices into the coefficients).
#[inline(always)]
fn exact<const K: usize>(s: &RowSolid, q: &Coefficients, need: &[u32], out: &mut [Opt]) {
    match *s {
        RowSolid::Cylinder {
            axis, z0, z1, ..
        } => {
            let dz = axis[K];
            let a = 1.0 - dz * dz;
            for (o, &j) in out.iter_mut().zip(need) {
                let j = j as usize;
                let axial = slab(q.z[j], dz, z0, z1);
                let radial = quadratic_le0(a, q.b[j], q.c[j]);
                *o = meet(axial, radial);
            }
        }
        RowSolid::Sphere { axis, .. } => {
            let dz = axis[K];
            let a = 1.0 - dz * dz + dz * dz;
            for (o, &j) in out.iter_mut().zip(need) {
                let j = j as usize;
                *o = quadratic_le0(a, q.b[j], q.c[j]);
            }
        }
        RowSolid::Capsule(ref k) => {
            for (o, &j) in out.iter_mut().zip(need) {
                let j = j as usize;
                let mut span = hull(
                    quadratic_le0(1.0, q.b0[j], q.c0[j]),
                    quadratic_le0(1.0, q.b1[j], q.c1[j]),
                );
                if k.len > 0.0 {
                    let axial = slab(q.z[j], k.dz, 0.0, k.len);
                    let radial = quadratic_le0(k.a, q.b[j], q.c[j]);
                    span = hull(span, meet(axial, radial));
                }
                *o = span;
            }
        }
        RowSolid::Other => {}
    }
}

#[inline(always)]
fn cut_row_k<const K: usize, const U: usize, const V: usize>(
    frame: &RowFrame,
    row: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    id: u32,
    scratch: &mut Scratch,
) {
    let Some(a_min) = active.iter().map(|s| s.a).min() else {
        return;
    };
    let b_max = active.iter().map(|s| s.b).max().unwrap_or(a_min);
    let sc = scratch;
    sc.first.clear();
    sc.last.clear();
    sc.pu.clear();
    for (iu, ray) in row[a_min..=b_max].iter().enumerate() {
        // An empty ray: no solid passes the test against its ends.
        let (f, l) = match (ray.first(), ray.last()) {
            (Some(f), Some(l)) => (f.lo, l.hi),
            _ => (f64::INFINITY, f64::NEG_INFINITY),
        };
        sc.first.push(f);
        sc.last.push(l);
        sc.pu
            .push(frame.origin_u + ((a_min + iu) as f64 + 0.5) * frame.h);
    }
    sc.m.clear();
    sc.m.extend_from_slice(&sc.last);
    sc.found.clear();
    let pv = frame.pv;
    for act in active {
        let (j0, j1) = (act.a - a_min, act.b - a_min);
        let s = &solids.prepared[act.solid];
        coefficients::<K, U, V>(s, &sc.pu[j0..=j1], pv, &mut sc.q);
        sc.flags.clear();
        sc.flags.resize(j1 + 1 - j0, false);
        flag::<K>(
            s,
            &sc.q,
            solids.along[act.solid],
            &sc.first[j0..=j1],
            &sc.last[j0..=j1],
            &sc.m[j0..=j1],
            &mut sc.flags,
        );
        sc.need.clear();
        for (j, &f) in sc.flags.iter().enumerate() {
            if f {
                sc.need.push(j as u32);
            }
        }
        if sc.need.is_empty() {
            continue;
        }
        sc.out.clear();
        sc.out.resize(
            sc.need.len(),
            Opt {
                lo: 0.0,
                hi: 0.0,
                some: false,
            },
        );
        if let RowSolid::Other = s {
            for (o, &j) in sc.out.iter_mut().zip(&sc.need) {
                if let Some(sp) = (solids.other)(act.solid, sc.pu[j0 + j as usize], pv) {
                    *o = Opt {
                        lo: sp.lo,
                        hi: sp.hi,
                        some: true,
                    };
                }
            }
        } else {
            exact::<K>(s, &sc.q, &sc.need, &mut sc.out);
        }
        // Keep them; a span that reaches the ray's top lowers its m.
        for (o, &j) in sc.out.iter().zip(&sc.need) {
            if o.some {
                let j = j0 + j as usize;
                sc.found.push((j as u32, Span { lo: o.lo, hi: o.hi }));
                if o.hi >= sc.last[j] && o.lo < sc.m[j] {
                    sc.m[j] = o.lo;
                }
            }
        }
    }
    // Subtract each ray's spans (their order does not matter: the union
    // is what is subtracted).
    sc.found.sort_by_key(|&(j, _)| j);
    let mut i = 0;
    while i < sc.found.len() {
        let j = sc.found[i].0;
        sc.spans.clear();
        while i < sc.found.len() && sc.found[i].0 == j {
            sc.spans.push(sc.found[i].1);
            i += 1;
        }
        remove_spans(&mut row[a_min + j as usize], &mut sc.spans, id);
    }
}
