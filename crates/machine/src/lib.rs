//! The machine model of kinpost: machine files, forward and inverse
//! kinematics (product of exponentials, Lynch & Park 2017), and the solids of the virtual machine with
//! the settings of its collision check ([`Solid`], [`CollisionSettings`],
//! moved by [`Kinematics::body_poses`]; checked by `kinpost-collide`).
//!
//! ```
//! use kinpost_machine::{builtin, Kinematics};
//! let machine = builtin::load("mts1600").unwrap().unwrap();
//! let kin = Kinematics::new(&machine);
//! let mut q = machine.home_joints();
//! q[machine.axis_index("X").unwrap()] = 459.0;
//! let pose = kin.fk(&q);
//! let mut solutions = Vec::new();
//! kin.ik(&pose, None, &mut solutions).unwrap();
//! assert!(solutions.iter().any(|s| (s.joints[0] - 459.0).abs() < 1e-9));
//! ```

#![deny(missing_docs)]

pub mod angle;
mod at_pressure;
pub use angle::angle_between;
pub mod builtin;
mod describe;
mod file;
mod kinematics;
mod model;
mod pressure;
mod solid;
pub mod subproblems;
pub mod tolerance;

pub use at_pressure::KinematicsAtPressure;
pub use describe::Mm;
pub use file::{
    MAX_MACHINE_FILE_BYTES, MAX_MESH_BYTES, MeshFiles, StlError, machine_from_toml,
    machine_from_toml_with, mesh_from_stl,
};
pub use kinematics::BodyPoses;
pub use kinematics::{
    AXIS_ROUNDING_RAD, Excursion, Folds, IkError, IkFailure, Joints, Kinematics,
    MAX_AXIS_ROUNDING_RAD, Singularity, Solution, Violation, lever_over, midpoint_bound, wrap180,
};
pub use model::{
    Axis, AxisKind, MAX_AXES, Machine, OutputMode, Pose, PostSettings, Prefer, Side, Tool, Wrap,
};
pub use pressure::{Clamp, PressureAxis, WheelModel, interpolate};
pub use solid::{
    Body, CollisionSettings, DEFAULT_ERROR_CLEARANCE_MM, DEFAULT_WARNING_CLEARANCE_MM, Mesh,
    PairClearance, Role, Shape, Solid,
};
