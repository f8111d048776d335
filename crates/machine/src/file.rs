//! Reading and validating machine files (TOML, DESIGN.md §2).
//!
//! Every mistake is reported as a [`Diagnostic`] naming the file, line and
//! column, and all mistakes of a file are reported at once.

use std::ops::Range;

use kinpost_diag::{Diagnostic, Diagnostics, Severity};
use nalgebra::{Matrix3, Vector3};
use serde::Deserialize;
use toml::Spanned;

use crate::model::{Axis, AxisKind, MAX_AXES, Machine, PostSettings, Side, Tool};

/// How far from 1 the length of a direction may be (it is then normalised).
const UNIT_TOLERANCE: f64 = 1e-6;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMachine {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    post: RawPost,
    #[serde(default)]
    axis: Vec<RawAxis>,
    workpiece: Option<RawWorkpiece>,
    tool: Spanned<RawTool>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawPost {
    dialect: Option<String>,
    header: Option<String>,
    footer: Option<String>,
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
#[serde(deny_unknown_fields)]
struct RawAxis {
    name: Spanned<String>,
    kind: RawKind,
    side: RawSide,
    direction: Spanned<[f64; 3]>,
    point: Option<Spanned<[f64; 3]>>,
    limits: Option<Spanned<[f64; 2]>>,
    fixed: Option<Spanned<f64>>,
    /// Limits are machine coordinates: machine = NC + offset (DESIGN.md §2).
    machine_offset: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWorkpiece {
    origin: [f64; 3],
    x: Spanned<[f64; 3]>,
    z: Spanned<[f64; 3]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTool {
    point: [f64; 3],
    axis: Spanned<[f64; 3]>,
    reference: Option<Spanned<[f64; 3]>>,
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

    /// A unit vector, or an error at `v`'s span.
    fn unit(&mut self, v: &Spanned<[f64; 3]>, what: &str) -> Vector3<f64> {
        let raw = Vector3::from(*v.get_ref());
        let n = raw.norm();
        if !n.is_finite() || n < 1e-12 {
            self.error(v.span(), format!("{what} must be a non-zero unit vector"));
            return Vector3::z();
        }
        if (n - 1.0).abs() > UNIT_TOLERANCE {
            let u = raw / n;
            self.error(
                v.span(),
                format!(
                    "{what} is not a unit vector (length {n:.9}); did you mean [{:.9}, {:.9}, {:.9}]?",
                    u.x, u.y, u.z
                ),
            );
        }
        raw / n
    }
}

/// Reads a machine file. `file` is the name used in diagnostics.
pub fn machine_from_toml(source: &str, file: &str) -> Result<Machine, Diagnostics> {
    let raw: RawMachine = toml::from_str(source).map_err(|e| {
        let span = e.span().unwrap_or(0..0);
        Diagnostics::from(Diagnostic::at_byte_span(
            Severity::Error,
            file,
            source,
            span,
            e.message().trim_end().to_string(),
        ))
    })?;
    let mut c = Checker {
        file,
        source,
        errors: Vec::new(),
    };

    let name = raw.name.get_ref().trim().to_string();
    if name.is_empty() {
        c.error(raw.name.span(), "machine name must not be empty");
    }

    let mut axes = Vec::with_capacity(raw.axis.len());
    for a in &raw.axis {
        axes.push(check_axis(&mut c, a, &raw.axis));
    }
    if axes.len() > MAX_AXES {
        c.error(
            raw.axis[MAX_AXES].name.span(),
            format!("a machine has at most {MAX_AXES} axes"),
        );
    }
    check_axis_counts(&mut c, &raw.axis, &axes);

    let (workpiece_rotation, workpiece_origin) = match &raw.workpiece {
        None => (Matrix3::identity(), Vector3::zeros()),
        Some(w) => {
            let x = c.unit(&w.x, "workpiece x");
            let z = c.unit(&w.z, "workpiece z");
            if x.dot(&z).abs() > UNIT_TOLERANCE {
                c.error(w.z.span(), "workpiece x and z must be perpendicular");
            }
            let y = z.cross(&x);
            (Matrix3::from_columns(&[x, y, z]), Vector3::from(w.origin))
        }
    };

    let t = raw.tool.get_ref();
    let tool_axis = c.unit(&t.axis, "tool axis");
    let reference = t.reference.as_ref().map(|r| {
        let u = c.unit(r, "tool reference");
        if u.dot(&tool_axis).abs() > UNIT_TOLERANCE {
            c.error(
                r.span(),
                "tool reference must be perpendicular to the tool axis",
            );
        }
        u
    });
    let free_rotary = axes.iter().filter(|a| a.is_rotary() && a.is_free()).count();
    if free_rotary == 3 && reference.is_none() {
        c.error(
            raw.tool.span(),
            "three free rotary axes need a tool `reference` direction (or lock one with `fixed`)",
        );
    }

    if !c.errors.is_empty() {
        return Err(Diagnostics(c.errors));
    }
    Ok(Machine {
        name,
        description: raw.description,
        axes,
        workpiece_rotation,
        workpiece_origin,
        tool: Tool {
            point: Vector3::from(t.point),
            axis: tool_axis,
            reference,
        },
        post: PostSettings {
            dialect: raw.post.dialect,
            header: raw.post.header,
            footer: raw.post.footer,
        },
    })
}

fn check_axis(c: &mut Checker, a: &RawAxis, all: &[RawAxis]) -> Axis {
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
        c.error(a.name.span(), format!("duplicate axis name `{name}`"));
    }
    let direction = c.unit(&a.direction, "axis direction");
    let kind = match a.kind {
        RawKind::Linear => AxisKind::Linear,
        RawKind::Rotary => AxisKind::Rotary,
    };
    let point = match (kind, &a.point) {
        (AxisKind::Rotary, Some(p)) => Vector3::from(*p.get_ref()),
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
    };
    let offset = a.machine_offset.unwrap_or(0.0);
    let limits = a.limits.as_ref().map(|l| {
        let [lo, hi] = *l.get_ref();
        if !(lo.is_finite() && hi.is_finite()) {
            c.error(l.span(), "limits must be finite numbers");
        } else if lo > hi {
            c.error(
                l.span(),
                format!("limits are reversed: minimum {lo} is greater than maximum {hi}"),
            );
        }
        [lo - offset, hi - offset]
    });
    let fixed = a.fixed.as_ref().map(|f| {
        let v = *f.get_ref();
        if let Some([lo, hi]) = limits
            && (v < lo || v > hi)
        {
            c.error(
                f.span(),
                format!("fixed value {v} is outside the limits [{lo}, {hi}] (NC values)"),
            );
        }
        v
    });
    Axis {
        name,
        kind,
        side: match a.side {
            RawSide::Workpiece => Side::Workpiece,
            RawSide::Tool => Side::Tool,
        },
        direction,
        point,
        limits,
        fixed,
    }
}

fn check_axis_counts(c: &mut Checker, raw: &[RawAxis], axes: &[Axis]) {
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
    // Free linear axes must span their space at home (no two parallel).
    let lin: Vec<usize> = (0..axes.len())
        .filter(|&i| !axes[i].is_rotary() && axes[i].is_free())
        .collect();
    let dirs: Vec<Vector3<f64>> = lin.iter().map(|&i| axes[i].direction).collect();
    let independent = match dirs.len() {
        2 => dirs[0].cross(&dirs[1]).norm() > 1e-6,
        3 => Matrix3::from_columns(&dirs).determinant().abs() > 1e-6,
        _ => true,
    };
    if !independent && let Some(&last) = lin.last() {
        c.error(
            raw[last].direction.span(),
            "the free linear axes are not independent (two are parallel or all three coplanar)",
        );
    }
    let rot: Vec<usize> = (0..axes.len())
        .filter(|&i| axes[i].is_rotary() && axes[i].is_free())
        .collect();
    for w in rot.windows(2) {
        if axes[w[0]].direction.cross(&axes[w[1]].direction).norm() < 1e-6 {
            c.error(
                raw[w[1]].direction.span(),
                "two consecutive free rotary axes are parallel: they cannot orient the tool",
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
        assert!(e.contains("unknown field `speed`"), "{e}");
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

    #[test]
    fn syntax_error_is_located() {
        let e = err("name = \"t\"\n[tool\n");
        assert!(e.contains("m.toml:2:"), "{e}");
    }
}
