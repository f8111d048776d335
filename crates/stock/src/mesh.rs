//! Triangle meshes: STL reading, and the crossings of the stock's rays with
//! a mesh.
//!
//! Ray–mesh crossings are found by rasterising each triangle onto the ray
//! grid of a family (the rays are the lattice points of the plane across
//! them). A ray is inside a triangle's projection by Shewchuk's exact
//! `orient2d` predicate, and a ray exactly on an edge or through a vertex is
//! given to one triangle only by the top-left rule of rasterisers: on a
//! shared edge the two neighbours see the edge in opposite directions, so
//! exactly one takes the ray; around a vertex the half-open edges tile the
//! plane. A ray grazing a silhouette edge (where the mesh turns from facing
//! the ray to facing away) is taken by both triangles or by neither: two
//! crossings at the same point or none, so the parity stays right. A
//! triangle seen edge-on (zero projected area, exactly) is skipped: the
//! rays through it cross its neighbours' shared edges instead.

use std::io::{Read, Seek};

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

/// A triangle mesh in the part frame (mm). Triangles are counter-clockwise
/// seen from outside when the mesh bounds a solid.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Vertex positions.
    pub vertices: Vec<Point3<f64>>,
    /// Vertex indices of each triangle.
    pub triangles: Vec<[u32; 3]>,
}

/// Why an STL file cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    /// The bytes are neither ASCII nor binary STL (or are cut short).
    #[error("{file}: not a readable STL file ({source})")]
    Stl {
        /// The file name as given.
        file: String,
        /// What the reader said.
        source: std::io::Error,
    },
    /// The file holds no triangle.
    #[error("{file}: the STL file holds no triangle")]
    Empty {
        /// The file name as given.
        file: String,
    },
    /// A vertex coordinate is not finite.
    #[error("{file}: triangle {triangle} has a vertex coordinate that is not a finite number")]
    NotFinite {
        /// The file name as given.
        file: String,
        /// 1-based triangle number.
        triangle: usize,
    },
    /// More vertices than 32-bit indices hold.
    #[error("{file}: more than 4 billion vertices")]
    TooLarge {
        /// The file name as given.
        file: String,
    },
}

impl Mesh {
    /// Reads an ASCII or binary STL (vertices merged where identical).
    pub fn read_stl<R: Read + Seek>(mut reader: R, file: &str) -> Result<Mesh, MeshError> {
        let m = stl_io::read_stl(&mut reader).map_err(|source| MeshError::Stl {
            file: file.to_string(),
            source,
        })?;
        if m.faces.is_empty() {
            return Err(MeshError::Empty {
                file: file.to_string(),
            });
        }
        if m.vertices.len() > u32::MAX as usize {
            return Err(MeshError::TooLarge {
                file: file.to_string(),
            });
        }
        let vertices: Vec<Point3<f64>> = m
            .vertices
            .iter()
            .map(|v| Point3::new(v[0] as f64, v[1] as f64, v[2] as f64))
            .collect();
        let mut triangles = Vec::with_capacity(m.faces.len());
        for (i, f) in m.faces.iter().enumerate() {
            let t = f.vertices;
            if t.iter()
                .any(|&k| k >= vertices.len() || !vertices[k].iter().all(|c| c.is_finite()))
            {
                return Err(MeshError::NotFinite {
                    file: file.to_string(),
                    triangle: i + 1,
                });
            }
            triangles.push([t[0] as u32, t[1] as u32, t[2] as u32]);
        }
        Ok(Mesh {
            vertices,
            triangles,
        })
    }

    /// The closed mesh of a box (12 triangles, facing out).
    pub fn cuboid(min: Point3<f64>, max: Point3<f64>) -> Mesh {
        let vertices = (0..8)
            .map(|i| {
                Point3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                )
            })
            .collect();
        // Corner i has x bit 1, y bit 2, z bit 4; each face counter-clockwise from outside.
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        Mesh {
            vertices,
            triangles,
        }
    }

    /// Axis-aligned bounds, `None` for a mesh without triangles.
    pub fn bounds(&self) -> Option<(Point3<f64>, Point3<f64>)> {
        let mut it = self
            .triangles
            .iter()
            .flatten()
            .map(|&i| self.vertices[i as usize]);
        let first = it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.inf(&p), hi.sup(&p))))
    }

    /// Six times the signed volume enclosed (positive for outward normals).
    pub fn signed_volume6(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.vertices[i as usize].coords);
                a.dot(&b.cross(&c))
            })
            .sum()
    }

    /// The same mesh with every triangle turned over.
    pub fn flipped(&self) -> Mesh {
        Mesh {
            vertices: self.vertices.clone(),
            triangles: self.triangles.iter().map(|t| [t[0], t[2], t[1]]).collect(),
        }
    }
}

/// Where a ray crosses a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// Coordinate along the ray, mm.
    pub t: f64,
    /// +1 where the ray leaves the solid (the triangle faces along the
    /// ray), −1 where it enters.
    pub orientation: i8,
    /// |n·d|: the cosine between the triangle's normal and the ray.
    pub cosine: f64,
    /// The axis of the largest component of the triangle's normal.
    pub dominant: u8,
    /// The triangle's index.
    pub triangle: u32,
}

