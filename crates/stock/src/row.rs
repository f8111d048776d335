//! The fast removal on a tile of rows of rays.
//!
//! The stock's fast removal hands the rays of a batch of moves to
//! [`cut_tile`], eight rows of one family at a time. Each ray keeps a top
//! level m, at first the top of its material (`last`), and a bottom level
//! mb, at first its start (`first`), each with the move that set it. The
//! solids are visited in the order given (the batch's last sample first,
//! then back through the batch halving the stride, so that every ray soon
//! meets a solid near its deepest); for each, whole segments of its rays
//! whose spans certainly start above their levels are dropped, for all the
//! tile's rows at once and then row by row (interval enclosures, [`Iv`]),
//! and the other rays are taken four at a time ([`crate::lanes`]): a *skip
//! test* asks whether the span the solid would compute there certainly
//! starts at or above m, without a root or a quotient
//! ([`quadratic_lo_at_least`]), and the rays that fail it get their exact
//! span, with the operations, in the order, of [`crate::kernel`]'s scalar
//! functions. A span that reaches the ray's top lowers m to its start; one
//! that starts at or below the ray's start and ends inside raises mb to its
//! end. At the end, a ray whose spans all reached its top or its start
//! loses (m, top) and (start, mb); a ray with a span that ends inside its
//! material at both ends (a slot across the ray) is cut move by move by the
//! reference procedure, with its levels in the places of the moves that
//! set them.
//!
//! Why this is the stock of the reference cutting the moves one by one,
//! bit for bit: the subtraction of a union of spans from a ray
//! ([`remove_spans`]) depends only on the union within the ray's material
//! (first, last): pieces that miss it are no-ops in [`subtract`], and a
//! piece that reaches past an end acts as if it ended there (no piece is
//! kept beyond it). A span that starts at or above m adds nothing within
//! the material: m is the top, or the start of a span that reaches the top.
//! The spans that reach the top, whichever their moves, remove everything
//! above the lowest start among them, and its end is made (and named) by
//! the first move to reach it: a later move lowers a level from at or
//! below it, an earlier one only from strictly below. So `subtract(m, +∞)`
//! as the move that set m does what all those moves do; the same holds
//! below mb (whose spans are computed, not skipped), and the two cuts
//! commute.
//!
//! [`cut_tile`] runs compiled for AVX2 when the processor has it, else for
//! the x86-64 baseline (or any other target): the same operations on the
//! same lanes, so the same bits on every processor and for any thread count
//! (each ray is cut alone).

use nalgebra::Vector3;

use crate::dexel::{Ray, remove_spans, subtract};
use crate::kernel::Span;
use crate::lanes::{F, M, W};
use crate::tolerance::SLIVER_MM;

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

/// What a tile of rows needs beyond its solids: where its rays are.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RowFrame<'a> {
    /// The rays' axis (the rows run along the first other axis).
    pub k: usize,
    /// Lattice origin along the rows, spacing, and each row's coordinate
    /// on the second other axis (increasing).
    pub origin_u: f64,
    pub h: f64,
    pub pv: &'a [f64],
    /// Rays a row of the stock holds.
    pub nu: usize,
}

/// A span on four rays: its ends and whether it exists.
#[derive(Clone, Copy)]
struct Opt {
    lo: F,
    hi: F,
    some: M,
}

#[inline(always)]
fn s(x: f64) -> F {
    F::splat(x)
}

/// `kernel::linear_le0`: t with a0 + a1·t ≤ 0.
#[inline(always)]
fn linear_le0(a0: F, a1: F) -> Opt {
    let q = (-a0) / a1;
    let (pos, neg) = (a1.gt(s(0.0)), a1.lt(s(0.0)));
    Opt {
        lo: neg.select(q, s(f64::NEG_INFINITY)),
        hi: pos.select(q, s(f64::INFINITY)),
        some: pos | neg | a0.le(s(0.0)),
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
        some: a.some & b.some & lo.le(hi),
    }
}

/// `kernel::hull`.
#[inline(always)]
fn hull(a: Opt, b: Opt) -> Opt {
    let both = a.some & b.some;
    Opt {
        lo: both.select(a.lo.min(b.lo), a.some.select(a.lo, b.lo)),
        hi: both.select(a.hi.max(b.hi), a.some.select(a.hi, b.hi)),
        some: a.some | b.some,
    }
}

/// `kernel::slab`: t with lo ≤ z0 + dz·t ≤ hi.
#[inline(always)]
fn slab(z0: F, dz: f64, lo: f64, hi: f64) -> Opt {
    meet(
        linear_le0(s(lo) - z0, s(-dz)),
        linear_le0(z0 - s(hi), s(dz)),
    )
}

/// `kernel::quadratic_le0`: t with a·t² + 2b·t + c ≤ 0.
#[inline(always)]
fn quadratic_le0(a: F, b: F, c: F) -> Opt {
    let lin = a.le(s(1e-15) * (b.abs() + c.abs()).max(s(1e-300))) | a.eq(s(0.0));
    let l = linear_le0(c, s(2.0) * b);
    let disc = b * b - a * c;
    let sq = disc.sqrt();
    let q = -(b + sq.copysign(b));
    let qz = q.eq(s(0.0));
    let (r1, r2) = (q / a, c / q);
    Opt {
        lo: lin.select(l.lo, qz.select(s(0.0), r1.min(r2))),
        hi: lin.select(l.hi, qz.select(s(0.0), r1.max(r2))),
        some: (lin & l.some) | (!lin & !disc.lt(s(0.0))),
    }
}

// ---------------------------------------------------------------------------
// The skip tests: certain bounds without roots or quotients.
//
// They decide whether a span, *as computed* (bits and all), starts at or
// above m, from the very coefficients the exact kernels use; sums and
// products only, each compared with a margin that bounds its rounding.

/// Unit roundoff of f64 (half an ulp of 1).
const U: f64 = f64::EPSILON / 2.0;
/// A margin of 32 u: every rounded product or sum below is within (1 + u)
/// of its exact value, and at most a handful are chained before a margin
/// is applied.
const SLACK: f64 = 32.0 * U;
/// An absolute floor under every margin: errors of results in the
/// subnormal range (far below any length in mm).
const TINY: f64 = 1e-290;

/// A certain lower bound of the exact value of the rounded `x`, where `x`
/// is the result of one or two rounded operations on exact operands whose
/// magnitudes sum to at most `scale`.
#[inline(always)]
fn lower(x: F, scale: F) -> F {
    x - s(SLACK) * scale - s(TINY)
}

/// A certain upper bound, likewise.
#[inline(always)]
fn upper(x: F, scale: F) -> F {
    x + s(SLACK) * scale + s(TINY)
}

