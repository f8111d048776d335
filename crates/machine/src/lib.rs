//! The machine model of kinpost: machine files, forward and inverse
//! kinematics (DESIGN.md §2).
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

pub mod angle;
pub use angle::angle_between;
pub mod builtin;
mod file;
mod kinematics;
mod model;
mod pressure;
pub mod subproblems;

pub use file::{MAX_MACHINE_FILE_BYTES, machine_from_toml};
pub use kinematics::{
    AXIS_ROUNDING_RAD, Excursion, Folds, IkError, Joints, Kinematics, MAX_AXIS_ROUNDING_RAD,
    Singularity, Solution, Violation, lever_over, midpoint_bound, wrap180,
};
pub use model::{
    Axis, AxisKind, MAX_AXES, Machine, OutputMode, Pose, PostSettings, Prefer, Side, Tool, Wrap,
};
pub use pressure::{Clamp, PressureAxis, WheelModel, interpolate};
