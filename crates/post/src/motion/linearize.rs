//! Linearization: the nodes to insert between two blocks of a feed move so
//! that the contact point, moved linearly in joint space from block to
//! block (as a controller without tool-centre-point control moves it),
//! stays within the tolerance of the straight CL segment, the tool axis
//! turning in its plane at constant speed.

use kinpost_machine::tolerance::{
    CHORD_SLACK_MM, COPLANAR_VOLUME, MAX_HALVING_DEPTH, MAX_PIECES, PIECES_MARGIN, STALL_SPAN_MM,
    STALL_TURN_RAD,
};
use kinpost_machine::{
    Joints, Kinematics, Pose, Singularity, Solution, angle_between, midpoint_bound,
};
use kinpost_plan::{Hold, Near, Node, interpolate, solve_near};
use nalgebra::Vector3;

use crate::error::LinearizationFailure;

/// What the linearization did, for the summary.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LinearizationReport {
    /// Largest distance of the contact point at the joint-space midpoint of
    /// a feed block from its straight CL segment, mm (an upper bound: the
    /// chord bound where it settled a block).
    pub max_error_mm: f64,
    /// Largest angle between an inserted block's tool axis and the CL's
    /// interpolated one, degrees, and the CL line of its segment.
    pub max_axis_deviation_deg: f64,
    /// See `max_axis_deviation_deg`.
    pub max_axis_deviation_line: Option<usize>,
}

/// The linearization of a machine's feed moves.
pub(crate) struct Linearizer {
    /// The tolerance, mm.
    lintol_mm: f64,
    /// The machine's singular direction and the cone around it, radians.
    singularity: Option<Singularity>,
    cone_rad: f64,
    n: usize,
    /// Free rotary axes.
    rotary: Vec<usize>,
    /// Free linear axes.
    linear: Vec<usize>,
    /// The equal pieces a long CL segment is first cut into (scratch).
    pieces: Vec<Node>,
    solutions: Vec<Solution>,
    /// The CL line of the segment being linearized.
    pub(crate) segment_line: usize,
    pub(crate) report: LinearizationReport,
}

impl Linearizer {
    /// A linearization to `lintol_mm` through `kin`'s machine: `n` axes,
    /// `rotary` and `linear` the free ones; the singular angle is held
    /// inside the cone of half-angle `cone_rad`.
    pub(crate) fn new(
        lintol_mm: f64,
        kin: &Kinematics,
        cone_rad: f64,
        rotary: Vec<usize>,
        linear: Vec<usize>,
    ) -> Linearizer {
        Linearizer {
            lintol_mm,
            singularity: kin.singularity(),
            cone_rad,
            n: kin.axis_count(),
            rotary,
            linear,
            pieces: Vec::new(),
            solutions: Vec::with_capacity(16),
            segment_line: 0,
            report: LinearizationReport::default(),
        }
    }

    /// The chord bound settles the segment `a`–`b` (see [`chord_settles`]);
    /// counted in the report when it does. `lever`: a bound of the lever at
    /// `a` (infinite when unknown).
    #[inline]
    pub(crate) fn settles(&mut self, kin: &Kinematics, a: &Node, b: &Node, lever: f64) -> bool {
        match chord_settles(kin, a, b, lever, self.lintol_mm) {
            Some(bound) => {
                self.report.max_error_mm = self.report.max_error_mm.max(bound);
                true
            }
            None => false,
        }
    }

    /// Halves the CL segment `a`–`b` until the contact point at the
    /// joint-space midpoint of every piece lies within the tolerance of the
    /// straight segment; the inserted nodes go to `out` in path order.
    pub(crate) fn linearize(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        b: &Node,
        lever: f64,
        depth: u32,
        out: &mut Vec<Node>,
    ) -> Result<(), LinearizationFailure> {
        if self.settles(kin, a, b, lever) {
            return Ok(());
        }
        self.split(kin, a, b, lever, depth, out)
    }

