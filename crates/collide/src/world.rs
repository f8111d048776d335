//! The collision world: the solids of a machine and its part, placed at any
//! joint values, and the pairs checked.

use std::sync::Arc;

use kinpost_machine::{Body, Kinematics, Machine, Mesh, Role, Solid};
use nalgebra::{Isometry3, Rotation3, Translation3, UnitQuaternion};
use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::query::gjk::{self, CsoPoint, GJKResult, VoronoiSimplex};
use parry3d_f64::query::{self, ClosestPoints};
use parry3d_f64::shape::SharedShape;
use rayon::prelude::*;

use crate::bound::MotionBound;
use crate::shapes::{build, to_pose};
use crate::{BuildError, SWEEP_TOLERANCE_MM};

/// What kind of move a pose belongs to: it decides whether a cutter may
/// touch stock.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Motion {
    /// A cutting move (G1, G2, G3): a cutter touching stock is cutting.
    Feed,
    /// A rapid (G0): a cutter touching stock is a "rapid into stock".
    Rapid,
}

/// What a contact is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum ContactKind {
    /// The two solids are within the pair's `error_clearance` (touching or
    /// overlapping with the default clearance of 0).
    Collision,
    /// A cutter within the `error_clearance` of stock during a rapid.
    RapidIntoStock,
    /// Within the pair's `warning_clearance`, not within its
    /// `error_clearance`.
    NearMiss,
}

impl ContactKind {
    /// Whether this contact is an error (a collision or a rapid into
    /// stock), not a warning.
    pub fn is_error(self) -> bool {
        !matches!(self, ContactKind::NearMiss)
    }
}

/// Two solids too close at one pose.
#[derive(Debug, Clone, PartialEq)]
pub struct Contact {
    /// The two solids, by name, in the world's order (see
    /// [`World::solid_names`]).
    pub solids: [Arc<str>; 2],
    /// Their indices in the world.
    pub indices: [usize; 2],
    /// Their distance, mm: 0 when they touch, overlap or one lies inside
    /// the other.
    pub distance_mm: f64,
    /// How deep they overlap, mm, where parry computes it (two convex
    /// solids, or a mesh and a convex solid whose surfaces cross); `None`
    /// when they do not overlap or the depth is not computed.
    pub penetration_mm: Option<f64>,
    /// What it is.
    pub kind: ContactKind,
    /// The pair's clearances, mm: (warning, error).
    pub clearances_mm: (f64, f64),
}

/// A contact found between two sampled poses by [`World::check_move`].
#[derive(Debug, Clone, PartialEq)]
pub struct MoveContact {
    /// The contact at the first pose of the move found in contact.
    pub contact: Contact,
    /// Where along the move, 0 (start) to 1 (end).
    pub fraction: f64,
    /// The joint values there.
    pub joints: Vec<f64>,
}

/// A solid ready for queries.
#[derive(Clone)]
struct Item {
    def: Solid,
    name: Arc<str>,
    shape: SharedShape,
    /// parry's shape frame at home, machine frame.
    home: Pose,
    /// The shape's bounding box in its own frame.
    local_aabb: Aabb,
    closed: bool,
    inner_point: Vector,
    bound: MotionBound,
}

/// A pair the world checks.
#[derive(Debug, Clone, Copy)]
struct Pair {
    a: usize,
    b: usize,
    warning: f64,
    error: f64,
    /// A cutter and stock: not checked in feed moves.
    cutting: bool,
}

/// A solid placed at one pose.
#[derive(Debug, Clone, Copy)]
struct Placed {
    pose: Pose,
    aabb: Aabb,
}

/// The virtual machine's solids, ready to be checked at any joint values.
///
/// Built from a validated [`Machine`] (its `[[solid]]` and `[collision]`
/// tables) and extended with run-time solids, such as the part or stock
/// mesh ([`World::add_part`]). Immutable once built: checks take `&self`
/// and run in parallel.
#[derive(Clone)]
pub struct World {
    machine: Machine,
    kin: Kinematics,
    items: Vec<Item>,
    pairs: Vec<Pair>,
}

impl World {
    /// The world of a machine's solids. The kinematics is the machine's
    /// own (`Kinematics::new(machine)`); for 6-axis output pass the machine
    /// with its `free_with_reference` axes free.
    pub fn new(machine: &Machine) -> Result<World, BuildError> {
        let mut world = World {
            machine: machine.clone(),
            kin: Kinematics::new(machine),
            items: Vec::with_capacity(machine.solids.len() + 1),
            pairs: Vec::new(),
        };
        for s in &machine.solids {
            world.add_solid(s.clone())?;
        }
        Ok(world)
    }

