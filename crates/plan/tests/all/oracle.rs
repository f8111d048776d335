//! The trellis against a straightforward reference implementation (the
//! algorithm before the fast path, kept here as the oracle): random layers
//! of candidates, random links; the same decisions and the same `best_last`
//! bit for bit.

use kinpost_machine::{Joints, MAX_AXES, Machine, Prefer, Solution, Violation, Wrap, builtin};
use kinpost_plan::{Choice, Costs, Link, RECONFIGURE, Trellis, UNCUT};
use proptest::prelude::*;

#[derive(Clone, Copy)]
struct Node {
    joints: Joints,
    branch: u8,
    cost: f64,
    back: u32,
    continuous: bool,
}

/// The reference: every pair through `Costs::transition`.
struct Oracle {
    costs: Costs,
    lag: usize,
    nodes: Vec<Node>,
    layers: Vec<u32>,
    anchor: Option<(Joints, u8)>,
}

impl Oracle {
    fn new(costs: Costs, lag: usize) -> Oracle {
        Oracle {
            costs,
            lag: lag.max(1),
            nodes: Vec::new(),
            layers: Vec::new(),
            anchor: None,
        }
    }

    fn is_full(&self) -> bool {
        self.layers.len() >= self.lag
    }

    fn best_last(&self) -> Option<&Joints> {
        match self.layers.last() {
            Some(&first) => self.nodes[first as usize..]
                .iter()
                .min_by(|a, b| a.cost.total_cmp(&b.cost))
                .map(|n| &n.joints),
            None => self.anchor.as_ref().map(|(j, _)| j),
        }
    }

    fn push(&mut self, candidates: &[Solution], link: Link) -> bool {
        if !candidates.iter().any(Solution::is_valid) {
            return false;
        }
        let first = self.nodes.len() as u32;
        let previous = self.layers.last().map(|&s| s as usize..first as usize);
        for s in candidates.iter().filter(|s| s.is_valid()) {
            let unary = self.costs.unary(&s.joints);
            let mut best = (f64::INFINITY, u32::MAX, true);
            match &previous {
                Some(range) => {
                    // A candidate no configuration of the point before
                    // reaches continuously leaves the segment uncut.
                    let mut reached = false;
                    for k in range.clone() {
                        let p = &self.nodes[k];
                        let (c, continuous) = self
                            .costs
                            .transition(&p.joints, p.branch, &s.joints, s.branch, link);
                        reached |= continuous;
                        let total = p.cost + c + if continuous { 0.0 } else { RECONFIGURE };
                        if total < best.0 {
                            best = (total, k as u32, continuous);
                        }
                    }
                    if !reached {
                        best.0 += UNCUT;
                    }
                }
                None => {
                    let (from, branch, link) = match &self.anchor {
                        Some((j, b)) => (*j, *b, link),
                        None => ([0.0; MAX_AXES], s.branch, Link::Free),
                    };
                    let (c, continuous) = self
                        .costs
                        .transition(&from, branch, &s.joints, s.branch, link);
                    let mut total = c + if continuous { 0.0 } else { RECONFIGURE };
                    if !continuous {
                        total += UNCUT;
                    }
                    best = (total, u32::MAX, continuous);
                }
            }
            self.nodes.push(Node {
                joints: s.joints,
                branch: s.branch,
                cost: best.0 + unary,
                back: best.1,
                continuous: best.2,
            });
        }
        self.layers.push(first);
        true
    }

    fn decide(&mut self, out: &mut Vec<Choice>) {
        let Some(&last) = self.layers.last() else {
            return;
        };
        let mut best = last as usize;
        for k in last as usize..self.nodes.len() {
            if self.nodes[k].cost < self.nodes[best].cost {
                best = k;
            }
        }
        let start = out.len();
        let mut k = best as u32;
        while k != u32::MAX {
            let n = &self.nodes[k as usize];
            out.push(Choice {
                joints: n.joints,
                branch: n.branch,
                continuous: n.continuous,
            });
            k = n.back;
        }
        out[start..].reverse();
        let n = &self.nodes[best];
        self.anchor = Some((n.joints, n.branch));
        self.nodes.clear();
        self.layers.clear();
    }
}

fn machine(which: u8) -> Machine {
    let name = ["trunnion-ac", "mts1600", "head-head-bc", "table-head-bc"][which as usize % 4];
    builtin::load(name).unwrap().unwrap()
}

fn bits(j: Option<&Joints>) -> Option<[u64; MAX_AXES]> {
    j.map(|j| j.map(f64::to_bits))
}

fn same(a: &[Choice], b: &[Choice]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.branch == y.branch
                && x.continuous == y.continuous
                && bits(Some(&x.joints)) == bits(Some(&y.joints))
        })
}

