//! What a choice of configurations costs, and which moves are continuous.
//!
//! Units are degrees of rotary travel: the planner minimises the rotary
//! motion along the path, with small extra costs for switching the
//! closed-form branch, for running close to a travel limit and for values
//! the user does not prefer.

use kinpost_machine::{Joints, Machine, Prefer, Wrap, wrap180};

/// Cost of switching the orientation branch between two points of a cut.
const BRANCH_SWITCH: f64 = 1.0;
/// Cost per point at a travel limit; falls quadratically to zero at the
/// margin (see [`Costs::unary`]).
const NEAR_LIMIT: f64 = 1.0;
/// Cost per point and degree away from the preferred side (`prefer`).
const PREFERENCE: f64 = 0.01;
/// Cost per whole turn away from the principal value, for `wrap = "unwind"`
/// axes at the start of a segment: large enough to always unwind.
const UNWIND: f64 = 1e4;
/// A rotary step this small is always continuous on one branch, whatever
/// the tool axis did (round-off, CL points that repeat the tool axis).
const STEP_FLOOR_DEG: f64 = 1.0;
/// The largest rotary step of a switch of branch where the branches do not
/// meet (neither a singular stretch nor a fold between the points): none.
/// Near a fold the branches may lie within a degree of each other, and a
/// switch there is a jump the linearization cannot follow.
const SWITCH_APART_DEG: f64 = 0.0;
/// No rotary axis turns by half a turn or more between two points of a cut.
pub const STEP_CEILING_DEG: f64 = 179.0;

/// Most rotary axes the planner's fast path handles (others go through
/// [`Costs::transition`]).
pub(crate) const MAX_ROTARY: usize = 3;

/// Cost of a branch switch inside a cut, for the planner's fast path.
pub(crate) const CUT_BRANCH_SWITCH: f64 = BRANCH_SWITCH;

/// What [`Costs::transition`] allows the rotary axes on a cut, for the
/// planner's fast path (see [`Costs::cut_rule`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CutRule {
    /// Indices of the rotary axes (the first `n`).
    pub axes: [usize; MAX_ROTARY],
    pub n: usize,
    /// Which one is the singular axis.
    singular: [bool; MAX_ROTARY],
    step_rate: f64,
}

/// Per-axis step limits of one cut link (see [`CutRule::limits`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CutLimits {
    /// On the same branch.
    pub same: [f64; MAX_ROTARY],
    /// Switching branch.
    pub switch: [f64; MAX_ROTARY],
}

impl CutRule {
    /// The limits of a [`Link::Cut`]: exactly those [`Costs::transition`]
    /// compares the steps with.
    #[inline]
    pub fn limits(
        &self,
        turn_deg: f64,
        across_singular: bool,
        fold_deg: f64,
        across_fold: bool,
    ) -> CutLimits {
        let bound = cut_bound(turn_deg, self.step_rate, fold_deg);
        let switching = if across_singular || across_fold {
            bound
        } else {
            SWITCH_APART_DEG
        };
        let mut same = [bound; MAX_ROTARY];
        let mut switch = [switching; MAX_ROTARY];
        for k in 0..MAX_ROTARY {
            if self.singular[k] && across_singular {
                same[k] = 180.0 + 1e-9;
                switch[k] = 180.0 + 1e-9;
            }
        }
        CutLimits { same, switch }
    }
}

/// The largest rotary step of a cut on one branch while the tool axis
/// turns by `turn_deg` (see [`Costs::step_bound`]).
#[inline(always)]
fn step_bound(turn_deg: f64, step_rate: f64) -> f64 {
    (turn_deg * step_rate).clamp(STEP_FLOOR_DEG, STEP_CEILING_DEG)
}

/// [`step_bound`] with the allowance `fold_deg` near a fold, still less
/// than half a turn (a step of half a turn or more goes the other way round
/// in joint space).
#[inline(always)]
fn cut_bound(turn_deg: f64, step_rate: f64, fold_deg: f64) -> f64 {
    (step_bound(turn_deg, step_rate) + fold_deg).min(STEP_CEILING_DEG)
}

