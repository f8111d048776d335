//! Dynamic programming over the inverse-kinematics solutions of a path
//! (Viterbi): one layer of candidate configurations per CL point, the
//! cheapest sequence through them by [`Costs`]. Work and memory are linear in
//! the number of points; the layers wait in memory until the caller decides
//! (at the end of the input, or every `lag` points, see
//! [`Trellis::is_full`]), or until the last layer has a single candidate
//! ([`Trellis::is_settled`]): every sequence of the later points goes through
//! it, so the waiting points are decided already, and deciding them then
//! ([`Trellis::decide_settled`]) keeps the layers small (in the cache) and
//! changes no decision.

use kinpost_machine::{Joints, Solution};

use crate::cost::{CUT_BRANCH_SWITCH, Costs, CutLimits, CutRule, Link, MAX_ROTARY};

/// Cost added to a move that is not continuous, so that a retract and
/// reconfiguration is only chosen where no continuous sequence exists.
pub const RECONFIGURE: f64 = 1e9;

/// Cost added to a candidate that no candidate of the point before reaches
/// continuously: after the reconfiguration into it, the tool cannot
/// re-approach the point before in its setting and cut the segment from
/// there, so the segment would be left uncut. Ten reconfigurations cost
/// less: another turn of the axes elsewhere is better than a skipped
/// segment.
pub const UNCUT: f64 = 10.0 * RECONFIGURE;

/// One candidate configuration of one point and how it is reached.
#[derive(Debug, Clone, Copy)]
struct Node {
    joints: Joints,
    /// Index in `nodes` of the predecessor on the cheapest sequence ending
    /// here (`u32::MAX`: the anchor).
    back: u32,
    branch: u8,
    /// Whether the move from that predecessor is continuous.
    continuous: bool,
}

/// A node of the last layer, as the next push reads it: only the rotary
/// values that the cost of a cut looks at, the branch and the cost.
#[derive(Debug, Clone, Copy)]
struct Tip {
    rotary: [f64; MAX_ROTARY],
    /// Cheapest cost of a sequence ending here.
    cost: f64,
    branch: u8,
}

/// Adds candidate `s` to the layer being built: its node (for the
/// decision) and its tip (for the next push). `best`: the cost of the
/// cheapest sequence into it, its predecessor and whether that move is
/// continuous.
#[inline(always)]
fn add_node(
    nodes: &mut Vec<Node>,
    next: &mut Vec<Tip>,
    s: &Solution,
    rotary: [f64; MAX_ROTARY],
    best: (f64, u32, bool),
) {
    next.push(Tip {
        rotary,
        cost: best.0,
        branch: s.branch,
    });
    nodes.push(Node {
        joints: s.joints,
        back: best.1,
        branch: s.branch,
        continuous: best.2,
    });
}

/// A decided point: the configuration chosen and how it is reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Choice {
    /// The axis values chosen.
    pub joints: Joints,
    /// Their closed-form branch.
    pub branch: u8,
    /// The move into this point is continuous; `false` for a cut that needs
    /// a retract and reconfiguration first.
    pub continuous: bool,
}

/// The layers of the points not decided yet.
#[derive(Debug, Clone)]
pub struct Trellis {
    costs: Costs,
    lag: usize,
    /// The rotary axes of a cut, when the fast path handles them (else every
    /// pair goes through [`Costs::transition`]).
    rule: Option<CutRule>,
    nodes: Vec<Node>,
    /// Index in `nodes` of the first node of each layer.
    layers: Vec<u32>,
    /// The nodes of the last layer, in order, as the next push reads them.
    tips: Vec<Tip>,
    /// The layer being pushed (swapped with `tips` once it has a node).
    next: Vec<Tip>,
    /// Index in `tips` of the first of the cheapest (by `total_cmp`).
    cheapest: usize,
    /// The configuration before the first layer (the last decided point),
    /// if any.
    anchor: Option<(Joints, u8)>,
    /// The cost of the cheapest sequence into the anchor since the last
    /// [`Trellis::decide`] (0 after it): what a settled decision leaves
    /// for the sums of the later points, so that they are those of one
    /// decision at the end, bit for bit.
    anchor_cost: f64,
    /// Points pushed since the last [`Trellis::decide`] (settled decisions
    /// do not count as one): `lag` counts these.
    pushed: usize,
}

