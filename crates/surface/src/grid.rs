//! Grids of measured points: `row,col,x,y,z` CSV files (as
//! `data/li-bspline/points.csv`), whitespace tables, and NASA blade
//! geometry tables (Rotor 37: per stream surface Z, R, θ1, θ2; Rotor 67:
//! blocks of axial distance, r·θ, thickness and radius per stream surface).
//!
//! Every problem is a [`Diagnostic`] naming the file, line and column with
//! the source line; nothing here panics on any input.

use std::collections::BTreeMap;

pub use kinpost_diag::{Diagnostic, Diagnostics};

/// An m × n grid of points, row-major (`points[i * cols + j]`): rows run
/// along the surface's u direction, columns along v.
#[derive(Debug, Clone, PartialEq)]
pub struct Grid {
    /// Rows (u).
    pub rows: usize,
    /// Columns (v).
    pub cols: usize,
    /// The points, row-major, mm.
    pub points: Vec<[f64; 3]>,
}

impl Grid {
    /// The point at row `i`, column `j`.
    pub fn at(&self, i: usize, j: usize) -> [f64; 3] {
        self.points[i * self.cols + j]
    }

    /// Every `step_rows`-th row and `step_cols`-th column, always keeping
    /// the last row and column (a reduced grid over the same area).
    pub fn reduced(&self, step_rows: usize, step_cols: usize) -> Grid {
        let pick = |n: usize, step: usize| -> Vec<usize> {
            let step = step.max(1);
            let mut v: Vec<usize> = (0..n).step_by(step).collect();
            if v.last() != Some(&(n - 1)) {
                v.push(n - 1);
            }
            v
        };
        let (ri, cj) = (pick(self.rows, step_rows), pick(self.cols, step_cols));
        let mut points = Vec::with_capacity(ri.len() * cj.len());
        for &i in &ri {
            for &j in &cj {
                points.push(self.at(i, j));
            }
        }
        Grid {
            rows: ri.len(),
            cols: cj.len(),
            points,
        }
    }
}

/// One line of a text file with its 1-based number.
struct Line<'a> {
    number: usize,
    text: &'a str,
}

fn lines(text: &str) -> impl Iterator<Item = Line<'_>> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.split('\n').enumerate().map(|(k, t)| Line {
        number: k + 1,
        text: t.strip_suffix('\r').unwrap_or(t),
    })
}

/// A field of a line: its text and 1-based character column.
#[derive(Clone, Copy)]
struct Field<'a> {
    text: &'a str,
    column: usize,
}

fn char_column(line: &str, byte: usize) -> usize {
    line[..byte].chars().count() + 1
}

/// The fields of a CSV line, each with its character column. One pass over
/// the line (the columns are counted as it goes): linear in the line's
/// length however many fields it has.
fn split_csv(line: &str) -> Vec<Field<'_>> {
    let mut out = Vec::new();
    let mut start = 0;
    // Characters before `start`.
    let mut start_chars = 0;
    for (chars, (k, c)) in line
        .char_indices()
        .chain(std::iter::once((line.len(), ',')))
        .enumerate()
    {
        if c == ',' {
            let raw = &line[start..k];
            let trimmed = raw.trim_start();
            let lead_chars = raw[..raw.len() - trimmed.len()].chars().count();
            out.push(Field {
                text: raw.trim(),
                column: start_chars + lead_chars + 1,
            });
            start = k + 1;
            start_chars = chars + 1;
        }
    }
    out
}

/// The whitespace-separated fields of a line, each with its character
/// column, in one pass.
fn split_ws(line: &str) -> Vec<Field<'_>> {
    let mut out = Vec::new();
    let mut start: Option<(usize, usize)> = None;
    for (chars, (k, c)) in line
        .char_indices()
        .chain(std::iter::once((line.len(), ' ')))
        .enumerate()
    {
        if c.is_whitespace() {
            if let Some((s, column)) = start.take() {
                out.push(Field {
                    text: &line[s..k],
                    column,
                });
            }
        } else if start.is_none() {
            start = Some((k, chars + 1));
        }
    }
    out
}

struct Ctx<'a> {
    file: &'a str,
}

