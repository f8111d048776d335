//! `[[solid]]` and `[collision]`: the solids of the virtual machine and the
//! settings of its collision check (see [`crate::solid`]).

use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use toml::Spanned;

use super::{Checker, MAX_COORDINATE_MM, Nums, UNIT_TOLERANCE, short};
use crate::model::Axis;
use crate::solid::{Body, CollisionSettings, Mesh, PairClearance, Role, Shape, Solid};

/// Where the `mesh` files of a machine file are read from.
#[derive(Debug, Clone, Copy)]
pub enum MeshFiles<'a> {
    /// A folder: `mesh` paths are relative to it (the machine file's own
    /// folder), absolute paths are read as they are.
    Folder(&'a Path),
    /// Files embedded in the program (built-in machines): `mesh` is one of
    /// these names.
    Embedded(&'a [(&'a str, &'a [u8])]),
}

/// Largest STL file read for a solid or a part, bytes (a 100,000-triangle
/// binary STL is 5 MB; 2 GiB keeps a wrong path to a disk image from
/// exhausting memory).
pub const MAX_MESH_BYTES: u64 = 2 << 30;

#[derive(Deserialize)]
pub(super) struct RawSolid {
    name: Spanned<String>,
    on: Spanned<String>,
    mesh: Option<Spanned<String>>,
    #[serde(rename = "box")]
    cuboid: Option<Spanned<RawBox>>,
    cylinder: Option<Spanned<RawCylinder>>,
    cone: Option<Spanned<RawCone>>,
    sphere: Option<Spanned<RawSphere>>,
    origin: Option<Spanned<Nums<3>>>,
    x: Option<Spanned<Nums<3>>>,
    z: Option<Spanned<Nums<3>>>,
    group: Option<Spanned<String>>,
    role: Option<Spanned<RawRole>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
pub(super) enum RawRole {
    Machine,
    Cutter,
    Stock,
}

#[derive(Deserialize)]
pub(super) struct RawBox {
    size: Spanned<Nums<3>>,
}

#[derive(Deserialize)]
pub(super) struct RawCylinder {
    radius: Spanned<f64>,
    height: Spanned<f64>,
}

#[derive(Deserialize)]
pub(super) struct RawCone {
    radius_bottom: Spanned<f64>,
    radius_top: Spanned<f64>,
    height: Spanned<f64>,
}

#[derive(Deserialize)]
pub(super) struct RawSphere {
    radius: Spanned<f64>,
}

/// A list of name pairs (`ignore`, `check`).
type NamePairs = Spanned<Vec<Spanned<Vec<Spanned<String>>>>>;

#[derive(Deserialize, Default)]
pub(super) struct RawCollision {
    warning_clearance: Option<Spanned<f64>>,
    error_clearance: Option<Spanned<f64>>,
    ignore: Option<NamePairs>,
    check: Option<NamePairs>,
    #[serde(default)]
    pair: Vec<RawPair>,
}

#[derive(Deserialize)]
pub(super) struct RawPair {
    groups: Spanned<Vec<Spanned<String>>>,
    warning_clearance: Spanned<f64>,
    error_clearance: Spanned<f64>,
}

/// The unknown keys and words of `[[solid]]` and `[collision]`.
pub(super) fn unknown_names(
    doc: &toml::de::DeTable,
    unknown: &mut kinpost_diag::toml_names::Unknown,
) {
    use kinpost_diag::toml_names::{names, table};
    use toml::de::DeValue;
    fn tables<'a, 'i>(v: Option<&'a toml::Spanned<DeValue<'i>>>) -> Vec<&'a toml::de::DeTable<'i>> {
        match v.map(|v| v.get_ref()) {
            Some(DeValue::Array(items)) => items
                .iter()
                .filter_map(|i| match i.get_ref() {
                    DeValue::Table(t) => Some(t),
                    _ => None,
                })
                .collect(),
            _ => Vec::new(),
        }
    }
    for solid in tables(doc.get("solid")) {
        unknown.check(solid, names::<RawSolid>(), &[("role", names::<RawRole>())]);
        for (key, fields) in [
            ("box", names::<RawBox>()),
            ("cylinder", names::<RawCylinder>()),
            ("cone", names::<RawCone>()),
            ("sphere", names::<RawSphere>()),
        ] {
            if let Some(t) = table(solid, key) {
                unknown.check(t, fields, &[]);
            }
        }
    }
    if let Some(c) = table(doc, "collision") {
        unknown.check(c, names::<RawCollision>(), &[]);
        for pair in tables(c.get("pair")) {
            unknown.check(pair, names::<RawPair>(), &[]);
        }
    }
}

/// A positive finite length, or an error at its span.
fn length(c: &mut Checker, v: &Spanned<f64>, what: &str, zero_ok: bool) -> f64 {
    let x = *v.get_ref();
    let ok = x.is_finite() && x <= MAX_COORDINATE_MM && (x > 0.0 || (zero_ok && x == 0.0));
    if !ok {
        let at_least = if zero_ok {
            "zero or more"
        } else {
            "greater than zero"
        };
        c.error(
            v.span(),
            format!("{what} must be a length {at_least} (mm, at most {MAX_COORDINATE_MM:e})"),
        );
    }
    x
}

/// The shape of a solid: exactly one of `mesh`, `box`, `cylinder`, `cone`,
/// `sphere`.
fn shape(c: &mut Checker, s: &RawSolid, meshes: MeshFiles) -> Option<Shape> {
    let mut given: Vec<(&str, Range<usize>)> = [
        ("mesh", s.mesh.as_ref().map(|v| v.span())),
        ("box", s.cuboid.as_ref().map(|v| v.span())),
        ("cylinder", s.cylinder.as_ref().map(|v| v.span())),
        ("cone", s.cone.as_ref().map(|v| v.span())),
        ("sphere", s.sphere.as_ref().map(|v| v.span())),
    ]
    .into_iter()
    .filter_map(|(k, span)| span.map(|span| (k, span)))
    .collect();
    given.sort_by_key(|(_, span)| span.start);
    match given.as_slice() {
        [] => {
            c.error(
                s.name.span(),
                format!(
                    "solid `{}` has no shape: give one of `mesh = \"file.stl\"`, `box = {{ size = [x, y, z] }}`, \
                     `cylinder = {{ radius, height }}`, `cone = {{ radius_bottom, radius_top, height }}`, `sphere = {{ radius }}`",
                    s.name.get_ref()
                ),
            );
            return None;
        }
        [_] => {}
        [(first, _), rest @ ..] => {
            for (k, span) in rest {
                c.error(
                    span.clone(),
                    format!("a solid has one shape: `{k}` and `{first}` are both given"),
                );
            }
            return None;
        }
    }
    if let Some(b) = &s.cuboid {
        let size = b.get_ref().size.get_ref().0;
        let ok = size
            .iter()
            .all(|x| x.is_finite() && *x > 0.0 && *x <= MAX_COORDINATE_MM);
        if !ok {
            c.error(
                b.get_ref().size.span(),
                "box size must be three lengths greater than zero (mm)",
            );
        }
        return Some(Shape::Box { size_mm: size });
    }
    if let Some(cy) = &s.cylinder {
        let cy = cy.get_ref();
        return Some(Shape::Cylinder {
            radius_mm: length(c, &cy.radius, "cylinder radius", false),
            height_mm: length(c, &cy.height, "cylinder height", false),
        });
    }
    if let Some(co) = &s.cone {
        let co = co.get_ref();
        let bottom = length(c, &co.radius_bottom, "cone radius_bottom", true);
        let top = length(c, &co.radius_top, "cone radius_top", true);
        if bottom == 0.0 && top == 0.0 {
            c.error(
                co.radius_top.span(),
                "a cone needs a radius greater than zero at one end at least",
            );
        }
        return Some(Shape::Cone {
            radius_bottom_mm: bottom,
            radius_top_mm: top,
            height_mm: length(c, &co.height, "cone height", false),
        });
    }
    if let Some(sp) = &s.sphere {
        return Some(Shape::Sphere {
            radius_mm: length(c, &sp.get_ref().radius, "sphere radius", false),
        });
    }
    let m = s.mesh.as_ref()?;
    match read_mesh(m.get_ref(), meshes) {
        Ok(mesh) => Some(Shape::Mesh(Arc::new(mesh))),
        Err(message) => {
            c.error(m.span(), message);
            None
        }
    }
}

/// Reads the mesh a `mesh` key names, or says why it cannot.
fn read_mesh(name: &str, meshes: MeshFiles) -> Result<Mesh, String> {
    let bytes = match meshes {
        MeshFiles::Embedded(files) => files
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, b)| b.to_vec())
            .ok_or_else(|| {
                format!("no mesh file `{name}` among the files built in with this machine")
            })?,
        MeshFiles::Folder(folder) => {
            let path: PathBuf = folder.join(name);
            let cannot = |e: std::io::Error| {
                format!(
                    "cannot read mesh file `{name}` ({}): {e} (a `mesh` path is relative to the machine file's folder)",
                    path.display()
                )
            };
            let meta = std::fs::metadata(&path).map_err(cannot)?;
            if meta.is_dir() {
                return Err(format!(
                    "mesh file `{name}` ({}) is a folder",
                    path.display()
                ));
            }
            if meta.len() > MAX_MESH_BYTES {
                return Err(format!(
                    "mesh file `{name}` has {} bytes, more than the {MAX_MESH_BYTES} read for a mesh",
                    meta.len()
                ));
            }
            std::fs::read(&path).map_err(cannot)?
        }
    };
    mesh_from_stl(&bytes, name).map_err(|e| format!("mesh file `{name}`: {e}"))
}

