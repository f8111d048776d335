//! The solids of a machine (`[[solid]]` in the machine file) and the
//! settings of its collision check (`[collision]`): what the virtual machine
//! moves and checks for interference, as the machine models of VERICUT
//! (Qiao et al. 2022, §4; Qi (thesis), §4.1; Zhang et al. (impeller), §4).
//!
//! Every solid is carried by one body of the chain ([`Body`]) and described
//! at home, in the machine frame; [`Kinematics::body_poses`](crate::Kinematics::body_poses)
//! moves it to any joint values.

use std::sync::Arc;

use nalgebra::Isometry3;

/// A body of the kinematic chain: what carries a solid.
///
/// The chain has two branches from the base, one per [`Side`](crate::Side):
/// the axes of a side in machine-file order, each carried by the one before
/// it (the first by the base). An axis's body is what that axis moves (and
/// with it every later axis of its side).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Body {
    /// The machine base (bed, column): it never moves.
    Base,
    /// What the axis with this machine-file index moves.
    Axis(usize),
    /// What every tool-side axis moves: the tool, the same body as the last
    /// tool-side axis (the base when the tool side has no axis).
    Tool,
    /// What every workpiece-side axis moves: the part, the same body as the
    /// last workpiece-side axis (the base when that side has no axis).
    Workpiece,
}

/// The shape of a solid in its own frame. Boxes, cylinders and cones stand
/// on their own origin: the origin is the centre of the bottom face and
/// the solid extends along its +z; a sphere is centred on the origin.
#[derive(Debug, Clone, PartialEq)]
pub enum Shape {
    /// A box `size_mm` = x, y, z edges: x and y centred on the origin,
    /// z from 0 to `size_mm[2]`.
    Box {
        /// Edge lengths along the solid's x, y, z, mm.
        size_mm: [f64; 3],
    },
    /// A cylinder about the solid's z axis, from z = 0 to `height_mm`.
    Cylinder {
        /// Radius, mm.
        radius_mm: f64,
        /// Length along z, mm.
        height_mm: f64,
    },
    /// A cone (frustum) about the solid's z axis: radius `radius_bottom_mm`
    /// at z = 0, `radius_top_mm` at z = `height_mm`.
    Cone {
        /// Radius at z = 0, mm.
        radius_bottom_mm: f64,
        /// Radius at z = height, mm.
        radius_top_mm: f64,
        /// Length along z, mm.
        height_mm: f64,
    },
    /// A sphere centred on the solid's origin.
    Sphere {
        /// Radius, mm.
        radius_mm: f64,
    },
    /// A triangle mesh (an STL file), in the solid's frame, mm.
    Mesh(Arc<Mesh>),
}

/// A triangle mesh: vertices (mm) and triangles by vertex index.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    /// Where it came from (the `mesh` key of the machine file, or a file
    /// name given at run time), for messages.
    pub source: String,
    /// Vertices, mm.
    pub vertices: Vec<[f64; 3]>,
    /// Triangles: three indices into `vertices`, counter-clockwise seen
    /// from outside for a closed mesh.
    pub triangles: Vec<[u32; 3]>,
}

/// What a solid is to the collision check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Role {
    /// Part of the machine, fixture, holder, arm: it must touch nothing.
    #[default]
    Machine,
    /// The cutting part of a tool (the flutes of a cutter, the contact
    /// wheel of a belt grinder): it may touch stock while cutting (feed
    /// moves), but not in a rapid ("rapid into stock"), and never touches
    /// the machine.
    Cutter,
    /// Material to be cut (the part, the blank): only a cutter may touch it,
    /// and only while cutting.
    Stock,
}

/// One solid of the virtual machine.
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    /// Its name, unique in the machine; contacts are reported by name.
    pub name: String,
    /// The body that carries it.
    pub on: Body,
    /// Its shape in its own frame.
    pub shape: Shape,
    /// Its own frame at home (every axis at zero), in the machine frame.
    pub home: Isometry3<f64>,
    /// Its collision group (clearances per group pair); its name when the
    /// file gives none.
    pub group: String,
    /// What it is to the check.
    pub role: Role,
}

/// Clearances of one pair of collision groups (`[[collision.pair]]`).
#[derive(Debug, Clone, PartialEq)]
pub struct PairClearance {
    /// The two groups (either order).
    pub groups: [String; 2],
    /// See [`CollisionSettings::warning_clearance_mm`].
    pub warning_clearance_mm: f64,
    /// See [`CollisionSettings::error_clearance_mm`].
    pub error_clearance_mm: f64,
}

