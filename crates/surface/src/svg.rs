//! Plain SVG pictures of surfaces (Li (B-spline grinding) Figures 5–6: the fitted surface
//! and its Gaussian curvature): an oblique parallel projection, the surface
//! as a mesh of quadrilaterals drawn back to front (painter's algorithm),
//! shaded by a fixed light and optionally coloured by curvature, with the
//! data points on top. Text uses the generic `sans-serif` family, so the
//! file needs no particular font; numbers are written with fixed decimals,
//! so the same surface gives the same bytes.

use std::fmt::Write as _;

use nalgebra::Vector3;

use crate::surface::Surface;

/// Which curvature colours the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Curvature {
    /// K.
    Gaussian,
    /// H.
    Mean,
}

/// Picture size in SVG user units (pixels).
pub const WIDTH: f64 = 900.0;
/// See [`WIDTH`].
pub const HEIGHT: f64 = 660.0;
const PLOT_RIGHT: f64 = 760.0;
const MARGIN: f64 = 40.0;
const TOP: f64 = 56.0;

/// An oblique parallel projection fitted to a set of points.
#[derive(Debug, Clone)]
pub struct Projection {
    centre: Vector3<f64>,
    x: Vector3<f64>,
    y: Vector3<f64>,
    depth: Vector3<f64>,
    scale: f64,
    offset: (f64, f64),
}

impl Projection {
    /// A view from the side of `normal` (the mean surface normal), tilted
    /// 35° towards `along` (a direction in the surface), fitted to `points`
    /// inside the plot area.
    pub fn new(points: &[Vector3<f64>], normal: Vector3<f64>, along: Vector3<f64>) -> Projection {
        let n = if normal.norm() > 1e-9 {
            normal.normalize()
        } else {
            Vector3::new(1.0, 1.0, 1.0).normalize()
        };
        let mut t1 = along - n * along.dot(&n);
        if t1.norm() < 1e-9 {
            t1 = n.cross(&Vector3::x());
            if t1.norm() < 1e-9 {
                t1 = n.cross(&Vector3::y());
            }
        }
        let t1 = t1.normalize();
        let t2 = n.cross(&t1);
        let tilt = 35f64.to_radians();
        let depth = (n * tilt.cos() - t2 * tilt.sin()).normalize();
        let x = (t1 - depth * t1.dot(&depth)).normalize();
        let y = depth.cross(&x);
        let centre =
            points.iter().fold(Vector3::zeros(), |a, p| a + p) / points.len().max(1) as f64;
        let mut p = Projection {
            centre,
            x,
            y,
            depth,
            scale: 1.0,
            offset: (0.0, 0.0),
        };
        let (mut lo, mut hi) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
        for q in points {
            let (a, b) = p.raw(q);
            lo = (lo.0.min(a), lo.1.min(b));
            hi = (hi.0.max(a), hi.1.max(b));
        }
        let (w, h) = ((hi.0 - lo.0).max(1e-9), (hi.1 - lo.1).max(1e-9));
        let (aw, ah) = (PLOT_RIGHT - 2.0 * MARGIN, HEIGHT - TOP - 2.0 * MARGIN);
        p.scale = (aw / w).min(ah / h);
        let cx = MARGIN + (aw - w * p.scale) / 2.0 - lo.0 * p.scale;
        let cy = TOP + MARGIN + (ah - h * p.scale) / 2.0 + hi.1 * p.scale;
        p.offset = (cx, cy);
        p
    }

    fn raw(&self, q: &Vector3<f64>) -> (f64, f64) {
        let d = q - self.centre;
        (d.dot(&self.x), d.dot(&self.y))
    }

    /// Screen position (SVG y grows downwards).
    pub fn screen(&self, q: &Vector3<f64>) -> (f64, f64) {
        let (a, b) = self.raw(q);
        (
            self.offset.0 + a * self.scale,
            self.offset.1 - b * self.scale,
        )
    }

    /// Distance towards the viewer.
    pub fn depth(&self, q: &Vector3<f64>) -> f64 {
        (q - self.centre).dot(&self.depth)
    }

    /// The viewing direction (towards the viewer).
    pub fn towards_viewer(&self) -> Vector3<f64> {
        self.depth
    }

    /// Millimetres per picture unit.
    pub fn mm_per_unit(&self) -> f64 {
        1.0 / self.scale
    }
}

/// The surface sampled on a regular parameter mesh, ready to draw.
#[derive(Debug, Clone)]
pub struct Mesh {
    /// (nu + 1) × (nv + 1) points, row-major.
    pub points: Vec<Vector3<f64>>,
    /// Quads along u.
    pub nu: usize,
    /// Quads along v.
    pub nv: usize,
    /// Per quad: unit normal and the curvatures (Gaussian, mean) at its
    /// centre (NaN where the surface is degenerate).
    pub quads: Vec<(Vector3<f64>, f64, f64)>,
}