impl Trellis {
    /// `lag`: how many points may wait before [`Trellis::is_full`] asks for a
    /// decision (1: decide point by point).
    pub fn new(costs: Costs, lag: usize) -> Trellis {
        Trellis {
            rule: costs.cut_rule(),
            costs,
            lag: lag.max(1),
            nodes: Vec::new(),
            layers: Vec::new(),
            tips: Vec::new(),
            next: Vec::new(),
            cheapest: 0,
            anchor: None,
            anchor_cost: 0.0,
            pushed: 0,
        }
    }

    /// The cost model.
    pub fn costs(&self) -> &Costs {
        &self.costs
    }

    /// Number of points waiting.
    pub fn len(&self) -> usize {
        self.layers.len()
    }

    /// Whether no point waits.
    pub fn is_empty(&self) -> bool {
        self.layers.is_empty()
    }

    /// Whether the caller should decide now: `lag` points were pushed since
    /// the last [`Trellis::decide`].
    pub fn is_full(&self) -> bool {
        self.pushed >= self.lag
    }

    /// Whether the waiting points are decided already: the last layer has a
    /// single candidate, which every sequence of the later points extends.
    pub fn is_settled(&self) -> bool {
        self.tips.len() == 1 && !self.layers.is_empty()
    }

    /// The configuration before the waiting points.
    pub fn anchor(&self) -> Option<&Joints> {
        self.anchor.as_ref().map(|(j, _)| j)
    }

    /// The cheapest configuration of the last waiting point, else the
    /// anchor.
    pub fn best_last(&self) -> Option<&Joints> {
        match self.layers.last() {
            Some(&first) => Some(&self.nodes[first as usize + self.cheapest].joints),
            None => self.anchor(),
        }
    }

    /// Adds a point with its candidate configurations (invalid ones are left
    /// out) reached from the previous point by `link`. The first point of a
    /// program starts from home (all zero), as a free move. Returns `false`
    /// (and adds nothing) when no candidate is valid.
    pub fn push(&mut self, candidates: &[Solution], link: Link) -> bool {
        let first = self.nodes.len();
        let previous = self.layers.last().map(|&s| s as usize);
        self.next.clear();
        match (previous, link, &self.rule) {
            (
                Some(p),
                Link::Cut {
                    turn_deg,
                    across_singular,
                    fold_deg,
                    across_fold,
                },
                Some(rule),
            ) => {
                let limits = rule.limits(turn_deg, across_singular, fold_deg, across_fold);
                let layer = Layer {
                    costs: &self.costs,
                    tips: &self.tips,
                    previous: p,
                    nodes: &mut self.nodes,
                    next: &mut self.next,
                };
                match rule.n {
                    1 => layer.cut::<1>(candidates, &rule.axes, &limits),
                    2 => layer.cut::<2>(candidates, &rule.axes, &limits),
                    _ => layer.cut::<3>(candidates, &rule.axes, &limits),
                }
            }
            _ => self.push_general(candidates, previous, link),
        }
        if self.next.is_empty() {
            return false;
        }
        let mut cheapest = 0;
        for (k, t) in self.next.iter().enumerate().skip(1) {
            if t.cost.total_cmp(&self.next[cheapest].cost).is_lt() {
                cheapest = k;
            }
        }
        self.cheapest = cheapest;
        std::mem::swap(&mut self.tips, &mut self.next);
        self.layers.push(first as u32);
        self.pushed += 1;
        true
    }