/// Whether the lower end of the span [`quadratic_le0`]`(a, b, c)` computes
/// is certainly ≥ `m`, or that span certainly empty (lanes set); a clear
/// lane is "not certain".
///
/// Let d be the computed discriminant (the float `quadratic_le0` computes,
/// d = b² − a·c + e with |e| ≤ 2.01u(b² + |a·c|)), Q = |b| + √d and σ =
/// −sign b. The computed s = fl(√d) and |q| = fl(|b| + s) are within (1 ±
/// u) and (1 ± 2.01u) of √d and Q, so the computed roots q/a and c/q are
/// within a relative 3.1u of X₁ = σ·Q/a and X₂ = σ·c/Q, and their minimum
/// (the span's start) is ≥ m when both X are ≥ m' = m + 32u·|m| (x − 3.1u·|x|
/// grows with x; the float m' is rounded up). With g(t) = a·t² + 2b·t + c:
/// * b < 0: X₁ ≥ m' ⇐ |b| ≥ a·m'; X₂ ≥ m' ⇔ Y = c − m'|b| ≥ m'·√d, that is
///   Y ≥ 0 and (m' ≤ 0, or Y² − m'²d = c·g(m') − m'²e ≥ 0: with c ≥ m'|b| >
///   0, c·g(m') ≥ m'²·|e| suffices);
/// * b > 0: X₁ ≥ m' ⇔ Z = −a·m' − |b| ≥ √d, that is Z ≥ 0 and Z² − d =
///   a·g(m') − e ≥ 0; X₂ ≥ m' ⇔ −c − m'|b| ≥ m'·√d, implied by −c − m'|b|
///   ≥ 0 (m' < 0 here, as Z ≥ 0 needs).
///
/// No root, no quotient: every product and sum is rounded, and every
/// comparison is made between a certain lower and a certain upper bound
/// ([`lower`], [`upper`], margins of 32u of the magnitudes involved). The
/// linear case of `quadratic_le0` (a negligible) and b = 0 are not decided.
#[inline(always)]
fn quadratic_lo_at_least(a: F, b: F, c: F, m: F) -> M {
    // The common case on all four lanes: the tool on the far side of the
    // rays' origin (b < 0) and a positive level.
    let common = b.lt(s(0.0)) & m.gt(s(1e-200)) & m.lt(s(f64::INFINITY));
    if (!common).any() {
        quadratic_lo_at_least_any(a, b, c, m)
    } else {
        quadratic_lo_at_least_common(a, b, c, m)
    }
}

/// [`quadratic_lo_at_least`] for b < 0 and 0 < m < ∞ on every lane: the
/// same conditions (X₁: |b| ≥ a·m'; X₂: c − m'|b| ≥ 0 and c·g(m') ≥
/// m'²·|e|) with the signs known, so that each margin is one product:
/// for x ≥ 0, fl(x·(1 + 32u)) is above x and fl(x·(1 − 32u)) below it by
/// more than the rounding of the few operations that made x. m' = fl(m·(1 +
/// 64u)) ≥ m + 32u·m.
#[inline(always)]
fn quadratic_lo_at_least_common(a: F, b: F, c: F, m: F) -> M {
    let (up, down, tiny) = (s(1.0 + SLACK), s(1.0 - SLACK), s(TINY));
    let lin = a.le(s(1e-15) * (b.abs() + c.abs()).max(s(1e-300))) | a.eq(s(0.0));
    let (bb2, ac) = (b * b, a * c);
    let none = (bb2 - ac).lt(s(0.0));
    let e = s(4.0 * U) * (bb2 + ac.abs());
    let m1 = m * s(1.0 + 2.0 * SLACK);
    let bb = -b;
    let am = a * m1;
    let first = bb.ge(am * up + tiny);
    let mb = m1 * bb;
    let y_ok = (c * down).ge(mb * up + tiny);
    // g(m') = a·m'² + 2b·m' + c, with g1 ≥ 0 ≥ g2.
    let (g1, g2) = (am * m1, (s(2.0) * b) * m1);
    let g = (g1 + g2 + c) - s(SLACK) * (g1 - g2 + c.abs()) - tiny;
    let second = y_ok & ((c * g) * down).ge(((m1 * m1) * e) * up + tiny);
    !lin & (none | (first & second))
}

/// [`quadratic_lo_at_least`] for any signs.
#[inline(always)]
fn quadratic_lo_at_least_any(a: F, b: F, c: F, m: F) -> M {
    let zero = s(0.0);
    // The same branch as `quadratic_le0`, from the same floats.
    let lin = a.le(s(1e-15) * (b.abs() + c.abs()).max(s(1e-300))) | a.eq(zero);
    let (bb2, ac) = (b * b, a * c);
    let d = bb2 - ac;
    // `quadratic_le0` returns None: nothing to cut.
    let none = d.lt(zero);
    // A bound of |e|: 2.01u(b² + |a·c|) from the rounded b² and a·c, with
    // room for their own rounding.
    let e = s(4.0 * U) * (bb2 + ac.abs());
    let m1 = upper(m + s(SLACK) * m.abs(), m.abs());
    let bb = b.abs();
    let neg = b.lt(zero);
    let am = a * m1;
    let mb = m1 * bb;
    // g(m') and a certain lower bound of it.
    let (g1, g2) = (am * m1, (s(2.0) * b) * m1);
    let g = lower(g1 + g2 + c, g1.abs() + g2.abs() + c.abs());
    // b < 0.
    let y_ok = (c - mb).ge(upper(zero, c.abs() + mb.abs()));
    let cg = c * g;
    let r = (m1 * m1) * e;
    let first_neg = bb.ge(upper(am, am.abs()));
    let second_neg = y_ok & (m1.le(zero) | lower(cg, cg.abs()).ge(upper(r, r)));
    // b > 0.
    let z_ok = (-am - bb).ge(upper(zero, am.abs() + bb));
    let ag = a * g;
    let first_pos = z_ok & lower(ag, ag.abs()).ge(upper(e, e));
    let second_pos = (-c - mb).ge(upper(zero, c.abs() + mb.abs()));
    let decided = (neg & first_neg & second_neg) | (b.gt(zero) & first_pos & second_pos);
    !lin & (none | (m.abs().lt(s(f64::INFINITY)) & decided))
}

/// Whether `kernel::slab(z0, dz, zlo, zhi)` certainly starts at or above
/// `m`, or is certainly empty. For dz = 0 the slab is everything or nothing,
/// decided by the same comparisons; otherwise its lower end is the rounded
/// quotient (zlo − z0)/dz (dz > 0) or −(z0 − zhi)/dz (dz < 0), at least m
/// when the exact quotient is (m is a float): zlo − z0 ≥ m·dz, or
/// z0 − zhi ≥ −m·dz, the product bounded with [`upper`].
#[inline(always)]
fn slab_lo_at_least(z0: F, dz: f64, zlo: f64, zhi: f64, m: F) -> M {
    let zero = s(0.0);
    let (a0, a1) = (s(zlo) - z0, z0 - s(zhi));
    if dz == 0.0 {
        return !(a0.le(zero) & a1.le(zero));
    }
    let md = m * s(dz);
    let finite = m.abs().lt(s(f64::INFINITY));
    if dz > 0.0 {
        finite & a0.ge(upper(md, md.abs()))
    } else if dz < 0.0 {
        finite & a1.ge(upper(-md, md.abs()))
    } else {
        M::splat(false)
    }
}

// ---------------------------------------------------------------------------
// Coefficients: the same expressions as `Local::along`, `capsule_span` and
// `Local::new`, lane by lane.

/// x·y summed as nalgebra's 3-vector dot product: (x₀y₀ + x₁y₁) + x₂y₂.
#[inline(always)]
fn dot(x: &[F; 3], y: &[F; 3]) -> F {
    x[0] * y[0] + x[1] * y[1] + x[2] * y[2]
}