impl Mesh {
    /// Samples `surface` with `nu × nv` quads.
    pub fn new(surface: &Surface, nu: usize, nv: usize) -> Mesh {
        let (u0, u1) = surface.u_range();
        let (v0, v1) = surface.v_range();
        let pu = |i: f64| u0 + (u1 - u0) * i / nu as f64;
        let pv = |j: f64| v0 + (v1 - v0) * j / nv as f64;
        let mut points = Vec::with_capacity((nu + 1) * (nv + 1));
        for i in 0..=nu {
            for j in 0..=nv {
                points.push(surface.point(pu(i as f64), pv(j as f64)));
            }
        }
        let mut quads = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                let g = surface.geometry(pu(i as f64 + 0.5), pv(j as f64 + 0.5));
                quads.push(match g {
                    Ok(g) => (g.normal, g.gaussian, g.mean),
                    Err(_) => (Vector3::zeros(), f64::NAN, f64::NAN),
                });
            }
        }
        Mesh {
            points,
            nu,
            nv,
            quads,
        }
    }

    fn corner(&self, i: usize, j: usize) -> Vector3<f64> {
        self.points[i * (self.nv + 1) + j]
    }

    /// Mean normal of the quads.
    pub fn mean_normal(&self) -> Vector3<f64> {
        self.quads.iter().fold(Vector3::zeros(), |a, q| a + q.0)
    }

    /// A projection that shows the whole mesh plus `extra` points.
    pub fn projection(&self, extra: &[Vector3<f64>]) -> Projection {
        let along = self.corner(self.nu, self.nv / 2) - self.corner(0, self.nv / 2);
        let mut pts = self.points.clone();
        pts.extend_from_slice(extra);
        Projection::new(&pts, self.mean_normal(), along)
    }

    /// Writes the quads back to front; `colour` gives each quad's base
    /// colour from its index, which is then shaded by the light.
    pub fn draw(&self, out: &mut String, view: &Projection, colour: impl Fn(usize) -> [f64; 3]) {
        let mut order: Vec<(f64, usize, usize)> = Vec::with_capacity(self.nu * self.nv);
        for i in 0..self.nu {
            for j in 0..self.nv {
                let c = (self.corner(i, j)
                    + self.corner(i + 1, j)
                    + self.corner(i, j + 1)
                    + self.corner(i + 1, j + 1))
                    / 4.0;
                order.push((view.depth(&c), i, j));
            }
        }
        // Farthest first; ties by index so that the output is deterministic.
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let light = (view.towards_viewer() + view.y * 0.6 + view.x * 0.3).normalize();
        out.push_str("<g stroke-width=\"0.3\" stroke-linejoin=\"round\">\n");
        for (_, i, j) in order {
            let k = i * self.nv + j;
            let n = self.quads[k].0;
            let lambert = n.dot(&light).abs();
            let base = colour(k);
            let shade = 0.55 + 0.45 * lambert;
            let rgb = hex([base[0] * shade, base[1] * shade, base[2] * shade]);
            out.push_str("<path d=\"");
            for (m, (a, b)) in [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                .into_iter()
                .enumerate()
            {
                let (x, y) = view.screen(&self.corner(a, b));
                let _ = write!(out, "{}{x:.2},{y:.2}", if m == 0 { "M" } else { "L" });
            }
            let _ = writeln!(out, "Z\" fill=\"{rgb}\" stroke=\"{rgb}\"/>");
        }
        out.push_str("</g>\n");
    }
}

/// `#rrggbb` of a colour with channels in [0, 1].
pub fn hex(c: [f64; 3]) -> String {
    let b = |v: f64| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    format!("#{:02x}{:02x}{:02x}", b(c[0]), b(c[1]), b(c[2]))
}

/// Moreland's cool-to-warm diverging map, `t` in [−1, 1] (0 is grey),
/// linear between its three anchor colours.
pub fn diverging(t: f64) -> [f64; 3] {
    const COOL: [f64; 3] = [0.230, 0.299, 0.754];
    const MID: [f64; 3] = [0.865, 0.865, 0.865];
    const WARM: [f64; 3] = [0.706, 0.016, 0.150];
    let t = if t.is_nan() { 0.0 } else { t.clamp(-1.0, 1.0) };
    let (a, b, s) = if t < 0.0 {
        (MID, COOL, -t)
    } else {
        (MID, WARM, t)
    };
    [
        a[0] + (b[0] - a[0]) * s,
        a[1] + (b[1] - a[1]) * s,
        a[2] + (b[2] - a[2]) * s,
    ]
}

/// The start of an SVG document with a white background and a title.
pub fn begin(title: &str, subtitle: &str) -> String {
    let mut o = String::new();
    let _ = writeln!(
        o,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{WIDTH:.0}\" height=\"{HEIGHT:.0}\" viewBox=\"0 0 {WIDTH:.0} {HEIGHT:.0}\" font-family=\"sans-serif\">"
    );
    let _ = writeln!(o, "<rect width=\"100%\" height=\"100%\" fill=\"#ffffff\"/>");
    let _ = writeln!(
        o,
        "<text x=\"20\" y=\"28\" font-size=\"18\">{}</text>",
        escape(title)
    );
    let _ = writeln!(
        o,
        "<text x=\"20\" y=\"48\" font-size=\"12\" fill=\"#444444\">{}</text>",
        escape(subtitle)
    );
    o
}

