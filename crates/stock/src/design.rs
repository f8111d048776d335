//! Comparison of the simulated part with the design, along the rays.
//!
//! **Method.** The design is a triangle mesh (an STL, or a B-spline surface
//! tessellated finely enough, see [`Design::from_surface`]). Every ray of the
//! stock's three families is crossed with it ([`crate::mesh`]). A design
//! crossing is measured on the family of the largest component of its
//! triangle's normal only (the ray at most 54.7° from the normal), so each
//! piece of design surface is measured once, by the rays most nearly along
//! its normal. There, the deviation is
//!
//! `δ = o · (t_stock − t_design) · |n·d|`
//!
//! with `t_stock` the nearest end of the simulated part on that ray facing
//! the same way (an interval's upper end where the ray leaves the design,
//! `o = +1`; a lower end where it enters, `o = −1`), and `|n·d|` the cosine
//! of the ray to the design normal: the distance along the normal for a
//! locally flat design. δ > 0 is material left above the design
//! (residual), δ < 0 material removed below it (gouge). Where the ray holds
//! no material at all, the gouge is the design's depth along the ray.
//! Material on rays that miss the design altogether (stock beyond the
//! part's outline) has no design surface to be measured against; for a
//! closed design it is counted in the residual volume (Z rays: the lengths
//! of part ∖ design, and design ∖ part for the gouge volume, times h²).
//!
//! Samples beyond the tolerance are kept and grouped into regions:
//! connected components on the ray grid (4-neighbours of the same family,
//! facing the same way, of the same sign, their design crossings within two
//! ray spacings along the ray). A region's area is the design area its
//! samples stand for (h² / cosine each). Regions are not merged across
//! families (a region crossing the 54.7° line of the normal reports as two).

use kinpost_surface::Surface;
use nalgebra::Point3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::dexel::{Segment, UNCUT};
use crate::mesh::{Crossing, Mesh, bin_rows, row_crossings};
use crate::stock::Stock;

/// The part as designed.
#[derive(Debug, Clone)]
pub struct Design {
    mesh: Mesh,
    closed: bool,
}

/// Why a design cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DesignError {
    /// The mesh has no triangle or a coordinate that is not finite.
    #[error("the design mesh is empty or has a coordinate that is not a finite number")]
    BadMesh,
    /// The tolerance is not a positive finite number.
    #[error("the comparison tolerance must be a positive number of mm, not {0}")]
    Tolerance(f64),
    /// The surface is degenerate where it is tessellated.
    #[error("the design surface cannot be tessellated: {0}")]
    Surface(&'static str),
}

impl Design {
    /// A closed design mesh (an STL of the part). Turned over if its
    /// triangles face inwards (negative enclosed volume).
    pub fn from_mesh(mesh: Mesh) -> Result<Design, DesignError> {
        let finite = mesh
            .vertices
            .iter()
            .all(|p| p.iter().all(|c| c.is_finite()));
        if mesh.triangles.is_empty()
            || !finite
            || mesh
                .triangles
                .iter()
                .flatten()
                .any(|&i| i as usize >= mesh.vertices.len())
        {
            return Err(DesignError::BadMesh);
        }
        let mesh = if mesh.signed_volume6() < 0.0 {
            mesh.flipped()
        } else {
            mesh
        };
        Ok(Design { mesh, closed: true })
    }