/// Why an STL file cannot be a mesh.
#[derive(Debug, Clone, PartialEq)]
pub enum StlError {
    /// The STL reader refuses it (its message).
    Unreadable(String),
    /// No triangle.
    NoTriangle,
    /// A vertex not finite or too far out.
    Vertex([f64; 3]),
    /// More vertices than a `u32` counts.
    TooManyVertices,
}

impl std::fmt::Display for StlError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            StlError::Unreadable(e) => write!(f, "not a readable STL file ({e})"),
            StlError::NoTriangle => f.write_str("the STL file has no triangle"),
            StlError::Vertex(v) => write!(
                f,
                "a vertex ({}, {}, {}) is not finite or farther than {MAX_COORDINATE_MM:e} mm out",
                v[0], v[1], v[2]
            ),
            StlError::TooManyVertices => f.write_str("more vertices than 2^32"),
        }
    }
}

impl std::error::Error for StlError {}

/// A mesh from the bytes of an STL file (binary or ASCII), mm. `source`
/// names it in messages. Its vertices must be finite and within
/// 1e6 mm of the origin, and it must have a triangle.
pub fn mesh_from_stl(bytes: &[u8], source: &str) -> Result<Mesh, StlError> {
    let read = stl_io::read_stl(&mut std::io::Cursor::new(bytes))
        .map_err(|e| StlError::Unreadable(e.to_string()))?;
    if read.faces.is_empty() {
        return Err(StlError::NoTriangle);
    }
    let vertices: Vec<[f64; 3]> = read
        .vertices
        .iter()
        .map(|v| [f64::from(v[0]), f64::from(v[1]), f64::from(v[2])])
        .collect();
    if let Some(v) = vertices.iter().find(|v| {
        v.iter()
            .any(|x| !x.is_finite() || x.abs() > MAX_COORDINATE_MM)
    }) {
        return Err(StlError::Vertex(*v));
    }
    let Ok(count) = u32::try_from(vertices.len()) else {
        return Err(StlError::TooManyVertices);
    };
    let triangles = read
        .faces
        .iter()
        .map(|f| f.vertices.map(|i| i as u32))
        .collect();
    debug_assert!(count as usize == vertices.len());
    Ok(Mesh {
        source: source.to_string(),
        vertices,
        triangles,
    })
}

