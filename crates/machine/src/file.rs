//! Reading and validating machine files (TOML; docs/machine-files.md).
//!
//! Every mistake is reported as a [`Diagnostic`] naming the file, line and
//! column, and all mistakes of a file are reported at once.

use std::ops::Range;

use kinpost_diag::{Diagnostic, Diagnostics, Severity};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Deserializer};
use toml::Spanned;

use crate::model::{
    Axis, AxisKind, MAX_AXES, Machine, OutputMode, PostSettings, Prefer, Side, Tool, Wrap,
};
use crate::pressure::{PressureAxis, WheelModel};

mod solids;
pub use solids::{MAX_MESH_BYTES, MeshFiles, StlError, mesh_from_stl};

/// How far from 1 the length of a direction may be (it is then normalised).
const UNIT_TOLERANCE: f64 = 1e-6;

/// Widest travel of a rotary axis, degrees. Every 360° equivalent inside the
/// limits is an inverse-kinematics solution, so the travel must stay small; an
/// axis that turns without end has no `limits`.
const MAX_ROTARY_TRAVEL: f64 = 3600.0;

/// The largest coordinate of a point in a machine file, mm. A double keeps
/// about 1e-10 mm at a kilometre; at 1e15 mm it keeps 0.1 mm, and a chain
/// through such a point solves to wrong positions.
const MAX_COORDINATE_MM: f64 = 1e6;

/// The largest machine file read: 1 MiB, hundreds of times a commented
/// machine with a pressure table. A larger text (300 000 `[[axis]]`
/// tables) is refused before it is parsed, in bounded time and memory.
pub const MAX_MACHINE_FILE_BYTES: usize = 1 << 20;

#[derive(Deserialize)]
struct RawMachine {
    name: Option<Spanned<String>>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    post: RawPost,
    #[serde(default)]
    axis: Vec<RawAxis>,
    workpiece: Option<RawWorkpiece>,
    tool: Option<Spanned<RawTool>>,
    pressure: Option<Spanned<RawPressure>>,
    #[serde(default)]
    solid: Vec<solids::RawSolid>,
    collision: Option<solids::RawCollision>,
}

#[derive(Deserialize, Default)]
struct RawPost {
    dialect: Option<String>,
    header: Option<String>,
    footer: Option<String>,
    output: Option<RawOutput>,
    /// Safe distance of a retract-and-reconfigure, mm.
    retract: Option<Spanned<f64>>,
    /// Singular cone half-angle, degrees.
    singular_cone: Option<Spanned<f64>>,
    /// The machine's home, NC values by axis name (`GOHOME` without a
    /// point goes there).
    home: Option<Spanned<std::collections::BTreeMap<String, Spanned<f64>>>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum RawWrap {
    None,
    Modulo,
    Unwind,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum RawPrefer {
    Positive,
    Negative,
    Zero,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum RawOutput {
    Joint,
    Tcp,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum RawKind {
    Linear,
    Rotary,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum RawSide {
    Workpiece,
    Tool,
}

#[derive(Deserialize)]
struct RawAxis {
    name: Spanned<String>,
    kind: RawKind,
    side: RawSide,
    direction: Spanned<Nums<3>>,
    point: Option<Spanned<Nums<3>>>,
    limits: Option<Spanned<Nums<2>>>,
    fixed: Option<Spanned<f64>>,
    /// Locked (`fixed`) unless the CL gives reference directions.
    free_with_reference: Option<Spanned<bool>>,
    /// Limits are machine coordinates: machine = NC + offset (docs/conventions.md).
    machine_offset: Option<Spanned<f64>>,
    wrap: Option<Spanned<RawWrap>>,
    prefer: Option<Spanned<RawPrefer>>,
    /// mm/min or degrees/min.
    max_velocity: Option<Spanned<f64>>,
}

#[derive(Deserialize)]
struct RawWorkpiece {
    origin: Spanned<Nums<3>>,
    x: Spanned<Nums<3>>,
    z: Spanned<Nums<3>>,
}

#[derive(Deserialize)]
struct RawTool {
    point: Spanned<Nums<3>>,
    axis: Spanned<Nums<3>>,
    reference: Option<Spanned<Nums<3>>>,
}

/// `[pressure]`: the grinding-pressure axis (Qi (thesis), chapter 2).
#[derive(Deserialize)]
struct RawPressure {
    name: Spanned<String>,
    reference: Spanned<f64>,
    plane: Spanned<Vec<Spanned<String>>>,
    link_length: Option<Spanned<f64>>,
    alpha_deg: Option<Table>,
    offsets: Option<Table>,
}

/// A table of numbers, each row with its place in the file.
type Table = Spanned<Vec<Spanned<Vec<f64>>>>;

/// Exactly `N` numbers (serde's own arrays accept longer lists).
#[derive(Clone, Copy)]
struct Nums<const N: usize>([f64; N]);

impl<'de, const N: usize> Deserialize<'de> for Nums<N> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        <[f64; N]>::try_from(v.as_slice()).map(Nums).map_err(|_| {
            let expected = format!("an array of length {N}");
            serde::de::Error::invalid_length(v.len(), &expected.as_str())
        })
    }
}

/// Collects the mistakes of one file.
struct Checker<'a> {
    file: &'a str,
    source: &'a str,
    errors: Vec<Diagnostic>,
}

impl Checker<'_> {
    fn error(&mut self, span: Range<usize>, message: impl Into<String>) {
        self.errors.push(Diagnostic::at_byte_span(
            Severity::Error,
            self.file,
            self.source,
            span,
            message,
        ));
    }

    /// A unit vector, or an error at `v`'s span. `None` when `v` has no
    /// direction at all (zero or not finite); a vector of another length is
    /// reported and normalised.
    fn unit(&mut self, v: &Spanned<Nums<3>>, what: &str) -> Option<Vector3<f64>> {
        let raw = Vector3::from(v.get_ref().0);
        if raw.iter().any(|x| !x.is_finite()) {
            self.error(v.span(), format!("{what} must be three finite numbers"));
            return None;
        }
        let n = raw.norm();
        if !n.is_finite() || n < 1e-12 {
            self.error(v.span(), format!("{what} must be a non-zero unit vector"));
            return None;
        }
        if (n - 1.0).abs() > UNIT_TOLERANCE {
            let u = raw / n;
            self.error(
                v.span(),
                format!(
                    "{what} is not a unit vector (length {}); did you mean [{}, {}, {}]?",
                    short(n, 9),
                    short(u.x, 9),
                    short(u.y, 9),
                    short(u.z, 9)
                ),
            );
        }
        Some(raw / n)
    }

    /// A point, or an error at `v`'s span when a coordinate is not finite
    /// or farther out than [`MAX_COORDINATE_MM`].
    fn point(&mut self, v: &Spanned<Nums<3>>, what: &str) -> Vector3<f64> {
        let p = Vector3::from(v.get_ref().0);
        if p.iter().any(|x| !x.is_finite()) {
            self.error(
                v.span(),
                format!("{what} must be three finite numbers (mm)"),
            );
            return Vector3::zeros();
        }
        if p.amax() > MAX_COORDINATE_MM {
            self.error(
                v.span(),
                format!(
                    "{what} has a coordinate of {:e} mm: a machine's points lie within {MAX_COORDINATE_MM:e} mm (a kilometre); \
                     farther out, the arithmetic loses the precision of a position",
                    p.amax()
                ),
            );
            return Vector3::zeros();
        }
        p
    }

    /// The 1-based line of a byte offset.
    fn line_of(&self, offset: usize) -> usize {
        self.source
            .get(..offset)
            .map_or(0, |s| s.matches('\n').count())
            + 1
    }
}

/// A number with at most `decimals` decimals and no trailing zeros.
fn short(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".to_string()
    } else {
        s.to_string()
    }
}