    /// An open design surface: a B-spline surface tessellated into a grid of
    /// triangles whose chords stay within `chord_mm` of the surface: the
    /// step √(8·chord/κ), κ the largest principal curvature found on a
    /// 33 × 33 grid of parameters, over the longest parameter line of that
    /// grid (its polygon length), with 8 to 2000 steps per direction. The
    /// surface's normal (S_u × S_v) points out of the material; `flip` turns
    /// it over. Pass a chord a tenth of the comparison tolerance or less.
    pub fn from_surface(
        surface: &Surface,
        chord_mm: f64,
        flip: bool,
    ) -> Result<Design, DesignError> {
        if !(chord_mm.is_finite() && chord_mm > 0.0) {
            return Err(DesignError::Tolerance(chord_mm));
        }
        let (u0, u1) = surface.u_range();
        let (v0, v1) = surface.v_range();
        let coarse = 33;
        let at = |i: usize, n: usize, a: f64, b: f64| a + (b - a) * i as f64 / (n - 1) as f64;
        let mut kappa: f64 = 0.0;
        let (mut len_u, mut len_v): (f64, f64) = (0.0, 0.0);
        for i in 0..coarse {
            let (mut lu, mut lv) = (0.0, 0.0);
            for j in 0..coarse {
                if let Ok(g) = surface.geometry(at(i, coarse, u0, u1), at(j, coarse, v0, v1)) {
                    kappa = kappa.max(g.k1.abs()).max(g.k2.abs());
                }
                if j > 0 {
                    let p = |a: usize, b: usize| {
                        surface.point(at(a, coarse, u0, u1), at(b, coarse, v0, v1))
                    };
                    lv += (p(i, j) - p(i, j - 1)).norm();
                    lu += (p(j, i) - p(j - 1, i)).norm();
                }
            }
            len_u = len_u.max(lu);
            len_v = len_v.max(lv);
        }
        if !(kappa.is_finite() && len_u.is_finite() && len_v.is_finite()) {
            return Err(DesignError::Surface(
                "its points or curvature are not finite",
            ));
        }
        let step = if kappa > 0.0 {
            (8.0 * chord_mm / kappa).sqrt()
        } else {
            f64::INFINITY
        };
        let count = |len: f64| ((len / step).ceil() as usize).clamp(8, 2000) + 1;
        let (nu, nv) = (count(len_u), count(len_v));
        let mut vertices = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                let p = surface.point(at(i, nu, u0, u1), at(j, nv, v0, v1));
                vertices.push(Point3::from(p));
            }
        }
        let mut triangles = Vec::with_capacity(2 * (nu - 1) * (nv - 1));
        let id = |i: usize, j: usize| (i * nv + j) as u32;
        for i in 0..nu - 1 {
            for j in 0..nv - 1 {
                // Counter-clockwise about S_u × S_v.
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if flip {
                    triangles.push([a, c, b]);
                    triangles.push([a, d, c]);
                } else {
                    triangles.push([a, b, c]);
                    triangles.push([a, c, d]);
                }
            }
        }
        if !vertices.iter().all(|p| p.iter().all(|c| c.is_finite())) {
            return Err(DesignError::Surface("its points are not finite"));
        }
        Ok(Design {
            mesh: Mesh {
                vertices,
                triangles,
            },
            closed: false,
        })
    }

    /// The design's triangles.
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// Whether the design bounds a solid (an STL) rather than being one
    /// open surface.
    pub fn is_closed(&self) -> bool {
        self.closed
    }
}

/// One measured point of the design surface beyond the tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Deviation along the design normal, mm: > 0 residual, < 0 gouge.
    pub deviation_mm: f64,
    /// The point of the design surface, part frame.
    pub design_point: [f64; 3],
    /// The point of the simulated part measured against it.
    pub part_point: [f64; 3],
    /// The move that last cut that point of the part (`None`: uncut stock).
    pub move_id: Option<u32>,
    /// The ray family (0 = X, 1 = Y, 2 = Z).
    pub family: u8,
    /// Ray index across (u).
    pub iu: u32,
    /// Ray index across (v).
    pub iv: u32,
    /// +1 where the ray leaves the design, −1 where it enters.
    pub orientation: i8,
    /// Design area the sample stands for, mm².
    pub area_mm2: f64,
}

/// A connected region beyond the tolerance.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Region {
    /// Samples in the region.
    pub samples: usize,
    /// Design area, mm².
    pub area_mm2: f64,
    /// The largest deviation (by magnitude, signed), mm.
    pub deviation_mm: f64,
    /// Where it is on the part.
    pub at: [f64; 3],
    /// The move that cut it there (`None`: uncut stock).
    pub move_id: Option<u32>,
}

/// One bar of the deviation histogram.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bin {
    /// Lower edge, mm (−∞ for the first).
    pub from_mm: f64,
    /// Upper edge, mm (+∞ for the last).
    pub to_mm: f64,
    /// Samples in the bar.
    pub samples: u64,
    /// Design area, mm².
    pub area_mm2: f64,
}

/// The result of [`compare`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Comparison {
    /// The tolerance, mm.
    pub tolerance_mm: f64,
    /// Design samples measured.
    pub measured: u64,
    /// Samples beyond the tolerance, in ray order.
    pub beyond: Vec<Sample>,
    /// Gouge regions, largest gouge first.
    pub gouge_regions: Vec<Region>,
    /// Residual regions, largest residual first.
    pub residual_regions: Vec<Region>,
    /// Histogram: bars at ±1, 2, 4, 8 tolerances.
    pub histogram: Vec<Bin>,
    /// Material missing inside a closed design (Z rays), mm³.
    pub gouge_volume_mm3: f64,
    /// Material outside a closed design (Z rays), mm³.
    pub residual_volume_mm3: f64,
}

impl Comparison {
    /// The deepest gouge (most negative deviation beyond the tolerance).
    pub fn gouge_max(&self) -> Option<&Sample> {
        self.beyond
            .iter()
            .filter(|s| s.deviation_mm < 0.0)
            .min_by(|a, b| a.deviation_mm.total_cmp(&b.deviation_mm))
    }