/// How two consecutive points are connected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Link {
    /// A new segment begins (a rapid, a tool change, a new operation, the
    /// start of the program): the axes may go anywhere.
    Free,
    /// A cutting move along which the tool axis turns by `turn_deg` (with a
    /// reference direction, the larger of its turn and the axis's).
    /// `across_singular`: singular points in between, where the singular
    /// angle is interpolated, so it may turn by up to half a turn.
    ///
    /// Near a fold (see [`kinpost_machine::Folds`]) the two branches meet
    /// and the angles move like the square root of the distance to it, far
    /// faster than the turn: `fold_deg` is how much more every rotary axis
    /// may move than the turn allows (0 on machines without folds), up to
    /// less than half a turn ([`STEP_CEILING_DEG`]).
    /// `across_fold`: the tool axis may pass a fold between the points, so
    /// a branch may switch there.
    Cut {
        /// The turn of the tool axis, degrees.
        turn_deg: f64,
        /// Singular points lie between.
        across_singular: bool,
        /// How much more a rotary axis may move near a fold, degrees.
        fold_deg: f64,
        /// The tool axis may pass a fold between the points.
        across_fold: bool,
    },
}

#[derive(Debug, Clone)]
struct Rotary {
    index: usize,
    wrap: Wrap,
    prefer: Option<Prefer>,
}

#[derive(Debug, Clone)]
struct Limited {
    index: usize,
    lo: f64,
    hi: f64,
    margin: f64,
}

/// The cost model of one machine.
#[derive(Debug, Clone)]
pub struct Costs {
    rotary: Vec<Rotary>,
    /// The rotary axes with a preference (in the order of `rotary`).
    preferring: Vec<Rotary>,
    limited: Vec<Limited>,
    /// Largest rotary step per degree of tool-axis turn on a continuous
    /// path outside the singular cone: 1 / sin(cone).
    step_rate: f64,
    singular_axis: Option<usize>,
}

impl Costs {
    /// `cone_deg`: half-angle of the singular cone (see the crate docs);
    /// `singular_axis`: the axis whose angle is free at the singular
    /// direction, if the machine has one.
    pub fn new(machine: &Machine, cone_deg: f64, singular_axis: Option<usize>) -> Costs {
        let free = |i: &usize| machine.axes[*i].is_free();
        let rotary: Vec<Rotary> = machine
            .free_rotary_axes()
            .map(|i| Rotary {
                index: i,
                wrap: machine.axes[i].wrap,
                prefer: machine.axes[i].prefer,
            })
            .collect();
        let preferring = rotary
            .iter()
            .filter(|r| r.prefer.is_some())
            .cloned()
            .collect();
        let limited = (0..machine.axes.len())
            .filter(free)
            .filter_map(|i| {
                let a = &machine.axes[i];
                let [lo, hi] = a.travel()?;
                let margin = ((hi - lo) * 0.05).min(if a.is_rotary() { 5.0 } else { 10.0 });
                (margin > 0.0).then_some(Limited {
                    index: i,
                    lo,
                    hi,
                    margin,
                })
            })
            .collect::<Vec<Limited>>();
        // Outside the cone a rotary angle changes at most 1/sin(cone) times
        // as fast as the tool axis turns; a cone of zero (no pole handling)
        // still bounds the rate by that of a 0.1° cone.
        let step_rate = 1.0 / cone_deg.max(0.1).to_radians().sin();
        Costs {
            rotary,
            preferring,
            limited,
            step_rate,
            singular_axis,
        }
    }

    /// The cost of closeness to the travel limits.
    fn near_limits(&self, q: &Joints) -> f64 {
        let mut cost = 0.0;
        for l in &self.limited {
            let d = (q[l.index] - l.lo).min(l.hi - q[l.index]);
            if d < l.margin {
                let x = (l.margin - d.max(0.0)) / l.margin;
                cost += NEAR_LIMIT * x * x;
            }
        }
        cost
    }