/// The pose of a solid's frame at home from `origin`, `x` and `z`.
fn home_pose(c: &mut Checker, s: &RawSolid) -> Isometry3<f64> {
    let origin = s
        .origin
        .as_ref()
        .map_or_else(Vector3::zeros, |o| c.point(o, "solid origin"));
    let x =
        s.x.as_ref()
            .map_or(Some(Vector3::x()), |x| c.unit(x, "solid x"));
    let z =
        s.z.as_ref()
            .map_or(Some(Vector3::z()), |z| c.unit(z, "solid z"));
    let (Some(x), Some(z)) = (x, z) else {
        return Isometry3::translation(origin.x, origin.y, origin.z);
    };
    if x.dot(&z).abs() > UNIT_TOLERANCE {
        let (span, hint) = match (&s.x, &s.z) {
            (_, Some(zs)) if s.x.is_none() => {
                (zs.span(), " (give `x` too: it is [1, 0, 0] unless given)")
            }
            (Some(xs), None) => (xs.span(), " (give `z` too: it is [0, 0, 1] unless given)"),
            (_, Some(zs)) => (zs.span(), ""),
            (_, None) => (s.name.span(), ""),
        };
        c.error(
            span,
            format!(
                "solid x and z must be perpendicular (they are {}° apart){hint}",
                short(x.angle(&z).to_degrees(), 3)
            ),
        );
        return Isometry3::translation(origin.x, origin.y, origin.z);
    }
    // Orthonormal columns: x, z × x, z (x made exactly perpendicular).
    let x = (x - z * z.dot(&x)).normalize();
    let rotation = Matrix3::from_columns(&[x, z.cross(&x), z]);
    Isometry3::from_parts(
        Translation3::from(origin),
        UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(rotation)),
    )
}

