//! SVG picture of a path on its surface: the surface shaded, the feed
//! moves of each pass as a polyline (alternating colours, so neighbouring
//! passes are told apart), leads and rapids dashed, the start marked.

use std::fmt::Write as _;

use kinpost_surface::Surface;
use kinpost_surface::svg::{self, Mesh};
use nalgebra::Vector3;

use crate::path::{PathOptions, Toolpath};

/// The picture, in surface coordinates.
pub fn plot_path(surface: &Surface, path: &Toolpath, options: &PathOptions, title: &str) -> String {
    let mesh = Mesh::new(surface, 40, 40);
    let lead = options.lead;
    let mut extra: Vec<Vector3<f64>> = Vec::new();
    for p in &path.passes {
        for c in [p.points.first(), p.points.last()].into_iter().flatten() {
            extra.push(c.point + c.axis * lead);
        }
    }
    let view = mesh.projection(&extra);
    let r = &path.report;
    let subtitle = format!(
        "{} passes, {} CL points, wheel R {} mm × W {} mm; step-over {:.3}–{:.3} mm, scallop ≤ {:.4} mm",
        r.passes,
        r.points,
        options.wheel.radius,
        options.wheel.width,
        r.stepover_min,
        r.stepover_max,
        r.scallop_max
    );
    let mut o = svg::begin(title, &subtitle);
    mesh.draw(&mut o, &view, |_| [0.80, 0.80, 0.80]);
    let xy = |p: &Vector3<f64>| view.screen(p);
    // Leads and rapids.
    o.push_str(
        "<g fill=\"none\" stroke=\"#666666\" stroke-width=\"1\" stroke-dasharray=\"4 3\">\n",
    );
    let mut previous: Option<Vector3<f64>> = None;
    for p in &path.passes {
        let (Some(a), Some(b)) = (p.points.first(), p.points.last()) else {
            continue;
        };
        let (start, end) = (a.point + a.axis * lead, b.point + b.axis * lead);
        let mut d = String::new();
        if let Some(q) = previous {
            let (x0, y0) = xy(&q);
            let (x1, y1) = xy(&start);
            let _ = write!(d, "M{x0:.2},{y0:.2}L{x1:.2},{y1:.2}");
        }
        let (x0, y0) = xy(&start);
        let (x1, y1) = xy(&a.point);
        let _ = write!(d, "M{x0:.2},{y0:.2}L{x1:.2},{y1:.2}");
        let (x0, y0) = xy(&b.point);
        let (x1, y1) = xy(&end);
        let _ = write!(d, "M{x0:.2},{y0:.2}L{x1:.2},{y1:.2}");
        let _ = writeln!(o, "<path d=\"{d}\"/>");
        previous = Some(end);
    }
    o.push_str("</g>\n<g fill=\"none\" stroke-width=\"1.6\" stroke-linejoin=\"round\">\n");
    for (k, p) in path.passes.iter().enumerate() {
        let colour = if k % 2 == 0 { "#c0392b" } else { "#1f5fa8" };
        let mut d = String::new();
        for (m, c) in p.points.iter().enumerate() {
            let (x, y) = xy(&c.point);
            let _ = write!(d, "{}{x:.2},{y:.2}", if m == 0 { "M" } else { "L" });
        }
        let _ = writeln!(o, "<path d=\"{d}\" stroke=\"{colour}\"/>");
    }
    o.push_str("</g>\n");
    if let Some(c) = path.passes.first().and_then(|p| p.points.first()) {
        let (x, y) = xy(&(c.point + c.axis * lead));
        let _ = writeln!(
            o,
            "<circle cx=\"{x:.2}\" cy=\"{y:.2}\" r=\"4\" fill=\"#2e8b57\"/><text x=\"{:.2}\" y=\"{:.2}\" font-size=\"11\">start</text>",
            x + 6.0,
            y - 6.0
        );
    }
    let _ = writeln!(
        o,
        "<text x=\"{:.2}\" y=\"{:.2}\" font-size=\"11\" fill=\"#444444\">solid: feed moves (passes alternate red / blue); dashed: leads along the normal and rapids</text>",
        20.0,
        svg::HEIGHT - 36.0
    );
    svg::scale_bar(&mut o, &view);
    svg::end(o)
}
