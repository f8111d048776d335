//! What the planner decides for a point: a configuration and the pose it
//! must reach.

use kinpost_machine::{Joints, Pose, Solution};

use crate::solve::Hold;

/// A configuration to write, with the pose it must reach.
#[derive(Debug, Clone, Copy)]
pub struct Node {
    /// The pose the block must reach (the CL pose, or the pose the machine
    /// points with a singular angle held).
    pub pose: Pose,
    /// Exact (unrounded, unwrapped) axis values.
    pub joints: Joints,
    /// The singular angle held at this node, if any.
    pub hold: Option<Hold>,
    /// The closed-form branch of `joints` (see [`Solution`]).
    pub branch: u8,
}

impl Node {
    /// The node of solution `sol`, which reaches `pose` with `hold` in force.
    pub fn solved(pose: Pose, sol: &Solution, hold: Option<Hold>) -> Node {
        Node {
            pose,
            joints: sol.joints,
            hold,
            branch: sol.branch,
        }
    }
}
