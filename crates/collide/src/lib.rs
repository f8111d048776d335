//! Collision checking for kinpost's virtual machine: the solids of a
//! machine file (`[[solid]]`), the part or stock mesh, and the clearances of
//! `[collision]`, checked at sampled poses and between them, as the machine
//! simulations of VERICUT that Qiao et al. 2022 (§4), Qi (thesis, §4.1) and
//! Zhang et al. (impeller) prove their programs on: interference of the
//! machine with itself, with the fixture and with the part, near misses
//! within a warning clearance, and rapids into stock.
//!
//! Geometry and exact distances are parry's (triangle meshes with their
//! BVH, convex primitives); the world places every solid by the body poses
//! of the kinematics ([`kinpost_machine::Kinematics::body_poses`]), skips
//! pairs whose boxes are farther apart than their clearance, and asks parry
//! only for the rest, with the clearance as the distance beyond which it
//! stops looking. Between two poses, [`World::check_move`] advances
//! conservatively ([`bound`]) so that no contact shorter than the sampling
//! is jumped over.
//!
//! ```
//! use kinpost_collide::{ContactKind, Motion, World};
//! use kinpost_machine::builtin;
//!
//! let machine = builtin::load("mts1600").unwrap().unwrap();
//! let world = World::new(&machine).unwrap();
//! let mut q = machine.home_joints();
//! // The flat-part grinding pose of Qiao et al. 2022, Figure 28: clear.
//! for (axis, value) in [("X", 459.0), ("Y", 8.807), ("Z", 361.368)] {
//!     q[machine.axis_index(axis).unwrap()] = value;
//! }
//! assert!(world.check_pose(&q, Motion::Feed).iter().all(|c| !c.kind.is_error()));
//! // X at 80 mm brings the right fixture under the wheel.
//! q[machine.axis_index("X").unwrap()] = 80.0;
//! let contacts = world.check_pose(&q, Motion::Feed);
//! let hit = contacts.iter().find(|c| c.kind == ContactKind::Collision).unwrap();
//! assert_eq!((&*hit.solids[0], &*hit.solids[1]), ("wheel", "right-fixture"));
//! ```

#![deny(missing_docs)]

pub mod bound;
pub mod shapes;
mod world;

pub use world::{Contact, ContactKind, Motion, MoveContact, World};

/// How near a clearance a pair may come, unreported, between two poses of
/// [`World::check_move`], mm: the sweep stops halving a stretch once the
/// solids cannot close by more than this over it. A micrometre: far below
/// any clearance a machine is given, far above the rounding of the
/// distances (1e-9 mm at a metre).
pub const SWEEP_TOLERANCE_MM: f64 = 1e-3;

/// Why a solid cannot be put into the world.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    /// Two solids of one name: contacts name their solids.
    #[error("there is already a solid called `{0}`")]
    DuplicateName(String),
    /// A solid on an axis the machine does not have.
    #[error("solid `{solid}` is on axis {axis}, which the machine does not have")]
    NoSuchAxis {
        /// The solid.
        solid: String,
        /// The axis index it names.
        axis: usize,
    },
    /// A shape parry cannot build.
    #[error("solid `{solid}`: {reason}")]
    Shape {
        /// The solid.
        solid: String,
        /// Why.
        reason: String,
    },
}