#[inline(always)]
fn splat3(v: &[f64; 3]) -> [F; 3] {
    [s(v[0]), s(v[1]), s(v[2])]
}

// ---------------------------------------------------------------------------
// Four rays of one solid: which need their span, and the spans.

const NONE: Opt = Opt {
    lo: F([0.0; W]),
    hi: F([0.0; W]),
    some: M([0; W]),
};

/// A solid's kernel on the rays of one row, its constants made once.
trait Kernel {
    /// The shortest segment (rays) a tile's test is worth: a test of all
    /// the tile's rows costs about a chunk of one row, so a kernel whose
    /// tests often succeed near the solid's deepest rays (a cylinder's
    /// flat profile) is tested down to one chunk.
    const TILE_LEAST: usize = 2 * W;

    /// The rays (lanes of `gate`) at `pu` whose span is not certainly at or
    /// above `m`, and their spans (meaningful on those lanes).
    fn chunk(&self, pu: F, m: F, gate: M) -> (M, Opt);

    /// Whether the span of every ray at (pu, pv) with pu in [pa, pb] and pv
    /// in [va, vb] (rays of rows of a tile) certainly starts at or above `m`
    /// (or is empty); `false` when not certain.
    #[inline(always)]
    fn segment_skips(&self, _pa: f64, _pb: f64, _va: f64, _vb: f64, _m: f64) -> bool {
        false
    }
}

/// A closed interval enclosing the *computed* values of an expression over
/// the rays of a row segment. Rounding to nearest is monotone, so a
/// rounded sum, difference or product of values within intervals lies
/// within the same operation on their ends (by sign for products), and the
/// ends are themselves rounded as the rays' values are.
#[derive(Clone, Copy, Debug)]
struct Iv {
    lo: f64,
    hi: f64,
}

impl Iv {
    #[inline(always)]
    fn point(x: f64) -> Iv {
        Iv { lo: x, hi: x }
    }
    #[inline(always)]
    fn add(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo + o.lo,
            hi: self.hi + o.hi,
        }
    }
    #[inline(always)]
    fn sub(self, o: Iv) -> Iv {
        Iv {
            lo: self.lo - o.hi,
            hi: self.hi - o.lo,
        }
    }
    /// Times a float (its sign decides the order of the ends).
    #[inline(always)]
    fn times(self, c: f64) -> Iv {
        let (a, b) = (self.lo * c, self.hi * c);
        if c >= 0.0 {
            Iv { lo: a, hi: b }
        } else {
            Iv { lo: b, hi: a }
        }
    }
    #[inline(always)]
    fn square(self) -> Iv {
        let (a, b) = (self.lo * self.lo, self.hi * self.hi);
        if self.lo >= 0.0 {
            Iv { lo: a, hi: b }
        } else if self.hi <= 0.0 {
            Iv { lo: b, hi: a }
        } else {
            Iv {
                lo: 0.0,
                hi: a.max(b),
            }
        }
    }
    #[inline(always)]
    fn abs_max(self) -> f64 {
        self.lo.abs().max(self.hi.abs())
    }
}

/// [`quadratic_lo_at_least_common`] for every (a, b, c) with b, c within
/// intervals, and every level up to `m`: its conditions at their worst
/// corner. With m' = fl(m·(1 + 64u)) ≥ each ray's m' (b < 0 < m'): |b| ≥
/// a·m' is hardest at the smallest |b|; c − m'|b| ≥ 0 at the smallest c and
/// largest |b|; g(m') = a·m'² + 2b·m' + c grows with b and c, so its least
/// value is at the least b and c; |e| is largest at the largest b² and |a·c|.
/// Every ray's span is also empty when the largest discriminant is negative.
#[inline(always)]
fn quadratic_segment_skips(a: f64, b: Iv, c: Iv, m: f64) -> bool {
    if !(b.hi < 0.0 && m > 1e-200 && m < f64::INFINITY) {
        return false;
    }
    let (up, down) = (1.0 + SLACK, 1.0 - SLACK);
    let (b_abs_lo, b_abs_hi) = (-b.hi, -b.lo);
    let c_abs = c.abs_max();
    // `quadratic_le0`'s linear branch on no ray.
    if a <= 1e-15 * (b_abs_hi + c_abs).max(1e-300) || a == 0.0 {
        return false;
    }
    let bb2_hi = b_abs_hi * b_abs_hi;
    if bb2_hi - a * c.lo < 0.0 {
        // Every discriminant below zero: no span.
        return true;
    }
    let m1 = m * (1.0 + 2.0 * SLACK);
    let am = a * m1;
    let first = b_abs_lo >= am * up + TINY;
    let y_ok = c.lo * down >= (m1 * b_abs_hi) * up + TINY;
    let (g1, g2) = (am * m1, (2.0 * b.lo) * m1);
    let g = (g1 + g2 + c.lo) - SLACK * (g1 - g2 + c_abs) - TINY;
    let e = 4.0 * U * (bb2_hi + (a * c_abs).abs());
    first && y_ok && (c.lo * g) * down >= ((m1 * m1) * e) * up + TINY
}

/// [`slab_lo_at_least`] for every z0 within an interval and every level up
/// to `m` (the bound on the quotient grows with m).
#[inline(always)]
fn slab_segment_skips(z0: Iv, dz: f64, zlo: f64, zhi: f64, m: f64) -> bool {
    let (a0_lo, a1_lo) = (zlo - z0.hi, z0.lo - zhi);
    if dz == 0.0 {
        return a0_lo > 0.0 || a1_lo > 0.0;
    }
    if !(m.abs() < f64::INFINITY) {
        return false;
    }
    let md = m * dz;
    let bound = md.abs() * SLACK + TINY;
    if dz > 0.0 {
        a0_lo >= md + bound
    } else if dz < 0.0 {
        a1_lo >= -md + bound
    } else {
        false
    }
}

/// A cylinder piece: `Local::along` and `kernel::cylinder`.
struct CylinderKernel<const K: usize, const U: usize, const V: usize> {
    /// The same constants as scalars, for [`Kernel::segment_skips`].
    origin_f: [f64; 3],
    axis_f: [f64; 3],
    r: f64,
    origin_u: F,
    /// p[V]·w[V] and p[K]·w[K] are constant along the row, but are summed in
    /// `Local::along`'s order with the varying term, so only the vectors
    /// are kept.
    p: [F; 3],
    w: [F; 3],
    dz: f64,
    a: F,
    rr: F,
    z0: f64,
    z1: f64,
}

impl<const K: usize, const U: usize, const V: usize> CylinderKernel<K, U, V> {
    #[inline(always)]
    fn new(origin: &[f64; 3], axis: &[f64; 3], z0: f64, z1: f64, r: f64, pv: f64) -> Self {
        let mut p = [s(0.0); 3];
        p[V] = s(pv - origin[V]);
        p[K] = s(-origin[K]);
        let dz = axis[K];
        CylinderKernel {
            origin_f: *origin,
            axis_f: *axis,
            r,
            origin_u: s(origin[U]),
            p,
            w: splat3(axis),
            dz,
            a: s(1.0 - dz * dz),
            rr: s(r * r),
            z0,
            z1,
        }
    }

