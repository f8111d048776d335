//! Files: the simulated part as STL, as a PLY coloured by deviation, and an
//! SVG map of the deviation. Every writer writes to a `Write` (the caller
//! decides where, and makes files all-or-nothing).

use std::collections::HashMap;
use std::io::{self, Write};

use crate::contour::PartMesh;
use crate::design::{Comparison, Sample};
use crate::stock::Stock;

/// Writes the mesh as binary STL (single precision, as the format has it).
pub fn write_stl<W: Write>(mesh: &PartMesh, w: &mut W) -> io::Result<()> {
    let v = |i: u32| {
        let p = mesh.vertices[i as usize];
        stl_io::Vertex::new([p[0] as f32, p[1] as f32, p[2] as f32])
    };
    let tris = mesh.triangles.iter().map(|t| {
        let n = normal(mesh, t);
        stl_io::Triangle {
            normal: stl_io::Normal::new([n[0] as f32, n[1] as f32, n[2] as f32]),
            vertices: t.map(v),
        }
    });
    stl_io::write_stl(w, tris)
}

fn normal(mesh: &PartMesh, t: &[u32; 3]) -> [f64; 3] {
    let p = t.map(|i| mesh.vertices[i as usize]);
    let e1 = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let e2 = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len > 0.0 {
        n.map(|c| c / len)
    } else {
        [0.0; 3]
    }
}

/// The colour of a deviation: green within the tolerance; beyond it blue
/// (residual) or red (gouge), deeper up to 4 tolerances.
pub fn deviation_colour(deviation_mm: f64, tolerance_mm: f64) -> [u8; 3] {
    if deviation_mm.abs() <= tolerance_mm {
        return [40, 170, 60];
    }
    let s = ((deviation_mm.abs() / tolerance_mm - 1.0) / 3.0).clamp(0.0, 1.0);
    let shade = (200.0 - 140.0 * s) as u8;
    if deviation_mm < 0.0 {
        [230, shade / 2, shade / 2]
    } else {
        [shade / 2, shade / 2, 230]
    }
}

/// Samples beyond tolerance hashed by cell of size `cell`.
struct SampleGrid<'a> {
    cell: f64,
    map: HashMap<[i64; 3], Vec<&'a Sample>>,
}

impl<'a> SampleGrid<'a> {
    fn new(samples: &'a [Sample], cell: f64) -> Self {
        let mut map: HashMap<[i64; 3], Vec<&Sample>> = HashMap::new();
        for s in samples {
            map.entry(s.part_point.map(|c| (c / cell).floor() as i64))
                .or_default()
                .push(s);
        }
        SampleGrid { cell, map }
    }
    /// The nearest sample within one cell size, if any.
    fn near(&self, p: [f64; 3]) -> Option<&'a Sample> {
        let c = p.map(|x| (x / self.cell).floor() as i64);
        let mut best: Option<(f64, &Sample)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = self.map.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    for s in list {
                        let d = (0..3)
                            .map(|i| (s.part_point[i] - p[i]).powi(2))
                            .sum::<f64>();
                        if d <= self.cell * self.cell
                            && best.is_none_or(|(bd, bs)| {
                                d < bd || (d == bd && s.deviation_mm.abs() > bs.deviation_mm.abs())
                            })
                        {
                            best = Some((d, s));
                        }
                    }
                }
            }
        }
        best.map(|(_, s)| s)
    }
}

/// Writes the mesh as binary little-endian PLY with a colour per vertex:
/// the deviation of the nearest sample beyond tolerance within 1.5 ray
/// spacings, else green (within tolerance). MeshLab, ParaView and Blender
/// read it.
pub fn write_ply<W: Write>(
    mesh: &PartMesh,
    cmp: &Comparison,
    resolution_mm: f64,
    w: &mut W,
) -> io::Result<()> {
    let grid = SampleGrid::new(&cmp.beyond, 1.5 * resolution_mm);
    let mut out = io::BufWriter::new(w);
    write!(
        out,
        "ply\nformat binary_little_endian 1.0\ncomment kinpost-stock: simulated part coloured by deviation from the design (tolerance {} mm; red gouge, blue residual, green within)\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float deviation\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        cmp.tolerance_mm,
        mesh.vertices.len(),
        mesh.triangles.len()
    )?;
    for p in &mesh.vertices {
        let dev = grid.near(*p).map_or(0.0, |s| s.deviation_mm);
        for c in p {
            out.write_all(&(*c as f32).to_le_bytes())?;
        }
        out.write_all(&(dev as f32).to_le_bytes())?;
        out.write_all(&deviation_colour(dev, cmp.tolerance_mm))?;
    }
    for t in &mesh.triangles {
        out.write_all(&[3u8])?;
        for i in t {
            out.write_all(&(*i as i32).to_le_bytes())?;
        }
    }
    out.flush()
}