/// Closes the document.
pub fn end(mut o: String) -> String {
    o.push_str("</svg>\n");
    o
}

/// XML text escaping.
pub fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A scale bar of `view` (a round length in mm) at the bottom left.
pub fn scale_bar(o: &mut String, view: &Projection) {
    let target = 120.0 * view.mm_per_unit();
    let pow = 10f64.powf(target.log10().floor());
    let len = [5.0, 2.0, 1.0]
        .into_iter()
        .map(|m| m * pow)
        .find(|l| *l <= target)
        .unwrap_or(pow);
    let px = len / view.mm_per_unit();
    let y = HEIGHT - 18.0;
    let _ = writeln!(
        o,
        "<path d=\"M20,{y:.2}h{px:.2}\" stroke=\"#000000\" stroke-width=\"2\"/><text x=\"20\" y=\"{:.2}\" font-size=\"11\">{} mm (in the picture plane)</text>",
        y - 6.0,
        trim_number(len)
    );
}

fn trim_number(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_string()
}

/// A vertical colour legend for a diverging range ±`range`.
fn legend(o: &mut String, title: &str, range: f64) {
    let (x, y0, h) = (PLOT_RIGHT + 40.0, TOP + 60.0, 360.0);
    let _ = writeln!(
        o,
        "<text x=\"{:.2}\" y=\"{:.2}\" font-size=\"12\">{}</text>",
        PLOT_RIGHT + 10.0,
        y0 - 20.0,
        escape(title)
    );
    let steps = 60;
    for k in 0..steps {
        let t = 1.0 - 2.0 * (k as f64 + 0.5) / steps as f64;
        let _ = writeln!(
            o,
            "<rect x=\"{x:.2}\" y=\"{:.2}\" width=\"22\" height=\"{:.2}\" fill=\"{}\"/>",
            y0 + h * k as f64 / steps as f64,
            h / steps as f64 + 0.5,
            hex(diverging(t))
        );
    }
    for (t, label) in [(1.0, range), (0.0, 0.0), (-1.0, -range)] {
        let y = y0 + h * (1.0 - t) / 2.0;
        let _ = writeln!(
            o,
            "<text x=\"{:.2}\" y=\"{:.2}\" font-size=\"11\">{}</text>",
            x + 28.0,
            y + 4.0,
            if label == 0.0 {
                "0".to_string()
            } else {
                format!("{label:+.3e}")
            }
        );
    }
}

/// The range of the colour scale: the 98th percentile of |values| (so that
/// a few extreme values at sharp edges do not wash out the rest), values
/// beyond it drawn in the end colours.
fn robust_range(values: impl Iterator<Item = f64>) -> f64 {
    let mut a: Vec<f64> = values.filter(|v| v.is_finite()).map(f64::abs).collect();
    if a.is_empty() {
        return 1.0;
    }
    a.sort_by(f64::total_cmp);
    let r = a[((a.len() - 1) as f64 * 0.98).round() as usize];
    if r > 0.0 {
        r
    } else {
        a[a.len() - 1].max(1e-300)
    }
}

/// The whole picture of a surface: shaded mesh (coloured by `curvature`
/// if given), data points, legend, scale bar.
pub fn plot_surface(surface: &Surface, curvature: Option<Curvature>, title: &str) -> String {
    let mesh = Mesh::new(surface, 48, 48);
    let data: Vec<Vector3<f64>> = surface
        .data()
        .map(|d| d.points.iter().map(|p| Vector3::from(*p)).collect())
        .unwrap_or_default();
    let view = mesh.projection(&data);
    let (rows, cols) = surface.net_size();
    let subtitle = format!(
        "cubic B-spline surface, {rows} × {cols} control points{}; {} data points (black)",
        match curvature {
            Some(Curvature::Gaussian) => ", coloured by Gaussian curvature K",
            Some(Curvature::Mean) => ", coloured by mean curvature H",
            None => "",
        },
        data.len()
    );
    let mut o = begin(title, &subtitle);
    match curvature {
        None => mesh.draw(&mut o, &view, |_| [0.62, 0.70, 0.82]),
        Some(kind) => {
            let value = |k: usize| match kind {
                Curvature::Gaussian => mesh.quads[k].1,
                Curvature::Mean => mesh.quads[k].2,
            };
            let range = robust_range((0..mesh.quads.len()).map(value));
            mesh.draw(&mut o, &view, |k| diverging(value(k) / range));
            legend(
                &mut o,
                match kind {
                    Curvature::Gaussian => "K (1/mm²)",
                    Curvature::Mean => "H (1/mm)",
                },
                range,
            );
        }
    }
    o.push_str("<g fill=\"#000000\">\n");
    for p in &data {
        let (x, y) = view.screen(p);
        let _ = writeln!(o, "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"2.5\"/>");
    }
    o.push_str("</g>\n");
    scale_bar(&mut o, &view);
    end(o)
}