    /// `Local::along`: (z0, b, c).
    #[inline(always)]
    fn line(&self, pu: F) -> (F, F, F) {
        let mut p = self.p;
        p[U] = pu - self.origin_u;
        let w = &self.w;
        let z0 = p[0] * w[0] + p[1] * w[1] + p[2] * w[2];
        let pp = [p[0] - z0 * w[0], p[1] - z0 * w[1], p[2] - z0 * w[2]];
        (z0, pp[K], pp[0] * pp[0] + pp[1] * pp[1] + pp[2] * pp[2])
    }
}

impl<const K: usize, const U: usize, const V: usize> CylinderKernel<K, U, V> {
    /// `Local::along` on the rays with pu in [pa, pb]: enclosures of the
    /// computed (z0, b, c) (the same operations, [`Iv`]).
    #[inline(always)]
    fn line_segment(&self, pa: f64, pb: f64, va: f64, vb: f64) -> (Iv, Iv, Iv) {
        let (o, w) = (&self.origin_f, &self.axis_f);
        let mut p = [Iv::point(0.0); 3];
        p[U] = Iv {
            lo: pa - o[U],
            hi: pb - o[U],
        };
        p[V] = Iv {
            lo: va - o[V],
            hi: vb - o[V],
        };
        p[K] = Iv::point(-o[K]);
        let z0 = p[0].times(w[0]).add(p[1].times(w[1])).add(p[2].times(w[2]));
        let pp = [
            p[0].sub(z0.times(w[0])),
            p[1].sub(z0.times(w[1])),
            p[2].sub(z0.times(w[2])),
        ];
        let c = pp[0].square().add(pp[1].square()).add(pp[2].square());
        (z0, pp[K], c)
    }
}

impl<const K: usize, const U: usize, const V: usize> Kernel for CylinderKernel<K, U, V> {
    const TILE_LEAST: usize = W;

    #[inline(always)]
    fn segment_skips(&self, pa: f64, pb: f64, va: f64, vb: f64, m: f64) -> bool {
        let (z0, b, c) = self.line_segment(pa, pb, va, vb);
        let dz = self.axis_f[K];
        slab_segment_skips(z0, dz, self.z0, self.z1, m)
            || quadratic_segment_skips(1.0 - dz * dz, b, c.sub(Iv::point(self.r * self.r)), m)
    }

    #[inline(always)]
    fn chunk(&self, pu: F, m: F, gate: M) -> (M, Opt) {
        let (lz, b, c) = self.line(pu);
        let c = c - self.rr;
        // The span is the slab met with the radial span: it starts no lower
        // than either.
        let mut need = gate & !quadratic_lo_at_least(self.a, b, c, m);
        if need.any() {
            need = need & !slab_lo_at_least(lz, self.dz, self.z0, self.z1, m);
        }
        if !need.any() {
            return (need, NONE);
        }
        (
            need,
            meet(
                slab(lz, self.dz, self.z0, self.z1),
                quadratic_le0(self.a, b, c),
            ),
        )
    }
}

/// A sphere piece: `Local::along` and the sphere of `piece_span`.
struct SphereKernel<const K: usize, const U: usize, const V: usize> {
    line: CylinderKernel<K, U, V>,
    zc: F,
    dz: F,
    a: F,
}

impl<const K: usize, const U: usize, const V: usize> Kernel for SphereKernel<K, U, V> {
    #[inline(always)]
    fn chunk(&self, pu: F, m: F, gate: M) -> (M, Opt) {
        let (lz, b, c) = self.line.line(pu);
        let zr = lz - self.zc;
        let (b, c) = (b + zr * self.dz, c + zr * zr - self.line.rr);
        let need = gate & !quadratic_lo_at_least(self.a, b, c, m);
        if !need.any() {
            return (need, NONE);
        }
        (need, quadratic_le0(self.a, b, c))
    }
}

/// A capsule: `capsule_span`.
struct CapsuleKernel<'a, const K: usize, const U: usize, const V: usize> {
    k: &'a Capsule,
    pv: F,
    d: [F; 3],
    c0: [F; 3],
    c1: [F; 3],
    w: [F; 3],
    dp: [F; 3],
    rr: F,
    a: F,
}

impl<const K: usize, const U: usize, const V: usize> CapsuleKernel<'_, K, U, V> {
    /// A sphere's (b, c) (a = 1).
    #[inline(always)]
    fn sphere(&self, o: &[F; 3], c: &[F; 3]) -> (F, F) {
        let oc = [o[0] - c[0], o[1] - c[1], o[2] - c[2]];
        (dot(&oc, &self.d), dot(&oc, &oc) - self.rr)
    }
}

impl<const K: usize, const U: usize, const V: usize> Kernel for CapsuleKernel<'_, K, U, V> {
    /// Every part certainly above m on every ray of the segment ([`Iv`]
    /// enclosures of the same operations as [`Kernel::chunk`]).
    #[inline(always)]
    fn segment_skips(&self, pa: f64, pb: f64, va: f64, vb: f64, m: f64) -> bool {
        let k = self.k;
        let mut o = [Iv::point(0.0); 3];
        o[U] = Iv { lo: pa, hi: pb };
        o[V] = Iv { lo: va, hi: vb };
        let dot = |x: &[Iv; 3], y: &[f64; 3]| {
            x[0].times(y[0]).add(x[1].times(y[1])).add(x[2].times(y[2]))
        };
        let norm2 = |x: &[Iv; 3]| x[0].square().add(x[1].square()).add(x[2].square());
        let minus = |x: &[Iv; 3], c: &[f64; 3]| {
            [
                x[0].sub(Iv::point(c[0])),
                x[1].sub(Iv::point(c[1])),
                x[2].sub(Iv::point(c[2])),
            ]
        };
        let rr = Iv::point(k.r * k.r);
        let sphere = |c: &[f64; 3]| {
            let oc = minus(&o, c);
            quadratic_segment_skips(1.0, dot(&oc, &k.d), norm2(&oc).sub(rr), m)
        };
        if !(sphere(&k.c0) && sphere(&k.c1)) {
            return false;
        }
        if !(k.len > 0.0) {
            return true;
        }
        let p = minus(&o, &k.c0);
        let lz = dot(&p, &k.w);
        let pp = [
            p[0].sub(lz.times(k.w[0])),
            p[1].sub(lz.times(k.w[1])),
            p[2].sub(lz.times(k.w[2])),
        ];
        slab_segment_skips(lz, k.dz, 0.0, k.len, m)
            || quadratic_segment_skips(k.a, dot(&pp, &k.dp), norm2(&pp).sub(rr), m)
    }

    #[inline(always)]
    fn chunk(&self, pu: F, m: F, gate: M) -> (M, Opt) {
        let mut o = [s(0.0); 3];
        o[U] = pu;
        o[V] = self.pv;
        let (b0, c0) = self.sphere(&o, &self.c0);
        let (b1, c1) = self.sphere(&o, &self.c1);
        // `Local::new(o, d, c0, w)`.
        let p = [o[0] - self.c0[0], o[1] - self.c0[1], o[2] - self.c0[2]];
        let lz = dot(&p, &self.w);
        let pp = [
            p[0] - lz * self.w[0],
            p[1] - lz * self.w[1],
            p[2] - lz * self.w[2],
        ];
        let (b, c) = (dot(&pp, &self.dp), dot(&pp, &pp) - self.rr);
        let one = s(1.0);
        let (len, dz) = (self.k.len, self.k.dz);
        // The hull starts at the lowest of its parts: a ray needs its span
        // unless every part is certainly above m. The parts are tested one
        // after the other while some gated ray may still be skipped.
        let mut need = gate & !quadratic_lo_at_least(one, b0, c0, m);
        if need != gate {
            need = need | (gate & !quadratic_lo_at_least(one, b1, c1, m));
        }
        if need != gate && len > 0.0 {
            let line =
                quadratic_lo_at_least(self.a, b, c, m) | slab_lo_at_least(lz, dz, 0.0, len, m);
            need = need | (gate & !line);
        }
        if !need.any() {
            return (need, NONE);
        }
        let mut span = hull(quadratic_le0(one, b0, c0), quadratic_le0(one, b1, c1));
        if len > 0.0 {
            span = hull(
                span,
                meet(slab(lz, dz, 0.0, len), quadratic_le0(self.a, b, c)),
            );
        }
        (need, span)
    }
}