/// The `[collision]` table: when two solids are too close, and which pairs
/// are not checked.
///
/// Two solids at distance `d` (0 when they touch or overlap) are in
/// *collision* when `d <= error_clearance_mm` and a *near miss* when
/// `error_clearance_mm < d <= warning_clearance_mm`, the near-miss and
/// collision tolerances of VERICUT, ModuleWorks and ISG virtual machines.
///
/// Pairs never checked: two solids on the same body (they never move
/// against each other); two solids on neighbouring bodies of the chain (the
/// base and the first axis of a side, or two consecutive axes of a side in
/// machine-file order; [`Body::Tool`] and [`Body::Workpiece`] count as the
/// last axis of their side), unless a `check` entry names them; and every
/// pair an `ignore` entry names.
#[derive(Debug, Clone, PartialEq)]
pub struct CollisionSettings {
    /// Near-miss distance of every pair without its own, mm.
    pub warning_clearance_mm: f64,
    /// Collision distance of every pair without its own, mm.
    pub error_clearance_mm: f64,
    /// Clearances of group pairs.
    pub pairs: Vec<PairClearance>,
    /// Pairs never checked: each entry names two solids or groups.
    pub ignore: Vec<[String; 2]>,
    /// Pairs on neighbouring bodies that are checked all the same: each
    /// entry names two solids or groups.
    pub check: Vec<[String; 2]>,
}

/// Near-miss distance when the machine file gives none, mm.
pub const DEFAULT_WARNING_CLEARANCE_MM: f64 = 2.0;
/// Collision distance when the machine file gives none, mm: touching is a
/// collision.
pub const DEFAULT_ERROR_CLEARANCE_MM: f64 = 0.0;

impl Default for CollisionSettings {
    fn default() -> Self {
        CollisionSettings {
            warning_clearance_mm: DEFAULT_WARNING_CLEARANCE_MM,
            error_clearance_mm: DEFAULT_ERROR_CLEARANCE_MM,
            pairs: Vec::new(),
            ignore: Vec::new(),
            check: Vec::new(),
        }
    }
}

impl CollisionSettings {
    /// The (warning, error) clearances of two groups, mm: the pair's own,
    /// or the global ones.
    pub fn clearances(&self, group_a: &str, group_b: &str) -> (f64, f64) {
        self.pairs
            .iter()
            .find(|p| {
                (p.groups[0] == group_a && p.groups[1] == group_b)
                    || (p.groups[0] == group_b && p.groups[1] == group_a)
            })
            .map_or((self.warning_clearance_mm, self.error_clearance_mm), |p| {
                (p.warning_clearance_mm, p.error_clearance_mm)
            })
    }
}

/// Whether `name` names solid `s`: its own name or its group.
fn names(name: &str, s: &Solid) -> bool {
    s.name == name || s.group == name
}

/// Whether a list of name pairs (`ignore`, `check`) names the two solids.
pub(crate) fn listed(list: &[[String; 2]], a: &Solid, b: &Solid) -> bool {
    list.iter()
        .any(|[x, y]| (names(x, a) && names(y, b)) || (names(x, b) && names(y, a)))
}

impl crate::Machine {
    /// The axis whose body `body` is (`None`: the base). [`Body::Tool`] is
    /// the last tool-side axis, [`Body::Workpiece`] the last workpiece-side
    /// one.
    pub fn body_axis(&self, body: Body) -> Option<usize> {
        let last = |side| self.axes.iter().rposition(|a| a.side == side);
        match body {
            Body::Base => None,
            Body::Axis(i) => Some(i),
            Body::Tool => last(crate::Side::Tool),
            Body::Workpiece => last(crate::Side::Workpiece),
        }
    }

    /// The axes that move `body`, from the base outwards: the axes of its
    /// side up to and including its own, in machine-file order.
    pub fn chain_of(&self, body: Body) -> Vec<usize> {
        match self.body_axis(body) {
            None => Vec::new(),
            Some(i) => {
                let side = self.axes[i].side;
                (0..=i).filter(|&j| self.axes[j].side == side).collect()
            }
        }
    }

    /// The axis that carries the body of axis `i` (`None`: the base).
    fn parent_axis(&self, i: usize) -> Option<usize> {
        let side = self.axes[i].side;
        (0..i).rev().find(|&j| self.axes[j].side == side)
    }

    /// Whether two bodies are one (they never move against each other).
    pub fn same_body(&self, a: Body, b: Body) -> bool {
        self.body_axis(a) == self.body_axis(b)
    }

    /// Whether two bodies are neighbours in the chain: one carries the
    /// other directly (the base and the first axis of a side, or two
    /// consecutive axes of one side).
    pub fn neighbour_bodies(&self, a: Body, b: Body) -> bool {
        let (a, b) = (self.body_axis(a), self.body_axis(b));
        let carries = |outer: Option<usize>, inner: Option<usize>| {
            inner.is_some_and(|i| self.parent_axis(i) == outer)
        };
        a != b && (carries(a, b) || carries(b, a))
    }

    /// Whether the collision check looks at the pair of two different
    /// solids `a` and `b` (of the machine's `solids`, or added at run time,
    /// e.g. the part): not on one body, not named by an `ignore` entry, and
    /// not on neighbouring bodies unless a `check` entry names them (see
    /// [`CollisionSettings`]).
    pub fn checks_pair(&self, a: &Solid, b: &Solid) -> bool {
        !self.same_body(a.on, b.on)
            && !listed(&self.collision.ignore, a, b)
            && (!self.neighbour_bodies(a.on, b.on) || listed(&self.collision.check, a, b))
    }
}