impl Ctx<'_> {
    fn at(&self, line: &Line, field: Field, message: impl Into<String>) -> Diagnostic {
        Diagnostic::error(
            self.file,
            line.number,
            field.column,
            field.text.chars().count().max(1),
            line.text,
            message,
        )
    }

    fn line(&self, line: &Line, message: impl Into<String>) -> Diagnostic {
        let start = line.text.len() - line.text.trim_start().len();
        Diagnostic::error(
            self.file,
            line.number,
            char_column(line.text, start),
            line.text.trim().chars().count().max(1),
            line.text,
            message,
        )
    }

    fn number(&self, line: &Line, field: Field, what: &str) -> Result<f64, Diagnostic> {
        match field.text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(self.at(
                line,
                field,
                format!("{what} `{}` is not finite", field.text),
            )),
            Err(_) if field.text.is_empty() => Err(self.at(line, field, format!("{what} missing"))),
            Err(_) => Err(self.at(
                line,
                field,
                format!("{what} `{}` is not a number", field.text),
            )),
        }
    }

    fn index(&self, line: &Line, field: Field, what: &str) -> Result<usize, Diagnostic> {
        field
            .text
            .parse::<usize>()
            .ok()
            .filter(|&v| v <= 1_000_000)
            .ok_or_else(|| {
                self.at(
                    line,
                    field,
                    format!(
                        "{what} `{}` is not a whole number from 0 to 1000000",
                        field.text
                    ),
                )
            })
    }
}

/// A point read with its row and column index and where it was.
struct Indexed {
    row: usize,
    col: usize,
    point: [f64; 3],
    line: usize,
    text: String,
}

/// Reads a grid file: CSV (`row,col,x,y,z`, header optional, columns
/// found by name when there is a header) when the first data line has a
/// comma, else a whitespace table: lines `row col x y z`, or lines `x y z`
/// with a blank line between grid rows. `#` starts a comment in tables.
pub fn read_grid(text: &str, file: &str) -> Result<Grid, Diagnostics> {
    let first = lines(text).find(|l| {
        let t = l.text.trim();
        !t.is_empty() && !t.starts_with('#')
    });
    match first {
        None => Err(Diagnostic::error(file, 0, 0, 1, "", "no points in the file").into()),
        Some(l) if l.text.contains(',') => read_csv(text, file),
        Some(_) => read_table(text, file),
    }
}

fn read_csv(text: &str, file: &str) -> Result<Grid, Diagnostics> {
    let ctx = Ctx { file };
    let mut columns = [0usize, 1, 2, 3, 4];
    let mut points = Vec::new();
    let mut errors = Vec::new();
    let mut header_seen = false;
    for line in lines(text) {
        if line.text.trim().is_empty() {
            continue;
        }
        let fields = split_csv(line.text);
        if !header_seen
            && points.is_empty()
            && fields.iter().any(|f| f.text.parse::<f64>().is_err())
        {
            header_seen = true;
            let names = ["row", "col", "x", "y", "z"];
            for (slot, name) in columns.iter_mut().zip(names) {
                match fields
                    .iter()
                    .position(|f| f.text.eq_ignore_ascii_case(name))
                {
                    Some(k) => *slot = k,
                    None => {
                        errors.push(ctx.line(
                            &line,
                            format!("the header has no `{name}` column (expected `row,col,x,y,z`)"),
                        ));
                        return Err(Diagnostics(errors));
                    }
                }
            }
            continue;
        }
        header_seen = true;
        let need = columns.iter().max().map_or(5, |m| m + 1);
        if fields.len() < need {
            errors.push(ctx.line(
                &line,
                format!("{} fields, expected {need} (`row,col,x,y,z`)", fields.len()),
            ));
            continue;
        }
        let parsed = (|| {
            let row = ctx.index(&line, fields[columns[0]], "row")?;
            let col = ctx.index(&line, fields[columns[1]], "col")?;
            let x = ctx.number(&line, fields[columns[2]], "x")?;
            let y = ctx.number(&line, fields[columns[3]], "y")?;
            let z = ctx.number(&line, fields[columns[4]], "z")?;
            Ok::<_, Diagnostic>((row, col, [x, y, z]))
        })();
        match parsed {
            Ok((row, col, point)) => points.push(Indexed {
                row,
                col,
                point,
                line: line.number,
                text: line.text.to_string(),
            }),
            Err(d) => errors.push(d),
        }
        if errors.len() >= MAX_ERRORS {
            break;
        }
    }
    assemble(points, errors, file)
}