    /// Adds a solid (a fixture, a tool, the part): it is checked against
    /// every solid already there by the machine's rules
    /// ([`Machine::checks_pair`]). Returns its index.
    pub fn add_solid(&mut self, solid: Solid) -> Result<usize, BuildError> {
        if self.items.iter().any(|i| i.def.name == solid.name) {
            return Err(BuildError::DuplicateName(solid.name));
        }
        if let Body::Axis(i) = solid.on
            && i >= self.machine.axes.len()
        {
            return Err(BuildError::NoSuchAxis {
                solid: solid.name,
                axis: i,
            });
        }
        let built = build(&solid.shape, &solid.name)?;
        let home = to_pose(&solid.home) * built.offset;
        let local_aabb = built.shape.compute_local_aabb();
        let sphere = built.shape.compute_local_bounding_sphere();
        let centre = home.transform_point(sphere.center());
        let bound = MotionBound::new(
            &self.machine,
            solid.on,
            nalgebra::Vector3::new(centre.x, centre.y, centre.z),
            sphere.radius(),
        );
        let index = self.items.len();
        for (j, other) in self.items.iter().enumerate() {
            if !self.machine.checks_pair(&other.def, &solid) {
                continue;
            }
            let (warning, error) = self
                .machine
                .collision
                .clearances(&other.def.group, &solid.group);
            let roles = [other.def.role, solid.role];
            self.pairs.push(Pair {
                a: j,
                b: index,
                warning,
                error,
                cutting: roles.contains(&Role::Cutter) && roles.contains(&Role::Stock),
            });
        }
        self.items.push(Item {
            name: Arc::from(solid.name.as_str()),
            def: solid,
            shape: built.shape,
            home,
            local_aabb,
            closed: built.closed,
            inner_point: built.inner_point,
            bound,
        });
        Ok(index)
    }

