//! Surface files: JSON with the degree, knots, control net,
//! parameterisation, end conditions and the data the surface was fitted to.
//!
//! Numbers are written by serde_json (shortest representation that reads
//! back to the same `f64`) and read with its exact (`float_roundtrip`)
//! parser, so save → load → save gives the same bytes and the same bits.
//! Errors name the file, line and column with the source line.

use kinpost_diag::{Diagnostic, Severity};
use serde::Deserialize;

use crate::fit1d::Ends;
use crate::surface::{FitData, Method, Parameterisation, Surface};

/// The `format` field of a surface file.
pub const FORMAT: &str = "kinpost-surface";
/// The version this code writes and reads.
pub const VERSION: u32 = 1;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    format: String,
    version: u32,
    degree: [u32; 2],
    #[serde(default)]
    fit: Option<FitKind>,
    #[serde(default)]
    parameterisation: Option<Parameterisation>,
    #[serde(default)]
    ends: Option<Ends>,
    knots_u: Vec<f64>,
    knots_v: Vec<f64>,
    control_net: [usize; 2],
    control_points: Vec<[f64; 3]>,
    #[serde(default)]
    data: Option<Data>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
enum FitKind {
    Interpolation,
    Approximation,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Data {
    grid: [usize; 2],
    u: Vec<f64>,
    v: Vec<f64>,
    points: Vec<[f64; 3]>,
}

fn num(out: &mut String, v: f64) {
    // serde_json writes the shortest round-tripping form (ryu), `null`
    // for non-finite values (which a valid surface does not have).
    out.push_str(&serde_json::to_string(&v).unwrap_or_else(|_| "null".into()));
}

fn list(out: &mut String, values: &[f64]) {
    out.push('[');
    for (k, v) in values.iter().enumerate() {
        if k > 0 {
            out.push_str(", ");
        }
        num(out, *v);
    }
    out.push(']');
}

fn points(out: &mut String, pts: &[[f64; 3]], indent: &str) {
    out.push_str("[\n");
    for (k, p) in pts.iter().enumerate() {
        out.push_str(indent);
        out.push_str("  ");
        list(out, p);
        out.push_str(if k + 1 < pts.len() { ",\n" } else { "\n" });
    }
    out.push_str(indent);
    out.push(']');
}

/// The surface as the text of a surface file (one point per line).
pub fn to_json(s: &Surface) -> String {
    let mut o = String::with_capacity(128 + 80 * s.control.len());
    o.push_str("{\n");
    o.push_str(&format!(
        "  \"format\": \"{FORMAT}\",\n  \"version\": {VERSION},\n"
    ));
    o.push_str("  \"degree\": [3, 3],\n");
    if let Some(m) = s.method {
        let (fit, ends) = match m {
            Method::Interpolation(e) => ("interpolation", Some(e)),
            Method::Approximation { .. } => ("approximation", None),
        };
        o.push_str(&format!("  \"fit\": \"{fit}\",\n"));
        if let Some(e) = ends {
            o.push_str(&format!("  \"ends\": \"{}\",\n", e.name()));
        }
    }
    if let Some(p) = s.parameterisation {
        o.push_str(&format!("  \"parameterisation\": \"{}\",\n", p.name()));
    }
    o.push_str("  \"knots_u\": ");
    list(&mut o, &s.knots_u);
    o.push_str(",\n  \"knots_v\": ");
    list(&mut o, &s.knots_v);
    o.push_str(&format!(
        ",\n  \"control_net\": [{}, {}],\n  \"control_points\": ",
        s.rows, s.cols
    ));
    points(&mut o, &s.control, "  ");
    if let Some(d) = &s.data {
        o.push_str(&format!(
            ",\n  \"data\": {{\n    \"grid\": [{}, {}],\n    \"u\": ",
            d.u.len(),
            d.v.len()
        ));
        list(&mut o, &d.u);
        o.push_str(",\n    \"v\": ");
        list(&mut o, &d.v);
        o.push_str(",\n    \"points\": ");
        points(&mut o, &d.points, "    ");
        o.push_str("\n  }");
    }
    o.push_str("\n}\n");
    o
}

/// A diagnostic at the first occurrence of `"key"` in the file (the field a
/// check failed on), or at its start.
fn at_key(src: &str, file: &str, key: &str, message: String) -> Diagnostic {
    let quoted = format!("\"{key}\"");
    let start = src.find(&quoted).unwrap_or(0);
    let end = if src.is_empty() {
        0
    } else {
        start + quoted.len().min(src.len() - start)
    };
    Diagnostic::at_byte_span(Severity::Error, file, src, start..end, message)
}

/// Reads a surface file; `file` names it in diagnostics.
pub fn from_json(src: &str, file: &str) -> Result<Surface, Diagnostic> {
    let f: File = serde_json::from_str(src).map_err(|e| {
        let (line, col) = (e.line(), e.column());
        let text = src.split('\n').nth(line.saturating_sub(1)).unwrap_or("");
        let text = text.strip_suffix('\r').unwrap_or(text);
        // serde_json counts columns in bytes; diagnostics in characters.
        let byte = col.saturating_sub(1).min(text.len());
        let mut b = byte;
        while b > 0 && !text.is_char_boundary(b) {
            b -= 1;
        }
        let column = if line == 0 {
            0
        } else {
            text[..b].chars().count() + 1
        };
        let msg = e.to_string();
        // serde_json appends " at line L column C"; the location is shown anyway.
        let msg = msg
            .rsplit_once(" at line ")
            .map_or(msg.as_str(), |(m, _)| m)
            .to_string();
        Diagnostic::error(
            file,
            line,
            column,
            1,
            text,
            format!("invalid surface file: {msg}"),
        )
    })?;
    if f.format != FORMAT {
        return Err(at_key(
            src,
            file,
            "format",
            format!("`format` is `{}`, expected `{FORMAT}`", f.format),
        ));
    }
    if f.version != VERSION {
        return Err(at_key(
            src,
            file,
            "version",
            format!(
                "version {} is not supported (this kinpost reads {VERSION})",
                f.version
            ),
        ));
    }
    if f.degree != [3, 3] {
        return Err(at_key(
            src,
            file,
            "degree",
            format!(
                "degree {:?}: only cubic surfaces ([3, 3]) are supported",
                f.degree
            ),
        ));
    }
    let method = match (f.fit, f.ends) {
        (Some(FitKind::Interpolation), Some(e)) => Some(Method::Interpolation(e)),
        (Some(FitKind::Interpolation), None) => {
            return Err(at_key(
                src,
                file,
                "fit",
                "an interpolation needs `ends`".into(),
            ));
        }
        (Some(FitKind::Approximation), None) => Some(Method::Approximation {
            rows: f.control_net[0],
            cols: f.control_net[1],
        }),
        (Some(FitKind::Approximation), Some(_)) => {
            return Err(at_key(
                src,
                file,
                "ends",
                "an approximation has no `ends`".into(),
            ));
        }
        (None, Some(_)) => return Err(at_key(src, file, "ends", "`ends` without `fit`".into())),
        (None, None) => None,
    };
    let data = match f.data {
        None => None,
        Some(d) => {
            let [m, n] = d.grid;
            let bad = |key: &str, msg: String| Err(at_key(src, file, key, msg));
            if d.u.len() != m || d.v.len() != n {
                return bad(
                    "grid",
                    format!(
                        "data grid {m} × {n} but {} u and {} v parameters",
                        d.u.len(),
                        d.v.len()
                    ),
                );
            }
            if d.points.len() != m * n {
                return bad(
                    "points",
                    format!("{} data points for a {m} × {n} grid", d.points.len()),
                );
            }
            if !d.u.iter().chain(&d.v).all(|t| t.is_finite())
                || !d.points.iter().flatten().all(|c| c.is_finite())
            {
                return bad("data", "data values must be finite".into());
            }
            Some(FitData {
                u: d.u,
                v: d.v,
                points: d.points,
            })
        }
    };
    let s = Surface {
        knots_u: f.knots_u,
        knots_v: f.knots_v,
        rows: f.control_net[0],
        cols: f.control_net[1],
        control: f.control_points,
        method,
        parameterisation: f.parameterisation,
        data,
    };
    s.check().map_err(|msg| {
        let key = msg
            .split([' ', '[', ':'])
            .find(|w| w.starts_with("knots_"))
            .unwrap_or(if msg.contains("control") {
                "control_points"
            } else {
                "control_net"
            })
            .to_string();
        at_key(src, file, &key, msg)
    })?;
    Ok(s)
}
