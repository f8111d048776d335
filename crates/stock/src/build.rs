//! Stocks from meshes: a closed mesh by ray parity, and a design grown by
//! an allowance.

use nalgebra::{Point3, Vector3};
use rayon::prelude::*;

use crate::dexel::{Ray, Segment, UNCUT, add};
use crate::kernel::triangle_offset_span;
use crate::mesh::{Mesh, RayGrid, bin_rows, row_crossings};
use crate::stock::{Stock, StockError};
use crate::tolerance::SLIVER_MM;

impl Stock {
    /// The grid of the rays of family `k`, for [`crate::mesh::crossings`].
    pub fn ray_grid(&self, k: usize) -> RayGrid {
        let f = self.family(k);
        let o = self.origin();
        RayGrid {
            k,
            u: f.u,
            v: f.v,
            nu: f.nu,
            nv: f.nv,
            origin: [o.x, o.y, o.z],
            h: self.resolution_mm(),
        }
    }

    /// The solid a closed mesh bounds: along each ray the sorted crossings
    /// pair up, entry then exit (parity; see [`crate::mesh`] for rays
    /// through edges and vertices). A ray that crosses the mesh an odd
    /// number of times means the mesh is not closed: an error naming how
    /// many rays did.
    pub fn from_mesh(mesh: &Mesh, resolution_mm: f64) -> Result<Stock, StockError> {
        let (lo, hi) = mesh_box(mesh)?;
        let mut stock = Stock::from_mesh_in(mesh, lo, hi, resolution_mm)?;
        stock.set_initial_volume();
        Ok(stock)
    }

    /// The design grown by `allowance_mm` (a stock "design+0.2"): the
    /// closed mesh's solid united with every triangle grown by a ball of the
    /// allowance (exact along each ray: see
    /// [`crate::kernel::triangle_offset_span`]), i.e. all points within the
    /// allowance of the solid.
    pub fn from_mesh_offset(
        mesh: &Mesh,
        allowance_mm: f64,
        resolution_mm: f64,
    ) -> Result<Stock, StockError> {
        if !(allowance_mm.is_finite() && allowance_mm >= 0.0) {
            return Err(StockError::Allowance(allowance_mm));
        }
        let (lo, hi) = mesh_box(mesh)?;
        let a = allowance_mm;
        let grow = Vector3::repeat(a + resolution_mm);
        let mut stock = Stock::from_mesh_in(mesh, lo - grow, hi + grow, resolution_mm)?;
        let grids: Vec<RayGrid> = (0..3).map(|k| stock.ray_grid(k)).collect();
        if a > 0.0 {
            for (f, g) in stock.families_mut().iter_mut().zip(grids) {
                let bins = bin_rows(mesh, &g, a);
                f.rays
                    .par_chunks_mut(g.nu)
                    .zip(bins.par_iter())
                    .enumerate()
                    .for_each(|(iv, (row, bin))| {
                        grow_row(mesh, &g, bin, iv, a, row);
                    });
            }
        }
        stock.set_initial_volume();
        Ok(stock)
    }

    /// [`Stock::from_mesh`] on a lattice over a given box.
    fn from_mesh_in(
        mesh: &Mesh,
        lo: Point3<f64>,
        hi: Point3<f64>,
        resolution_mm: f64,
    ) -> Result<Stock, StockError> {
        let mut stock = Stock::empty(lo, hi, resolution_mm)?;
        let grids: Vec<RayGrid> = (0..3).map(|k| stock.ray_grid(k)).collect();
        let mut odd = 0usize;
        for (f, g) in stock.families_mut().iter_mut().zip(grids) {
            let bins = bin_rows(mesh, &g, 0.0);
            odd += f
                .rays
                .par_chunks_mut(g.nu)
                .zip(bins.par_iter())
                .enumerate()
                .map(|(iv, (row, bin))| {
                    let mut odd = 0;
                    for (ray, c) in row.iter_mut().zip(row_crossings(mesh, &g, bin, iv)) {
                        odd += c.len() % 2;
                        for pair in c.chunks_exact(2) {
                            push_merged(ray, pair[0].t, pair[1].t);
                        }
                    }
                    odd
                })
                .sum::<usize>();
        }
        if odd > 0 {
            return Err(StockError::OpenMesh { rays: odd });
        }
        Ok(stock)
    }
}

fn grow_row(mesh: &Mesh, g: &RayGrid, bin: &[u32], iv: usize, a: f64, row: &mut [Ray]) {
    let pv = g.origin[g.v] + (iv as f64 + 0.5) * g.h;
    let mut d = Vector3::zeros();
    d[g.k] = 1.0;
    for &ti in bin {
        let p = mesh.triangles[ti as usize].map(|i| mesh.vertices[i as usize].coords);
        let lo = p[0][g.u].min(p[1][g.u]).min(p[2][g.u]) - a;
        let hi = p[0][g.u].max(p[1][g.u]).max(p[2][g.u]) + a;
        let i0 = ((lo - g.origin[g.u]) / g.h - 0.5).ceil().max(0.0);
        let i1 = ((hi - g.origin[g.u]) / g.h - 0.5)
            .floor()
            .min(g.nu as f64 - 1.0);
        if !(i0 <= i1) {
            continue;
        }
        for iu in i0 as usize..=i1 as usize {
            let mut o = Vector3::zeros();
            o[g.u] = g.origin[g.u] + (iu as f64 + 0.5) * g.h;
            o[g.v] = pv;
            if let Some(s) = triangle_offset_span(&o, &d, p, a) {
                add(&mut row[iu], s.lo, s.hi);
            }
        }
    }
}

fn mesh_box(mesh: &Mesh) -> Result<(Point3<f64>, Point3<f64>), StockError> {
    let (lo, hi) = mesh.bounds().ok_or(StockError::BadMesh)?;
    if !(lo.iter().chain(hi.iter()).all(|c| c.is_finite())) {
        return Err(StockError::BadMesh);
    }
    // A flat mesh still gets a lattice one cell thick.
    let pad = Vector3::from_fn(|i, _| {
        if hi[i] > lo[i] {
            0.0
        } else {
            1e-6 * lo[i].abs().max(1.0)
        }
    });
    Ok((lo - pad, hi + pad))
}

/// Appends [a, b] to a ray built in order, merging with the last interval
/// when they touch; slivers are dropped.
fn push_merged(ray: &mut Ray, a: f64, b: f64) {
    if !(b - a >= SLIVER_MM) {
        return;
    }
    if let Some(last) = ray.last_mut()
        && a <= last.hi
    {
        last.hi = last.hi.max(b);
        return;
    }
    ray.push(Segment {
        lo: a,
        hi: b,
        lo_move: UNCUT,
        hi_move: UNCUT,
    });
}