/// The body an `on` value names.
fn body(c: &mut Checker, on: &Spanned<String>, axes: &[Axis]) -> Body {
    let word = on.get_ref().trim();
    match word {
        "base" => Body::Base,
        "tool" => Body::Tool,
        "workpiece" => Body::Workpiece,
        _ => match axes.iter().position(|a| a.name.eq_ignore_ascii_case(word)) {
            Some(i) => Body::Axis(i),
            None => {
                let names: Vec<&str> = axes.iter().map(|a| a.name.as_str()).collect();
                c.error(
                    on.span(),
                    format!(
                        "unknown `on` value `{word}`: a solid is on \"base\", \"tool\", \"workpiece\" or an axis ({})",
                        names.join(", ")
                    ),
                );
                Body::Base
            }
        },
    }
}

/// Checks the `[[solid]]` tables.
///
/// Also returns the name and group of every solid the file declares (those
/// whose shape is wrong too), for the names of `[collision]`.
pub(super) fn check_solids(
    c: &mut Checker,
    raw: &[RawSolid],
    axes: &[Axis],
    meshes: MeshFiles,
) -> (Vec<Solid>, Vec<(String, String)>) {
    let mut declared = Vec::with_capacity(raw.len());
    let mut solids = Vec::with_capacity(raw.len());
    for (k, s) in raw.iter().enumerate() {
        let name = s.name.get_ref().trim().to_string();
        if name.is_empty() {
            c.error(s.name.span(), "solid name must not be empty");
        } else if let Some(first) = raw[..k].iter().find(|o| o.name.get_ref().trim() == name) {
            let line = c.line_of(first.name.span().start);
            c.error(
                s.name.span(),
                format!(
                    "duplicate solid name `{name}`: the solid on line {line} has the same name"
                ),
            );
        }
        let on = body(c, &s.on, axes);
        let shape = shape(c, s, meshes);
        let home = home_pose(c, s);
        let group = match &s.group {
            Some(g) if g.get_ref().trim().is_empty() => {
                c.error(g.span(), "group name must not be empty");
                name.clone()
            }
            Some(g) => g.get_ref().trim().to_string(),
            None => name.clone(),
        };
        let role = match s.role.as_ref().map(|r| *r.get_ref()) {
            None | Some(RawRole::Machine) => Role::Machine,
            Some(RawRole::Cutter) => Role::Cutter,
            Some(RawRole::Stock) => Role::Stock,
        };
        declared.push((name.clone(), group.clone()));
        if let Some(shape) = shape {
            solids.push(Solid {
                name,
                on,
                shape,
                home,
                group,
                role,
            });
        }
    }
    // A group may share a name with a solid only if that solid is in it:
    // `ignore` and `check` entries name either.
    for (k, (_, group)) in declared.iter().enumerate() {
        if let Some((name, other)) = declared.iter().find(|(n, g)| n == group && g != group) {
            c.error(
                raw[k].group.as_ref().map_or(raw[k].name.span(), |g| g.span()),
                format!(
                    "group `{group}` has the name of solid `{name}`, which is in group `{other}`: names in `ignore` and `check` would be ambiguous"
                ),
            );
        }
    }
    (solids, declared)
}

/// A clearance: a finite distance of zero or more, mm.
fn clearance(c: &mut Checker, v: &Spanned<f64>, what: &str) -> f64 {
    let x = *v.get_ref();
    if !(x.is_finite() && (0.0..=MAX_COORDINATE_MM).contains(&x)) {
        c.error(
            v.span(),
            format!("{what} must be a distance of zero or more (mm)"),
        );
        return 0.0;
    }
    x
}

