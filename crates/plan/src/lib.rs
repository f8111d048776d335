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
//! Points whose tool axis lies within the singular cone are not candidates
//! here: the caller solves them between the decided neighbours (exactly
//! where no axis swings, else with the singular angle held and
//! interpolated) and links the neighbours with `across_singular`.

mod cost;
mod trellis;

pub use cost::{Costs, Link, STEP_CEILING_DEG};
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
