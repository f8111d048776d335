//! Motion planning: which of the inverse-kinematics solutions of each CL
//! point the machine goes to, decided over the whole path.
//!
//! The [`Trellis`] holds, for every point not decided yet, its candidate
//! configurations (every branch and every 360° equivalent inside the
//! travel) and finds the cheapest sequence through them by dynamic
//! programming (Viterbi), with the costs of [`Costs`]: rotary travel, branch
//! switches, closeness to the travel limits and the user's preferences. A
//! move inside a cut that no continuous motion explains (a flip, a jump of a
//! turn) is allowed only at a very high cost: it is where the post must
//! retract and reconfigure. A lag of 1 decides point by point, as simple
//! posts do.
//!
//! The [`Planner`] is the post's planning stage around the trellis: CL
//! points and the commands between them wait in it until it decides; points
//! whose tool axis lies within the singular cone are not candidates of the
//! trellis but are solved between their decided neighbours (exactly where
//! no axis swings, else with the singular angle held and interpolated), and
//! the neighbours are linked with `across_singular`; folds of machines that
//! reach only a band of tool axes are crossed where the tool axis reaches
//! them. Every decided point goes to a [`PlanSink`] as a [`Node`] (the
//! configuration and the pose it reaches), the commands in their places.
//! [`solve_near`] solves a pose near a known configuration, for the
//! planner and for the points the later stages insert.

#![deny(missing_docs)]

mod cost;
mod node;
mod planner;
mod pole;
mod solve;
mod trellis;

pub use cost::{Costs, Link, STEP_CEILING_DEG};
pub use node::Node;
pub use planner::{PathPoint, PlanError, PlanSink, Planned, Planner, SingularStretch};
pub use solve::{Hold, Near, interpolate, solve_near};
pub use trellis::{Choice, RECONFIGURE, Trellis, UNCUT};

use kinpost_machine::{Solution, Violation};

/// Why no solution of a point can be used.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    /// Every branch leaves the travel; the violation of the first branch is
    /// given.
    OutsideLimits(Violation),
    /// The kinematics found no solution at all.
    NoSolution,
}

/// Why none of `solutions` is valid (call when none is).
pub fn rejection(solutions: &[Solution]) -> Rejection {
    match solutions.iter().find_map(|s| s.violation) {
        Some(v) => Rejection::OutsideLimits(v),
        None => Rejection::NoSolution,
    }
}