fn read_table(text: &str, file: &str) -> Result<Grid, Diagnostics> {
    let ctx = Ctx { file };
    let mut points = Vec::new();
    let mut errors = Vec::new();
    let mut width: Option<(usize, usize)> = None; // (fields, line)
    let (mut row, mut col) = (0usize, 0usize);
    for line in lines(text) {
        let content = line.text.split('#').next().unwrap_or("");
        let fields = split_ws(content);
        if fields.is_empty() {
            // A blank line ends a grid row of an `x y z` table.
            if line.text.trim().is_empty() && col > 0 {
                row += 1;
                col = 0;
            }
            continue;
        }
        match width {
            None => {
                if fields.len() != 3 && fields.len() != 5 {
                    errors.push(ctx.line(
                        &line,
                        format!(
                            "{} values; a table has `x y z` or `row col x y z` on each line",
                            fields.len()
                        ),
                    ));
                    break;
                }
                width = Some((fields.len(), line.number));
            }
            Some((w, first)) if w != fields.len() => {
                errors.push(ctx.line(
                    &line,
                    format!("{} values, but line {first} has {w}", fields.len()),
                ));
                continue;
            }
            Some(_) => {}
        }
        let five = fields.len() == 5;
        let parsed = (|| {
            let (r, c, k) = if five {
                (
                    ctx.index(&line, fields[0], "row")?,
                    ctx.index(&line, fields[1], "col")?,
                    2,
                )
            } else {
                (row, col, 0)
            };
            let x = ctx.number(&line, fields[k], "x")?;
            let y = ctx.number(&line, fields[k + 1], "y")?;
            let z = ctx.number(&line, fields[k + 2], "z")?;
            Ok::<_, Diagnostic>((r, c, [x, y, z]))
        })();
        match parsed {
            Ok((r, c, point)) => {
                points.push(Indexed {
                    row: r,
                    col: c,
                    point,
                    line: line.number,
                    text: line.text.to_string(),
                });
                col += 1;
            }
            Err(d) => errors.push(d),
        }
        if errors.len() >= MAX_ERRORS {
            break;
        }
    }
    assemble(points, errors, file)
}

/// Errors reported from one file at most (the first ones).
const MAX_ERRORS: usize = 20;

/// Puts indexed points on their grid, unless reading found errors: the
/// distinct row and column indices in increasing order; every combination
/// must be there exactly once.
fn assemble(
    points: Vec<Indexed>,
    errors: Vec<Diagnostic>,
    file: &str,
) -> Result<Grid, Diagnostics> {
    if !errors.is_empty() {
        return Err(Diagnostics(errors));
    }
    if points.is_empty() {
        return Err(Diagnostic::error(file, 0, 0, 1, "", "no points in the file").into());
    }
    let mut rows: BTreeMap<usize, usize> = points.iter().map(|p| (p.row, 0)).collect();
    let mut cols: BTreeMap<usize, usize> = points.iter().map(|p| (p.col, 0)).collect();
    for (k, v) in rows.values_mut().enumerate() {
        *v = k;
    }
    for (k, v) in cols.values_mut().enumerate() {
        *v = k;
    }
    let (m, n) = (rows.len(), cols.len());
    let mut slots: Vec<Option<usize>> = vec![None; m * n];
    let mut errors = Vec::new();
    for (k, p) in points.iter().enumerate() {
        let slot = rows[&p.row] * n + cols[&p.col];
        if let Some(first) = slots[slot] {
            errors.push(Diagnostic::error(
                file,
                p.line,
                1,
                p.text.chars().count(),
                p.text.clone(),
                format!(
                    "row {} col {} again (first on line {})",
                    p.row, p.col, points[first].line
                ),
            ));
        } else {
            slots[slot] = Some(k);
        }
    }
    if errors.is_empty() && points.len() != m * n {
        let missing: Vec<String> = slots
            .iter()
            .enumerate()
            .filter(|(_, s)| s.is_none())
            .take(5)
            .map(|(k, _)| {
                let r = rows
                    .iter()
                    .find(|(_, v)| **v == k / n)
                    .map_or(0, |(r, _)| *r);
                let c = cols
                    .iter()
                    .find(|(_, v)| **v == k % n)
                    .map_or(0, |(c, _)| *c);
                format!("row {r} col {c}")
            })
            .collect();
        let last = points.last().expect("not empty");
        errors.push(Diagnostic::error(
            file,
            last.line,
            1,
            last.text.chars().count(),
            last.text.clone(),
            format!(
                "the points do not fill a {m} × {n} grid: {} missing ({}{}) by the end of the file",
                m * n - points.len(),
                missing.join(", "),
                if m * n - points.len() > 5 {
                    ", …"
                } else {
                    ""
                }
            ),
        ));
    }
    if !errors.is_empty() {
        return Err(Diagnostics(errors));
    }
    let points = slots
        .into_iter()
        .map(|s| points[s.expect("every slot filled")].point)
        .collect();
    Ok(Grid {
        rows: m,
        cols: n,
        points,
    })
}