    /// The largest residual.
    pub fn residual_max(&self) -> Option<&Sample> {
        self.beyond
            .iter()
            .filter(|s| s.deviation_mm > 0.0)
            .max_by(|a, b| a.deviation_mm.total_cmp(&b.deviation_mm))
    }
}

/// Histogram edges in tolerances.
const EDGES: [f64; 8] = [-8.0, -4.0, -2.0, -1.0, 1.0, 2.0, 4.0, 8.0];

#[derive(Default)]
struct RowResult {
    beyond: Vec<Sample>,
    measured: u64,
    bins: [(u64, f64); 9],
    gouge_len: f64,
    residual_len: f64,
}

fn bin_of(dev: f64, tol: f64) -> usize {
    EDGES.iter().take_while(|&&e| dev > e * tol).count()
}

/// Compares the simulated part with the design (see the module doc).
/// Rows of rays run in parallel; the result does not depend on the thread
/// count.
pub fn compare(
    stock: &Stock,
    design: &Design,
    tolerance_mm: f64,
) -> Result<Comparison, DesignError> {
    if !(tolerance_mm.is_finite() && tolerance_mm > 0.0) {
        return Err(DesignError::Tolerance(tolerance_mm));
    }
    let h = stock.resolution_mm();
    let mut total = RowResult::default();
    for k in 0..3 {
        let g = stock.ray_grid(k);
        let bins = bin_rows(&design.mesh, &g, 0.0);
        let fam = stock.family(k);
        let rows: Vec<RowResult> = bins
            .par_iter()
            .enumerate()
            .map(|(iv, bin)| {
                let crossings = row_crossings(&design.mesh, &g, bin, iv);
                let mut out = RowResult::default();
                for (iu, c) in crossings.iter().enumerate() {
                    let ray = fam.ray(iu, iv);
                    let at = |t: f64| {
                        let mut p = [0.0; 3];
                        p[g.u] = stock.coordinate(g.u, iu);
                        p[g.v] = stock.coordinate(g.v, iv);
                        p[g.k] = t;
                        p
                    };
                    measure_ray(k, iu, iv, c, ray, tolerance_mm, h, &at, &mut out);
                    if k == 2 && design.closed {
                        let (g_len, r_len) = symmetric_difference(c, ray);
                        out.gouge_len += g_len;
                        out.residual_len += r_len;
                    }
                }
                out
            })
            .collect();
        for r in rows {
            total.beyond.extend(r.beyond);
            total.measured += r.measured;
            for (t, b) in total.bins.iter_mut().zip(r.bins) {
                t.0 += b.0;
                t.1 += b.1;
            }
            total.gouge_len += r.gouge_len;
            total.residual_len += r.residual_len;
        }
    }
    let (gouge_regions, residual_regions) = regions(&total.beyond, h);
    let histogram = (0..9)
        .map(|i| Bin {
            from_mm: if i == 0 {
                f64::NEG_INFINITY
            } else {
                EDGES[i - 1] * tolerance_mm
            },
            to_mm: if i == 8 {
                f64::INFINITY
            } else {
                EDGES[i] * tolerance_mm
            },
            samples: total.bins[i].0,
            area_mm2: total.bins[i].1,
        })
        .collect();
    Ok(Comparison {
        tolerance_mm,
        measured: total.measured,
        beyond: total.beyond,
        gouge_regions,
        residual_regions,
        histogram,
        gouge_volume_mm3: total.gouge_len * h * h,
        residual_volume_mm3: total.residual_len * h * h,
    })
}

/// The samples of one ray's design crossings measured on this family.
#[allow(clippy::too_many_arguments)]
fn measure_ray(
    k: usize,
    iu: usize,
    iv: usize,
    c: &[Crossing],
    ray: &[Segment],
    tol: f64,
    h: f64,
    at: &dyn Fn(f64) -> [f64; 3],
    out: &mut RowResult,
) {
    for (i, x) in c.iter().enumerate() {
        if x.dominant as usize != k {
            continue;
        }
        let end = nearest_end(ray, x.t, x.orientation);
        let (dev, t_part, move_id) = match end {
            Some((t, m)) => (f64::from(x.orientation) * (t - x.t) * x.cosine, t, m),
            None => {
                // No material on the ray: the design's depth, inward.
                let depth = if x.orientation > 0 {
                    i.checked_sub(1).map_or(0.0, |j| x.t - c[j].t)
                } else {
                    c.get(i + 1).map_or(0.0, |n| n.t - x.t)
                };
                (-depth * x.cosine, x.t, UNCUT)
            }
        };
        out.measured += 1;
        let area = h * h / x.cosine;
        let b = bin_of(dev, tol);
        out.bins[b].0 += 1;
        out.bins[b].1 += area;
        if dev.abs() > tol {
            out.beyond.push(Sample {
                deviation_mm: dev,
                design_point: at(x.t),
                part_point: at(t_part),
                move_id: (move_id != UNCUT).then_some(move_id),
                family: k as u8,
                iu: iu as u32,
                iv: iv as u32,
                orientation: x.orientation,
                area_mm2: area,
            });
        }
    }
}