/// A solid without a lane kernel: the scalar span of every gated ray.
struct ScalarKernel<'a> {
    solids: &'a RowSolids<'a>,
    solid: usize,
    pv: f64,
}

impl Kernel for ScalarKernel<'_> {
    #[inline(always)]
    fn chunk(&self, pu: F, _m: F, gate: M) -> (M, Opt) {
        let mut out = NONE;
        for l in 0..W {
            if gate.lane(l)
                && let Some(sp) = (self.solids.span)(self.solid, pu.0[l], self.pv)
            {
                out.lo.0[l] = sp.lo;
                out.hi.0[l] = sp.hi;
                out.some.0[l] = u64::MAX;
            }
        }
        (gate, out)
    }
}

// ---------------------------------------------------------------------------
// A tile of rows.

/// Scratch buffers of a tile of rows, kept by each thread from tile to tile.
/// Per-ray arrays hold the tile's rows one after the other, `padded` rays
/// each (the rays of the tile's range, rounded up to whole chunks).
#[derive(Default)]
pub(crate) struct Scratch {
    /// The rays' coordinate along the rows (the same on every row).
    pu: Vec<f64>,
    first: Vec<f64>,
    last: Vec<f64>,
    m: Vec<f64>,
    /// The move whose span set m (its place in the batch, from 1, as an
    /// exact float); 0 while m is the ray's top.
    ms: Vec<f64>,
    /// Each ray's largest m over the tile's rows.
    col: Vec<f64>,
    /// The bottom level: the material's start, raised to the end of every
    /// span found that starts at or below it (and ends below the top).
    mb: Vec<f64>,
    /// The move that set mb, as `ms`.
    mbs: Vec<f64>,
    /// Rays with a span that ends inside their material.
    split: Vec<bool>,
    /// The spans that end inside their ray's material: ray (its place in
    /// the arrays above), move, span.
    found: Vec<(u32, u32, Span)>,
    spans: Vec<Span>,
    /// `found` grouped by ray (a counting sort), and where each ray's
    /// group starts.
    by_ray: Vec<(u32, u32, Span)>,
    starts: Vec<u32>,
}

/// A solid that meets a tile: its index, its first and last ray (indices
/// along the rows, within the solid's bounds: the same on every row), its
/// first and last row in the tile, and its move.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Active {
    pub solid: usize,
    pub a: usize,
    pub b: usize,
    pub r0: usize,
    pub r1: usize,
    /// The solid's move: its place in the batch, from 1.
    pub seq: u32,
}

/// What [`cut_tile`] needs of the solids: the prepared kernels, each
/// solid's extent along the rays, and the scalar span of every solid.
pub(crate) struct RowSolids<'a> {
    pub prepared: &'a [RowSolid],
    /// Each solid's bounds along the rays (lo, hi).
    pub along: &'a [(f64, f64)],
    /// The span of solid `i` on the ray at (`pu`, `pv`): `kernel`'s scalar
    /// function, for [`RowSolid::Other`].
    pub span: &'a (dyn Fn(usize, f64, f64) -> Option<Span> + Sync),
}

/// Cuts a tile of consecutive rows (`rows` holds them whole, `frame.nu`
/// rays each): every active solid (visited in the order given) on the rays
/// of its range and rows, then each ray as the reference removal would
/// (module doc).
pub(crate) fn cut_tile(
    frame: &RowFrame,
    rows: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    ids: &[u32],
    scratch: &mut Scratch,
) {
    #[cfg(target_arch = "x86_64")]
    {
        if !portable_forced() && std::is_x86_feature_detected!("avx2") {
            // SAFETY: the processor has AVX2 (checked just above), the one
            // requirement of `cut_tile_avx2`.
            unsafe { cut_tile_avx2(frame, rows, active, solids, ids, scratch) };
            return;
        }
    }
    cut_tile_any(frame, rows, active, solids, ids, scratch);
}

/// Tests can force the portable path, to check it on processors with AVX2.
#[cfg(test)]
pub(crate) static FORCE_PORTABLE: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

#[cfg(all(test, target_arch = "x86_64"))]
fn portable_forced() -> bool {
    FORCE_PORTABLE.load(std::sync::atomic::Ordering::Relaxed)
}

// (Only the x86-64 dispatch asks.)
#[cfg(all(not(test), target_arch = "x86_64"))]
#[inline(always)]
fn portable_forced() -> bool {
    false
}

/// [`cut_tile`] compiled for AVX2: the same operations, four lanes in one
/// instruction.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn cut_tile_avx2(
    frame: &RowFrame,
    rows: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    ids: &[u32],
    scratch: &mut Scratch,
) {
    cut_tile_any(frame, rows, active, solids, ids, scratch);
}

#[inline(always)]
fn cut_tile_any(
    frame: &RowFrame,
    rows: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    ids: &[u32],
    scratch: &mut Scratch,
) {
    match frame.k {
        0 => cut_tile_k::<0, 1, 2>(frame, rows, active, solids, ids, scratch),
        1 => cut_tile_k::<1, 0, 2>(frame, rows, active, solids, ids, scratch),
        _ => cut_tile_k::<2, 0, 1>(frame, rows, active, solids, ids, scratch),
    }
}

/// Narrows [j0, end) from either end to the rays whose span may start
/// below their level: segments certainly above every level in them are
/// dropped, in steps of four chunks at first that double while segments
/// are dropped and halve (down to `least` rays) when one is not.
/// `level(a, b)` is the float after
/// the largest m of rays a..b on the rows tested, so a dropped segment's
/// spans start strictly above every level in it and none lowers one,
/// whichever move set it.
#[inline(always)]
fn narrow(
    (mut j0, mut end): (usize, usize),
    least: usize,
    pu: &[f64],
    level: impl Fn(usize, usize) -> f64,
    skips: impl Fn(f64, f64, f64) -> bool,
) -> (usize, usize) {
    let (mut step, mut grow) = (4 * W, true);
    while step >= least && j0 + step <= end {
        if skips(pu[j0], pu[j0 + step - 1], level(j0, j0 + step)) {
            j0 += step;
            if grow {
                step *= 2;
            }
        } else {
            (step, grow) = (step / 2, false);
        }
    }
    (step, grow) = (4 * W, true);
    while step >= least && end >= j0 + step {
        let (a, b) = (end - step, end);
        if skips(pu[a], pu[b - 1], level(a, b)) {
            end = a;
            if grow {
                step *= 2;
            }
        } else {
            (step, grow) = (step / 2, false);
        }
    }
    (j0, end)
}