    /// Any other push, through [`Costs::transition`].
    fn push_general(&mut self, candidates: &[Solution], previous: Option<usize>, link: Link) {
        for s in candidates.iter().filter(|s| s.is_valid()) {
            let unary = self.costs.unary(&s.joints);
            let mut best = (f64::INFINITY, u32::MAX, true);
            match previous {
                Some(first) => {
                    let mut reached = false;
                    for (k, p) in self.tips.iter().enumerate() {
                        let k = first + k;
                        let (c, continuous) = self.costs.transition(
                            &self.nodes[k].joints,
                            p.branch,
                            &s.joints,
                            s.branch,
                            link,
                        );
                        reached |= continuous;
                        let total = p.cost + c + if continuous { 0.0 } else { RECONFIGURE };
                        // Strictly less: ties keep the earlier candidate.
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
                        None => ([0.0; kinpost_machine::MAX_AXES], s.branch, Link::Free),
                    };
                    let (c, continuous) = self
                        .costs
                        .transition(&from, branch, &s.joints, s.branch, link);
                    // The same sum, in the same order, as from a previous
                    // layer (the anchor's cost is 0 after a decision that is
                    // not settled), the anchor being the only configuration
                    // of its point.
                    let mut total =
                        self.anchor_cost + c + if continuous { 0.0 } else { RECONFIGURE };
                    if !continuous {
                        total += UNCUT;
                    }
                    best = (total, u32::MAX, continuous);
                }
            }
            let mut rotary = [0.0; MAX_ROTARY];
            if let Some(rule) = &self.rule {
                for (v, &i) in rotary.iter_mut().zip(&rule.axes[..rule.n]) {
                    *v = s.joints[i];
                }
            }
            add_node(
                &mut self.nodes,
                &mut self.next,
                s,
                rotary,
                (best.0 + unary, best.1, best.2),
            );
        }
    }

    /// Decides every waiting point: the cheapest sequence, in path order,
    /// appended to `out`. The last choice becomes the anchor of what follows,
    /// whose costs start from zero.
    pub fn decide(&mut self, out: &mut Vec<Choice>) {
        self.pushed = 0;
        self.anchor_cost = 0.0;
        self.decide_waiting(out);
    }

    /// [`Trellis::decide`] for a settled trellis ([`Trellis::is_settled`]):
    /// the same choices, and the later points are costed as if nothing had
    /// been decided (their decisions are those of one decision at the end,
    /// bit for bit, and [`Trellis::is_full`] still counts them from the last
    /// [`Trellis::decide`]). Not settled, it is [`Trellis::decide`].
    pub fn decide_settled(&mut self, out: &mut Vec<Choice>) {
        if !self.is_settled() {
            return self.decide(out);
        }
        let cost = self.tips[0].cost;
        self.decide_waiting(out);
        self.anchor_cost = cost;
    }

    fn decide_waiting(&mut self, out: &mut Vec<Choice>) {
        let Some(&last) = self.layers.last() else {
            return;
        };
        let mut best = 0;
        for k in 1..self.tips.len() {
            if self.tips[k].cost < self.tips[best].cost {
                best = k;
            }
        }
        let best = last as usize + best;
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
        debug_assert_eq!(out.len() - start, self.layers.len());
        let n = &self.nodes[best];
        self.anchor = Some((n.joints, n.branch));
        self.nodes.clear();
        self.layers.clear();
        self.tips.clear();
    }

    /// Sets the configuration the machine is in (e.g. after points decided
    /// outside the trellis); the costs of what follows start from zero.
    pub fn set_anchor(&mut self, joints: Joints, branch: u8) {
        self.anchor = Some((joints, branch));
        self.anchor_cost = 0.0;
    }
}

/// A push of a cut onto a previous layer, on the fast path.
struct Layer<'a> {
    costs: &'a Costs,
    /// The previous layer.
    tips: &'a [Tip],
    /// Index in `nodes` of its first node.
    previous: usize,
    nodes: &'a mut Vec<Node>,
    next: &'a mut Vec<Tip>,
}