/// A grid of parallel rays: along axis `k`, at `origin[u] + (iu + 0.5)·h`,
/// `origin[v] + (iv + 0.5)·h`.
#[derive(Debug, Clone, Copy)]
pub struct RayGrid {
    /// The rays' axis.
    pub k: usize,
    /// First axis across.
    pub u: usize,
    /// Second axis across.
    pub v: usize,
    /// Ray counts across.
    pub nu: usize,
    /// Ray counts across.
    pub nv: usize,
    /// Lattice origin.
    pub origin: [f64; 3],
    /// Spacing.
    pub h: f64,
}

/// Top-left rule for an edge a→b of a counter-clockwise triangle: a point
/// exactly on it belongs to the triangle when the edge runs downwards, or
/// horizontally to the left... in the (u, v) plane: dv < 0, or dv = 0 and
/// du > 0. The reverse edge of the neighbour gets the opposite answer.
fn owns_edge(a: [f64; 2], b: [f64; 2]) -> bool {
    let (du, dv) = (b[0] - a[0], b[1] - a[1]);
    dv < 0.0 || (dv == 0.0 && du > 0.0)
}

fn coord(p: &[f64; 2]) -> robust::Coord<f64> {
    robust::Coord { x: p[0], y: p[1] }
}

/// Whether the point p lies in the counter-clockwise triangle (a, b, c)
/// under the top-left rule.
fn covers(a: [f64; 2], b: [f64; 2], c: [f64; 2], p: [f64; 2]) -> bool {
    for (s, e) in [(a, b), (b, c), (c, a)] {
        let o = robust::orient2d(coord(&s), coord(&e), coord(&p));
        if o < 0.0 || (o == 0.0 && !owns_edge(s, e)) {
            return false;
        }
    }
    true
}

/// Triangles binned by the rows (index `iv`) of the grid their projection
/// spans, grown by `grow` mm.
pub fn bin_rows(mesh: &Mesh, g: &RayGrid, grow: f64) -> Vec<Vec<u32>> {
    let v = g.v;
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); g.nv];
    for (ti, t) in mesh.triangles.iter().enumerate() {
        let p = t.map(|i| mesh.vertices[i as usize]);
        let lo = p[0][v].min(p[1][v]).min(p[2][v]) - grow;
        let hi = p[0][v].max(p[1][v]).max(p[2][v]) + grow;
        let a = ((lo - g.origin[v]) / g.h - 0.5).ceil().max(0.0);
        let b = ((hi - g.origin[v]) / g.h - 0.5)
            .floor()
            .min(g.nv as f64 - 1.0);
        if a <= b {
            for bin in &mut bins[a as usize..=b as usize] {
                bin.push(ti as u32);
            }
        }
    }
    bins
}

/// The crossings of the rays of row `iv` with the triangles of its bin,
/// per ray, sorted along the ray (ties by triangle index).
pub fn row_crossings(mesh: &Mesh, g: &RayGrid, bin: &[u32], iv: usize) -> Vec<Vec<Crossing>> {
    let (k, u, v, h) = (g.k, g.u, g.v, g.h);
    let mut row: Vec<Vec<Crossing>> = vec![Vec::new(); g.nu];
    let pv = g.origin[v] + (iv as f64 + 0.5) * h;
    for &ti in bin {
        let p = mesh.triangles[ti as usize].map(|i| mesh.vertices[i as usize]);
        let n: Vector3<f64> = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let q = p.map(|x| [x[u], x[v]]);
        let area = robust::orient2d(coord(&q[0]), coord(&q[1]), coord(&q[2]));
        if area == 0.0 || n[k] == 0.0 {
            continue;
        }
        let (q0, q1, q2) = if area > 0.0 {
            (q[0], q[1], q[2])
        } else {
            (q[0], q[2], q[1])
        };
        let lo = q0[0].min(q1[0]).min(q2[0]);
        let hi = q0[0].max(q1[0]).max(q2[0]);
        let a = ((lo - g.origin[u]) / h - 0.5).ceil().max(0.0);
        let b = ((hi - g.origin[u]) / h - 0.5)
            .floor()
            .min(g.nu as f64 - 1.0);
        if !(a <= b) {
            continue;
        }
        let norm = n.norm();
        let dominant = if n.x.abs() >= n.y.abs() && n.x.abs() >= n.z.abs() {
            0
        } else if n.y.abs() >= n.z.abs() {
            1
        } else {
            2
        };
        for iu in a as usize..=b as usize {
            let pu = g.origin[u] + (iu as f64 + 0.5) * h;
            if covers(q0, q1, q2, [pu, pv]) {
                // The plane n·(x − p0) = 0 at (pu, pv).
                let t = p[0][k] - (n[u] * (pu - p[0][u]) + n[v] * (pv - p[0][v])) / n[k];
                row[iu].push(Crossing {
                    t,
                    orientation: if n[k] > 0.0 { 1 } else { -1 },
                    cosine: n[k].abs() / norm,
                    dominant,
                    triangle: ti,
                });
            }
        }
    }
    for r in &mut row {
        r.sort_by(|a, b| a.t.total_cmp(&b.t).then(a.triangle.cmp(&b.triangle)));
    }
    row
}

/// The crossings of every ray of the grid with the mesh, per ray (row-major
/// as the stock's families). Rows run in parallel; the result does not
/// depend on the thread count.
pub fn crossings(mesh: &Mesh, g: &RayGrid) -> Vec<Vec<Crossing>> {
    let bins = bin_rows(mesh, g, 0.0);
    let rows: Vec<Vec<Vec<Crossing>>> = bins
        .par_iter()
        .enumerate()
        .map(|(iv, bin)| row_crossings(mesh, g, bin, iv))
        .collect();
    rows.into_iter().flatten().collect()
}