    /// Cost of being at `q` for one point: closeness to the travel limits
    /// and distance from the preferred values.
    pub fn unary(&self, q: &Joints) -> f64 {
        let mut cost = 0.0;
        // Whether any axis is within its margin, without branches, before
        // the loop that adds. The axes with limits only, each value loaded
        // on its own: `q` was just written value by value (the inverse
        // kinematics), and a load of several at once would wait for those
        // stores to retire.
        let mut near = false;
        for l in &self.limited {
            let v = q[l.index];
            near |= (v - l.lo < l.margin) | (l.hi - v < l.margin);
        }
        if near {
            cost = self.near_limits(q);
        }
        // Axes without a preference would add PREFERENCE · 0 = +0, which
        // leaves the (non-negative or NaN) sum as it is: they are left out.
        for r in &self.preferring {
            let v = q[r.index];
            cost += PREFERENCE
                * match r.prefer {
                    None => 0.0,
                    Some(Prefer::Zero) => v.abs(),
                    Some(Prefer::Positive) => (-v).max(0.0),
                    Some(Prefer::Negative) => v.max(0.0),
                };
        }
        cost
    }

    /// The rotary axes [`Costs::transition`] adds the steps of, in its
    /// order, and what a cut allows them, when there are 1 to
    /// [`MAX_ROTARY`] of them (else `None`).
    pub(crate) fn cut_rule(&self) -> Option<CutRule> {
        let n = self.rotary.len();
        if n == 0 || n > MAX_ROTARY {
            return None;
        }
        let mut axes = [0; MAX_ROTARY];
        let mut singular = [false; MAX_ROTARY];
        for (k, r) in self.rotary.iter().enumerate() {
            axes[k] = r.index;
            singular[k] = self.singular_axis == Some(r.index);
        }
        Some(CutRule {
            axes,
            n,
            singular,
            step_rate: self.step_rate,
        })
    }

    /// The largest step of any rotary axis between two points of a cut on
    /// one branch, away from folds, while the tool axis turns by `turn_deg`:
    /// the turn times 1/sin(cone) (how fast an angle turns at the edge of
    /// the singular cone), at least 1° and less than half a turn.
    pub fn step_bound(&self, turn_deg: f64) -> f64 {
        step_bound(turn_deg, self.step_rate)
    }