/// A float above each finite lane of `m` (at most a few ulps above):
/// |m|·2⁻⁵² is at least the spacing of the floats just above m, and the
/// floor lifts 0 (`f64::next_up` lane by lane, without its branches).
#[inline(always)]
fn above(m: F) -> F {
    m + m.abs() * s(f64::EPSILON) + s(TINY)
}

/// The float after the largest of `m[a..b]`, b − a a multiple of the lane
/// count (four lanes at once: `f64::max` is exact, so the order is free).
#[inline(always)]
fn level_above(m: &[f64], a: usize, b: usize) -> f64 {
    let mut top = F::splat(f64::NEG_INFINITY);
    for i in (a..b).step_by(W) {
        top = top.max(F::load(m, i));
    }
    top.0
        .iter()
        .fold(f64::NEG_INFINITY, |x, &y| x.max(y))
        .next_up()
}

/// One solid on its rays `j0..=j1` of rows `r0..=r1` of the tile: first
/// whole segments across all those rows (one interval test for all), then
/// row by row ([`sweep_row`]); `make` gives the solid's kernel for a row's
/// coordinate. Returns whether a span ends inside a ray's material.
#[inline(always)]
fn sweep_tile<Kn: Kernel>(
    make: impl Fn(f64) -> Kn,
    (j0, j1): (usize, usize),
    (r0, r1): (usize, usize),
    along: (f64, f64),
    seq: u32,
    pv: &[f64],
    sc: &mut Scratch,
) -> bool {
    // (Every row holds as many rays as `pu`.)
    let padded = sc.pu.len();
    let mut range = (j0, j1 + 1);
    if r1 > r0 {
        // The rows' largest level on each ray (`col`) bounds them all.
        let kern = make(pv[r0]);
        let (va, vb) = (pv[r0], pv[r1]);
        range = narrow(
            range,
            Kn::TILE_LEAST,
            &sc.pu,
            |a, b| level_above(&sc.col, a, b),
            |pa, pb, m| kern.segment_skips(pa, pb, va, vb, m),
        );
    }
    // Row by row, segments are tested again unless the tile's test left
    // less than half the rays (then testing costs more than it saves).
    let narrow_rows = 2 * (range.1 - range.0) > j1 + 1 - j0;
    let mut any_split = false;
    if range.1 > range.0 {
        for r in r0..=r1 {
            let row = (pv[r], r * padded, narrow_rows);
            any_split |= sweep_row(&make(pv[r]), range, along, seq, row, sc);
        }
        // Levels only fall: `col` is exact again once the rays swept are
        // taken again.
        // (Whole chunks, four rays at a time: `padded` is a multiple of W.)
        let rows = pv.len();
        for base in (range.0 / W * W..range.1).step_by(W) {
            let mut top = F::load(&sc.m, base);
            for r in 1..rows {
                top = top.max(F::load(&sc.m, r * padded + base));
            }
            top.store(&mut sc.col, base);
        }
    }
    any_split
}

/// The solid's rays `j0..end` of one row (its arrays from `off`): whole
/// segments dropped first ([`narrow`]), then the skip test and the exact
/// spans four rays at a time, and the levels they lower. Returns whether a
/// span ends inside a ray's material.
#[inline(always)]
fn sweep_row<Kn: Kernel>(
    kern: &Kn,
    range: (usize, usize),
    (lo_k, hi_k): (f64, f64),
    seq: u32,
    (pv, off, narrow_first): (f64, usize, bool),
    sc: &mut Scratch,
) -> bool {
    let lane = F(std::array::from_fn(|i| i as f64));
    let (lo_k, hi_k) = (s(lo_k), s(hi_k));
    let mut any_split = false;
    let (j0, end) = if narrow_first {
        narrow(
            range,
            2 * W,
            &sc.pu,
            |a, b| level_above(&sc.m, off + a, off + b),
            |pa, pb, m| kern.segment_skips(pa, pb, pv, pv, m),
        )
    } else {
        range
    };
    if end <= j0 {
        return false;
    }
    let j1 = end - 1;
    let j0f = s(j0 as f64);
    let j1f = s(j1 as f64);
    let seqf = s(f64::from(seq));
    let mut base = j0 / W * W;
    while base <= j1 {
        let at = off + base;
        let idx = s(base as f64) + lane;
        let (first, last) = (F::load(&sc.first, at), F::load(&sc.last, at));
        // The reference's gate: the ray's index within the solid's bounds
        // and its material within the solid's extent.
        let gate = idx.ge(j0f) & idx.le(j1f) & !(hi_k.le(first) | lo_k.ge(last));
        if gate.any() {
            let m = F::load(&sc.m, at);
            let ms = F::load(&sc.ms, at);
            // A move before the one that set m lowers it only from strictly
            // below: of two moves that reach the same level, the first makes
            // the end (and names it), as when they are cut one by one.
            let earlier = seqf.lt(ms);
            let level = if earlier.any() {
                earlier.select(above(m), m)
            } else {
                m
            };
            let (need, span) = kern.chunk(F::load(&sc.pu, base), level, gate);
            let keep = need & span.some;
            if keep.any() {
                let reach = keep & span.hi.ge(last);
                let lower = reach & (span.lo.lt(m) | (span.lo.eq(m) & earlier));
                lower.select(span.lo, m).store(&mut sc.m, at);
                lower.select(seqf, ms).store(&mut sc.ms, at);
                // Spans that meet the material below its top: those from
                // below its bottom are summed up by mb, as the others by m
                // (mirrored); those that end inside it are kept for their
                // ray.
                let rest = keep & !reach & span.hi.gt(first);
                if !rest.any() {
                    base += W;
                    continue;
                }
                let bottom = rest & span.lo.le(first);
                if bottom.any() {
                    let (mb, mbs) = (F::load(&sc.mb, at), F::load(&sc.mbs, at));
                    let raise = bottom & (span.hi.gt(mb) | (span.hi.eq(mb) & seqf.lt(mbs)));
                    raise.select(span.hi, mb).store(&mut sc.mb, at);
                    raise.select(seqf, mbs).store(&mut sc.mbs, at);
                }
                let split = rest & !bottom;
                if split.any() {
                    any_split = true;
                    for i in 0..W {
                        if split.lane(i) {
                            sc.found.push((
                                (at + i) as u32,
                                seq,
                                Span {
                                    lo: span.lo.0[i],
                                    hi: span.hi.0[i],
                                },
                            ));
                            sc.split[at + i] = true;
                        }
                    }
                }
            }
        }
        base += W;
    }
    any_split
}