/// Checks that an error clearance is not larger than its warning one.
fn ordered(c: &mut Checker, warning: f64, error: f64, span: Range<usize>) {
    if error > warning {
        c.error(
            span,
            format!(
                "error_clearance {} is larger than warning_clearance {}: a near miss is farther than a collision",
                short(error, 6),
                short(warning, 6)
            ),
        );
    }
}

/// Name pairs of `ignore` or `check`: two names each, each a solid or a
/// group.
fn name_pairs(
    c: &mut Checker,
    list: &Option<NamePairs>,
    key: &str,
    declared: &[(String, String)],
) -> Vec<[String; 2]> {
    let Some(list) = list else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for pair in list.get_ref() {
        let names = pair.get_ref();
        if names.len() != 2 {
            c.error(
                pair.span(),
                format!("an entry of `{key}` names two solids or groups, e.g. [\"wheel\", \"fixture\"]; found {} names", names.len()),
            );
            continue;
        }
        let mut ok = true;
        for n in names {
            let w = n.get_ref().trim();
            if !declared.iter().any(|(n, g)| n == w || g == w) {
                c.error(
                    n.span(),
                    format!(
                        "`{key}` names `{w}`, which is neither a solid nor a group of this machine"
                    ),
                );
                ok = false;
            }
        }
        if ok {
            out.push([
                names[0].get_ref().trim().to_string(),
                names[1].get_ref().trim().to_string(),
            ]);
        }
    }
    out
}

/// Checks `[collision]` against the solids.
pub(super) fn check_collision(
    c: &mut Checker,
    raw: &RawCollision,
    declared: &[(String, String)],
) -> CollisionSettings {
    let mut settings = CollisionSettings::default();
    if let Some(w) = &raw.warning_clearance {
        settings.warning_clearance_mm = clearance(c, w, "warning_clearance");
    }
    if let Some(e) = &raw.error_clearance {
        settings.error_clearance_mm = clearance(c, e, "error_clearance");
    }
    let span = raw
        .error_clearance
        .as_ref()
        .or(raw.warning_clearance.as_ref())
        .map_or(0..0, |s| s.span());
    ordered(
        c,
        settings.warning_clearance_mm,
        settings.error_clearance_mm,
        span,
    );
    for p in &raw.pair {
        let warning = clearance(c, &p.warning_clearance, "warning_clearance");
        let error = clearance(c, &p.error_clearance, "error_clearance");
        ordered(c, warning, error, p.error_clearance.span());
        let names = p.groups.get_ref();
        if names.len() != 2 {
            c.error(
                p.groups.span(),
                format!("`groups` names two collision groups, e.g. [\"head\", \"table\"]; found {} names", names.len()),
            );
            continue;
        }
        let mut ok = true;
        for n in names {
            let w = n.get_ref().trim();
            if !declared.iter().any(|(_, g)| g == w) {
                c.error(n.span(), format!("no solid is in group `{w}`"));
                ok = false;
            }
        }
        let groups = [
            names[0].get_ref().trim().to_string(),
            names[1].get_ref().trim().to_string(),
        ];
        if let Some(before) = settings.pairs.iter().find(|q| {
            (q.groups[0] == groups[0] && q.groups[1] == groups[1])
                || (q.groups[0] == groups[1] && q.groups[1] == groups[0])
        }) {
            c.error(
                p.groups.span(),
                format!(
                    "the groups `{}` and `{}` already have their clearances",
                    before.groups[0], before.groups[1]
                ),
            );
            ok = false;
        }
        if ok {
            settings.pairs.push(PairClearance {
                groups,
                warning_clearance_mm: warning,
                error_clearance_mm: error,
            });
        }
    }
    settings.ignore = name_pairs(c, &raw.ignore, "ignore", declared);
    settings.check = name_pairs(c, &raw.check, "check", declared);
    settings
}

#[cfg(test)]
mod tests {
    use super::super::machine_from_toml;
    use crate::solid::{Body, Role, Shape};

    /// A mill: X Y Z on the head, B on the head, C table.
    const MILL: &str = r#"
name = "t"
[[axis]]
name = "X"
kind = "linear"
side = "tool"
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