/// Which blade surface of a NASA blade table.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BladeSide {
    /// THETA 1.
    Theta1,
    /// THETA 2.
    Theta2,
}

/// Reads a NASA blade geometry table (NASA Rotor 37 / Rotor 67 reports,
/// Table IV: `SURFACE NUMBER k` headers, then lines `J Z R THETA1 THETA2`,
/// Z and R in centimetres, θ in radians) and converts one blade side to a
/// Cartesian grid in millimetres: one grid row per stream surface (hub to
/// tip), one column per J (leading to trailing edge), with
///
/// ```text
/// x = 10·R·cos θ,   y = 10·R·sin θ,   z = 10·Z
/// ```
///
/// (z along the rotor axis, x radial through θ = 0). Every stream surface
/// must have the same J values.
///
/// The NASA Rotor 67 file (stream surfaces as four blocks of values, 8 a
/// line: axial distance, r·θ of the upper surface, the tangential
/// thickness, radius; in feet) is read too; see [`read_stream_surfaces`].
pub fn read_blade_table(text: &str, file: &str, side: BladeSide) -> Result<Grid, Diagnostics> {
    if lines(text).any(|l| l.text.trim().eq_ignore_ascii_case("Axial Distance")) {
        return read_stream_surfaces(text, file, side);
    }
    let ctx = Ctx { file };
    let mut surfaces: Vec<(Vec<usize>, Vec<[f64; 3]>, usize)> = Vec::new();
    let mut errors = Vec::new();
    for line in lines(text) {
        let fields = split_ws(line.text);
        let Some(first) = fields.first() else {
            continue;
        };
        if first.text.eq_ignore_ascii_case("SURFACE") {
            surfaces.push((Vec::new(), Vec::new(), line.number));
            continue;
        }
        if first.text.parse::<usize>().is_err() {
            // Titles, units and column headings.
            if surfaces.is_empty() || first.text.chars().next().is_some_and(char::is_alphabetic) {
                continue;
            }
        }
        let Some(surface) = surfaces.last_mut() else {
            continue;
        };
        if fields.len() != 5 {
            errors.push(ctx.line(
                &line,
                format!("{} values; expected `J Z R THETA1 THETA2`", fields.len()),
            ));
            if errors.len() >= MAX_ERRORS {
                break;
            }
            continue;
        }
        let parsed = (|| {
            let j = ctx.index(&line, fields[0], "J")?;
            let z = ctx.number(&line, fields[1], "Z")?;
            let r = ctx.number(&line, fields[2], "R")?;
            let t1 = ctx.number(&line, fields[3], "THETA 1")?;
            let t2 = ctx.number(&line, fields[4], "THETA 2")?;
            if r < 0.0 {
                return Err(ctx.at(&line, fields[2], "R is negative"));
            }
            Ok::<_, Diagnostic>((j, z, r, t1, t2))
        })();
        match parsed {
            Ok((j, z, r, t1, t2)) => {
                let t = match side {
                    BladeSide::Theta1 => t1,
                    BladeSide::Theta2 => t2,
                };
                surface.0.push(j);
                surface
                    .1
                    .push([10.0 * r * t.cos(), 10.0 * r * t.sin(), 10.0 * z]);
            }
            Err(d) => errors.push(d),
        }
        if errors.len() >= MAX_ERRORS {
            break;
        }
    }
    if !errors.is_empty() {
        return Err(Diagnostics(errors));
    }
    surfaces.retain(|s| !s.0.is_empty());
    let Some(first) = surfaces.first() else {
        return Err(Diagnostic::error(
            file,
            0,
            0,
            1,
            "",
            "no `SURFACE NUMBER` section with points: not a NASA blade table",
        )
        .into());
    };
    let js = first.0.clone();
    let src: Vec<&str> = lines(text).map(|l| l.text).collect();
    for s in &surfaces {
        if s.0 != js {
            let header = src.get(s.2 - 1).copied().unwrap_or("");
            return Err(Diagnostic::error(
                file,
                s.2,
                1,
                header.trim_end().chars().count(),
                header,
                format!(
                    "this stream surface has {} points (J {:?}…), the first has {}: not a grid",
                    s.0.len(),
                    &s.0[..s.0.len().min(3)],
                    js.len()
                ),
            )
            .into());
        }
    }
    let cols = js.len();
    let rows = surfaces.len();
    let points = surfaces.into_iter().flat_map(|s| s.1).collect();
    Ok(Grid { rows, cols, points })
}