impl Scratch {
    /// The tile's arrays for the rays `a_min..=b_max` of each row, `padded`
    /// a row: the rays' coordinates, their material's ends, the levels at
    /// those ends, no split.
    #[inline(always)]
    fn prepare(
        &mut self,
        frame: &RowFrame,
        rows: &[Ray],
        (a_min, b_max): (usize, usize),
        padded: usize,
    ) {
        let (nu, pv) = (frame.nu, frame.pv);
        self.pu.clear();
        self.pu
            .extend((0..padded).map(|j| frame.origin_u + ((a_min + j) as f64 + 0.5) * frame.h));
        self.first.clear();
        self.last.clear();
        for r in 0..pv.len() {
            for ray in &rows[r * nu + a_min..=r * nu + b_max] {
                // Empty rays (and the padding): no solid passes the gate against
                // their ends.
                let (f, l) = match (ray.first(), ray.last()) {
                    (Some(f), Some(l)) => (f.lo, l.hi),
                    _ => (f64::INFINITY, f64::NEG_INFINITY),
                };
                self.first.push(f);
                self.last.push(l);
            }
            self.first.resize((r + 1) * padded, f64::INFINITY);
            self.last.resize((r + 1) * padded, f64::NEG_INFINITY);
        }
        let all = pv.len() * padded;
        self.m.clear();
        self.m.extend_from_slice(&self.last);
        self.col.clear();
        self.col.extend_from_slice(&self.m[..padded]);
        for r in 1..pv.len() {
            for j in 0..padded {
                self.col[j] = self.col[j].max(self.m[r * padded + j]);
            }
        }
        self.ms.clear();
        self.ms.resize(all, 0.0);
        self.mb.clear();
        self.mb.extend_from_slice(&self.first);
        self.mbs.clear();
        self.mbs.resize(all, 0.0);
        self.split.clear();
        self.split.resize(all, false);
        self.found.clear();
    }
}

#[inline(always)]
fn cut_tile_k<const K: usize, const U: usize, const V: usize>(
    frame: &RowFrame,
    rows: &mut [Ray],
    active: &[Active],
    solids: &RowSolids,
    ids: &[u32],
    sc: &mut Scratch,
) {
    let Some(a_min) = active.iter().map(|s| s.a).min() else {
        return;
    };
    let b_max = active.iter().map(|s| s.b).max().unwrap_or(a_min);
    let n = b_max + 1 - a_min;
    let padded = n.div_ceil(W) * W;
    let (nu, pv) = (frame.nu, frame.pv);
    sc.prepare(frame, rows, (a_min, b_max), padded);
    let mut any_split = false;
    for act in active {
        let range = (act.a - a_min, act.b - a_min);
        let rows_of = (act.r0, act.r1);
        let along = solids.along[act.solid];
        let seq = act.seq;
        any_split |= match solids.prepared[act.solid] {
            RowSolid::Cylinder {
                ref origin,
                ref axis,
                z0,
                z1,
                r,
            } => sweep_tile(
                |pv| CylinderKernel::<K, U, V>::new(origin, axis, z0, z1, r, pv),
                range,
                rows_of,
                along,
                seq,
                pv,
                sc,
            ),
            RowSolid::Sphere {
                ref origin,
                ref axis,
                zc,
                r,
            } => {
                let dz = axis[K];
                let make = |pv| SphereKernel {
                    line: CylinderKernel::<K, U, V>::new(origin, axis, 0.0, 0.0, r, pv),
                    zc: s(zc),
                    dz: s(dz),
                    a: s(1.0 - dz * dz + dz * dz),
                };
                sweep_tile(make, range, rows_of, along, seq, pv, sc)
            }
            RowSolid::Capsule(ref k) => {
                let make = |pv| CapsuleKernel::<K, U, V> {
                    k,
                    pv: s(pv),
                    d: splat3(&k.d),
                    c0: splat3(&k.c0),
                    c1: splat3(&k.c1),
                    w: splat3(&k.w),
                    dp: splat3(&k.dp),
                    rr: s(k.r * k.r),
                    a: s(k.a),
                };
                sweep_tile(make, range, rows_of, along, seq, pv, sc)
            }
            RowSolid::Other => {
                let make = |pv| ScalarKernel {
                    solids,
                    solid: act.solid,
                    pv,
                };
                sweep_tile(make, range, rows_of, along, seq, pv, sc)
            }
        };
    }
    cut_levels(sc, rows, (a_min, n, padded, nu), ids);
    if any_split {
        replay_splits(sc, rows, (a_min, padded, nu), ids);
    }
}

/// Each ray whose spans all reached its top or its start loses (m, top)
/// and (start, mb).
#[inline(always)]
fn cut_levels(
    sc: &Scratch,
    rows: &mut [Ray],
    (a_min, n, padded, nu): (usize, usize, usize, usize),
    ids: &[u32],
) {
    for r in 0..rows.len() / nu {
        for j in 0..n {
            let at = r * padded + j;
            if sc.split[at] {
                continue;
            }
            let ray = &mut rows[r * nu + a_min + j];
            // Every span that met the material reached its bottom or its
            // top. (The two cuts commute: each removes all beyond its level.)
            if sc.mb[at] > sc.first[at] {
                subtract(ray, f64::NEG_INFINITY, sc.mb[at], ids[sc.mbs[at] as usize]);
            }
            if sc.m[at] < sc.last[at] {
                cut_top(ray, sc.m[at], ids[sc.ms[at] as usize]);
            }
        }
    }
}

/// The rays with a span that ends inside their material, move by move.
#[inline(always)]
fn replay_splits(
    sc: &mut Scratch,
    rows: &mut [Ray],
    (a_min, padded, nu): (usize, usize, usize),
    ids: &[u32],
) {
    // Rays with a span that ends inside the material: move by move, the
    // union of that move's such spans, with (−∞, mb] for the move that set
    // mb and [m, +∞) for the one that set m. Within the material this is
    // what the reference subtracts move by move: every span that reaches
    // the top starts at or above m, so only the first move to reach m
    // leaves an end at m, and the same below mb (module doc).
    let n_found = sc.found.len();
    for f in 0..n_found {
        let at = sc.found[f].0 as usize;
        if sc.split[at] {
            // Each split ray's two levels, once.
            sc.split[at] = false;
            if sc.m[at] < sc.last[at] {
                let span = Span {
                    lo: sc.m[at],
                    hi: f64::INFINITY,
                };
                sc.found.push((at as u32, sc.ms[at] as u32, span));
            }
            if sc.mb[at] > sc.first[at] {
                let span = Span {
                    lo: f64::NEG_INFINITY,
                    hi: sc.mb[at],
                };
                sc.found.push((at as u32, sc.mbs[at] as u32, span));
            }
        }
    }
    // Grouped by ray (counting them: there are many), then each ray's by
    // move. (Spans of one ray and one move are united: their order is
    // free.)
    let all = rows.len() / nu * padded;
    sc.starts.clear();
    sc.starts.resize(all + 1, 0);
    for &(at, _, _) in &sc.found {
        sc.starts[at as usize + 1] += 1;
    }
    for at in 0..all {
        sc.starts[at + 1] += sc.starts[at];
    }
    sc.by_ray.clear();
    sc.by_ray
        .resize(sc.found.len(), (0, 0, Span { lo: 0.0, hi: 0.0 }));
    for &entry in &sc.found {
        let at = entry.0 as usize;
        sc.by_ray[sc.starts[at] as usize] = entry;
        sc.starts[at] += 1;
    }
    // (Each start has moved to the next ray's: the groups end there.)
    let mut begin = 0;
    for at in 0..all {
        let end = sc.starts[at] as usize;
        if end == begin {
            continue;
        }
        let group = &mut sc.by_ray[begin..end];
        group.sort_unstable_by_key(|&(_, seq, _)| seq);
        let ray = &mut rows[at / padded * nu + a_min + at % padded];
        let mut i = 0;
        while i < group.len() {
            let seq = group[i].1;
            sc.spans.clear();
            while i < group.len() && group[i].1 == seq {
                sc.spans.push(group[i].2);
                i += 1;
            }
            remove_spans(ray, &mut sc.spans, ids[seq as usize]);
        }
        begin = end;
    }
}