impl Layer<'_> {
    /// `N` rotary axes (`axes`): the same sums and comparisons as
    /// [`Costs::transition`], in the same order, with the limits of the link
    /// worked out once.
    #[inline]
    fn cut<const N: usize>(
        self,
        candidates: &[Solution],
        axes: &[usize; MAX_ROTARY],
        limits: &CutLimits,
    ) {
        for s in candidates.iter().filter(|s| s.is_valid()) {
            let unary = self.costs.unary(&s.joints);
            let mut v = [0.0; MAX_ROTARY];
            for k in 0..N {
                v[k] = s.joints[axes[k]];
            }
            let mut best = (f64::INFINITY, u32::MAX, true);
            let mut reached = false;
            for (k, p) in self.tips.iter().enumerate() {
                let switch = p.branch != s.branch;
                let limit = if switch { &limits.switch } else { &limits.same };
                let mut c = 0.0;
                let mut continuous = true;
                for r in 0..N {
                    let step = (v[r] - p.rotary[r]).abs();
                    if step > limit[r] {
                        continuous = false;
                    }
                    c += step;
                }
                if switch {
                    c += CUT_BRANCH_SWITCH;
                }
                reached |= continuous;
                let total = p.cost + c + if continuous { 0.0 } else { RECONFIGURE };
                // Strictly less: ties keep the earlier candidate.
                if total < best.0 {
                    best = (total, (self.previous + k) as u32, continuous);
                }
            }
            if !reached {
                best.0 += UNCUT;
            }
            add_node(
                self.nodes,
                self.next,
                s,
                v,
                (best.0 + unary, best.1, best.2),
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinpost_machine::{MAX_AXES, Machine, builtin};

    fn sol(a: f64, c: f64, branch: u8) -> Solution {
        let mut joints = [0.0; MAX_AXES];
        joints[3] = a;
        joints[4] = c;
        Solution {
            joints,
            branch,
            singular: false,
            nearest_axis: false,
            violation: None,
        }
    }

    fn machine() -> Machine {
        builtin::load("trunnion-ac").unwrap().unwrap()
    }

    fn cut(turn_deg: f64) -> Link {
        Link::Cut {
            turn_deg,
            across_singular: false,
            fold_deg: 0.0,
            across_fold: false,
        }
    }

    #[test]
    fn the_whole_path_decides_the_first_choice() {
        // Point by point, the first point takes A = 10 (nearest zero); but
        // only the A = -10 family stays continuous up to the end, where
        // A = +40 is not offered.
        let m = machine();
        let path: Vec<Vec<Solution>> = vec![
            vec![sol(10.0, 0.0, 0), sol(-12.0, 180.0, 1)],
            vec![sol(20.0, 0.0, 0), sol(-20.0, 180.0, 1)],
            vec![sol(-40.0, 180.0, 1)],
        ];
        let mut global = Trellis::new(Costs::new(&m, 0.5, Some(4)), 100);
        let mut greedy = Trellis::new(Costs::new(&m, 0.5, Some(4)), 1);
        let (mut g, mut p) = (Vec::new(), Vec::new());
        for (i, layer) in path.iter().enumerate() {
            let link = if i == 0 { Link::Free } else { cut(10.0) };
            assert!(global.push(layer, link));
            assert!(greedy.push(layer, link));
            if greedy.is_full() {
                greedy.decide(&mut p);
            }
        }
        global.decide(&mut g);
        let a: Vec<f64> = g.iter().map(|c| c.joints[3]).collect();
        assert_eq!(a, [-12.0, -20.0, -40.0]);
        assert!(g.iter().all(|c| c.continuous));
        let a: Vec<f64> = p.iter().map(|c| c.joints[3]).collect();
        assert_eq!(a, [10.0, 20.0, -40.0]);
        assert!(!p[2].continuous, "point by point needs a reconfiguration");
    }

    #[test]
    fn no_valid_candidate_is_refused() {
        let m = machine();
        let mut t = Trellis::new(Costs::new(&m, 0.5, None), 10);
        let mut bad = sol(0.0, 0.0, 0);
        bad.violation = Some(kinpost_machine::Violation {
            axis: 3,
            value: 200.0,
        });
        assert!(!t.push(&[bad], Link::Free));
        assert!(t.is_empty());
    }

    #[test]
    fn a_forced_flip_is_reported_once() {
        let m = machine();
        let mut t = Trellis::new(Costs::new(&m, 0.5, Some(4)), 10);
        t.push(&[sol(5.0, 0.0, 0)], Link::Free);
        t.push(&[sol(5.0, 0.0, 0)], cut(0.0));
        t.push(&[sol(-5.0, 180.0, 1)], cut(0.1));
        t.push(&[sol(-5.2, 180.0, 1)], cut(0.2));
        let mut out = Vec::new();
        t.decide(&mut out);
        let flags: Vec<bool> = out.iter().map(|c| c.continuous).collect();
        assert_eq!(flags, [true, true, false, true]);
        assert_eq!(t.anchor().unwrap()[3], -5.2);
    }
}