/// Reads the NASA Rotor 67 geometry file: after `JM NS NB JLE JTE` and
/// their values, `Surface number k` sections (hub to casing), each with
/// four blocks — `Axial Distance`, `Radius*Theta Distance` (of the upper
/// surface), `Delta (Radius*Theta) = Tangential thickness` (subtracted from
/// the upper surface for the lower one) and `Radius` — of a scale factor
/// and then JM values, in feet. The blade is J = JLE … JTE of every stream
/// surface; side 1 is the upper surface, side 2 the lower one, in
/// millimetres as [`read_blade_table`] writes them:
///
/// ```text
/// θ = (r·θ − [side 2] thickness) / r,   x = r cos θ,   y = r sin θ,   z = axial
/// ```
pub fn read_stream_surfaces(text: &str, file: &str, side: BladeSide) -> Result<Grid, Diagnostics> {
    const FOOT_MM: f64 = 304.8;
    let ctx = Ctx { file };
    let fail = |line: usize, source: &str, message: String| -> Diagnostics {
        let width = source.trim_end().chars().count().max(1);
        Diagnostic::error(file, line, 1, width, source, message).into()
    };
    // [JM, JLE, JTE], from the value line after the last `JM NS NB JLE JTE`
    // heading before the first surface.
    let mut sizes: Option<[usize; 3]> = None;
    let mut heading = false;
    // Per surface: its header line and its four blocks (scale, values).
    let mut surfaces: Vec<(usize, [Vec<f64>; 4])> = Vec::new();
    let mut block: Option<usize> = None;
    let mut scale = [1.0; 4];
    for line in lines(text) {
        let t = line.text.trim();
        let upper = t.to_ascii_uppercase();
        if surfaces.is_empty()
            && upper
                .split_whitespace()
                .eq(["JM", "NS", "NB", "JLE", "JTE"])
        {
            heading = true;
            continue;
        }
        if heading {
            heading = false;
            let v: Vec<usize> = t
                .split_whitespace()
                .filter_map(|f| f.parse().ok())
                .collect();
            if let [jm, _, _, jle, jte] = v[..] {
                sizes = Some([jm, jle, jte]);
            }
            continue;
        }
        if upper.starts_with("SURFACE NUMBER") {
            surfaces.push((line.number, Default::default()));
            block = None;
            continue;
        }
        let Some((_, blocks)) = surfaces.last_mut() else {
            continue;
        };
        let which = if upper.starts_with("AXIAL") {
            Some(0)
        } else if upper.starts_with("RADIUS*THETA") {
            Some(1)
        } else if upper.starts_with("DELTA") {
            Some(2)
        } else if upper.starts_with("RADIUS") {
            Some(3)
        } else {
            None
        };
        if let Some(k) = which {
            block = Some(k);
            scale[k] = f64::NAN; // the next value
            continue;
        }
        let Some(k) = block else {
            continue;
        };
        for field in split_ws(line.text) {
            let v = ctx
                .number(&line, field, "a value")
                .map_err(Diagnostics::from)?;
            if scale[k].is_nan() {
                scale[k] = v;
            } else {
                blocks[k].push(v * scale[k]);
            }
        }
    }
    let Some([jm, jle, jte]) = sizes else {
        return Err(fail(
            0,
            "",
            "no `JM NS NB JLE JTE` values before the first surface".into(),
        ));
    };
    if !(1 <= jle && jle < jte && jte <= jm) {
        return Err(fail(
            0,
            "",
            format!("JLE {jle} and JTE {jte} do not lie in 1 … JM {jm}"),
        ));
    }
    if surfaces.is_empty() {
        return Err(fail(0, "", "no `Surface number` section".into()));
    }
    let src: Vec<&str> = lines(text).map(|l| l.text).collect();
    let mut points = Vec::new();
    for (at, blocks) in &surfaces {
        if let Some(b) = blocks.iter().position(|b| b.len() != jm) {
            let name = [
                "Axial Distance",
                "Radius*Theta Distance",
                "Tangential thickness",
                "Radius",
            ][b];
            let header = src.get(at - 1).copied().unwrap_or("");
            return Err(fail(
                *at,
                header,
                format!(
                    "`{name}` of this surface has {} values, JM is {jm}",
                    blocks[b].len()
                ),
            ));
        }
        let [axial, r_theta, thickness, radius] = blocks;
        for j in jle - 1..jte {
            let r = radius[j];
            if !(r > 0.0) {
                let header = src.get(at - 1).copied().unwrap_or("");
                return Err(fail(
                    *at,
                    header,
                    format!("radius {r} at J {} is not positive", j + 1),
                ));
            }
            let arc = match side {
                BladeSide::Theta1 => r_theta[j],
                BladeSide::Theta2 => r_theta[j] - thickness[j],
            };
            let theta = arc / r;
            points.push([
                FOOT_MM * r * theta.cos(),
                FOOT_MM * r * theta.sin(),
                FOOT_MM * axial[j],
            ]);
        }
    }
    Ok(Grid {
        rows: surfaces.len(),
        cols: jte - jle + 1,
        points,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Rotor 67 style file: JM = 3, the blade J = 2 … 3, two surfaces;
    /// values by hand (feet → mm, θ = r·θ / r, side 2 less the thickness).
    #[test]
    fn stream_surfaces_of_the_rotor_67_file() {
        let surface = |k: usize, z: [f64; 3], rt: [f64; 3], th: [f64; 3], r: [f64; 3]| {
            let block = |name: &str, v: [f64; 3]| {
                format!(" {name}\n  1.000000\n {} {} {}\n", v[0], v[1], v[2])
            };
            format!(
                " Surface number  {k} from hub\n{}{}{}{}",
                block("Axial Distance", z),
                block("Radius*Theta Distance", rt),
                block("Delta (Radius*Theta) = Tangential thickness", th),
                block("Radius", r)
            )
        };
        let text = format!(
            " ROTOR 67 GEOMETRY\n   JM   NS   NB  JLE  JTE\n    3    2   22    2    3\n{}{}",
            surface(
                1,
                [-1.0, 0.0, 0.5],
                [9.0, 0.1, 0.2],
                [0.0, 0.01, 0.0],
                [0.5, 0.5, 0.5]
            ),
            surface(
                2,
                [-1.0, 0.1, 0.6],
                [9.0, 0.3, 0.4],
                [0.0, 0.02, 0.0],
                [0.8, 0.8, 0.8]
            ),
        );
        let g = read_blade_table(&text, "r67.dat", BladeSide::Theta2).unwrap();
        assert_eq!((g.rows, g.cols), (2, 2));
        let (r, theta, z) = (0.8 * 304.8, (0.3 - 0.02) / 0.8, 0.1 * 304.8);
        let want = [r * f64::cos(theta), r * f64::sin(theta), z];
        let got = g.points[2];
        assert!(
            (0..3).all(|i| (got[i] - want[i]).abs() < 1e-9),
            "{got:?} vs {want:?}"
        );
        // A block one value short names its surface.
        let short = text.replacen(" 0.8 0.8 0.8\n", " 0.8 0.8\n", 1);
        let e = read_blade_table(&short, "r67.dat", BladeSide::Theta1).unwrap_err();
        assert_eq!(e.0[0].line, 17, "{e}");
        assert!(
            e.0[0]
                .message
                .contains("`Radius` of this surface has 2 values, JM is 3"),
            "{e}"
        );
    }

    /// The columns counted in one pass agree with counting from the
    /// start of the line, multi-byte characters and blanks included.
    #[test]
    fn field_columns_are_character_columns() {
        let line = " ä, b ,  平c,,d";
        for f in split_csv(line) {
            let byte = f.text.as_ptr() as usize - line.as_ptr() as usize;
            assert_eq!(f.column, char_column(line, byte), "{}", f.text);
        }
        let line = "  ä b\t平c  d ";
        let fields = split_ws(line);
        assert_eq!(fields.len(), 4);
        for f in fields {
            let byte = f.text.as_ptr() as usize - line.as_ptr() as usize;
            assert_eq!(f.column, char_column(line, byte), "{}", f.text);
        }
    }

    #[test]
    fn csv_with_header_in_any_column_order() {
        let g = read_grid("z,x,y,col,row\n3,1,2,0,0\n6,4,5,1,0\n", "g.csv").unwrap();
        assert_eq!((g.rows, g.cols), (1, 2));
        assert_eq!(g.points, vec![[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]]);
    }

    #[test]
    fn csv_errors_are_located() {
        let e = read_grid("row,col,x,y,z\n0,0,1,2,3\n0,1,1,x2,3\n", "g.csv").unwrap_err();
        let d = &e.0[0];
        assert_eq!((d.line, d.column, d.width), (3, 7, 2));
        assert_eq!(d.source_line, "0,1,1,x2,3");
        assert!(d.message.contains("`x2` is not a number"), "{}", d.message);
        let e = read_grid("row,col,x,y,z\n0,0,1,2,3\n0,0,1,2,3\n", "g.csv").unwrap_err();
        assert!(e.0[0].message.contains("again (first on line 2)"));
        let e = read_grid("0,0,1,2,3\n1,1,1,2,3\n", "g.csv").unwrap_err();
        assert!(
            e.0[0]
                .message
                .contains("2 missing (row 0 col 1, row 1 col 0)"),
            "{}",
            e
        );
        let e = read_grid("row,col,x,y\n", "g.csv").unwrap_err();
        assert!(e.0[0].message.contains("no `z` column"));
    }

    #[test]
    fn tables_with_blank_lines_between_rows_or_indices() {
        let g = read_grid("# grid\n0 0 0\n1 0 0\n\n0 1 0\n1 1 1 # corner\n", "t.txt").unwrap();
        assert_eq!((g.rows, g.cols), (2, 2));
        assert_eq!(g.at(1, 1), [1.0, 1.0, 1.0]);
        let g = read_grid("1 0 0 0 5\n0 0 1 2 3\n0 1 0 0 0\n1 1 0 0 0\n", "t.txt").unwrap();
        assert_eq!(g.at(0, 0), [1.0, 2.0, 3.0]);
        let e = read_grid("0 0 0\n1 0\n", "t.txt").unwrap_err();
        assert_eq!(
            (e.0[0].line, e.0[0].message.as_str()),
            (2, "2 values, but line 1 has 3")
        );
    }

    #[test]
    fn blade_table_converts_to_millimetres() {
        let text = " Table\n Z and R are in centimeters\n\n SURFACE NUMBER     1 FROM THE HUB\n    J      Z           R         THETA 1     THETA 2\n    1   1.0  10.0  0.0  0.5\n    2   2.0  10.0  0.1  0.5\n SURFACE NUMBER     2\n    J      Z           R         THETA 1     THETA 2\n    1   1.0  20.0  0.0  0.5\n    2   2.0  20.0  0.1  0.5\n";
        let g = read_blade_table(text, "b.dat", BladeSide::Theta1).unwrap();
        assert_eq!((g.rows, g.cols), (2, 2));
        assert_eq!(g.at(0, 0), [100.0, 0.0, 10.0]);
        let p = g.at(1, 1);
        assert!(
            (p[0] - 200.0 * 0.1f64.cos()).abs() < 1e-12
                && (p[1] - 200.0 * 0.1f64.sin()).abs() < 1e-12
        );
        let bad = text.replace("2   2.0  20.0", "2   2.0  2O.0");
        let e = read_blade_table(&bad, "b.dat", BladeSide::Theta2).unwrap_err();
        assert_eq!(e.0[0].line, 11);
        assert!(e.0[0].message.contains("R `2O.0` is not a number"));
    }
}
