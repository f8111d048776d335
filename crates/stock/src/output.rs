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

/// The colour of a deviation on the map: within the tolerance a scale from
/// amber (−tol, cutting into the design) through green (on it) to teal
/// (+tol, material left), so the pattern of a pass shows; beyond it the
/// red and blue of [`deviation_colour`].
pub fn map_colour(deviation_mm: f64, tolerance_mm: f64) -> [u8; 3] {
    if deviation_mm.abs() > tolerance_mm {
        return deviation_colour(deviation_mm, tolerance_mm);
    }
    let t = deviation_mm / tolerance_mm;
    let (green, end) = (
        [40.0, 170.0, 60.0],
        if t < 0.0 {
            [215.0, 175.0, 40.0]
        } else {
            [40.0, 150.0, 210.0]
        },
    );
    let a = t.abs();
    std::array::from_fn(|i| (green[i] + (end[i] - green[i]) * a).round() as u8)
}

const AXES: [&str; 3] = ["X", "Y", "Z"];

/// Writes an SVG map of the deviation, seen along the ray family that
/// measured most of the design (the axis closest to most of its normals):
/// every measured deviation (the largest magnitude per cell of at most
/// 300 × 300), coloured by [`map_colour`], the deepest gouge and largest
/// residual marked with their moves, and a legend.
pub fn write_svg<W: Write>(stock: &Stock, cmp: &Comparison, w: &mut W) -> io::Result<()> {
    let map = cmp.maps.iter().max_by_key(|m| (m.measured_rays, m.axis));
    let (axis, [a, b]) = map.map_or((2, [0, 1]), |m| (m.axis, m.across));
    let (lo, hi) = (stock.origin(), stock.max_corner());
    let (sx, sy) = (hi[a] - lo[a], hi[b] - lo[b]);
    let scale = 800.0 / sx.max(sy);
    let (width, height) = (sx * scale + 40.0, sy * scale + 140.0);
    let t = cmp.tolerance_mm;
    let mut out = io::BufWriter::new(w);
    writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.1} {height:.1}" font-family="sans-serif" font-size="12">"#
    )?;
    writeln!(
        out,
        r#"<title>Deviation from the design, seen along {} ({} to the right, {} up; tolerance {} mm)</title>"#,
        AXES[axis], AXES[a], AXES[b], cmp.tolerance_mm
    )?;
    writeln!(
        out,
        r#"<text x="20" y="14">Deviation from the design seen along {}: {} to the right, {} up, {:.0} mm across</text>"#,
        AXES[axis], AXES[a], AXES[b], sx
    )?;
    let px = |x: f64| 20.0 + (x - lo[a]) * scale;
    let py = |y: f64| 20.0 + (hi[b] - y) * scale;
    writeln!(
        out,
        r##"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="#f4f4f4" stroke="#333"/>"##,
        px(lo[a]),
        py(hi[b]),
        sx * scale,
        sy * scale
    )?;
    if let Some(m) = map {
        // Colours in steps (a tenth of the tolerance within it, half a
        // tolerance beyond), runs of a row in one colour drawn as one
        // rectangle: the file stays small. Rectangles a hair taller than
        // their pitch, so no seams show.
        let step = |d: f64| {
            let r = d / t;
            if r.abs() <= 1.0 {
                (r * 10.0).round() / 10.0 * t
            } else {
                r.signum() * t * (1.0 + ((r.abs() - 1.0) * 2.0).round() / 2.0)
            }
        };
        let pitch = m.cell_mm * scale;
        for j in 0..m.size[1] {
            let row = &m.cells[j * m.size[0]..(j + 1) * m.size[0]];
            let mut i = 0;
            while i < row.len() {
                let Some(d) = row[i] else {
                    i += 1;
                    continue;
                };
                let colour = map_colour(step(f64::from(d)), t);
                let start = i;
                while i < row.len()
                    && row[i].is_some_and(|e| map_colour(step(f64::from(e)), t) == colour)
                {
                    i += 1;
                }
                let [r, g, bl] = colour;
                writeln!(
                    out,
                    r#"<rect x="{:.2}" y="{:.2}" width="{:.2}" height="{:.2}" fill="rgb({r},{g},{bl})"/>"#,
                    px(m.origin[0] + start as f64 * m.cell_mm),
                    py(m.origin[1] + (j + 1) as f64 * m.cell_mm),
                    (i - start) as f64 * pitch + 0.3,
                    pitch + 0.3
                )?;
            }
        }
    }
    let mut mark = |s: Option<&Sample>, label: &str| -> io::Result<()> {
        if let Some(s) = s {
            let mv = s
                .move_id
                .map_or("uncut stock".to_string(), |m| format!("move {m}"));
            let (x, y) = (px(s.part_point[a]), py(s.part_point[b]));
            writeln!(
                out,
                r#"<circle cx="{x:.2}" cy="{y:.2}" r="6" fill="none" stroke="black" stroke-width="1.5"/>"#
            )?;
            writeln!(
                out,
                r#"<text x="{:.2}" y="{:.2}">{label} {:.4} mm ({mv})</text>"#,
                x + 8.0,
                y - 8.0,
                s.deviation_mm
            )?;
        }
        Ok(())
    };
    mark(cmp.gouge_max(), "gouge")?;
    mark(cmp.residual_max(), "residual")?;
    write_legend(&mut out, cmp, sy * scale + 50.0)?;
    writeln!(out, "</svg>")?;
    out.flush()
}

/// The legend and the summary line of the deviation map, from height `ly`.
fn write_legend<W: Write>(out: &mut W, cmp: &Comparison, ly: f64) -> io::Result<()> {
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
    // The scale within the tolerance: 21 steps from −tol to +tol.
    let sy2 = ly + 30.0;
    for k in 0..21 {
        let d = t * (k as f64 / 10.0 - 1.0);
        let [r, g, b] = map_colour(d, t);
        writeln!(
            out,
            r#"<rect x="{:.0}" y="{sy2:.0}" width="15" height="12" fill="rgb({r},{g},{b})"/>"#,
            60.0 + k as f64 * 15.0
        )?;
    }
    writeln!(
        out,
        r#"<text x="20" y="{:.0}">−{t}</text><text x="380" y="{:.0}">+{t} mm</text>"#,
        sy2 + 10.0,
        sy2 + 10.0
    )?;
    let range = cmp
        .deviation_range_mm
        .map_or("nothing measured".into(), |[lo, hi]| {
            format!("deviation {lo:+.4} to {hi:+.4} mm")
        });
    writeln!(
        out,
        r#"<text x="20" y="{:.0}">{range} · gouge max {} · residual max {} · {} gouge and {} residual regions</text>"#,
        sy2 + 40.0,
        cmp.gouge_max()
            .map_or("none".into(), |s| format!("{:.4} mm", s.deviation_mm)),
        cmp.residual_max()
            .map_or("none".into(), |s| format!("{:.4} mm", s.deviation_mm)),
        cmp.gouge_regions.len(),
        cmp.residual_regions.len()
    )?;
    Ok(())
}