    /// Adds the part (or stock) mesh, in the part (program) frame of the
    /// machine, on the workpiece body, as stock called `name`. Returns its
    /// index.
    pub fn add_part(&mut self, name: &str, mesh: Mesh) -> Result<usize, BuildError> {
        let home = Isometry3::from_parts(
            Translation3::from(self.machine.workpiece_origin),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
                self.machine.workpiece_rotation,
            )),
        );
        self.add_solid(Solid {
            name: name.to_string(),
            on: Body::Workpiece,
            shape: kinpost_machine::Shape::Mesh(Arc::new(mesh)),
            home,
            group: name.to_string(),
            role: Role::Stock,
        })
    }

    /// The names of the solids, in the world's order (machine-file order,
    /// then those added).
    pub fn solid_names(&self) -> impl Iterator<Item = &str> {
        self.items.iter().map(|i| &*i.name)
    }

    /// The solids as they were given.
    pub fn solids(&self) -> impl Iterator<Item = &Solid> {
        self.items.iter().map(|i| &i.def)
    }

    /// The pairs checked, by index, in the order contacts are reported.
    pub fn checked_pairs(&self) -> impl Iterator<Item = [usize; 2]> + '_ {
        self.pairs.iter().map(|p| [p.a, p.b])
    }

    /// The mesh solids that are not closed: one lying wholly inside such a
    /// mesh is not found (only their surfaces are checked).
    pub fn open_meshes(&self) -> impl Iterator<Item = &str> {
        self.items.iter().filter(|i| !i.closed).map(|i| &*i.name)
    }

    /// The machine the world was built for.
    pub fn machine(&self) -> &Machine {
        &self.machine
    }

    /// Every solid placed at joint values `q`.
    fn place_all(&self, q: &[f64]) -> Vec<Placed> {
        let bodies = self.kin.body_poses(q);
        self.items.iter().map(|item| place(item, &bodies)).collect()
    }

    /// Every pair too close at joint values `q` (machine-file order, every
    /// axis), in pair order. In a [`Motion::Feed`] a cutter may touch stock.
    pub fn check_pose(&self, q: &[f64], motion: Motion) -> Vec<Contact> {
        let placed = self.place_all(q);
        let mut out = Vec::new();
        for p in &self.pairs {
            if p.cutting && motion == Motion::Feed {
                continue;
            }
            let (a, b) = (&placed[p.a], &placed[p.b]);
            if let Some(d) = self.pair_distance(p, a, b, p.warning) {
                out.push(self.contact(p, a, b, d, motion));
            }
        }
        out
    }

    /// [`World::check_pose`] for many poses, in parallel on rayon's pool:
    /// the same result, in the same order, for any number of threads.
    pub fn check_poses<Q: AsRef<[f64]> + Sync>(
        &self,
        poses: &[Q],
        motion: Motion,
    ) -> Vec<Vec<Contact>> {
        poses
            .par_iter()
            .with_min_len(64)
            .map(|q| self.check_pose(q.as_ref(), motion))
            .collect()
    }

    /// The contact of pair `p` at distance `d`.
    fn contact(&self, p: &Pair, a: &Placed, b: &Placed, d: f64, motion: Motion) -> Contact {
        let kind = match (d <= p.error, p.cutting && motion == Motion::Rapid) {
            (true, true) => ContactKind::RapidIntoStock,
            (true, false) => ContactKind::Collision,
            (false, _) => ContactKind::NearMiss,
        };
        let (ia, ib) = (&self.items[p.a], &self.items[p.b]);
        let penetration_mm = if d == 0.0 {
            query::contact(&a.pose, &*ia.shape.0, &b.pose, &*ib.shape.0, 0.0)
                .ok()
                .flatten()
                .filter(|c| c.dist < 0.0)
                .map(|c| -c.dist)
        } else {
            None
        };
        Contact {
            solids: [ia.name.clone(), ib.name.clone()],
            indices: [p.a, p.b],
            distance_mm: d,
            penetration_mm,
            kind,
            clearances_mm: (p.warning, p.error),
        }
    }

    /// The distance of a pair, if it is at most `margin`: 0 when the solids
    /// touch, overlap or one is inside the other.
    fn pair_distance(&self, p: &Pair, a: &Placed, b: &Placed, margin: f64) -> Option<f64> {
        if aabb_gap(&a.aabb, &b.aabb) > margin {
            return None;
        }
        let (ia, ib) = (&self.items[p.a], &self.items[p.b]);
        let (sa, sb) = (&*ia.shape.0, &*ib.shape.0);
        let distance = match (sa.as_trimesh(), sb.as_trimesh()) {
            (Some(mesh), None) if sb.as_support_map().is_some() => {
                mesh_to_convex(mesh, &a.pose, sb, &b.pose, margin)
            }
            (None, Some(mesh)) if sa.as_support_map().is_some() => {
                mesh_to_convex(mesh, &b.pose, sa, &a.pose, margin)
            }
            _ => match query::closest_points(&a.pose, sa, &b.pose, sb, margin) {
                Ok(ClosestPoints::Intersecting) => Some(0.0),
                // GJK runs to convergence within the margin (parry asks
                // it for exact distances), so these are the closest points.
                // Not `query::distance`: for two cuboids parry 0.31 takes
                // its own routine, which overestimates some poses
                // (dimforge/parry#431: 27.7 mm for a 3.2 mm gap between
                // mts1600's arm and tailstock), and a near miss went
                // unreported.
                Ok(ClosestPoints::WithinMargin(p1, p2)) => Some((p1 - p2).length()),
                Ok(ClosestPoints::Disjoint) => None,
                // No query for these shapes (none of kinpost's): the boxes'
                // gap is a distance the solids are not nearer than.
                Err(_) => Some(aabb_gap(&a.aabb, &b.aabb)),
            },
        };
        if distance == Some(0.0) {
            return distance;
        }
        // Surfaces apart: one solid may still lie wholly inside the other
        // (a mesh has no inside for the distance query); then its box is
        // inside the other's, and any one of its points is inside.
        if nested(ia, a, ib, b) || nested(ib, b, ia, a) {
            return Some(0.0);
        }
        distance
    }

    /// The first contact of every pair along a joint-linear move from
    /// `from` to `to` (both ends included), in pair order: for each pair
    /// its first collision, or if it has none its first near miss.
    ///
    /// Nothing shorter than the sampling is jumped over: conservative
    /// advancement ([`crate::bound`]) proves each stretch clear or halves
    /// it; a pair is reported at a pose where parry measures it within its
    /// clearance, and a pair not reported stays farther than its clearance
    /// less [`SWEEP_TOLERANCE_MM`] along the whole move.
    pub fn check_move(&self, from: &[f64], to: &[f64], motion: Motion) -> Vec<MoveContact> {
        let n = from.len().min(to.len());
        self.check_path(
            &|t: f64, q: &mut Vec<f64>| {
                q.clear();
                q.extend((0..n).map(|i| from[i] + t * (to[i] - from[i])));
            },
            motion,
        )
    }

    /// [`World::check_move`] along any path `path(t, q)`, `t` from 0 to 1,
    /// on which every axis moves monotonically (never turns back: the
    /// bound of [`crate::bound`] takes the travel of an axis over a stretch
    /// to be the difference of its ends), e.g. the axis profiles of a
    /// controller's rapid. `path` writes the joint values at `t` into `q`.
    pub fn check_path(
        &self,
        path: &(dyn Fn(f64, &mut Vec<f64>) + Sync),
        motion: Motion,
    ) -> Vec<MoveContact> {
        // A pair whose boxes at the start are farther apart than the two
        // solids can travel over the whole move, plus its clearance, stays
        // clear: dismissed without a query.
        let (mut q0, mut q1) = (Vec::new(), Vec::new());
        path(0.0, &mut q0);
        path(1.0, &mut q1);
        let start = self.place_all(&q0);
        let travel: Vec<f64> = self
            .items
            .iter()
            .map(|i| i.bound.path_bound_mm(&q0, &q1))
            .collect();
        self.pairs
            .iter()
            .filter(|p| !(p.cutting && motion == Motion::Feed))
            .filter(|p| {
                aabb_gap(&start[p.a].aabb, &start[p.b].aabb) - (travel[p.a] + travel[p.b])
                    <= p.warning
            })
            .filter_map(|p| {
                self.sweep_pair(p, path, p.error, motion).or_else(|| {
                    (p.warning > p.error)
                        .then(|| self.sweep_pair(p, path, p.warning, motion))
                        .flatten()
                })
            })
            .collect()
    }

    /// The first pose of `path` at which pair `p` is within `threshold`, by
    /// conservative advancement.
    fn sweep_pair(
        &self,
        p: &Pair,
        path: &(dyn Fn(f64, &mut Vec<f64>) + Sync),
        threshold: f64,
        motion: Motion,
    ) -> Option<MoveContact> {
        let (ia, ib) = (&self.items[p.a], &self.items[p.b]);
        let (mut qa, mut qb) = (Vec::new(), Vec::new());
        // Stretches still to prove, the earliest on top.
        let mut stack = vec![(0.0f64, 1.0f64)];
        while let Some((ta, tb)) = stack.pop() {
            path(ta, &mut qa);
            path(tb, &mut qb);
            let bound = ia.bound.path_bound_mm(&qa, &qb) + ib.bound.path_bound_mm(&qa, &qb);
            let bodies = self.kin.body_poses(&qa);
            let (a, b) = (place(ia, &bodies), place(ib, &bodies));
            let Some(d) = self.pair_distance(p, &a, &b, threshold + bound) else {
                continue;
            };
            if d <= threshold {
                return Some(MoveContact {
                    contact: self.contact(p, &a, &b, d, motion),
                    fraction: ta,
                    joints: qa,
                });
            }
            // Clear here; nearer than the bound allows: prove the halves,
            // unless what the pair can still close is within the tolerance,
            // or the stretch cannot be halved any more (a path that jumps).
            let tm = 0.5 * (ta + tb);
            if bound <= SWEEP_TOLERANCE_MM || tm <= ta || tm >= tb {
                continue;
            }
            stack.push((tm, tb));
            stack.push((ta, tm));
        }
        // The end itself (proven only to within the tolerance above).
        path(1.0, &mut qb);
        let bodies = self.kin.body_poses(&qb);
        let (a, b) = (place(ia, &bodies), place(ib, &bodies));
        let d = self.pair_distance(p, &a, &b, threshold)?;
        Some(MoveContact {
            contact: self.contact(p, &a, &b, d, motion),
            fraction: 1.0,
            joints: qb,
        })
    }
}

