//! Motion planning: which of the inverse-kinematics solutions of each CL
//! point the machine goes to.
//!
//! Version 1 decides point by point ([`NearestPlanner`]): among the solutions
//! inside every limit, the one that moves the free rotary axes least from the
//! previous block; the first point of the program takes the one nearest to
//! zero. The planner sees the path as [`Planner::choose`] calls separated by
//! [`Planner::break_segment`] (rapids, tool changes, operation ends), which
//! is where whole-segment planning (dynamic programming over the candidates,
//! singularity handling, linearization) plugs in.

use kinpost_machine::{Joints, Machine, Solution, Violation};

/// Why no solution of a point can be used.
#[derive(Debug, Clone, PartialEq)]
pub enum Rejection {
    /// Every branch leaves the travel; the violation of the branch nearest to
    /// the previous block is given.
    OutsideLimits(Violation),
    /// The kinematics found no solution at all.
    NoSolution,
}

/// Chooses one solution per CL point.
pub trait Planner {
    /// The index in `solutions` of the configuration to go to.
    fn choose(&mut self, solutions: &[Solution]) -> Result<usize, Rejection>;
    /// The path is interrupted here (rapid, tool change, end of an operation).
    fn break_segment(&mut self) {}
    /// The configuration the machine is in, if any: used as the hint for free
    /// angles at singular poses.
    fn current(&self) -> Option<&Joints>;
}

/// Point-by-point choice: least rotary motion from the previous block.
#[derive(Debug, Clone)]
pub struct NearestPlanner {
    /// Indices of the free rotary axes.
    rotary: Vec<usize>,
    previous: Option<Joints>,
}

impl NearestPlanner {
    pub fn new(machine: &Machine) -> Self {
        NearestPlanner {
            rotary: (0..machine.axes.len())
                .filter(|&i| machine.axes[i].is_rotary() && machine.axes[i].is_free())
                .collect(),
            previous: None,
        }
    }

    /// Rotary travel from the previous block (or from zero) to `s`, degrees.
    fn travel(&self, s: &Solution) -> f64 {
        self.rotary
            .iter()
            .map(|&i| (s.joints[i] - self.previous.map_or(0.0, |p| p[i])).abs())
            .sum()
    }
}

impl Planner for NearestPlanner {
    fn choose(&mut self, solutions: &[Solution]) -> Result<usize, Rejection> {
        // `min_by` keeps the first of equal candidates: ties go to the lower
        // branch, so the result is deterministic.
        let best = |valid: bool| {
            solutions
                .iter()
                .enumerate()
                .filter(|(_, s)| s.is_valid() == valid)
                .min_by(|(_, a), (_, b)| self.travel(a).total_cmp(&self.travel(b)))
                .map(|(i, _)| i)
        };
        match best(true) {
            Some(i) => {
                self.previous = Some(solutions[i].joints);
                Ok(i)
            }
            None => match best(false).and_then(|i| solutions[i].violation) {
                Some(v) => Err(Rejection::OutsideLimits(v)),
                None => Err(Rejection::NoSolution),
            },
        }
    }

    fn current(&self) -> Option<&Joints> {
        self.previous.as_ref()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::{MAX_AXES, builtin};

    fn sol(a: f64, b: f64, violation: Option<Violation>) -> Solution {
        let mut joints = [0.0; MAX_AXES];
        joints[1] = a;
        joints[4] = b;
        Solution {
            joints,
            branch: 0,
            singular: false,
            violation,
        }
    }

    #[test]
    fn first_point_nearest_zero_then_least_motion() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let mut p = NearestPlanner::new(&m);
        let first = [sol(350.0, 0.0, None), sol(-10.0, 0.0, None)];
        assert_eq!(p.choose(&first), Ok(1));
        let next = [sol(340.0, 0.0, None), sol(-20.0, 1.0, None)];
        assert_eq!(p.choose(&next), Ok(1));
        assert_eq!(p.current().unwrap()[1], -20.0);
    }

    #[test]
    fn only_invalid_solutions_report_the_violation() {
        let m = builtin::load("mts1600").unwrap().unwrap();
        let mut p = NearestPlanner::new(&m);
        let v = Violation {
            axis: 4,
            value: 50.0,
        };
        let sols = [sol(0.0, 50.0, Some(v))];
        assert_eq!(p.choose(&sols), Err(Rejection::OutsideLimits(v)));
        assert_eq!(p.choose(&[]), Err(Rejection::NoSolution));
    }
}