/// `subtract(ray, m, +∞, id)` for m below the ray's top, with the one
/// interval case inline: the interval keeps [lo, m] when it is at least
/// `SLIVER_MM` long, else goes.
#[inline(always)]
fn cut_top(ray: &mut Ray, m: f64, id: u32) {
    if ray.len() == 1 {
        let seg = &mut ray[0];
        if seg.lo < m && m - seg.lo >= SLIVER_MM {
            seg.hi = m;
            seg.hi_move = id;
        } else {
            ray.clear();
        }
    } else {
        subtract(ray, m, f64::INFINITY, id);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel;
    use proptest::prelude::*;

    fn lanes(x: f64) -> F {
        F::splat(x)
    }

    /// Coefficients of every kind: ordinary, a negligible (the linear
    /// case), b = 0 and b of either sign, an empty span.
    fn coefficient() -> impl Strategy<Value = f64> {
        prop_oneof![
            4 => -1e4f64..1e4,
            1 => -1.0f64..1.0,
            1 => Just(0.0),
            1 => Just(-0.0),
            1 => -1e-12f64..1e-12,
        ]
    }

    /// The levels to test against a computed start: the start itself, one
    /// ulp either side, and values near it.
    fn levels(lo: f64) -> [f64; 6] {
        [
            lo,
            lo.next_up(),
            lo.next_down(),
            lo + 1e-9,
            lo - 1e-9,
            lo * (1.0 + 1e-13),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20000))]

        #[test]
        fn the_lane_quadratic_is_the_scalar_one_bit_for_bit(
            a in prop_oneof![0.0f64..2.0, Just(0.0), 0.0f64..1e-13],
            b in coefficient(),
            c in coefficient(),
        ) {
            let lane = quadratic_le0(lanes(a), lanes(b), lanes(c));
            let scalar = kernel::quadratic_le0(a, b, c);
            match scalar {
                Some(sp) => {
                    prop_assert!(lane.some.lane(0));
                    prop_assert_eq!(lane.lo.0[0].to_bits(), sp.lo.to_bits());
                    prop_assert_eq!(lane.hi.0[0].to_bits(), sp.hi.to_bits());
                }
                None => prop_assert!(!lane.some.lane(0)),
            }
        }

        #[test]
        fn the_lane_slab_is_the_scalar_one_bit_for_bit(
            z0 in coefficient(), dz in prop_oneof![-1.0f64..1.0, Just(0.0)],
            lo in -10.0f64..0.0, len in 0.0f64..10.0,
        ) {
            let lane = slab(lanes(z0), dz, lo, lo + len);
            match kernel::slab(z0, dz, lo, lo + len) {
                Some(sp) => {
                    prop_assert!(lane.some.lane(0));
                    prop_assert_eq!(lane.lo.0[0].to_bits(), sp.lo.to_bits());
                    prop_assert_eq!(lane.hi.0[0].to_bits(), sp.hi.to_bits());
                }
                None => prop_assert!(!lane.some.lane(0)),
            }
        }

        /// Never "certainly at or above m" when the computed start is below
        /// m, even by an ulp.
        #[test]
        fn the_quadratic_skip_test_is_sound(
            a in prop_oneof![0.0f64..2.0, 0.999f64..1.0, Just(1.0)],
            b in coefficient(),
            c in coefficient(),
            m in -1e4f64..1e4,
        ) {
            let span = kernel::quadratic_le0(a, b, c);
            let mut ms = vec![m];
            if let Some(sp) = span {
                ms.extend(levels(sp.lo));
            }
            for m in ms {
                let claim = quadratic_lo_at_least(lanes(a), lanes(b), lanes(c), lanes(m)).lane(0);
                if claim {
                    prop_assert!(span.is_none_or(|sp| sp.lo >= m), "{span:?} claimed ≥ {m}");
                }
            }
        }

        /// Near tangency (d ≈ 0) the computed start moves most with the
        /// discriminant's rounding.
        #[test]
        fn the_quadratic_skip_test_is_sound_near_tangency(
            a in 0.5f64..1.5,
            b in prop_oneof![-100.0f64..-1.0, 1.0f64..100.0],
            delta in prop_oneof![-1e-12f64..1e-12, -1e-15f64..1e-15, -1e-9f64..1e-9],
        ) {
            let c = b * b / a * (1.0 + delta);
            let span = kernel::quadratic_le0(a, b, c);
            if let Some(sp) = span {
                for m in levels(sp.lo).into_iter().chain([sp.lo - 1e-6, sp.lo - 1e-7]) {
                    if quadratic_lo_at_least(lanes(a), lanes(b), lanes(c), lanes(m)).lane(0) {
                        prop_assert!(sp.lo >= m, "{sp:?} claimed ≥ {m}");
                    }
                }
            }
        }

        #[test]
        fn the_slab_skip_test_is_sound(
            z0 in coefficient(), dz in prop_oneof![-1.0f64..1.0, Just(0.0), -1e-9f64..1e-9],
            lo in -10.0f64..0.0, len in 0.0f64..10.0, m in -1e4f64..1e4,
        ) {
            let span = kernel::slab(z0, dz, lo, lo + len);
            let mut ms = vec![m];
            if let Some(sp) = span {
                ms.extend(levels(sp.lo));
            }
            for m in ms {
                if slab_lo_at_least(lanes(z0), dz, lo, lo + len, lanes(m)).lane(0) {
                    prop_assert!(span.is_none_or(|sp| sp.lo >= m), "{span:?} claimed ≥ {m}");
                }
            }
        }
    }

    /// The skip test decides most of the cases it is meant for: a wheel's
    /// rim well above the level (a test that never skips would be sound
    /// and useless).
    #[test]
    fn the_quadratic_skip_test_skips_what_is_clearly_above() {
        // |p⊥ + t·d⊥|² ≤ 50² for a wheel centred 90 mm up: the span starts
        // at 40; a level of 39.9 is below it, 40.1 above.
        let (a, b, c) = (1.0, -90.0, 90.0 * 90.0 - 50.0 * 50.0);
        let lo = kernel::quadratic_le0(a, b, c).unwrap().lo;
        assert!((lo - 40.0).abs() < 1e-9);
        assert!(quadratic_lo_at_least(lanes(a), lanes(b), lanes(c), lanes(39.9)).lane(0));
        assert!(!quadratic_lo_at_least(lanes(a), lanes(b), lanes(c), lanes(40.1)).lane(0));
        // Below the origin (b > 0): the span starts at −140.
        let lo = kernel::quadratic_le0(a, 90.0, c).unwrap().lo;
        assert!((lo + 140.0).abs() < 1e-9);
        assert!(quadratic_lo_at_least(lanes(a), lanes(90.0), lanes(c), lanes(-140.1)).lane(0));
        assert!(!quadratic_lo_at_least(lanes(a), lanes(90.0), lanes(c), lanes(-139.9)).lane(0));
    }
}
