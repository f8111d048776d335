//! Test and bench support: closed triangle meshes made by hand.

#![allow(dead_code)]

use kinpost_machine::Mesh;

/// A closed slab over `[x0, x1] × [y0, y1]`, bottom at `z0`, top at
/// `z1 + wave_mm · sin(x / 7) · sin(y / 5)`, its top and bottom cut into
/// `nx × ny` vertices (`4 (nx − 1)(ny − 1)` triangles and the sides),
/// oriented outwards.
#[allow(clippy::too_many_arguments)]
pub fn slab(
    [x0, x1]: [f64; 2],
    [y0, y1]: [f64; 2],
    [z0, z1]: [f64; 2],
    nx: usize,
    ny: usize,
    wave_mm: f64,
) -> Mesh {
    let mut vertices = Vec::with_capacity(2 * nx * ny);
    for (layer, z) in [(0, z0), (1, z1)] {
        for j in 0..ny {
            for i in 0..nx {
                let x = x0 + (x1 - x0) * i as f64 / (nx - 1) as f64;
                let y = y0 + (y1 - y0) * j as f64 / (ny - 1) as f64;
                let edge = i == 0 || j == 0 || i == nx - 1 || j == ny - 1;
                let dz = if layer == 1 && !edge {
                    wave_mm * (x / 7.0).sin() * (y / 5.0).sin()
                } else {
                    0.0
                };
                vertices.push([x, y, z + dz]);
            }
        }
    }
    let v = |layer: usize, i: usize, j: usize| (layer * nx * ny + j * nx + i) as u32;
    let mut triangles = Vec::new();
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            // Top: counter-clockwise seen from +z; bottom the other way.
            let (a, b, c, d) = (
                v(1, i, j),
                v(1, i + 1, j),
                v(1, i + 1, j + 1),
                v(1, i, j + 1),
            );
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
            let (a, b, c, d) = (
                v(0, i, j),
                v(0, i + 1, j),
                v(0, i + 1, j + 1),
                v(0, i, j + 1),
            );
            triangles.push([a, c, b]);
            triangles.push([a, d, c]);
        }
    }
    // The boundary loop counter-clockwise seen from +z; each side quad
    // faces outwards.
    let mut ring = Vec::new();
    ring.extend((0..nx - 1).map(|i| (i, 0)));
    ring.extend((0..ny - 1).map(|j| (nx - 1, j)));
    ring.extend((1..nx).rev().map(|i| (i, ny - 1)));
    ring.extend((1..ny).rev().map(|j| (0, j)));
    for k in 0..ring.len() {
        let (i0, j0) = ring[k];
        let (i1, j1) = ring[(k + 1) % ring.len()];
        let (a, b, c, d) = (v(0, i0, j0), v(0, i1, j1), v(1, i1, j1), v(1, i0, j0));
        triangles.push([a, b, c]);
        triangles.push([a, c, d]);
    }
    Mesh {
        source: format!("slab {nx}x{ny}"),
        vertices,
        triangles,
    }
}

/// The closed slab of about `triangles` triangles standing for the blank of
/// the flat part of Qiao et al. 2022 (§4.1.2: 400 × 100 × 7.5 mm) in the
/// part frame of `mts1600`: x from −452 to −52, y ±50, z from −6 to 1.5.
pub fn flat_part_blank(triangles: usize, wave_mm: f64) -> Mesh {
    // 4 (nx − 1)(ny − 1) ≈ triangles with nx − 1 = 4 (ny − 1).
    let ny = ((triangles as f64 / 16.0).sqrt().round() as usize).max(1) + 1;
    let nx = 4 * (ny - 1) + 1;
    slab([-452.0, -52.0], [-50.0, 50.0], [-6.0, 1.5], nx, ny, wave_mm)
}
