//! Machine solids as parry shapes, and poses across the boundary between
//! the workspace's nalgebra and parry's glam.

use std::collections::HashMap;
use std::f64::consts::PI;

use kinpost_machine::{Mesh, Shape};
use nalgebra::Isometry3;
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::shape::{
    Ball, Cone, ConvexPolyhedron, Cuboid, Cylinder, SharedShape, TriMesh, TriMeshFlags,
};

use crate::BuildError;

/// Sides of the polygon that stands in for the circles of a frustum (a cone
/// with two radii, which parry does not have): the polygon is drawn
/// *around* each circle (its edges touch it), so the shape contains the true
/// frustum and is at most `r·(1/cos(π/n) − 1)` = 0.21 % of the radius
/// larger (0.11 mm at r = 50 mm): a near miss may be reported that much
/// early, a collision is never missed.
pub const FRUSTUM_SIDES: usize = 48;

/// A nalgebra isometry as a parry pose.
pub fn to_pose(iso: &Isometry3<f64>) -> Pose {
    let t = iso.translation.vector;
    let q = iso.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w).normalize(),
    )
}

/// A parry vector as a nalgebra vector.
pub fn to_vector(v: Vector) -> nalgebra::Vector3<f64> {
    nalgebra::Vector3::new(v.x, v.y, v.z)
}

/// A solid's shape as parry builds it, with the pose of parry's shape in
/// the solid's own frame (parry's cylinders and cones are centred on their
/// origin along y; a machine file's stand on it along z).
pub(crate) struct Built {
    pub shape: SharedShape,
    pub offset: Pose,
    /// A closed, consistently oriented mesh: it has an inside, which
    /// point-containment tests find.
    pub closed: bool,
    /// A point of the solid, in parry's shape frame: a solid lies entirely
    /// inside another exactly when (their surfaces apart) this point does.
    pub inner_point: Vector,
}

/// Parry's y axis turned onto the solid's z, and lifted by `half` along it.
fn standing(half: f64) -> Pose {
    Pose::from_parts(
        Vector::new(0.0, 0.0, half),
        Rotation::from_rotation_x(PI / 2.0),
    )
}

/// Builds the parry shape of a machine solid's shape.
pub(crate) fn build(shape: &Shape, solid: &str) -> Result<Built, BuildError> {
    let convex = |shape: SharedShape, offset: Pose| Built {
        shape,
        offset,
        closed: true,
        inner_point: Vector::ZERO,
    };
    Ok(match shape {
        Shape::Box { size_mm } => convex(
            SharedShape::new(Cuboid::new(Vector::new(
                size_mm[0] / 2.0,
                size_mm[1] / 2.0,
                size_mm[2] / 2.0,
            ))),
            Pose::from_translation(Vector::new(0.0, 0.0, size_mm[2] / 2.0)),
        ),
        Shape::Sphere { radius_mm } => {
            convex(SharedShape::new(Ball::new(*radius_mm)), Pose::IDENTITY)
        }
        Shape::Cylinder {
            radius_mm,
            height_mm,
        } => convex(
            SharedShape::new(Cylinder::new(height_mm / 2.0, *radius_mm)),
            standing(height_mm / 2.0),
        ),
        Shape::Cone {
            radius_bottom_mm: bottom,
            radius_top_mm: top,
            height_mm: h,
        } => {
            let half = h / 2.0;
            if bottom == top {
                convex(
                    SharedShape::new(Cylinder::new(half, *bottom)),
                    standing(half),
                )
            } else if *bottom == 0.0 {
                // parry's cone: apex at +y, base at −y; the apex up at the top.
                let flip = Pose::from_parts(
                    Vector::new(0.0, 0.0, half),
                    Rotation::from_rotation_x(-PI / 2.0),
                );
                convex(SharedShape::new(Cone::new(half, *top)), flip)
            } else if *top == 0.0 {
                convex(SharedShape::new(Cone::new(half, *bottom)), standing(half))
            } else {
                let grow = 1.0 / (PI / FRUSTUM_SIDES as f64).cos();
                let ring = |r: f64, z: f64| {
                    (0..FRUSTUM_SIDES).map(move |k| {
                        let a = 2.0 * PI * k as f64 / FRUSTUM_SIDES as f64;
                        Vector::new(r * grow * a.cos(), r * grow * a.sin(), z)
                    })
                };
                let points: Vec<Vector> = ring(*bottom, 0.0).chain(ring(*top, *h)).collect();
                let hull = ConvexPolyhedron::from_convex_hull(&points).ok_or_else(|| {
                    BuildError::Shape {
                        solid: solid.to_string(),
                        reason: "the cone's hull could not be built".into(),
                    }
                })?;
                Built {
                    shape: SharedShape::new(hull),
                    offset: Pose::IDENTITY,
                    closed: true,
                    inner_point: Vector::new(0.0, 0.0, h / 2.0),
                }
            }
        }
        Shape::Mesh(mesh) => build_mesh(mesh, solid)?,
    })
}

/// A triangle mesh with its BVH; oriented (an inside) when it is closed.
pub(crate) fn build_mesh(mesh: &Mesh, solid: &str) -> Result<Built, BuildError> {
    let n = mesh.vertices.len();
    let bad = |reason: String| BuildError::Shape {
        solid: solid.to_string(),
        reason,
    };
    if mesh.triangles.is_empty() {
        return Err(bad(format!("mesh `{}` has no triangle", mesh.source)));
    }
    if let Some(t) = mesh
        .triangles
        .iter()
        .find(|t| t.iter().any(|&i| i as usize >= n))
    {
        return Err(bad(format!(
            "mesh `{}`: triangle {t:?} names a vertex beyond its {n} vertices",
            mesh.source
        )));
    }
    if mesh.vertices.iter().flatten().any(|x| !x.is_finite()) {
        return Err(bad(format!(
            "mesh `{}` has a vertex that is not finite",
            mesh.source
        )));
    }
    let vertices: Vec<Vector> = mesh
        .vertices
        .iter()
        .map(|v| Vector::new(v[0], v[1], v[2]))
        .collect();
    let closed = is_closed(&mesh.triangles);
    let flags = if closed {
        TriMeshFlags::ORIENTED
    } else {
        TriMeshFlags::empty()
    };
    let inner_point = vertices[mesh.triangles[0][0] as usize];
    let trimesh = TriMesh::with_flags(vertices, mesh.triangles.clone(), flags)
        .map_err(|e| bad(format!("mesh `{}`: {e}", mesh.source)))?;
    Ok(Built {
        shape: SharedShape::new(trimesh),
        offset: Pose::IDENTITY,
        closed,
        inner_point,
    })
}

/// Whether a triangle mesh is closed and consistently oriented: every edge
/// is used once in each direction (by two triangles that agree on which
/// side is out), and no triangle repeats a vertex.
pub fn is_closed(triangles: &[[u32; 3]]) -> bool {
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 3);
    for t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return false;
        }
        for k in 0..3 {
            *edges.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    edges
        .iter()
        .all(|(&(a, b), &count)| count == 1 && edges.get(&(b, a)) == Some(&1))
}
