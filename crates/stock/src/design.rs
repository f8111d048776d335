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
use crate::mesh::{Crossing, Mesh, RayGrid, bin_rows, row_crossings};
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
    /// The parameter region is empty or leaves the surface's domain.
    #[error(
        "the parameter region {0:?} (U0, U1, V0, V1) must have U0 < U1 and V0 < V1 inside the surface's domain"
    )]
    Region([f64; 4]),
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
    /// triangles whose chords stay within `chord_mm` of the surface (see
    /// [`Design::from_surface_region`]), over its whole parameter domain.
    pub fn from_surface(
        surface: &Surface,
        chord_mm: f64,
        flip: bool,
    ) -> Result<Design, DesignError> {
        let (u0, u1) = surface.u_range();
        let (v0, v1) = surface.v_range();
        Design::from_surface_region(surface, [u0, u1, v0, v1], chord_mm, flip)
    }

    /// An open design surface over the parameter rectangle
    /// `[u0, u1, v0, v1]` (the part of a surface a path grinds): a grid of
    /// triangles whose chords stay within `chord_mm` of the surface: the
    /// step √(8·chord/κ), κ the largest principal curvature found on a
    /// 33 × 33 grid of parameters, over the longest parameter line of that
    /// grid (its polygon length), with 8 to 2000 steps per direction. The
    /// surface's normal (S_u × S_v) points out of the material; `flip` turns
    /// it over. Pass a chord a tenth of the comparison tolerance or less.
    pub fn from_surface_region(
        surface: &Surface,
        region: [f64; 4],
        chord_mm: f64,
        flip: bool,
    ) -> Result<Design, DesignError> {
        let grid = SurfaceGrid::new(surface, region, chord_mm)?;
        let (nu, nv) = (grid.nu, grid.nv);
        let vertices = grid.points.clone();
        let mut triangles = Vec::with_capacity(2 * (nu - 1) * (nv - 1));
        grid.cells(0, flip, &mut triangles);
        Ok(Design {
            mesh: Mesh {
                vertices,
                triangles,
            },
            closed: false,
        })
    }

    /// The closed shell of an open design surface over `region`: from
    /// `above_mm` outside the surface (along its outward normal, turned over
    /// by `flip`) to `below_mm` inside it, closed by walls along the
    /// region's edges: the stock `design+ALLOWANCE` of a part known by one
    /// surface (a blade side), whose material further in is never reached.
    /// The offsets are exact at the grid points (the chord error of
    /// [`Design::from_surface_region`] between them). An offset that
    /// reaches the smallest radius of curvature found (the shell would fold)
    /// and a point without a normal (it would pinch) are errors.
    pub fn shell_of_surface(
        surface: &Surface,
        region: [f64; 4],
        chord_mm: f64,
        flip: bool,
        above_mm: f64,
        below_mm: f64,
    ) -> Result<Mesh, DesignError> {
        for t in [above_mm, below_mm] {
            if !(t.is_finite() && t >= 0.0) {
                return Err(DesignError::Surface(
                    "the shell's offsets must be finite numbers of mm, 0 or more",
                ));
            }
        }
        if above_mm + below_mm <= 0.0 {
            return Err(DesignError::Surface("the shell has no thickness"));
        }
        let grid = SurfaceGrid::new(surface, region, chord_mm)?;
        if above_mm.max(below_mm) * grid.kappa >= 1.0 {
            return Err(DesignError::Surface(
                "the shell's offset reaches the surface's centre of curvature: the shell would fold over itself",
            ));
        }
        if grid.normals.iter().any(|n| n.norm() == 0.0) {
            return Err(DesignError::Surface(
                "its normal is undefined at a point (S_u × S_v = 0): the shell would pinch there",
            ));
        }
        let (nu, nv) = (grid.nu, grid.nv);
        let n = nu * nv;
        let sign = if flip { -1.0 } else { 1.0 };
        let mut vertices = Vec::with_capacity(2 * n);
        for (p, nrm) in grid.points.iter().zip(&grid.normals) {
            vertices.push(p + nrm * (sign * above_mm));
        }
        for (p, nrm) in grid.points.iter().zip(&grid.normals) {
            vertices.push(p - nrm * (sign * below_mm));
        }
        let mut triangles = Vec::with_capacity(4 * n);
        // Outer sheet facing out, inner sheet facing in.
        grid.cells(0, flip, &mut triangles);
        grid.cells(n as u32, !flip, &mut triangles);
        // Walls: each boundary edge (a, b) of the outer sheet, walked with the
        // sheet on its left seen from outside, joined to its inner copy.
        let id = |i: usize, j: usize| (i * nv + j) as u32;
        let mut boundary = Vec::with_capacity(2 * (nu + nv));
        for i in 0..nu - 1 {
            boundary.push((id(i + 1, 0), id(i, 0)));
            boundary.push((id(i, nv - 1), id(i + 1, nv - 1)));
        }
        for j in 0..nv - 1 {
            boundary.push((id(0, j), id(0, j + 1)));
            boundary.push((id(nu - 1, j + 1), id(nu - 1, j)));
        }
        let m = n as u32;
        for (a, b) in boundary {
            let (a, b) = if flip { (b, a) } else { (a, b) };
            triangles.push([a, b, b + m]);
            triangles.push([a, b + m, a + m]);
        }
        if !vertices.iter().all(|p| p.iter().all(|c| c.is_finite())) {
            return Err(DesignError::Surface("its points are not finite"));
        }
        Ok(Mesh {
            vertices,
            triangles,
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

/// A surface sampled on a grid fine enough for a chord tolerance, with its
/// unit normals (S_u × S_v).
struct SurfaceGrid {
    nu: usize,
    nv: usize,
    points: Vec<Point3<f64>>,
    normals: Vec<nalgebra::Vector3<f64>>,
    /// The largest principal curvature found, 1/mm.
    kappa: f64,
}

impl SurfaceGrid {
    fn new(surface: &Surface, region: [f64; 4], chord_mm: f64) -> Result<SurfaceGrid, DesignError> {
        if !(chord_mm.is_finite() && chord_mm > 0.0) {
            return Err(DesignError::Tolerance(chord_mm));
        }
        let [u0, u1, v0, v1] = region;
        let (du0, du1) = surface.u_range();
        let (dv0, dv1) = surface.v_range();
        let inside = |a: f64, b: f64, lo: f64, hi: f64| {
            a.is_finite() && b.is_finite() && lo <= a && a < b && b <= hi
        };
        if !(inside(u0, u1, du0, du1) && inside(v0, v1, dv0, dv1)) {
            return Err(DesignError::Region(region));
        }
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
        let mut points = Vec::with_capacity(nu * nv);
        let mut normals = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                let d = surface.derivatives(at(i, nu, u0, u1), at(j, nv, v0, v1));
                points.push(Point3::from(d.point));
                normals.push(d.du.cross(&d.dv).try_normalize(0.0).unwrap_or_default());
            }
        }
        if !points.iter().all(|p| p.iter().all(|c| c.is_finite())) {
            return Err(DesignError::Surface("its points are not finite"));
        }
        Ok(SurfaceGrid {
            nu,
            nv,
            points,
            normals,
            kappa,
        })
    }

    /// Two triangles a grid cell, vertex ids from `offset`, counter-clockwise
    /// about S_u × S_v (clockwise with `flip`).
    fn cells(&self, offset: u32, flip: bool, out: &mut Vec<[u32; 3]>) {
        let nv = self.nv;
        let id = |i: usize, j: usize| offset + (i * nv + j) as u32;
        for i in 0..self.nu - 1 {
            for j in 0..nv - 1 {
                let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
                if flip {
                    out.push([a, c, b]);
                    out.push([a, d, c]);
                } else {
                    out.push([a, b, c]);
                    out.push([a, c, d]);
                }
            }
        }
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
    /// The most negative and the most positive deviation measured, within
    /// the tolerance or not, mm (`None` when nothing was measured).
    pub deviation_range_mm: Option<[f64; 2]>,
    /// Every measured deviation, seen along X, Y and Z (one map a ray
    /// family), for the deviation picture.
    pub maps: Vec<DeviationMap>,
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

/// The deviations measured on one ray family, seen along its rays: a grid
/// of at most [`DeviationMap::MAX_CELLS`] cells a side over the rays'
/// cross-section, each holding the deviation of largest magnitude measured
/// on its rays.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DeviationMap {
    /// The rays' axis (0 = X, 1 = Y, 2 = Z): the direction of view.
    pub axis: usize,
    /// The axes across, to the right and up.
    pub across: [usize; 2],
    /// The part coordinates of the grid's low corner on those axes, mm.
    pub origin: [f64; 2],
    /// Cell size, mm.
    pub cell_mm: f64,
    /// Cells to the right and up.
    pub size: [usize; 2],
    /// Row-major from the low corner; `None`: nothing measured there.
    pub cells: Vec<Option<f32>>,
    /// Rays with a measured deviation.
    pub measured_rays: u64,
}

impl DeviationMap {
    /// Largest number of cells a side (a picture of 300 × 300 squares).
    pub const MAX_CELLS: usize = 300;

    fn of_rows(g: &RayGrid, rows: &[RowResult]) -> DeviationMap {
        let per = g.nu.max(g.nv).div_ceil(Self::MAX_CELLS).max(1);
        let size = [g.nu.div_ceil(per), g.nv.div_ceil(per)];
        let mut cells: Vec<Option<f32>> = vec![None; size[0] * size[1]];
        let mut measured_rays = 0;
        for (iv, row) in rows.iter().enumerate() {
            for (iu, &d) in row.rays.iter().enumerate() {
                if d.is_nan() {
                    continue;
                }
                measured_rays += 1;
                let c = &mut cells[(iv / per) * size[0] + iu / per];
                if c.is_none_or(|e| d.abs() > e.abs()) {
                    *c = Some(d);
                }
            }
        }
        DeviationMap {
            axis: g.k,
            across: [g.u, g.v],
            origin: [g.origin[g.u], g.origin[g.v]],
            cell_mm: per as f64 * g.h,
            size,
            cells,
            measured_rays,
        }
    }
}

/// Histogram edges in tolerances.
const EDGES: [f64; 8] = [-8.0, -4.0, -2.0, -1.0, 1.0, 2.0, 4.0, 8.0];

struct RowResult {
    beyond: Vec<Sample>,
    measured: u64,
    /// The largest-magnitude deviation measured on each ray of the row
    /// (NaN: none), for the deviation map.
    rays: Vec<f32>,
    /// Smallest and largest deviation measured.
    range: (f64, f64),
    bins: [(u64, f64); 9],
    gouge_len: f64,
    residual_len: f64,
}

impl Default for RowResult {
    fn default() -> RowResult {
        RowResult {
            beyond: Vec::new(),
            measured: 0,
            rays: Vec::new(),
            range: (f64::INFINITY, f64::NEG_INFINITY),
            bins: Default::default(),
            gouge_len: 0.0,
            residual_len: 0.0,
        }
    }
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
    let mut maps = Vec::with_capacity(3);
    for k in 0..3 {
        let g = stock.ray_grid(k);
        let bins = bin_rows(&design.mesh, &g, 0.0);
        let fam = stock.family(k);
        let rows: Vec<RowResult> = bins
            .par_iter()
            .enumerate()
            .map(|(iv, bin)| {
                let crossings = row_crossings(&design.mesh, &g, bin, iv);
                let mut out = RowResult {
                    rays: vec![f32::NAN; g.nu],
                    ..RowResult::default()
                };
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
        maps.push(DeviationMap::of_rows(&g, &rows));
        for r in rows {
            total.beyond.extend(r.beyond);
            total.measured += r.measured;
            total.range = (total.range.0.min(r.range.0), total.range.1.max(r.range.1));
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
        deviation_range_mm: (total.measured > 0).then_some([total.range.0, total.range.1]),
        maps,
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
        out.range = (out.range.0.min(dev), out.range.1.max(dev));
        let seen = &mut out.rays[iu];
        if seen.is_nan() || dev.abs() > f64::from(seen.abs()) {
            *seen = dev as f32;
        }
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