/// The diagnostic of a TOML syntax or type error, in words for machine-file
/// authors rather than for Rust programmers.
fn toml_error(e: &toml::de::Error, file: &str, source: &str, syntax: bool) -> Diagnostic {
    let span = e.span().unwrap_or(0..0);
    let mut message = e.message().trim_end().to_string();
    for (from, to) in [
        ("unknown field", "unknown key"),
        ("missing field", "missing key"),
        ("expected f64", "expected a number"),
        ("unknown variant", "unknown value"),
    ] {
        message = message.replace(from, to);
    }
    if let Some(rest) = message.strip_prefix("invalid length ")
        && let Some((found, wanted)) = rest.split_once(", expected an array of length ")
    {
        message = format!("expected {wanted} numbers, found {found}");
    }
    let boundary = |mut i: usize| {
        i = i.min(source.len());
        while !source.is_char_boundary(i) {
            i -= 1;
        }
        i
    };
    let start = boundary(span.start);
    let line_start = source[..start].rfind('\n').map_or(0, |i| i + 1);
    let before = &source[line_start..start];
    let token: String = source[start..]
        .chars()
        .take_while(|c| !matches!(c, ',' | ']' | '\n') && !c.is_whitespace())
        .collect();
    if message == "duplicate key" && !token.is_empty() {
        message = format!("`{token}` is defined twice");
        if token == "axis" {
            message.push_str(" (write every axis as `[[axis]]`, with two brackets)");
        }
    }
    // `[0, 0 100]`: the parser reads `0 100` as one bare word.
    let end = boundary(span.end.max(start));
    let words: Vec<&str> = source[start..end]
        .lines()
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    if syntax
        && before.matches('[').count() > before.matches(']').count()
        && words.len() >= 2
        && words.iter().all(|w| w.parse::<f64>().is_ok())
    {
        message = format!(
            "missing comma between `{}` and `{}` in this array",
            words[0], words[1]
        );
    }
    // A syntax error at the start of a line is often an array or string left
    // open on an earlier line: the parser only notices on the next key.
    if syntax && before.trim().is_empty() && line_start > 0 {
        let before: Vec<&str> = source[..line_start - 1].lines().collect();
        let earlier = before
            .iter()
            .enumerate()
            .rev()
            .find(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
        if let Some((i, l)) = earlier
            && l.matches('[').count() > l.matches(']').count()
        {
            message = format!(
                "{message} (is the array on line {} missing its closing `]`?)",
                i + 1
            );
        }
    }
    Diagnostic::at_byte_span(Severity::Error, file, source, span, message)
}

/// Every key the machine file does not know and every unknown value of a
/// key that takes a word (`kind`, `side`, `wrap`, …), in file order. The
/// `Raw*` types do not deny unknown keys themselves: this is where they are
/// refused.
fn unknown_names(source: &str, file: &str) -> Vec<Diagnostic> {
    use kinpost_diag::toml_names::{Unknown, names, table};
    use toml::de::{DeTable, DeValue};
    let Ok(doc) = DeTable::parse(source) else {
        return Vec::new();
    };
    let doc = doc.get_ref();
    let mut unknown = Unknown::default();
    unknown.check(doc, names::<RawMachine>(), &[]);
    if let Some(t) = table(doc, "post") {
        unknown.check(t, names::<RawPost>(), &[("output", names::<RawOutput>())]);
    }
    if let Some(DeValue::Array(axes)) = doc.get("axis").map(|v| v.get_ref()) {
        let words = [
            ("kind", names::<RawKind>()),
            ("side", names::<RawSide>()),
            ("wrap", names::<RawWrap>()),
            ("prefer", names::<RawPrefer>()),
        ];
        for axis in axes {
            if let DeValue::Table(t) = axis.get_ref() {
                unknown.check(t, names::<RawAxis>(), &words);
            }
        }
    }
    for (name, fields) in [
        ("workpiece", names::<RawWorkpiece>()),
        ("tool", names::<RawTool>()),
        ("pressure", names::<RawPressure>()),
    ] {
        if let Some(t) = table(doc, name) {
            unknown.check(t, fields, &[]);
        }
    }
    solids::unknown_names(doc, &mut unknown);
    unknown.into_diagnostics(file, source)
}

/// Reads a machine file. `file` is the name used in diagnostics and, taken
/// as a path, the file whose folder its `mesh` files are read from (see
/// [`machine_from_toml_with`]).
pub fn machine_from_toml(source: &str, file: &str) -> Result<Machine, Diagnostics> {
    let folder = std::path::Path::new(file)
        .parent()
        .unwrap_or(std::path::Path::new(""));
    machine_from_toml_with(source, file, MeshFiles::Folder(folder))
}

/// Reads a machine file whose `mesh` files are read from `meshes`. `file`
/// is the name used in diagnostics.
pub fn machine_from_toml_with(
    source: &str,
    file: &str,
    meshes: MeshFiles,
) -> Result<Machine, Diagnostics> {
    let (raw, unknown) = parse_raw_machine(source, file)?;
    let mut c = Checker {
        file,
        source,
        errors: unknown,
    };

    let name = check_name(&mut c, raw.name.as_ref());
    let Some(axes) = check_axes(&mut c, &raw.axis) else {
        return Err(Diagnostics(c.errors));
    };
    let (workpiece_rotation, workpiece_origin) = check_workpiece(&mut c, raw.workpiece.as_ref());
    let Some(tool) = &raw.tool else {
        c.error(
            0..0,
            "the machine file has no [tool] table (the tool `point` and `axis` at home)",
        );
        return Err(Diagnostics(c.errors));
    };
    let tool = check_tool(&mut c, tool, &axes);
    let post = check_post(&mut c, raw.post, &axes);
    let pressure = raw
        .pressure
        .as_ref()
        .and_then(|p| check_pressure(&mut c, p, &axes));
    let (solids, declared) = solids::check_solids(&mut c, &raw.solid, &axes, meshes);
    let collision = raw
        .collision
        .as_ref()
        .map(|r| solids::check_collision(&mut c, r, &declared))
        .unwrap_or_default();

    if !c.errors.is_empty() {
        return Err(Diagnostics(c.errors));
    }
    Ok(Machine {
        name,
        description: raw.description,
        axes,
        workpiece_rotation,
        workpiece_origin,
        tool,
        post,
        pressure,
        solids,
        collision,
    })
}

/// The machine file as read by serde, with every unknown key and value
/// (in file order), or the file's first fatal mistake: more than
/// [`MAX_MACHINE_FILE_BYTES`] (refused before it is parsed), a TOML
/// syntax error, or a key of the wrong type (reported after the unknown
/// names found before it).
fn parse_raw_machine(
    source: &str,
    file: &str,
) -> Result<(RawMachine, Vec<Diagnostic>), Diagnostics> {
    if let Some(e) = kinpost_diag::oversized_file(file, source, "machine", MAX_MACHINE_FILE_BYTES) {
        return Err(e.into());
    }
    // Syntax first, then the keys and types of the machine file.
    if let Err(e) = source.parse::<toml::Table>() {
        return Err(toml_error(&e, file, source, true).into());
    }
    // serde would stop at the first unknown key or value: they are all
    // found here (the `Raw*` types let unknown keys pass), and reported with
    // the mistakes the checks after it find.
    let unknown = unknown_names(source, file);
    match toml::from_str(source) {
        Ok(raw) => Ok((raw, unknown)),
        Err(e) => {
            let first = toml_error(&e, file, source, false);
            Err(Diagnostics(kinpost_diag::toml_names::with_serde_error(
                unknown, first,
            )))
        }
    }
}

/// The machine's `name`, trimmed: it must be given and not blank (the
/// post names the machine in its output and messages).
fn check_name(c: &mut Checker, name: Option<&Spanned<String>>) -> String {
    match name {
        Some(n) => {
            let name = n.get_ref().trim().to_string();
            if name.is_empty() {
                c.error(n.span(), "machine name must not be empty");
            }
            name
        }
        None => {
            c.error(
                0..0,
                "the machine file has no `name` (e.g. `name = \"my-mill\"` at the top)",
            );
            String::new()
        }
    }
}

/// Checks every `[[axis]]` ([`check_axis`]) and then their counts
/// ([`check_axis_counts`]). `None` when there are more than [`MAX_AXES`]:
/// that is reported and nothing after the axes is checked.
fn check_axes(c: &mut Checker, raw: &[RawAxis]) -> Option<Vec<Axis>> {
    // Past the limit, only the axes up to it are checked (each against the
    // others, for duplicate names): the first table past it is the error,
    // and a file of 300 000 tables takes no quadratic work.
    let listed = &raw[..raw.len().min(MAX_AXES)];
    let mut axes = Vec::with_capacity(listed.len());
    let mut direction_ok = Vec::with_capacity(listed.len());
    for a in listed {
        let (axis, ok) = check_axis(c, a, listed);
        axes.push(axis);
        direction_ok.push(ok);
    }
    if raw.len() > MAX_AXES {
        c.error(
            raw[MAX_AXES].name.span(),
            format!("a machine has at most {MAX_AXES} axes"),
        );
        return None;
    }
    check_axis_counts(c, raw, &axes, &direction_ok);
    Some(axes)
}

/// The workpiece frame of `[workpiece]` (rotation and origin; identity
/// without the table): unit `x` and `z` at right angles, `y = z × x`.
fn check_workpiece(
    c: &mut Checker,
    workpiece: Option<&RawWorkpiece>,
) -> (Matrix3<f64>, Vector3<f64>) {
    match workpiece {
        None => (Matrix3::identity(), Vector3::zeros()),
        Some(w) => {
            let origin = c.point(&w.origin, "workpiece origin");
            let x = c.unit(&w.x, "workpiece x");
            let z = c.unit(&w.z, "workpiece z");
            let (x, z) = match (x, z) {
                (Some(x), Some(z)) => {
                    if x.dot(&z).abs() > UNIT_TOLERANCE {
                        c.error(
                            w.z.span(),
                            format!(
                                "workpiece x and z must be perpendicular (they are {}° apart)",
                                short(x.angle(&z).to_degrees(), 3)
                            ),
                        );
                    }
                    (x, z)
                }
                _ => (Vector3::x(), Vector3::z()),
            };
            let y = z.cross(&x);
            (Matrix3::from_columns(&[x, y, z]), origin)
        }
    }
}

/// The tool at home (`[tool]`): its point, unit axis and optional
/// reference direction at right angles to the axis. The reference fixes
/// the rotation about the tool axis, so it is needed (and allowed) only
/// when the free rotary axes number three.
fn check_tool(c: &mut Checker, tool: &Spanned<RawTool>, axes: &[Axis]) -> Tool {
    let t = tool.get_ref();
    let tool_point = c.point(&t.point, "tool point");
    let tool_axis = c.unit(&t.axis, "tool axis");
    let reference = t.reference.as_ref().map(|r| {
        let u = c.unit(r, "tool reference");
        if let (Some(u), Some(a)) = (u, tool_axis)
            && u.dot(&a).abs() > UNIT_TOLERANCE
        {
            c.error(
                r.span(),
                format!(
                    "tool reference must be perpendicular to the tool axis (they are {}° apart)",
                    short(u.angle(&a).to_degrees(), 3)
                ),
            );
        }
        u.unwrap_or_else(Vector3::x)
    });
    let free_rotary = axes
        .iter()
        .filter(|a| a.is_rotary() && (a.is_free() || a.free_with_reference))
        .count();
    if free_rotary > 3 && axes.iter().any(|a| a.free_with_reference) {
        c.error(
            tool.span(),
            "with the `free_with_reference` axes unlocked there are more than 3 free rotary axes",
        );
    }
    if free_rotary == 3 && reference.is_none() {
        c.error(
            tool.span(),
            "three free rotary axes need a tool `reference` direction (or lock one with `fixed`)",
        );
    }
    Tool {
        point: tool_point,
        axis: tool_axis.unwrap_or_else(Vector3::z),
        reference,
    }
}

/// The post settings of `[post]`: a retract distance above zero and a
/// singular cone from 0 to under 45° (a wider cone would take most
/// orientations for singular).
fn check_post(c: &mut Checker, post: RawPost, axes: &[Axis]) -> PostSettings {
    let home = post.home.as_ref().and_then(|h| check_home(c, h, axes));
    let retract = post.retract.as_ref().map(|r| {
        let v = *r.get_ref();
        if !(v.is_finite() && v > 0.0) {
            c.error(
                r.span(),
                "retract must be a distance greater than zero (mm)",
            );
        }
        v
    });
    let singular_cone_deg = post.singular_cone.as_ref().map(|r| {
        let v = *r.get_ref();
        if !(v.is_finite() && (0.0..45.0).contains(&v)) {
            c.error(
                r.span(),
                "singular_cone must be an angle from 0 to less than 45 degrees",
            );
        }
        v
    });
    PostSettings {
        dialect: post.dialect,
        header: post.header,
        footer: post.footer,
        output: post.output.map(|o| match o {
            RawOutput::Joint => OutputMode::Joint,
            RawOutput::Tcp => OutputMode::Tcp,
        }),
        retract,
        singular_cone_deg,
        home,
    }
}

/// `[post] home`: an NC value for every axis that is not locked (a locked
/// axis may be named with its locked value), each inside its travel;
/// `None` when anything is wrong (each mistake is reported).
fn check_home(
    c: &mut Checker,
    home: &Spanned<std::collections::BTreeMap<String, Spanned<f64>>>,
    axes: &[Axis],
) -> Option<Vec<f64>> {
    let mut values: Vec<Option<f64>> = axes.iter().map(|a| a.fixed).collect();
    let mut ok = true;
    for (name, v) in home.get_ref() {
        let value = *v.get_ref();
        let Some(i) = axes.iter().position(|a| a.name.eq_ignore_ascii_case(name)) else {
            c.error(
                v.span(),
                format!("home names `{name}`, which is not an axis of this machine"),
            );
            ok = false;
            continue;
        };
        let a = &axes[i];
        let wrong = if !value.is_finite() {
            Some("a finite NC value".to_string())
        } else if a.fixed.is_some_and(|f| f != value) {
            Some(format!(
                "{} is locked at {}",
                a.name,
                a.fixed.unwrap_or(0.0)
            ))
        } else if let Some([lo, hi]) = a.limits.filter(|[lo, hi]| !(lo..=hi).contains(&&value)) {
            Some(format!("{} travels from {lo} to {hi}", a.name))
        } else {
            None
        };
        if let Some(why) = wrong {
            c.error(v.span(), format!("home {} = {value}: {why}", a.name));
            ok = false;
        }
        values[i] = Some(value);
    }
    let missing: Vec<&str> = axes
        .iter()
        .zip(&values)
        .filter(|(_, v)| v.is_none())
        .map(|(a, _)| a.name.as_str())
        .collect();
    if !missing.is_empty() {
        c.error(
            home.span(),
            format!("home gives no value for {}", missing.join(", ")),
        );
        ok = false;
    }
    ok.then(|| values.into_iter().map(|v| v.unwrap_or(0.0)).collect())
}

/// Checks the `[pressure]` table against the axes: its name, reference,
/// linkage plane, wheel model, and the reference within the calibration.
/// `None` when any of them is wrong (each mistake is reported).
fn check_pressure(
    c: &mut Checker,
    raw: &Spanned<RawPressure>,
    axes: &[Axis],
) -> Option<PressureAxis> {
    let p = raw.get_ref();
    let errors_before = c.errors.len();
    let name = check_pressure_name(c, &p.name, axes);
    let reference = *p.reference.get_ref();
    if !reference.is_finite() {
        c.error(p.reference.span(), "reference must be a finite number");
    }
    let plane = check_linkage_plane(c, &p.plane, axes);
    let model = check_wheel_model(c, raw);
    check_reference_in_calibration(c, &p.reference, model.as_ref());
    if c.errors.len() > errors_before {
        return None;
    }
    Some(PressureAxis {
        name,
        reference,
        directions: [axes[plane[0]].direction, axes[plane[1]].direction],
        plane,
        model: model?,
    })
}

/// The pressure's NC word (`H1`), trimmed: a letter then letters and
/// digits, and no axis's name (the word would be read as the axis).
fn check_pressure_name(c: &mut Checker, name: &Spanned<String>, axes: &[Axis]) -> String {
    let trimmed = name.get_ref().trim().to_string();
    if !trimmed.starts_with(|ch: char| ch.is_ascii_alphabetic())
        || !trimmed.chars().all(|ch| ch.is_ascii_alphanumeric())
    {
        c.error(
            name.span(),
            "pressure name must be a letter followed by letters and digits (the NC word, e.g. \"H1\")",
        );
    } else if let Some(a) = axes.iter().find(|a| a.name.eq_ignore_ascii_case(&trimmed)) {
        c.error(
            name.span(),
            format!(
                "pressure name `{trimmed}` is also the name of axis `{}`",
                a.name
            ),
        );
    }
    trimmed
}

/// The linkage plane: two distinct, perpendicular linear axes of the
/// machine, as indices into `axes`; an index that cannot be had is
/// `usize::MAX` (and reported).
fn check_linkage_plane(
    c: &mut Checker,
    plane_names: &Spanned<Vec<Spanned<String>>>,
    axes: &[Axis],
) -> [usize; 2] {
    let mut plane = [usize::MAX; 2];
    let names = plane_names.get_ref();
    if names.len() != 2 {
        c.error(
            plane_names.span(),
            format!(
                "plane names the two linear axes that span the linkage plane, e.g. [\"Y\", \"Z\"]; found {} names",
                names.len()
            ),
        );
        return plane;
    }
    for (k, n) in names.iter().enumerate() {
        let wanted = n.get_ref().trim();
        match axes
            .iter()
            .position(|a| a.name.eq_ignore_ascii_case(wanted))
        {
            None => c.error(n.span(), format!("the machine has no axis `{wanted}`")),
            Some(i) if axes[i].is_rotary() => c.error(
                n.span(),
                format!(
                    "plane axis `{}` is rotary; the plane is spanned by linear axes",
                    axes[i].name
                ),
            ),
            Some(i) => plane[k] = i,
        }
    }
    if plane[0] != usize::MAX && plane[0] == plane[1] {
        c.error(plane_names.span(), "plane names the same axis twice");
        plane[1] = usize::MAX;
    }
    if plane.iter().all(|&i| i != usize::MAX) {
        let (a, b) = (&axes[plane[0]], &axes[plane[1]]);
        let cos = a.direction.dot(&b.direction);
        if cos.abs() > UNIT_TOLERANCE {
            c.error(
                plane_names.span(),
                format!(
                    "plane axes `{}` and `{}` must be perpendicular (they are {}° apart)",
                    a.name,
                    b.name,
                    short(a.direction.angle(&b.direction).to_degrees(), 3)
                ),
            );
        }
    }
    plane
}

/// The wheel model: the four-bar linkage (`link_length` with
/// `alpha_deg`) or measured `offsets`, exactly one of the two, with its
/// calibration table checked.
fn check_wheel_model(c: &mut Checker, raw: &Spanned<RawPressure>) -> Option<WheelModel> {
    let p = raw.get_ref();
    match (&p.link_length, &p.alpha_deg, &p.offsets) {
        (Some(l), Some(t), None) => {
            let length = *l.get_ref();
            if !(length.is_finite() && length > 0.0) {
                c.error(l.span(), "link_length must be a positive number of mm");
            }
            let rows = table::<2>(c, t, "alpha_deg", "[pressure, angle in degrees]");
            if rows.iter().any(|r| r[1].abs() > 180.0) {
                c.error(t.span(), "alpha_deg angles must lie within ±180°");
            }
            Some(WheelModel::Linkage {
                link_length: length,
                alpha_deg: rows,
            })
        }
        (None, None, Some(t)) => Some(WheelModel::Offsets(table::<3>(
            c,
            t,
            "offsets",
            "[pressure, offset along the first plane axis, offset along the second]",
        ))),
        (_, _, Some(t)) => {
            c.error(
                t.span(),
                "give either `link_length` with `alpha_deg` (the four-bar linkage) or `offsets` (measured offsets), not both",
            );
            None
        }
        (Some(l), None, None) => {
            c.error(
                l.span(),
                "`link_length` needs `alpha_deg`, the calibration [[pressure, angle], ...]",
            );
            None
        }
        (None, Some(t), None) => {
            c.error(
                t.span(),
                "`alpha_deg` needs `link_length`, the input link length in mm",
            );
            None
        }
        (None, None, None) => {
            c.error(
                raw.span(),
                "[pressure] needs `link_length` with `alpha_deg` (the four-bar linkage) or `offsets` (measured offsets)",
            );
            None
        }
    }
}

/// The tool point was measured at the reference: it must lie on the
/// calibration (a reference beyond a stop is ambiguous; a row on the stop
/// says what is meant). A non-finite reference was reported already.
fn check_reference_in_calibration(
    c: &mut Checker,
    reference: &Spanned<f64>,
    model: Option<&WheelModel>,
) {
    fn ends<const N: usize>(rows: &[[f64; N]]) -> Option<(f64, f64)> {
        (rows.len() >= 2).then(|| (rows[0][0], rows[rows.len() - 1][0]))
    }
    let ends = match model {
        Some(WheelModel::Linkage { alpha_deg, .. }) => ends(alpha_deg),
        Some(WheelModel::Offsets(rows)) => ends(rows),
        None => None,
    };
    let value = *reference.get_ref();
    if let Some((lo, hi)) = ends
        && value.is_finite()
        && (value < lo || value > hi)
    {
        c.error(
            reference.span(),
            format!(
                "reference {} is outside the calibration ({} .. {}); if the wheel is on a stop there, add a row at {} with the stop's value",
                short(value, 9),
                short(lo, 9),
                short(hi, 9),
                short(value, 9)
            ),
        );
    }
}

/// The rows of a calibration table: `N` finite numbers each, at least two
/// rows, strictly increasing in the first column (the pressure).
fn table<const N: usize>(c: &mut Checker, t: &Table, key: &str, row: &str) -> Vec<[f64; N]> {
    let mut rows: Vec<[f64; N]> = Vec::with_capacity(t.get_ref().len());
    for r in t.get_ref() {
        let Ok(values) = <[f64; N]>::try_from(r.get_ref().as_slice()) else {
            c.error(
                r.span(),
                format!(
                    "a row of `{key}` is {row}: expected {N} numbers, found {}",
                    r.get_ref().len()
                ),
            );
            continue;
        };
        if values.iter().any(|v| !v.is_finite()) {
            c.error(r.span(), format!("a row of `{key}` must be finite numbers"));
            continue;
        }
        if let Some(before) = rows.last()
            && values[0] <= before[0]
        {
            c.error(
                r.span(),
                format!(
                    "`{key}` must be sorted by pressure without repeats: {} follows {}",
                    short(values[0], 9),
                    short(before[0], 9)
                ),
            );
            continue;
        }
        rows.push(values);
    }
    if t.get_ref().len() < 2 {
        c.error(
            t.span(),
            format!("`{key}` needs at least two rows (the calibration between the stops)"),
        );
    }
    rows
}

/// Checks one axis; also says whether its direction is usable.
fn check_axis(c: &mut Checker, a: &RawAxis, all: &[RawAxis]) -> (Axis, bool) {
    let name = check_axis_name(c, a, all);
    let direction = c.unit(&a.direction, "axis direction");
    let direction_ok = direction.is_some();
    let direction = direction.unwrap_or_else(Vector3::z);
    let kind = match a.kind {
        RawKind::Linear => AxisKind::Linear,
        RawKind::Rotary => AxisKind::Rotary,
    };
    let point = check_axis_point(c, a, kind, &name);
    let offset = check_machine_offset(c, a.machine_offset.as_ref());
    let (limits, limits_ok) = check_limits(c, a.limits.as_ref(), kind, offset);
    let fixed = check_fixed(c, a.fixed.as_ref(), limits.filter(|_| limits_ok));
    let mut axis = Axis {
        name,
        kind,
        side: match a.side {
            RawSide::Workpiece => Side::Workpiece,
            RawSide::Tool => Side::Tool,
        },
        direction,
        point,
        wrap: Axis::default_wrap(kind, limits),
        limits,
        fixed,
        free_with_reference: false,
        prefer: None,
        max_velocity: None,
        machine_offset: offset,
    };
    check_axis_options(c, a, &mut axis);
    (axis, direction_ok)
}

/// The axis name, trimmed: letters and digits (the NC address), and no
/// earlier axis of the same name (names are not case-sensitive); a
/// duplicate names the line of the first.
fn check_axis_name(c: &mut Checker, a: &RawAxis, all: &[RawAxis]) -> String {
    let name = a.name.get_ref().trim().to_string();
    if name.is_empty() || !name.chars().all(|ch| ch.is_ascii_alphanumeric()) {
        c.error(
            a.name.span(),
            "axis name must be letters and digits (the NC address, e.g. \"X\" or \"A\")",
        );
    }
    let first = all
        .iter()
        .position(|b| b.name.get_ref().trim().eq_ignore_ascii_case(&name))
        .expect("the axis itself is in the list");
    if !std::ptr::eq(&all[first], a) {
        let other = &all[first].name;
        let line = c.line_of(other.span().start);
        c.error(
            a.name.span(),
            format!(
                "duplicate axis name `{name}`: axis `{}` on line {line} has the same name (names are not case-sensitive)",
                other.get_ref().trim()
            ),
        );
    }
    name
}

/// A point on a rotary axis's rotation line: required for a rotary axis,
/// refused on a linear one (zero where missing or refused).
fn check_axis_point(c: &mut Checker, a: &RawAxis, kind: AxisKind, name: &str) -> Vector3<f64> {
    match (kind, &a.point) {
        (AxisKind::Rotary, Some(p)) => c.point(p, "axis point"),
        (AxisKind::Rotary, None) => {
            c.error(
                a.name.span(),
                format!("rotary axis `{name}` needs a `point` on its rotation line"),
            );
            Vector3::zeros()
        }
        (AxisKind::Linear, Some(p)) => {
            c.error(
                p.span(),
                "a linear axis has no `point` (only rotary axes do)",
            );
            Vector3::zeros()
        }
        (AxisKind::Linear, None) => Vector3::zeros(),
    }
}

/// The machine offset (machine value − NC value): finite and within
/// ±[`MAX_COORDINATE_MM`]; 0 where missing or wrong.
fn check_machine_offset(c: &mut Checker, offset: Option<&Spanned<f64>>) -> f64 {
    match offset {
        Some(o) if !o.get_ref().is_finite() => {
            c.error(o.span(), "machine_offset must be a finite number");
            0.0
        }
        Some(o) if o.get_ref().abs() > MAX_COORDINATE_MM => {
            c.error(
                o.span(),
                format!("machine_offset must lie within ±{MAX_COORDINATE_MM:e}"),
            );
            0.0
        }
        Some(o) => *o.get_ref(),
        None => 0.0,
    }
}

/// The axis limits as NC values (machine limits − `offset`), and whether
/// they are usable: finite and within ±[`MAX_COORDINATE_MM`] as machine
/// and NC values, in order, and for a rotary axis at most
/// [`MAX_ROTARY_TRAVEL`] apart. The first mistake is reported.
fn check_limits(
    c: &mut Checker,
    limits: Option<&Spanned<Nums<2>>>,
    kind: AxisKind,
    offset: f64,
) -> (Option<[f64; 2]>, bool) {
    let mut limits_ok = true;
    let limits = limits.map(|l| {
        let [lo, hi] = l.get_ref().0;
        let (nc_lo, nc_hi) = (lo - offset, hi - offset);
        limits_ok = false;
        if !(lo.is_finite() && hi.is_finite() && nc_lo.is_finite() && nc_hi.is_finite()) {
            c.error(l.span(), "limits must be finite numbers");
        } else if [lo, hi, nc_lo, nc_hi]
            .iter()
            .any(|v| v.abs() > MAX_COORDINATE_MM)
        {
            // (Tolerances and travel diagonals are computed from them:
            // ±1e154 would make them infinite.)
            c.error(
                l.span(),
                format!(
                    "limits must lie within ±{MAX_COORDINATE_MM:e} (mm or degrees, NC and machine values)"
                ),
            );
        } else if lo > hi {
            c.error(
                l.span(),
                format!("limits are reversed: minimum {lo} is greater than maximum {hi}"),
            );
        } else if kind == AxisKind::Rotary && nc_hi - nc_lo > MAX_ROTARY_TRAVEL {
            c.error(
                l.span(),
                format!(
                    "rotary limits span {}°, more than {} turns; leave `limits` out for an axis that turns without end",
                    short(nc_hi - nc_lo, 3),
                    MAX_ROTARY_TRAVEL / 360.0
                ),
            );
        } else {
            limits_ok = true;
        }
        [nc_lo, nc_hi]
    });
    (limits, limits_ok)
}

/// The value a locked (`fixed`) axis keeps: finite, within
/// ±[`MAX_COORDINATE_MM`], and within the axis's usable limits (NC values)
/// if it has them.
fn check_fixed(
    c: &mut Checker,
    fixed: Option<&Spanned<f64>>,
    usable_limits: Option<[f64; 2]>,
) -> Option<f64> {
    fixed.map(|f| {
        let v = *f.get_ref();
        if !v.is_finite() {
            c.error(f.span(), "fixed value must be a finite number");
        } else if v.abs() > MAX_COORDINATE_MM {
            c.error(
                f.span(),
                format!("fixed value must lie within ±{MAX_COORDINATE_MM:e}"),
            );
        } else if let Some([lo, hi]) = usable_limits
            && (v < lo || v > hi)
        {
            c.error(
                f.span(),
                format!("fixed value {v} is outside the limits [{lo}, {hi}] (NC values)"),
            );
        }
        v
    })
}

/// The optional settings of an axis, set on `axis`: `wrap` and `prefer`
/// (rotary axes only), `max_velocity` (above zero), and
/// `free_with_reference` (a locked rotary axis only).
fn check_axis_options(c: &mut Checker, a: &RawAxis, axis: &mut Axis) {
    let kind = axis.kind;
    if let Some(w) = &a.wrap {
        if kind != AxisKind::Rotary {
            c.error(w.span(), "`wrap` applies to rotary axes only");
        }
        axis.wrap = match w.get_ref() {
            RawWrap::None => Wrap::None,
            RawWrap::Modulo => Wrap::Modulo,
            RawWrap::Unwind => Wrap::Unwind,
        };
    }
    if let Some(p) = &a.prefer {
        if kind != AxisKind::Rotary {
            c.error(p.span(), "`prefer` applies to rotary axes only");
        }
        axis.prefer = Some(match p.get_ref() {
            RawPrefer::Positive => Prefer::Positive,
            RawPrefer::Negative => Prefer::Negative,
            RawPrefer::Zero => Prefer::Zero,
        });
    }
    if let Some(v) = &a.max_velocity {
        let value = *v.get_ref();
        if !(value.is_finite() && value > 0.0) {
            c.error(
                v.span(),
                "max_velocity must be a speed greater than zero (mm/min or degrees/min)",
            );
        }
        axis.max_velocity = Some(value);
    }
    if let Some(f) = &a.free_with_reference {
        axis.free_with_reference = *f.get_ref();
        if axis.free_with_reference && (axis.fixed.is_none() || !axis.is_rotary()) {
            c.error(
                f.span(),
                "`free_with_reference` applies to a rotary axis locked with `fixed` \
                 (the value it keeps for CL points without a reference direction)",
            );
        }
    }
}

fn check_axis_counts(c: &mut Checker, raw: &[RawAxis], axes: &[Axis], direction_ok: &[bool]) {
    for (kind, word) in [(AxisKind::Linear, "linear"), (AxisKind::Rotary, "rotary")] {
        let free: Vec<usize> = (0..axes.len())
            .filter(|&i| axes[i].kind == kind && axes[i].is_free())
            .collect();
        if free.len() > 3 {
            c.error(
                raw[free[3]].name.span(),
                format!("more than 3 free {word} axes; lock the extra ones with `fixed = value`"),
            );
        }
    }
    // Directions already reported as unusable are left out of the geometry
    // checks below, which would only repeat that mistake.
    if direction_ok.iter().any(|ok| !ok) {
        return;
    }
    // Free linear axes must span their space at home: report the first one
    // whose direction the earlier ones already give.
    let lin: Vec<usize> = (0..axes.len())
        .filter(|&i| !axes[i].is_rotary() && axes[i].is_free())
        .collect();
    let independent = "the free linear axes must move in three independent directions";
    for k in 1..lin.len().min(3) {
        let (i, d) = (lin[k], axes[lin[k]].direction);
        let message = if let Some(&j) = lin[..k]
            .iter()
            .find(|&&j| axes[j].direction.cross(&d).norm() <= 1e-6)
        {
            format!(
                "linear axis `{}` is parallel to linear axis `{}`: {independent}",
                axes[i].name, axes[j].name
            )
        } else if k == 2
            && Matrix3::from_columns(&[axes[lin[0]].direction, axes[lin[1]].direction, d])
                .determinant()
                .abs()
                <= 1e-6
        {
            format!(
                "linear axis `{}` lies in the plane of linear axes `{}` and `{}`: {independent}",
                axes[i].name, axes[lin[0]].name, axes[lin[1]].name
            )
        } else {
            continue;
        };
        c.error(raw[i].direction.span(), message);
        break;
    }
    let rot: Vec<usize> = (0..axes.len())
        .filter(|&i| axes[i].is_rotary() && axes[i].is_free())
        .collect();
    for w in rot.windows(2) {
        if axes[w[0]].direction.cross(&axes[w[1]].direction).norm() < 1e-6 {
            c.error(
                raw[w[1]].direction.span(),
                format!(
                    "free rotary axes `{}` and `{}` are parallel: together they turn about one direction only and cannot orient the tool",
                    axes[w[0]].name, axes[w[1]].name
                ),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const GOOD: &str = r#"
name = "t"
[[axis]]
name = "X"
kind = "linear"
side = "workpiece"
direction = [1, 0, 0]
[[axis]]
name = "Y"
kind = "linear"
side = "tool"
direction = [0, 1, 0]
[[axis]]
name = "Z"
kind = "linear"
side = "tool"
direction = [0, 0, 1]
[[axis]]
name = "B"
kind = "rotary"
side = "tool"
direction = [0, 1, 0]
point = [0, 0, 0]
limits = [-90, 90]
[[axis]]
name = "C"
kind = "rotary"
side = "workpiece"
direction = [0, 0, 1]
point = [0, 0, 0]
[tool]
point = [0, 0, 0]
axis = [0, 0, 1]
"#;

    fn err(src: &str) -> String {
        machine_from_toml(src, "m.toml").unwrap_err().to_string()
    }

    #[test]
    fn good_file_loads() {
        let m = machine_from_toml(GOOD, "m.toml").unwrap();
        assert_eq!(m.axes.len(), 5);
        assert_eq!(m.free_rotary_count(), 2);
    }

    #[test]
    fn unknown_key_names_line_and_column() {
        let src = GOOD.replace(
            "kind = \"linear\"\nside = \"tool\"\ndirection = [0, 1, 0]",
            "kind = \"linear\"\nside = \"tool\"\ndirection = [0, 1, 0]\nspeed = 3",
        );
        let e = err(&src);
        assert!(e.contains("unknown key `speed`"), "{e}");
        assert!(e.contains("m.toml:13:1"), "{e}");
    }

    #[test]
    fn zero_and_non_unit_directions() {
        let e = err(&GOOD.replace("direction = [1, 0, 0]", "direction = [0, 0, 0]"));
        assert!(
            e.contains("axis direction must be a non-zero unit vector"),
            "{e}"
        );
        assert!(e.contains("m.toml:7:13"), "{e}");
        let e = err(&GOOD.replace("direction = [1, 0, 0]", "direction = [1, 1, 0]"));
        assert!(e.contains("not a unit vector (length 1.414213562)"), "{e}");
    }

    /// Limits so large that a tolerance would become infinite, and a file
    /// of many axis tables: errors, the latter at its first table past the
    /// limit.
    #[test]
    fn huge_limits_and_many_axis_tables_are_errors() {
        let src = crate::builtin::source("trunnion-ac").unwrap();
        let huge = src.replacen("limits = [", "limits = [-1e154, 1e154] # was [", 1);
        let e = machine_from_toml(&huge, "m.toml").unwrap_err().to_string();
        assert!(e.contains("limits must lie within"), "{e}");
        let mut many = String::from("name = \"m\"\n");
        for i in 0..50_000 {
            many.push_str(&format!(
                "[[axis]]\nname = \"X{i}\"\nkind = \"linear\"\nside = \"tool\"\ndirection = [1, 0, 0]\n"
            ));
        }
        let e = machine_from_toml(&many, "m.toml").unwrap_err();
        assert_eq!(e.0.len(), 1, "{e}");
        assert!(e.0[0].message.contains("bytes"), "{e}");
        let few = many[..many.find("[[axis]]\nname = \"X300\"").unwrap()].to_string();
        let e = machine_from_toml(&few, "m.toml").unwrap_err();
        assert_eq!(e.0.len(), 1, "{e}");
        assert_eq!(e.0[0].line, 5 * MAX_AXES + 3, "{e}");
        assert!(e.0[0].message.contains("at most 9 axes"), "{e}");
    }

    #[test]
    fn rotary_without_point_reversed_limits_duplicates() {
        let src = GOOD
            .replace(
                "point = [0, 0, 0]\nlimits = [-90, 90]",
                "limits = [90, -90]",
            )
            .replace("name = \"Z\"", "name = \"x\"");
        let e = err(&src);
        assert!(e.contains("rotary axis `B` needs a `point`"), "{e}");
        assert!(e.contains("limits are reversed"), "{e}");
        assert!(e.contains("duplicate axis name `x`"), "{e}");
    }

    #[test]
    fn too_many_free_axes() {
        let extra = "[[axis]]\nname = \"W\"\nkind = \"linear\"\nside = \"tool\"\ndirection = [1, 0, 0]\n[tool]";
        let e = err(&GOOD.replace("[tool]", extra));
        assert!(e.contains("more than 3 free linear axes"), "{e}");
        let fixed = "[[axis]]\nname = \"W\"\nkind = \"linear\"\nside = \"tool\"\ndirection = [1, 0, 0]\nfixed = 0\n[tool]";
        assert!(machine_from_toml(&GOOD.replace("[tool]", fixed), "m").is_ok());
    }

    #[test]
    fn three_free_rotaries_need_reference() {
        let extra = "[[axis]]\nname = \"A\"\nkind = \"rotary\"\nside = \"tool\"\ndirection = [1, 0, 0]\npoint = [0, 0, 0]\n[tool]";
        let e = err(&GOOD.replace("[tool]", extra));
        assert!(
            e.contains("three free rotary axes need a tool `reference`"),
            "{e}"
        );
    }

    const PRESSURE: &str = "[pressure]\nname = \"H1\"\nreference = 3475\nplane = [\"Y\", \"z\"]\n";

    #[test]
    fn pressure_section_loads() {
        let m = machine_from_toml(GOOD, "m.toml").unwrap();
        assert!(m.pressure.is_none());
        let src =
            format!("{GOOD}{PRESSURE}link_length = 250\nalpha_deg = [[3000, -6.73], [3600, 5]]\n");
        let p = machine_from_toml(&src, "m.toml").unwrap().pressure.unwrap();
        assert_eq!(
            (p.name.as_str(), p.reference, p.plane),
            ("H1", 3475.0, [1, 2])
        );
        assert_eq!(p.directions, [Vector3::y(), Vector3::z()]);
        assert_eq!(
            p.model,
            WheelModel::Linkage {
                link_length: 250.0,
                alpha_deg: vec![[3000.0, -6.73], [3600.0, 5.0]]
            }
        );
        // Measured offsets, the reference on the upper stop.
        let src = format!("{GOOD}{PRESSURE}offsets = [[3000, -1.12, -51.075], [3600, 0, 0]]\n")
            .replace("3475", "3600");
        let p = machine_from_toml(&src, "m.toml").unwrap().pressure.unwrap();
        assert_eq!(p.plane_offset(4000.0), [0.0, 0.0]);
        assert_eq!(p.plane_offset(3000.0), [-1.12, -51.075]);
        // A reference beyond the calibration is ambiguous: an error.
        let e = err(&src.replace("= 3600", "= 4000"));
        assert!(
            e.contains("reference 4000 is outside the calibration (3000 .. 3600)"),
            "{e}"
        );
    }

    #[test]
    fn pressure_mistakes() {
        let linkage = "link_length = 250\nalpha_deg = [[3000, -6.73], [3600, 5]]\n";
        let e = err(&format!("{GOOD}{PRESSURE}"));
        assert!(e.contains("[pressure] needs `link_length`"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("\"z\"]", "\"Q\"]"));
        assert!(e.contains("the machine has no axis `Q`"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("[\"Y\", \"z\"]", "[\"Y\"]"));
        assert!(e.contains("found 1 names"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("\"z\"]", "\"y\"]"));
        assert!(e.contains("plane names the same axis twice"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("250", "-1"));
        assert!(e.contains("link_length must be a positive"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("\"H1\"", "\"1H\""));
        assert!(e.contains("pressure name must be a letter"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("5]]", "500]]"));
        assert!(e.contains("within ±180°"), "{e}");
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}").replace("3600", "3000"));
        assert!(
            e.contains("sorted by pressure without repeats: 3000 follows 3000"),
            "{e}"
        );
        let e = err(&format!("{GOOD}{PRESSURE}{linkage}speed = 1\n"));
        assert!(e.contains("unknown key `speed`"), "{e}");
    }

    #[test]
    fn syntax_error_is_located() {
        let e = err("name = \"t\"\n[tool\n");
        assert!(e.contains("m.toml:2:"), "{e}");
    }
}
