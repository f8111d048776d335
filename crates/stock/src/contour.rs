//! A watertight triangle mesh of the simulated part from the tri-dexels.
//!
//! **Method: marching tetrahedra on the ray lattice.** The lattice nodes
//! are where the three families' rays meet (cell centres of the stock's
//! grid), padded by one layer of empty nodes so the mesh closes at the
//! stock's faces. A node is solid when the Z ray through it holds material
//! there. Each lattice cell is split into six tetrahedra around its main
//! diagonal (the same diagonal in every cell, so the splits of neighbouring
//! cells match on their shared faces: Freudenthal's triangulation), and each
//! tetrahedron with solid and empty corners gets one or two triangles with
//! their vertices on its edges. Vertices are identified by their lattice
//! edge, so a triangle's edge is shared with exactly one other triangle:
//! the mesh is closed and 2-manifold by construction.
//!
//! Vertex positions: on an edge along X, Y or Z the vertex is snapped to the
//! end of that ray's material inside the edge (the end nearest the edge's
//! middle): exact along the ray. On a diagonal edge it is interpolated
//! linearly between the corners' signed distances to the nearest ray end
//! (an estimate within the resolution). No vertex leaves its edge, so no
//! vertex is farther than √3·h from the true surface, and the ones on
//! axis edges are on it.
//!
//! Only the cells whose corners differ are visited: per column of four Z
//! rays, the Z ranges where the four rays change or disagree.

use std::collections::HashMap;

use crate::dexel::{Segment, contains};
use crate::stock::Stock;

/// A triangle mesh of the simulated part.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PartMesh {
    /// Vertex positions, part frame (mm).
    pub vertices: Vec<[f64; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
}

/// The six tetrahedra of a cell by corner bits (x = 1, y = 2, z = 4), each
/// along a path 0 → e_a → e_a + e_b → 7.
const TETS: [[usize; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

struct Lattice<'a> {
    stock: &'a Stock,
    n: [i64; 3],
    h: f64,
    origin: [f64; 3],
}

impl Lattice<'_> {
    fn inside(&self, p: [i64; 3]) -> bool {
        (0..3).all(|i| p[i] >= 0 && p[i] < self.n[i])
    }
    fn coord(&self, i: usize, n: i64) -> f64 {
        self.origin[i] + (n as f64 + 0.5) * self.h
    }
    /// The ray along axis `a` through node `p` (inside the lattice).
    fn ray(&self, a: usize, p: [i64; 3]) -> &[Segment] {
        let f = self.stock.family(a);
        f.ray(p[f.u] as usize, p[f.v] as usize)
    }
    fn solid(&self, p: [i64; 3]) -> bool {
        self.inside(p) && contains(self.ray(2, p), self.coord(2, p[2]))
    }
    fn id(&self, p: [i64; 3]) -> u64 {
        let m = |i: usize| (self.n[i] + 2) as u64;
        ((p[2] + 1) as u64 * m(1) + (p[1] + 1) as u64) * m(0) + (p[0] + 1) as u64
    }
    /// Signed distance estimate: + inside, the nearest ray end along the
    /// three rays through the node.
    fn signed(&self, p: [i64; 3]) -> f64 {
        let solid = self.solid(p);
        let mut d = self.h;
        for a in 0..3 {
            // The ray along a through p exists when the other two indices
            // are in the lattice (p itself may be a padding node).
            let f = self.stock.family(a);
            let (iu, iv) = (p[f.u], p[f.v]);
            if iu < 0 || iv < 0 || iu >= self.n[f.u] || iv >= self.n[f.v] {
                continue;
            }
            let t = self.coord(a, p[a]);
            for s in f.ray(iu as usize, iv as usize) {
                d = d.min((s.lo - t).abs()).min((s.hi - t).abs());
            }
        }
        let d = d.max(1e-3 * self.h);
        if solid { d } else { -d }
    }
    fn position(&self, a: [i64; 3], b: [i64; 3]) -> [f64; 3] {
        let pa: [f64; 3] = std::array::from_fn(|i| self.coord(i, a[i]));
        let pb: [f64; 3] = std::array::from_fn(|i| self.coord(i, b[i]));
        let diff: Vec<usize> = (0..3).filter(|&i| a[i] != b[i]).collect();
        if let [axis] = diff[..] {
            let node = if self.inside(a) { a } else { b };
            if self.inside(node) {
                let (lo, hi) = (pa[axis].min(pb[axis]), pa[axis].max(pb[axis]));
                let mid = 0.5 * (lo + hi);
                let best = self
                    .ray(axis, node)
                    .iter()
                    .flat_map(|s| [s.lo, s.hi])
                    .filter(|&t| t >= lo && t <= hi)
                    .min_by(|x, y| (x - mid).abs().total_cmp(&(y - mid).abs()));
                if let Some(t) = best {
                    let mut p = pa;
                    p[axis] = t;
                    return p;
                }
            }
        }
        let (fa, fb) = (self.signed(a), self.signed(b));
        let s = (fa / (fa - fb)).clamp(0.0, 1.0);
        std::array::from_fn(|i| pa[i] + s * (pb[i] - pa[i]))
    }
}

/// The watertight mesh of the simulated part (module doc). Deterministic:
/// cells are visited in lattice order.
pub fn contour(stock: &Stock) -> PartMesh {
    let c = stock.counts();
    let l = Lattice {
        stock,
        n: [c[0] as i64, c[1] as i64, c[2] as i64],
        h: stock.resolution_mm(),
        origin: [stock.origin().x, stock.origin().y, stock.origin().z],
    };
    let mut mesh = PartMesh::default();
    let mut ids: HashMap<(u64, u64), u32> = HashMap::new();
    for j in -1..l.n[1] {
        for i in -1..l.n[0] {
            for k in active_cells(&l, i, j) {
                cell(&l, [i, j, k], &mut ids, &mut mesh);
            }
        }
    }
    mesh
}