/// A joint value: often from a small grid (ties, equal steps), else any.
fn value() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-4i32..=4).prop_map(|k| k as f64 * 45.0),
        (-200i32..=200).prop_map(|k| k as f64 * 0.25),
        -400.0..400.0f64,
    ]
}

fn solution() -> impl Strategy<Value = Solution> {
    (
        proptest::collection::vec(value(), MAX_AXES),
        0u8..2,
        prop::bool::weighted(0.85),
    )
        .prop_map(|(v, branch, valid)| {
            let mut joints = [0.0; MAX_AXES];
            joints.copy_from_slice(&v);
            Solution {
                joints,
                branch,
                singular: false,
                nearest_axis: false,
                violation: (!valid).then_some(Violation {
                    axis: 3,
                    value: 999.0,
                }),
            }
        })
}

fn link() -> impl Strategy<Value = Link> {
    prop_oneof![
        1 => Just(Link::Free),
        6 => (
            prop_oneof![Just(0.0), 0.0..0.05f64, 0.0..3.0f64, 0.0..200.0f64],
            prop::bool::weighted(0.2),
            prop_oneof![4 => Just(0.0), 1 => 0.0..20.0f64],
            prop::bool::weighted(0.2),
        )
            .prop_map(|(turn_deg, across_singular, fold_deg, across_fold)| Link::Cut {
                turn_deg,
                across_singular,
                fold_deg,
                across_fold,
            }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn the_trellis_decides_as_the_reference(
        which in 0u8..4,
        tweaks in proptest::collection::vec((0u8..4, 0u8..4), MAX_AXES),
        lag in 1usize..8,
        cone in prop_oneof![Just(0.0), 0.1..5.0f64],
        singular in prop::option::of(0usize..6),
        anchor in prop::option::of((solution(), any::<bool>())),
        path in proptest::collection::vec(
            (proptest::collection::vec(solution(), 0..5), link()),
            1..40,
        ),
    ) {
        let mut m = machine(which);
        // Preferences and wraps the built-in machines do not have.
        for (axis, (prefer, wrap)) in m.axes.iter_mut().zip(&tweaks) {
            if axis.is_rotary() {
                axis.prefer = [None, Some(Prefer::Zero), Some(Prefer::Positive), Some(Prefer::Negative)]
                    [*prefer as usize];
                if *wrap == 3 {
                    axis.wrap = Wrap::Unwind;
                }
            }
        }
        let costs = Costs::new(&m, cone, singular);
        let mut fast = Trellis::new(costs.clone(), lag);
        let mut slow = Oracle::new(costs, lag);
        if let Some((s, true)) = anchor {
            fast.set_anchor(s.joints, s.branch);
            slow.anchor = Some((s.joints, s.branch));
        }
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for (layer, link) in &path {
            prop_assert_eq!(bits(fast.best_last()), bits(slow.best_last()));
            prop_assert_eq!(fast.push(layer, *link), slow.push(layer, *link));
            prop_assert_eq!(bits(fast.best_last()), bits(slow.best_last()));
            prop_assert_eq!(fast.is_full(), slow.is_full());
            if fast.is_full() {
                fast.decide(&mut a);
                slow.decide(&mut b);
                prop_assert!(same(&a, &b));
            }
        }
        fast.decide(&mut a);
        slow.decide(&mut b);
        prop_assert!(same(&a, &b));
        prop_assert_eq!(bits(fast.anchor()), bits(slow.anchor.as_ref().map(|(j, _)| j)));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    /// Deciding a settled trellis at once changes no decision: the choices,
    /// the hints and the anchor are those of deciding only when it is full,
    /// bit for bit (the later points are costed as if nothing had been
    /// decided).
    #[test]
    fn settled_decisions_change_nothing(
        which in 0u8..4,
        lag in 1usize..50,
        cone in prop_oneof![Just(0.0), 0.1..5.0f64],
        singular in prop::option::of(0usize..6),
        path in proptest::collection::vec(
            (proptest::collection::vec(solution(), 0..4), link()),
            1..60,
        ),
    ) {
        let costs = Costs::new(&machine(which), cone, singular);
        let mut early = Trellis::new(costs.clone(), lag);
        let mut late = Trellis::new(costs, lag);
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for (layer, link) in &path {
            prop_assert_eq!(early.push(layer, *link), late.push(layer, *link));
            prop_assert_eq!(bits(early.best_last()), bits(late.best_last()));
            prop_assert_eq!(early.is_full(), late.is_full());
            if early.is_full() {
                early.decide(&mut a);
                late.decide(&mut b);
            } else if early.is_settled() {
                early.decide_settled(&mut a);
                prop_assert!(early.is_empty());
            }
        }
        early.decide(&mut a);
        late.decide(&mut b);
        prop_assert!(same(&a, &b));
        prop_assert_eq!(bits(early.anchor()), bits(late.anchor()));
    }
}