/// Writes an SVG map of the deviation seen from +Z: the stock's outline,
/// every sample beyond tolerance at its XY position (the largest magnitude
/// per display cell of at most 600 × 600), the deepest gouge and largest
/// residual marked with their moves, and a legend.
pub fn write_svg<W: Write>(stock: &Stock, cmp: &Comparison, w: &mut W) -> io::Result<()> {
    let (lo, hi) = (stock.origin(), stock.max_corner());
    let (sx, sy) = (hi.x - lo.x, hi.y - lo.y);
    let cell = (sx.max(sy) / 600.0).max(stock.resolution_mm());
    let scale = 800.0 / sx.max(sy);
    let (width, height) = (sx * scale + 40.0, sy * scale + 110.0);
    let mut cells: HashMap<(i64, i64), f64> = HashMap::new();
    for s in &cmp.beyond {
        let key = (
            ((s.part_point[0] - lo.x) / cell).floor() as i64,
            ((s.part_point[1] - lo.y) / cell).floor() as i64,
        );
        let e = cells.entry(key).or_insert(0.0);
        if s.deviation_mm.abs() > e.abs() {
            *e = s.deviation_mm;
        }
    }
    let mut keys: Vec<_> = cells.into_iter().collect();
    keys.sort_by_key(|k| k.0);
    let mut out = io::BufWriter::new(w);
    writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.1} {height:.1}" font-family="sans-serif" font-size="12">"#
    )?;
    writeln!(
        out,
        r#"<title>Deviation from the design, seen from +Z (tolerance {} mm)</title>"#,
        cmp.tolerance_mm
    )?;
    // Part frame X to the right, Y up.
    let px = |x: f64| 20.0 + (x - lo.x) * scale;
    let py = |y: f64| 20.0 + (hi.y - y) * scale;
    writeln!(
        out,
        r##"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="#2aaa3c" fill-opacity="0.25" stroke="#333"/>"##,
        px(lo.x),
        py(hi.y),
        sx * scale,
        sy * scale
    )?;
    let side = (cell * scale).max(0.5);
    for ((i, j), dev) in keys {
        let [r, g, b] = deviation_colour(dev, cmp.tolerance_mm);
        let (x, y) = (lo.x + i as f64 * cell, lo.y + (j + 1) as f64 * cell);
        writeln!(
            out,
            r#"<rect x="{:.2}" y="{:.2}" width="{side:.2}" height="{side:.2}" fill="rgb({r},{g},{b})"/>"#,
            px(x),
            py(y)
        )?;
    }
    let mut mark = |s: Option<&Sample>, label: &str| -> io::Result<()> {
        if let Some(s) = s {
            let mv = s
                .move_id
                .map_or("uncut stock".to_string(), |m| format!("move {m}"));
            writeln!(
                out,
                r#"<circle cx="{:.2}" cy="{:.2}" r="6" fill="none" stroke="black" stroke-width="1.5"/>"#,
                px(s.part_point[0]),
                py(s.part_point[1])
            )?;
            writeln!(
                out,
                r#"<text x="{:.2}" y="{:.2}">{label} {:.4} mm ({mv})</text>"#,
                px(s.part_point[0]) + 8.0,
                py(s.part_point[1]) - 8.0,
                s.deviation_mm
            )?;
        }
        Ok(())
    };
    mark(cmp.gouge_max(), "gouge")?;
    mark(cmp.residual_max(), "residual")?;
    let ly = sy * scale + 50.0;
    let t = cmp.tolerance_mm;
    for (i, (dev, text)) in [
        (-4.0 * t, "gouge ≥ 4 tol"),
        (-1.5 * t, "gouge"),
        (0.0, "within ±tol"),
        (1.5 * t, "residual"),
        (4.0 * t, "residual ≥ 4 tol"),
    ]
    .iter()
    .enumerate()
    {
        let [r, g, b] = deviation_colour(*dev, t);
        let x = 20.0 + i as f64 * 150.0;
        writeln!(
            out,
            r#"<rect x="{x:.0}" y="{ly:.0}" width="14" height="14" fill="rgb({r},{g},{b})"/><text x="{:.0}" y="{:.0}">{text}</text>"#,
            x + 20.0,
            ly + 12.0
        )?;
    }
    writeln!(
        out,
        r#"<text x="20" y="{:.0}">gouge max {} · residual max {} · {} gouge and {} residual regions</text>"#,
        ly + 40.0,
        cmp.gouge_max()
            .map_or("none".into(), |s| format!("{:.4} mm", s.deviation_mm)),
        cmp.residual_max()
            .map_or("none".into(), |s| format!("{:.4} mm", s.deviation_mm)),
        cmp.gouge_regions.len(),
        cmp.residual_regions.len()
    )?;
    writeln!(out, "</svg>")?;
    out.flush()
}