    const SOLIDS: &str = r#"
[[solid]]
name = "table"
on = "c"
cylinder = { radius = 200, height = 50 }
origin = [0, 0, -50]
group = "table"
[[solid]]
name = "cutter"
on = "tool"
cone = { radius_bottom = 5, radius_top = 5, height = 30 }
role = "cutter"
[[solid]]
name = "holder"
on = "tool"
box = { size = [60, 60, 80] }
origin = [0, 0, 30]
z = [0, 0, 1]
x = [0, 1, 0]
group = "head"
[[solid]]
name = "bed"
on = "base"
sphere = { radius = 10 }
origin = [0, 0, -500]
[collision]
warning_clearance = 5
error_clearance = 1
ignore = [["bed", "head"]]
[[collision.pair]]
groups = ["head", "table"]
warning_clearance = 20
error_clearance = 2
"#;

    fn err(src: &str) -> String {
        machine_from_toml(src, "m.toml").unwrap_err().to_string()
    }

    #[test]
    fn solids_and_collision_settings_load() {
        let m = machine_from_toml(&format!("{MILL}{SOLIDS}"), "m.toml").unwrap();
        assert_eq!(m.solids.len(), 4);
        let table = &m.solids[0];
        assert_eq!((table.on, table.group.as_str()), (Body::Axis(4), "table"));
        assert_eq!(
            table.home.translation.vector,
            nalgebra::Vector3::new(0.0, 0.0, -50.0)
        );
        assert_eq!(m.solids[1].role, Role::Cutter);
        assert_eq!(m.solids[1].group, "cutter");
        assert!(matches!(
            m.solids[2].shape,
            Shape::Box {
                size_mm: [60.0, 60.0, 80.0]
            }
        ));
        // The holder's x is machine y: its frame is turned 90° about z.
        let x = m.solids[2].home.rotation * nalgebra::Vector3::x();
        assert!((x - nalgebra::Vector3::y()).norm() < 1e-12);
        assert_eq!(m.solids[3].on, Body::Base);
        assert_eq!(m.collision.clearances("table", "head"), (20.0, 2.0));
        assert_eq!(m.collision.clearances("bed", "head"), (5.0, 1.0));
        assert_eq!(
            m.collision.ignore,
            vec![["bed".to_string(), "head".to_string()]]
        );
    }

    #[test]
    fn pair_rules() {
        let m = machine_from_toml(&format!("{MILL}{SOLIDS}"), "m.toml").unwrap();
        let s = &m.solids;
        // Tool (B) and table (C): different sides, not neighbours.
        assert!(m.checks_pair(&s[0], &s[2]));
        // Same body (both on the tool): never.
        assert!(!m.checks_pair(&s[1], &s[2]));
        // Base and C (the first workpiece axis): neighbours.
        assert!(!m.checks_pair(&s[3], &s[0]));
        // Base and the holder's group: ignored.
        assert!(!m.checks_pair(&s[3], &s[2]));
        // The base and the cutter: checked.
        assert!(m.checks_pair(&s[3], &s[1]));
        // `check` brings neighbours back.
        let src = format!("{MILL}{SOLIDS}")
            .replace("ignore =", "check = [[\"bed\", \"table\"]]\nignore =");
        let m = machine_from_toml(&src, "m.toml").unwrap();
        assert!(m.checks_pair(&m.solids[3], &m.solids[0]));
        assert!(m.neighbour_bodies(Body::Axis(2), Body::Axis(3)));
        assert!(!m.neighbour_bodies(Body::Axis(3), Body::Tool));
        assert!(m.neighbour_bodies(Body::Axis(2), Body::Tool));
        assert!(m.same_body(Body::Axis(3), Body::Tool));
        assert!(m.neighbour_bodies(Body::Base, Body::Axis(0)));
        assert!(!m.neighbour_bodies(Body::Base, Body::Axis(1)));
        assert_eq!(m.chain_of(Body::Tool), vec![0, 1, 2, 3]);
        assert_eq!(m.chain_of(Body::Workpiece), vec![4]);
    }