/// The k of the cells of column (i, j) whose corners may differ.
fn active_cells(l: &Lattice, i: i64, j: i64) -> Vec<i64> {
    let mut ends: Vec<f64> = Vec::new();
    let mut any = false;
    let mut all = true;
    for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
        let p = [i + di, j + dj, 0];
        if l.inside(p) {
            let r = l.ray(2, p);
            any |= !r.is_empty();
            all &= r.len() == 1;
            ends.extend(r.iter().flat_map(|s| [s.lo, s.hi]));
        } else {
            all = false;
        }
    }
    if !any {
        return Vec::new();
    }
    // Node index range around each end, and where the rays disagree.
    let to_k = |t: f64| (t - l.origin[2]) / l.h - 0.5;
    let mut ks: Vec<i64> = Vec::new();
    for &t in &ends {
        let k = to_k(t).floor() as i64;
        ks.extend([k - 1, k, k + 1]);
    }
    if !all || !same_four(l, i, j) {
        // Disagreeing columns: every cell between the extreme ends.
        let lo = ends.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = ends.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (a, b) = (to_k(lo).floor() as i64 - 1, to_k(hi).ceil() as i64 + 1);
        ks.extend(a..=b);
    }
    ks.retain(|&k| k >= -1 && k < l.n[2]);
    ks.sort_unstable();
    ks.dedup();
    ks
}

/// Whether the four Z rays of a column hold the same single interval
/// (the common case of an untouched or evenly cut column: only the cells
/// at its ends can be active).
fn same_four(l: &Lattice, i: i64, j: i64) -> bool {
    let r0 = l.ray(2, [i, j, 0]);
    [(1, 0), (0, 1), (1, 1)].iter().all(|&(di, dj)| {
        let r = l.ray(2, [i + di, j + dj, 0]);
        let k = |t: f64| ((t - l.origin[2]) / l.h - 0.5).floor() as i64;
        r.len() == r0.len()
            && r.iter()
                .zip(r0)
                .all(|(a, b)| k(a.lo) == k(b.lo) && k(a.hi) == k(b.hi))
    })
}

fn cell(l: &Lattice, base: [i64; 3], ids: &mut HashMap<(u64, u64), u32>, mesh: &mut PartMesh) {
    let corner = |c: usize| {
        [
            base[0] + (c & 1) as i64,
            base[1] + ((c >> 1) & 1) as i64,
            base[2] + ((c >> 2) & 1) as i64,
        ]
    };
    let solid: [bool; 8] = std::array::from_fn(|c| l.solid(corner(c)));
    if solid.iter().all(|&s| s) || solid.iter().all(|&s| !s) {
        return;
    }
    for tet in TETS {
        let inside: Vec<usize> = tet.iter().copied().filter(|&c| solid[c]).collect();
        let outside: Vec<usize> = tet.iter().copied().filter(|&c| !solid[c]).collect();
        if inside.is_empty() || outside.is_empty() {
            continue;
        }
        // Faces as triples of corner edges (solid corner, empty corner).
        let faces: Vec<[(usize, usize); 3]> = match (inside.len(), outside.len()) {
            (1, 3) => vec![[
                (inside[0], outside[0]),
                (inside[0], outside[1]),
                (inside[0], outside[2]),
            ]],
            (3, 1) => vec![[
                (inside[0], outside[0]),
                (inside[1], outside[0]),
                (inside[2], outside[0]),
            ]],
            _ => {
                let (a, b, c, d) = (inside[0], inside[1], outside[0], outside[1]);
                vec![[(a, c), (a, d), (b, d)], [(a, c), (b, d), (b, c)]]
            }
        };
        // Orientation from the lattice: the normal of the triangle of edge
        // midpoints must point from the solid corners to the empty ones
        // (decided on the lattice, so snapping cannot flip it).
        let centre = |cs: &[usize]| -> [f64; 3] {
            let mut m = [0.0; 3];
            for &c in cs {
                let p = corner(c);
                for i in 0..3 {
                    m[i] += p[i] as f64 / cs.len() as f64;
                }
            }
            m
        };
        let (ci, co) = (centre(&inside), centre(&outside));
        let dir = [co[0] - ci[0], co[1] - ci[1], co[2] - ci[2]];
        for f in faces {
            let mids = f.map(|(a, b)| {
                let (pa, pb) = (corner(a), corner(b));
                [0, 1, 2].map(|i| 0.5 * (pa[i] + pb[i]) as f64)
            });
            let f = if normal_dot(&mids, dir) < 0.0 {
                [f[0], f[2], f[1]]
            } else {
                f
            };
            let tri = f.map(|(a, b)| {
                let (pa, pb) = (corner(a), corner(b));
                let (ia, ib) = (l.id(pa), l.id(pb));
                let key = (ia.min(ib), ia.max(ib));
                *ids.entry(key).or_insert_with(|| {
                    mesh.vertices.push(if ia < ib {
                        l.position(pa, pb)
                    } else {
                        l.position(pb, pa)
                    });
                    (mesh.vertices.len() - 1) as u32
                })
            });
            mesh.triangles.push(tri);
        }
    }
}

fn normal_dot(p: &[[f64; 3]; 3], dir: [f64; 3]) -> f64 {
    let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    n[0] * dir[0] + n[1] * dir[1] + n[2] * dir[2]
}