    /// [`Linearizer::linearize`] for a segment the chord bound did not
    /// settle: the midpoint's forward kinematics decides, and the pieces
    /// recurse.
    pub(crate) fn split(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        b: &Node,
        lever: f64,
        depth: u32,
        out: &mut Vec<Node>,
    ) -> Result<(), LinearizationFailure> {
        let n = self.n;
        let mid = joints_at(a, b, 0.5, n);
        let reached = kin.fk(&mid[..n]).point;
        let deviation = distance_to_segment(&reached, &a.pose.point, &b.pose.point);
        let lintol = self.lintol_mm;
        if deviation <= lintol {
            self.report.max_error_mm = self.report.max_error_mm.max(deviation);
            return Ok(());
        }
        let turn = angle_between(&a.pose.axis, &b.pose.axis);
        let span = (a.pose.point - b.pose.point).norm();
        if depth >= MAX_HALVING_DEPTH || (span < STALL_SPAN_MM && turn < STALL_TURN_RAD) {
            return Err(self.stall(kin, a, b));
        }
        // The deviation of a piece shrinks like the square of its length: a
        // CL segment that strays too far for two halves (a long move with a
        // large turn) is cut at once into as many equal pieces as that says
        // it needs, instead of being halved down to a power of two of them.
        // Each piece is then checked like any segment, and halved where it
        // still strays. (Not where the interpolated tool axis leaves the
        // directions the machine can point: the deviation is uneven along
        // such a segment, and halving puts its nodes where it is.)
        if depth == 0
            && deviation > 4.0 * lintol
            && kin
                .folds()
                .is_none_or(|f| f.arc_outside(&a.pose.axis, &b.pose.axis).is_none())
        {
            let pieces = ((deviation / lintol).sqrt() * PIECES_MARGIN).ceil();
            if let Some(result) = self.in_pieces(kin, a, b, lever, pieces.min(MAX_PIECES), out) {
                return result;
            }
        }
        let (m, _, off) = self.node_at(kin, a, b, 0.5)?;
        self.axis_off(off);
        self.linearize_through(kin, a, &[m], b, lever, depth, out)
    }

    /// Why halving stopped: the axes move while the pose hardly does, not a
    /// continuous motion of the tool. Where the volume the linear axes span
    /// (1 for axes at right angles) is nearly zero or changes sign, their
    /// directions (turned by rotary axes between them in the chain) become
    /// coplanar there, and their travel grows like the inverse of the
    /// distance to that place.
    fn stall(&self, kin: &Kinematics, a: &Node, b: &Node) -> LinearizationFailure {
        let volume = |q: &Joints| linear_volume(kin, q, self.n, &self.linear);
        let coplanar = match (volume(&a.joints), volume(&b.joints)) {
            (Some(va), Some(vb)) => va * vb <= 0.0 || va.abs().min(vb.abs()) < COPLANAR_VOLUME,
            _ => false,
        };
        if coplanar {
            LinearizationFailure::LinearPlane
        } else {
            LinearizationFailure::NoConvergence
        }
    }

    /// `a`–`b` cut at once into `pieces` equal pieces, each linearized on
    /// its own; `None` where a node between them cannot be had as such (an
    /// interpolated tool axis the machine cannot point, a node it cannot
    /// reach, or one in the singular cone between ends outside it, its
    /// angle held beside exact ones that swing round the pole): halving
    /// decides then, as it does for shorter segments. (Halving holds the
    /// angle of every node of a half with a held end.)
    fn in_pieces(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        b: &Node,
        lever: f64,
        pieces: f64,
        out: &mut Vec<Node>,
    ) -> Option<Result<(), LinearizationFailure>> {
        let mut nodes = std::mem::take(&mut self.pieces);
        nodes.clear();
        let mut off: f64 = 0.0;
        let held_ends = a.hold.is_some() || b.hold.is_some();
        for k in 1..pieces as u32 {
            match self.node_at(kin, a, b, f64::from(k) / pieces) {
                Ok((m, false, m_off)) if m.hold.is_some() == held_ends => {
                    nodes.push(m);
                    off = off.max(m_off);
                }
                _ => break,
            }
        }
        let all = nodes.len() + 1 == pieces as usize;
        let result = all.then(|| {
            self.axis_off(off);
            self.linearize_through(kin, a, &nodes, b, lever, 0, out)
        });
        self.pieces = nodes;
        result
    }

    /// Linearizes `a`–`nodes[0]`–…–`b` (the nodes inserted between `a` and
    /// `b`, in order), pushing the nodes with those between them.
    #[allow(clippy::too_many_arguments)]
    fn linearize_through(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        nodes: &[Node],
        b: &Node,
        lever: f64,
        depth: u32,
        out: &mut Vec<Node>,
    ) -> Result<(), LinearizationFailure> {
        let (mut from, mut from_lever) = (a, lever);
        for m in nodes {
            self.linearize(kin, from, m, from_lever, depth + 1, out)?;
            out.push(*m);
            (from, from_lever) = (m, f64::INFINITY);
        }
        self.linearize(kin, from, b, from_lever, depth + 1, out)
    }