/// A solid placed by the body poses.
fn place(item: &Item, bodies: &kinpost_machine::BodyPoses) -> Placed {
    let pose = to_pose(bodies.of(item.def.on)) * item.home;
    Placed {
        pose,
        aabb: item.local_aabb.transform_by(&pose),
    }
}

/// The distance between a triangle mesh and a convex shape, if it is at
/// most `margin`.
///
/// parry's own query bounds the distance to a node of the mesh's BVH by
/// the gap between the node's box and the shape's box, which for a large
/// round solid over a finely cut surface (a wheel over a blank, a tilted
/// holder) leaves thousands of triangles to measure. Here a node's bound
/// is the distance from the shape to the node's box (GJK; the box
/// holds every triangle below it, so no triangle is nearer), asked only
/// whether it exceeds the best distance so far, and only when the gap of
/// the boxes does not already prune the node: a surface farther than the
/// margin is usually dismissed at its root.
fn mesh_to_convex(
    mesh: &parry3d_f64::shape::TriMesh,
    mesh_pose: &Pose,
    shape: &dyn parry3d_f64::shape::Shape,
    shape_pose: &Pose,
    margin: f64,
) -> Option<f64> {
    use parry3d_f64::shape::Cuboid;
    // The shape in the mesh's frame.
    let pose = mesh_pose.inv_mul(shape_pose);
    let shape_aabb = shape.compute_aabb(&pose);
    // `find_best` keeps strictly smaller costs: a distance exactly at the
    // margin is kept.
    let limit = margin + margin.abs().max(1.0) * 1e-12;
    let node_bound = |node: &parry3d_f64::partitioning::BvhNode, best: f64| {
        let aabb = node.aabb();
        let gap = aabb_gap(&aabb, &shape_aabb);
        if gap >= best {
            return gap;
        }
        // GJK stops as soon as it proves the box farther than the best
        // distance so far (the node is pruned) or nearer (not pruned: the
        // boxes' gap stays its bound, a true lower one); it never needs
        // to converge on the distance itself.
        let cuboid = Cuboid::new(aabb.half_extents());
        let centre = Pose::from_translation(aabb.center());
        let farther = match shape.as_support_map() {
            Some(map) => {
                let pos12 = centre.inv_mul(&pose);
                let dir = (-pos12.translation).try_normalize().unwrap_or(Vector::X);
                let mut simplex = VoronoiSimplex::new();
                simplex.reset(CsoPoint::from_shapes(&pos12, &cuboid, map, dir));
                matches!(
                    gjk::closest_points(&pos12, &cuboid, map, best, false, &mut simplex),
                    GJKResult::NoIntersection(_)
                )
            }
            None => matches!(
                query::closest_points(&centre, &cuboid, &pose, shape, best),
                Ok(ClosestPoints::Disjoint)
            ),
        };
        if farther { f64::MAX } else { gap }
    };
    // A triangle is measured only when GJK cannot prove it farther than
    // the best distance so far; then by `query::distance`, exact where
    // parry has a closed form (a ball).
    let leaf = |i: u32, best: f64| {
        let triangle = mesh.triangle(i);
        if let Some(map) = shape.as_support_map() {
            let dir = (-pose.translation).try_normalize().unwrap_or(Vector::X);
            let mut simplex = VoronoiSimplex::new();
            simplex.reset(CsoPoint::from_shapes(&pose, &triangle, map, dir));
            let far = gjk::closest_points(&pose, &triangle, map, best, false, &mut simplex);
            if matches!(far, GJKResult::NoIntersection(_)) {
                return None;
            }
        }
        query::distance(&Pose::IDENTITY, &triangle, &pose, shape)
            .ok()
            .map(|d| d.distance)
    };
    mesh.bvh()
        .find_best(limit, node_bound, leaf)
        .map(|(_, d)| d.min(margin))
}

/// The distance between two boxes (0 when they overlap).
fn aabb_gap(a: &Aabb, b: &Aabb) -> f64 {
    let gap = (a.mins - b.maxs).max(b.mins - a.maxs).max(Vector::ZERO);
    gap.length()
}

/// Whether solid `inner` lies inside the closed solid `outer`, given that
/// their surfaces do not meet: its box is inside the other's and its inner
/// point is inside the other.
fn nested(inner: &Item, pi: &Placed, outer: &Item, po: &Placed) -> bool {
    let inside_box = (pi.aabb.mins - po.aabb.mins).min_element() >= 0.0
        && (po.aabb.maxs - pi.aabb.maxs).min_element() >= 0.0;
    outer.closed
        && inside_box
        && outer
            .shape
            .contains_point(&po.pose, pi.pose.transform_point(inner.inner_point))
}