    #[test]
    fn every_mistake_is_located() {
        let all = format!("{MILL}{SOLIDS}");
        let cases: &[(&str, &str, &str)] = &[
            (
                "role = \"cutter\"",
                "role = \"cutter\"\ncolour = 3",
                "unknown key `colour`\u{0}m.toml:45:1",
            ),
            (
                "radius = 200,",
                "radius = 200, hight = 3,",
                "unknown key `hight`",
            ),
            (
                "on = \"c\"",
                "on = \"Q\"",
                "unknown `on` value `Q`\u{0}m.toml:36:6",
            ),
            (
                "cylinder = { radius = 200, height = 50 }",
                "mesh = \"nowhere.stl\"",
                "cannot read mesh file `nowhere.stl`\u{0}m.toml:37:8",
            ),
            (
                "z = [0, 0, 1]\nx",
                "z = [0, 0, 2]\nx",
                "solid z is not a unit vector\u{0}m.toml:50:5",
            ),
            (
                "x = [0, 1, 0]",
                "x = [0, 1, 1]",
                "solid x is not a unit vector",
            ),
            (
                "x = [0, 1, 0]",
                "x = [0, 0.6, 0.8]",
                "solid x and z must be perpendicular",
            ),
            (
                "error_clearance = 1",
                "error_clearance = -1",
                "error_clearance must be a distance of zero or more",
            ),
            (
                "warning_clearance = 5",
                "warning_clearance = 0.5",
                "error_clearance 1 is larger than warning_clearance 0.5",
            ),
            (
                "[\"bed\", \"head\"]",
                "[\"bed\", \"spindle\"]",
                "`ignore` names `spindle`, which is neither a solid nor a group\u{0}m.toml:61:19",
            ),
            (
                "[\"bed\", \"head\"]",
                "[\"bed\"]",
                "an entry of `ignore` names two solids or groups",
            ),
            (
                "groups = [\"head\", \"table\"]",
                "groups = [\"head\", \"tabel\"]",
                "no solid is in group `tabel`",
            ),
            (
                "name = \"bed\"",
                "name = \"holder\"",
                "duplicate solid name `holder`: the solid on line 46 has the same name",
            ),
            (
                "sphere = { radius = 10 }",
                "sphere = { radius = 0 }",
                "sphere radius must be a length greater than zero",
            ),
            (
                "sphere = { radius = 10 }",
                "sphere = { radius = 10 }\nbox = { size = [1, 1, 1] }",
                "a solid has one shape: `box` and `sphere` are both given",
            ),
            ("sphere = { radius = 10 }", "", "solid `bed` has no shape"),
            (
                "box = { size = [60, 60, 80] }",
                "box = { size = [60, 0, 80] }",
                "box size must be three lengths greater than zero",
            ),
            (
                "radius_bottom = 5, radius_top = 5",
                "radius_bottom = 0, radius_top = 0",
                "a cone needs a radius greater than zero",
            ),
            (
                "role = \"cutter\"",
                "role = \"knife\"",
                "unknown value `knife`",
            ),
            (
                "group = \"head\"",
                "group = \"table\"\n[[solid]]\nname = \"x\"\non = \"base\"\nsphere = { radius = 1 }\ngroup = \"holder\"",
                "group `holder` has the name of solid `holder`",
            ),
        ];
        for (from, to, want) in cases {
            assert!(all.contains(from), "{from}");
            let e = err(&all.replacen(from, to, 1));
            // `message\0file:line:column`: the message and where it points.
            for part in want.split('\0') {
                assert!(e.contains(part), "{from} -> {to}: want `{part}` in\n{e}");
            }
        }
    }

    #[test]
    fn mesh_files_are_read_relative_to_the_machine_file() {
        let dir = std::env::temp_dir().join(format!("kinpost-solids-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let stl = "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
        std::fs::write(dir.join("tri.stl"), stl).unwrap();
        std::fs::write(
            dir.join("bad.stl"),
            "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0\n",
        )
        .unwrap();
        let src = format!("{MILL}{SOLIDS}").replace(
            "cylinder = { radius = 200, height = 50 }",
            "mesh = \"tri.stl\"",
        );
        let path = dir.join("m.toml");
        let m = machine_from_toml(&src, path.to_str().unwrap()).unwrap();
        let Shape::Mesh(mesh) = &m.solids[0].shape else {
            panic!()
        };
        assert_eq!((mesh.vertices.len(), mesh.triangles.len()), (3, 1));
        let e = machine_from_toml(&src.replace("tri.stl", "bad.stl"), path.to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("mesh file `bad.stl`: not a readable STL file"),
            "{e}"
        );
        let e = machine_from_toml(&src.replace("tri.stl", "."), path.to_str().unwrap())
            .unwrap_err()
            .to_string();
        assert!(e.contains("is a folder"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