    /// Cost of moving from `a` (branch `ba`) to `b` (branch `bb`) and whether
    /// the move is continuous (a cut may follow it without lifting the tool).
    pub fn transition(&self, a: &Joints, ba: u8, b: &Joints, bb: u8, link: Link) -> (f64, bool) {
        let mut cost = 0.0;
        let mut continuous = true;
        match link {
            Link::Free => {
                for r in &self.rotary {
                    let (va, vb) = (a[r.index], b[r.index]);
                    cost += match r.wrap {
                        Wrap::None => (vb - va).abs(),
                        Wrap::Modulo => wrap180(vb - va).abs(),
                        Wrap::Unwind => {
                            wrap180(vb - va).abs() + UNWIND * ((vb - wrap180(vb)) / 360.0).abs()
                        }
                    };
                }
            }
            Link::Cut {
                turn_deg,
                across_singular,
                fold_deg,
                across_fold,
            } => {
                // Along one branch of the closed form a rotary angle turns at
                // most 1/sin(cone) times as fast as the tool axis outside the
                // singular cone; whole turns (360° equivalents) never pass.
                // The branches meet only at the singular direction and at
                // the folds (the edges of the reachable directions of axes
                // at other angles, `across_fold`): a switch elsewhere is a
                // flip.
                let bound = cut_bound(turn_deg, self.step_rate, fold_deg);
                let switch = ba != bb;
                for r in &self.rotary {
                    let step = (b[r.index] - a[r.index]).abs();
                    let limit = match self.singular_axis {
                        Some(i) if i == r.index && across_singular => 180.0 + 1e-9,
                        _ if switch && !across_singular && !across_fold => SWITCH_APART_DEG,
                        _ => bound,
                    };
                    if step > limit {
                        continuous = false;
                    }
                    cost += step;
                }
                if ba != bb {
                    cost += BRANCH_SWITCH;
                }
            }
        }
        (cost, continuous)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::{MAX_AXES, builtin};

    fn joints(a: f64, c: f64) -> Joints {
        let mut q = [0.0; MAX_AXES];
        q[3] = a;
        q[4] = c;
        q
    }

    fn trunnion() -> Machine {
        builtin::load("trunnion-ac").unwrap().unwrap()
    }

    #[test]
    fn a_flip_is_not_continuous_but_a_small_step_is() {
        let m = trunnion();
        let (ia, ic) = (m.axis_index("A").unwrap(), m.axis_index("C").unwrap());
        assert_eq!((ia, ic), (3, 4), "test joints assume X Y Z A C");
        let costs = Costs::new(&m, 0.5, Some(ic));
        let cut = Link::Cut {
            turn_deg: 0.5,
            across_singular: false,
            fold_deg: 0.0,
            across_fold: false,
        };
        let (c, ok) = costs.transition(&joints(30.0, 10.0), 0, &joints(30.5, 10.2), 0, cut);
        assert!(ok);
        assert!((c - 0.7).abs() < 1e-12, "{c}");
        let (_, ok) = costs.transition(&joints(30.0, 10.0), 0, &joints(-30.0, 190.0), 1, cut);
        assert!(!ok, "a 180° flip of C for a 0.5° turn of the tool axis");
        // Across a singular stretch C may turn by half a turn, A may not.
        let across = Link::Cut {
            turn_deg: 1.0,
            across_singular: true,
            fold_deg: 0.0,
            across_fold: false,
        };
        let (_, ok) = costs.transition(&joints(0.4, 10.0), 0, &joints(0.4, 190.0), 0, across);
        assert!(ok);
        // A switch of branch away from the pole is a flip, however small
        // the turn of the tool axis.
        let (_, ok) = costs.transition(&joints(40.0, 10.0), 0, &joints(38.0, 12.0), 1, cut);
        assert!(!ok);
        // Also within the step floor (near a fold the branches may lie that
        // close without meeting between the points).
        let (_, ok) = costs.transition(&joints(40.0, 10.0), 0, &joints(40.2, 10.9), 1, cut);
        assert!(!ok);
        let (_, ok) = costs.transition(&joints(40.0, 10.0), 0, &joints(40.2, 10.9), 0, cut);
        assert!(ok);
        // Whole turns never pass.
        let (_, ok) = costs.transition(&joints(40.0, 10.0), 0, &joints(40.0, 370.0), 0, across);
        assert!(!ok);
        // Free moves only cost travel.
        let (c, ok) = costs.transition(&joints(0.0, 0.0), 0, &joints(90.0, 170.0), 1, Link::Free);
        assert!(ok);
        assert_eq!(c, 260.0);
    }

    #[test]
    fn near_a_fold_a_branch_moves_faster_and_across_it_may_switch() {
        let m = trunnion();
        let costs = Costs::new(&m, 0.5, None);
        // A 0.005° turn allows the 1° floor; near a fold the branches'
        // separation adds `fold_deg`.
        let link = |fold_deg, across_fold| Link::Cut {
            turn_deg: 0.005,
            across_singular: false,
            fold_deg,
            across_fold,
        };
        let near = |across_fold| link(1.5, across_fold);
        let (a, b) = (joints(56.8, 32.7), joints(58.3, 32.5));
        let cut = link(0.0, false);
        assert!(!costs.transition(&a, 0, &b, 0, cut).1);
        assert!(costs.transition(&a, 0, &b, 0, near(false)).1);
        // Switching branch needs the fold between the points, even for a
        // step within the floor.
        assert!(!costs.transition(&a, 0, &b, 1, near(false)).1);
        let c = joints(57.0, 32.6);
        assert!(!costs.transition(&a, 0, &c, 1, near(false)).1);
        assert!(costs.transition(&a, 0, &c, 1, near(true)).1);
        assert!(costs.transition(&a, 0, &b, 1, near(true)).1);
        // The fast path's limits say the same.
        let rule = costs.cut_rule().unwrap();
        for across_fold in [false, true] {
            let l = rule.limits(0.005, false, 1.5, across_fold);
            assert_eq!(l.same[0], 2.5);
            assert_eq!(l.switch[0], if across_fold { 2.5 } else { 0.0 });
        }
        // However far apart the branches, no step of a cut reaches half a
        // turn (joint interpolation would go the other way round).
        let (d, e) = (joints(10.0, -142.0), joints(10.0, 76.0));
        assert!(!costs.transition(&d, 0, &e, 0, link(250.0, false)).1);
        assert!(
            costs
                .transition(&d, 0, &joints(10.0, 36.0), 0, link(250.0, false))
                .1
        );
        assert_eq!(
            rule.limits(0.005, false, 250.0, false).same[0],
            STEP_CEILING_DEG
        );
    }

    #[test]
    fn near_a_limit_and_against_the_preference_cost_more() {
        let mut m = trunnion();
        let ia = m.axis_index("A").unwrap();
        let [_, hi] = m.axes[ia].limits.unwrap();
        let costs = Costs::new(&m, 0.5, None);
        assert_eq!(costs.unary(&joints(0.0, 0.0)), 0.0);
        assert!(costs.unary(&joints(hi, 0.0)) >= NEAR_LIMIT * 0.999);
        m.axes[ia].prefer = Some(Prefer::Negative);
        let costs = Costs::new(&m, 0.5, None);
        assert!(costs.unary(&joints(10.0, 0.0)) > costs.unary(&joints(-10.0, 0.0)));
    }

    #[test]
    fn unwind_axes_return_to_the_principal_turn_between_segments() {
        let mut m = trunnion();
        let ic = m.axis_index("C").unwrap();
        m.axes[ic].wrap = Wrap::Unwind;
        m.axes[ic].limits = Some([-1080.0, 1080.0]);
        let costs = Costs::new(&m, 0.5, None);
        let from = joints(0.0, 700.0);
        let (near, _) = costs.transition(&from, 0, &joints(0.0, 710.0), 0, Link::Free);
        let (principal, _) = costs.transition(&from, 0, &joints(0.0, -10.0), 0, Link::Free);
        assert!(principal < near);
    }

    #[test]
    fn unary_leaves_out_only_what_adds_nothing() {
        // The sum over every rotary axis, as before axes without a
        // preference were left out: the same bits.
        let reference = |c: &Costs, q: &Joints| {
            let mut cost = 0.0;
            for l in &c.limited {
                let d = (q[l.index] - l.lo).min(l.hi - q[l.index]);
                if d < l.margin {
                    let x = (l.margin - d.max(0.0)) / l.margin;
                    cost += NEAR_LIMIT * x * x;
                }
            }
            for r in &c.rotary {
                let v = q[r.index];
                cost += PREFERENCE
                    * match r.prefer {
                        None => 0.0,
                        Some(Prefer::Zero) => v.abs(),
                        Some(Prefer::Positive) => (-v).max(0.0),
                        Some(Prefer::Negative) => v.max(0.0),
                    };
            }
            cost
        };
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let prefs = [
            None,
            Some(Prefer::Zero),
            Some(Prefer::Positive),
            Some(Prefer::Negative),
        ];
        for name in ["trunnion-ac", "mts1600", "head-head-bc", "table-head-bc"] {
            for round in 0..64 {
                let mut m = builtin::load(name).unwrap().unwrap();
                for a in m.axes.iter_mut().filter(|a| a.is_rotary()) {
                    a.prefer = prefs[(next() % 4) as usize];
                }
                let costs = Costs::new(&m, 0.5, None);
                for _ in 0..256 {
                    let mut q = [0.0; MAX_AXES];
                    for v in &mut q {
                        *v = match next() % 8 {
                            0 => (next() % 9) as f64 * 45.0 - 180.0,
                            1 => -0.0,
                            2 => {
                                [f64::NAN, f64::INFINITY, f64::NEG_INFINITY][(next() % 3) as usize]
                            }
                            3 => (next() % 4000) as f64 * 0.1 - 200.0,
                            _ => (next() % 2_000_000) as f64 * 1e-3 - 1000.0,
                        };
                    }
                    let (a, b) = (costs.unary(&q), reference(&costs, &q));
                    assert_eq!(a.to_bits(), b.to_bits(), "{name} {round} {q:?}");
                }
            }
        }
    }
}