/// The end of the ray's material nearest to `t` facing the same way
/// (+1: upper ends, −1: lower ends), with the move that made it.
pub fn nearest_end(ray: &[Segment], t: f64, orientation: i8) -> Option<(f64, u32)> {
    let end = |s: &Segment| {
        if orientation > 0 {
            (s.hi, s.hi_move)
        } else {
            (s.lo, s.lo_move)
        }
    };
    let i = ray.partition_point(|s| end(s).0 < t);
    let after = ray.get(i).map(end);
    let before = i.checked_sub(1).map(|j| end(&ray[j]));
    match (before, after) {
        (Some(b), Some(a)) => Some(if t - b.0 <= a.0 - t { b } else { a }),
        (b, a) => b.or(a),
    }
}

/// Lengths of design ∖ part and part ∖ design on one ray (design intervals
/// from the crossings by parity).
fn symmetric_difference(c: &[Crossing], ray: &[Segment]) -> (f64, f64) {
    let design: Vec<(f64, f64)> = c.chunks_exact(2).map(|p| (p[0].t, p[1].t)).collect();
    let part: Vec<(f64, f64)> = ray.iter().map(|s| (s.lo, s.hi)).collect();
    let len = |a: &[(f64, f64)]| a.iter().map(|(l, h)| h - l).sum::<f64>();
    let common = overlap(&design, &part);
    (len(&design) - common, len(&part) - common)
}

fn overlap(a: &[(f64, f64)], b: &[(f64, f64)]) -> f64 {
    let (mut i, mut j, mut sum) = (0, 0, 0.0);
    while i < a.len() && j < b.len() {
        let lo = a[i].0.max(b[j].0);
        let hi = a[i].1.min(b[j].1);
        if hi > lo {
            sum += hi - lo;
        }
        if a[i].1 < b[j].1 {
            i += 1;
        } else {
            j += 1;
        }
    }
    sum
}

/// Connected components of the samples beyond tolerance (module doc).
fn regions(samples: &[Sample], h: f64) -> (Vec<Region>, Vec<Region>) {
    use std::collections::HashMap;
    let mut by_ray: HashMap<(u8, u32, u32), Vec<usize>> = HashMap::new();
    for (i, s) in samples.iter().enumerate() {
        by_ray.entry((s.family, s.iu, s.iv)).or_default().push(i);
    }
    let mut parent: Vec<usize> = (0..samples.len()).collect();
    fn find(p: &mut [usize], mut i: usize) -> usize {
        while p[i] != i {
            p[i] = p[p[i]];
            i = p[i];
        }
        i
    }
    for (i, s) in samples.iter().enumerate() {
        let k = s.family as usize;
        let t = s.design_point;
        for (du, dv) in [(1i64, 0i64), (0, 1)] {
            let key = (
                s.family,
                (s.iu as i64 + du) as u32,
                (s.iv as i64 + dv) as u32,
            );
            let Some(list) = by_ray.get(&key) else {
                continue;
            };
            for &j in list {
                let o = &samples[j];
                if o.orientation == s.orientation
                    && (o.deviation_mm > 0.0) == (s.deviation_mm > 0.0)
                    && (o.design_point[k] - t[k]).abs() <= 2.0 * h
                {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    // The smaller index is the root: independent of order.
                    let (lo, hi) = (a.min(b), a.max(b));
                    parent[hi] = lo;
                }
            }
        }
    }
    let mut acc: Vec<Option<Region>> = vec![None; samples.len()];
    for (i, s) in samples.iter().enumerate() {
        let r = find(&mut parent, i);
        let reg = acc[r].get_or_insert(Region {
            samples: 0,
            area_mm2: 0.0,
            deviation_mm: 0.0,
            at: s.part_point,
            move_id: s.move_id,
        });
        reg.samples += 1;
        reg.area_mm2 += s.area_mm2;
        if s.deviation_mm.abs() > reg.deviation_mm.abs() {
            reg.deviation_mm = s.deviation_mm;
            reg.at = s.part_point;
            reg.move_id = s.move_id;
        }
    }
    let (mut gouge, mut residual): (Vec<Region>, Vec<Region>) = acc
        .into_iter()
        .flatten()
        .partition(|r| r.deviation_mm < 0.0);
    gouge.sort_by(|a, b| a.deviation_mm.total_cmp(&b.deviation_mm));
    residual.sort_by(|a, b| b.deviation_mm.total_cmp(&a.deviation_mm));
    (gouge, residual)
}