    /// The node the linearization inserts at `t` (0..1) between `a` and `b`:
    /// the CL pose interpolated there, solved nearest the joint-space
    /// interpolation; `true` with it where the machine cannot point the
    /// interpolated tool axis and the node keeps the joint-space one; and
    /// the angle between the node's tool axis and the interpolated one,
    /// radians (not 0 where an angle is held or the axis is beyond reach).
    fn node_at(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        b: &Node,
        t: f64,
    ) -> Result<(Node, bool, f64), LinearizationFailure> {
        let guess = joints_at(a, b, t, self.n);
        let pose = interpolate(&a.pose, &b.pose, t);
        // Inside the singular cone the singular angle moves linearly in
        // joint space (held between the ends) instead of swinging.
        let hold = self.singularity.and_then(|s| {
            let held = a.hold.is_some() || b.hold.is_some();
            (held || s.distance(&pose.axis) < self.cone_rad).then_some(Hold {
                axis: s.axis,
                value_deg: guess[s.axis],
            })
        });
        // Both ends on one branch: the node too. Near a fold the branches
        // lie close, and the joint-space interpolation may be nearer the
        // other one: a switch there would never converge. (Ends on two
        // branches: the nearest.)
        let branch = (a.branch == b.branch).then_some(a.branch);
        let near = Near {
            joints: &guess,
            hold,
            branch,
        };
        let mut natural = false;
        let solved =
            solve_near(kin, &pose, &near, &self.rotary, &mut self.solutions).or_else(|| {
                // The machine cannot point the interpolated tool axis (two
                // rotary axes at an angle other than 90° reach a band of
                // directions only): keep the axis of the joint-space
                // interpolation and put the contact point on the segment.
                natural = true;
                let natural = Pose {
                    axis: kin.fk(&guess[..self.n]).axis,
                    ..pose
                };
                solve_near(kin, &natural, &near, &self.rotary, &mut self.solutions)
            });
        let Some((solved, sol)) = solved else {
            return Err(LinearizationFailure::OutsideTravel);
        };
        let off = angle_between(&solved.axis, &pose.axis);
        Ok((Node::solved(solved, &sol, hold), natural, off))
    }

    /// Counts an inserted node whose tool axis lies `off_rad` from the CL's
    /// interpolated one (held near the pole, or at the edge of what the
    /// machine can point).
    fn axis_off(&mut self, off_rad: f64) {
        let r = &mut self.report;
        let deg = off_rad.to_degrees();
        if deg > r.max_axis_deviation_deg {
            r.max_axis_deviation_deg = deg;
            r.max_axis_deviation_line = Some(self.segment_line);
        }
    }
}

/// Most segments of a fine path are settled by the chord bound of the chain
/// (see [`midpoint_bound`]), without the forward kinematics of their
/// midpoint: the bound, when it is within the linearization tolerance.
/// `lever`: a bound of the lever at `a`.
#[inline]
fn chord_settles(kin: &Kinematics, a: &Node, b: &Node, lever: f64, lintol: f64) -> Option<f64> {
    let n = kin.axis_count();
    let (w, v) = kin.joint_travel(&a.joints[..n], &b.joints[..n]);
    let bound = midpoint_bound(lever, w, v) + CHORD_SLACK_MM;
    (bound <= lintol).then_some(bound)
}

/// The joints at `t` (0..1) of the straight joint motion from `a` to `b`
/// (at 0.5 the exact midpoint).
fn joints_at(a: &Node, b: &Node, t: f64, n: usize) -> Joints {
    let mut q = a.joints;
    for (q, v) in q.iter_mut().zip(&b.joints).take(n) {
        *q = (1.0 - t) * *q + t * v;
    }
    q
}

/// Distance from `p` to the segment `a`–`b`.
pub(crate) fn distance_to_segment(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// The signed volume the directions of three linear axes span at `q` (part
/// frame, by the forward kinematics: the tool point's motion per unit of
/// each axis); `None` unless there are three. It changes sign where rotary
/// axes between them in the chain turn them into a plane.
fn linear_volume(kin: &Kinematics, q: &Joints, n: usize, linear: &[usize]) -> Option<f64> {
    let &[i, j, k] = linear else {
        return None;
    };
    let base = kin.fk(&q[..n]).point;
    let direction = |axis: usize| {
        let mut moved = *q;
        moved[axis] += 1.0;
        kin.fk(&moved[..n]).point - base
    };
    Some(direction(i).dot(&direction(j).cross(&direction(k))))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_to_a_segment() {
        let a = Vector3::new(0.0, 0.0, 0.0);
        let b = Vector3::new(10.0, 0.0, 0.0);
        assert_eq!(
            distance_to_segment(&Vector3::new(5.0, 3.0, 0.0), &a, &b),
            3.0
        );
        assert_eq!(
            distance_to_segment(&Vector3::new(-4.0, 3.0, 0.0), &a, &b),
            5.0
        );
        assert_eq!(
            distance_to_segment(&Vector3::new(1.0, 1.0, 0.0), &a, &a),
            2f64.sqrt()
        );
    }
}
