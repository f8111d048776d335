//! Writing the planned path: every block is rounded as the dialect writes it,
//! run back through the forward kinematics and checked, given its feed word,
//! and written. Between two feed blocks the post inserts blocks until the
//! contact point, moved linearly in joint space, stays on the straight CL
//! segment (linearization); where the planner found no continuous motion it
//! retracts along the tool axis, reconfigures and re-approaches.

use std::io::Write;

use kinpost_diag::{Diagnostic, Severity};
use kinpost_machine::angle::SinCosMemo;
use kinpost_machine::{
    Joints, Kinematics, MAX_AXES, Machine, Pose, Singularity, Solution, lever_over, midpoint_bound,
};
use kinpost_nc::{Block, Motion, NcWriter};
use kinpost_plan::STEP_CEILING_DEG;
use nalgebra::Vector3;

use crate::check::{CheckStats, Tolerance, angle_between, pose_error, reference_error};
use crate::post::{FeedMode, Pending, PostError, describe, write_pending};
use crate::solve::{Hold, Near, interpolate, solve_near};
use crate::summary::{FeedClamp, Planning, Reconfiguration};

/// Deepest halving of one CL segment by the linearization (2^16 blocks).
const MAX_DEPTH: u32 = 16;
/// Most equal pieces a CL segment is cut into at once by the linearization
/// (each may still be halved).
const MAX_PIECES: f64 = 4096.0;
/// How many more pieces than the midpoint's deviation says are cut at once,
/// so that a segment of even curvature needs no halving after.
const PIECES_MARGIN: f64 = 1.05;
/// What the chord bound adds for the ends of a joint motion not being
/// exactly on their CL points (the inverse kinematics is exact to 1e-9 mm).
const CHORD_SLACK_MM: f64 = 1e-6;
/// A block whose tool point moves less than this, mm, only turns.
const PURE_TURN_MM: f64 = 1e-3;
/// A rotary axis without a maximum velocity that a feed block turns faster
/// than this, degrees per minute (100 turns a minute), is warned about once.
const FAST_TURN_DEG_PER_MIN: f64 = 36_000.0;
/// At most this many feed clamps are listed (all are counted).
const MAX_CLAMPS_LISTED: usize = 1000;

/// A configuration to write, with the pose it must reach.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Node {
    /// The pose the block must reach (the CL pose, or the pose the machine
    /// points with a singular angle held).
    pub pose: Pose,
    /// Exact (unrounded, unwrapped) axis values.
    pub joints: Joints,
    /// The singular angle held at this node, if any.
    pub hold: Option<Hold>,
    /// The closed-form branch of `joints` (see [`kinpost_machine::Solution`]).
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

/// One CL point as the planner hands it over.
pub(crate) struct Target<'a> {
    pub node: &'a Node,
    pub motion: Motion,
    pub line: usize,
    /// CL feed rate, mm/min.
    pub feed: Option<f64>,
    /// The pressure as written (NaN: none); the caller has put the
    /// kinematics of the wheel there in force.
    pub pressure: f64,
    /// The move into it is continuous (else: retract and reconfigure).
    pub continuous: bool,
    /// The move into it is part of a cut (not the start of a segment).
    pub cut: bool,
    /// Makes an error diagnostic at this point's CL line.
    pub at: &'a dyn Fn(String) -> PostError,
}

/// The previous written block.
#[derive(Debug, Clone, Copy)]
struct Last {
    node: Node,
    /// The pressure it was written at (NaN: none).
    pressure: f64,
    line: usize,
    /// Values as handed to the writer (tool point on X, Y, Z in TCP output).
    values: Joints,
    /// Upper bound of the lever of `node.joints` (see
    /// [`kinpost_machine::midpoint_bound`]); infinite when unknown.
    lever: f64,
}

/// Settings of the emitter.
#[derive(Debug, Clone)]
pub(crate) struct EmitSettings {
    pub feed_mode: FeedMode,
    /// Linearization tolerance, mm; 0: off.
    pub lintol: f64,
    pub retract_mm: f64,
    pub reconfigure: bool,
    pub tolerance: Tolerance,
    pub tolerance_given: bool,
    /// Tool-centre-point output: indices of X, Y, Z.
    pub tcp: Option<[usize; 3]>,
    /// One unit of the last written decimal, per axis.
    pub resolution: Vec<f64>,
    /// The machine's singular direction and the cone around it, rad.
    pub singularity: Option<Singularity>,
    pub cone_rad: f64,
}

pub(crate) struct Emitter<W: Write> {
    pub writer: NcWriter<W>,
    pub settings: EmitSettings,
    n: usize,
    /// Free rotary axes.
    rotary: Vec<usize>,
    /// Free linear axes.
    linear: Vec<usize>,
    /// Free rotary axes with `wrap = "unwind"`.
    unwind: Vec<usize>,
    /// How far rounding can move the axes, as [`Kinematics::joint_travel`]
    /// measures it: one unit of the last decimal of every free axis.
    rounding_travel: (f64, f64),
    /// Rotary axes without a maximum velocity already warned about for
    /// turning implausibly fast in a feed block, and the block just found
    /// (axis, degrees per minute, degrees, minutes).
    fast_warned: Vec<usize>,
    fast_turn: Option<(usize, f64, f64, f64)>,
    /// Axes with a maximum velocity (index, units per minute).
    vmax: Vec<(usize, f64)>,
    names: Vec<String>,
    /// The machine has a pressure axis: its column follows the axes.
    has_pressure: bool,
    /// The pressure of the blocks being written.
    pressure: f64,
    last: Option<Last>,
    /// Where the tool is before the next block is not known: at the start
    /// and after a tool change (the machine went to where it changes
    /// tools). A feed block from there has no length, hence no time.
    start_unknown: bool,
    /// Inverse-time feed (`inverse_time_on`) is in force: switched on for
    /// the first feed block with a known start, off again for a feed block
    /// without one (see [`Emitter::block`]).
    pub inverse_time_on: bool,
    written: Joints,
    /// The sines and cosines of the written rotary values, for the next
    /// block's check.
    sin_cos: SinCosMemo,
    solutions: Vec<Solution>,
    inserted: Vec<Node>,
    /// The equal pieces a long CL segment is first cut into (scratch).
    pieces: Vec<Node>,
    /// The CL line of the point being written (the end of the segment the
    /// linearization works on).
    segment_line: usize,
    pub stats: CheckStats,
    pub planning: Planning,
    /// Warnings about what the post could not do as the CL asks (a segment
    /// left uncut), at their CL lines.
    pub warnings: Vec<Diagnostic>,
}

impl<W: Write> Emitter<W> {
    pub fn new(machine: &Machine, writer: NcWriter<W>, settings: EmitSettings) -> Self {
        let axes = &machine.axes;
        let free = |rotary: bool| {
            (0..axes.len())
                .filter(|&i| axes[i].is_free() && axes[i].is_rotary() == rotary)
                .map(|i| settings.resolution[i])
                .sum::<f64>()
        };
        let rounding_travel = (free(true).to_radians(), free(false));
        Emitter {
            writer,
            rounding_travel,
            fast_warned: Vec::new(),
            fast_turn: None,
            settings,
            n: axes.len(),
            rotary: machine.free_rotary_axes().collect(),
            unwind: machine.unwinding_axes().collect(),
            linear: (0..axes.len())
                .filter(|&i| axes[i].is_free() && !axes[i].is_rotary())
                .collect(),
            vmax: (0..axes.len())
                .filter(|&i| axes[i].is_free())
                .filter_map(|i| axes[i].max_velocity.map(|v| (i, v)))
                .collect(),
            names: axes.iter().map(|a| a.name.clone()).collect(),
            has_pressure: machine.pressure.is_some(),
            pressure: f64::NAN,
            last: None,
            start_unknown: true,
            inverse_time_on: false,
            written: [0.0; MAX_AXES],
            sin_cos: SinCosMemo::default(),
            solutions: Vec::with_capacity(16),
            inserted: Vec::new(),
            pieces: Vec::new(),
            segment_line: 0,
            stats: CheckStats::default(),
            planning: Planning::default(),
            warnings: Vec::new(),
        }
    }

    /// Writes a statement of the CL between motion blocks (comment, tool
    /// change, spindle, coolant, insert).
    pub fn write_pending(&mut self, p: Pending) -> Result<(), PostError> {
        if p.changes_tool() {
            self.start_unknown = true;
        }
        write_pending(&mut self.writer, p)
    }

    /// Writes one planned CL point and whatever must come before it.
    pub fn emit(
        &mut self,
        machine: &Machine,
        kin: &Kinematics,
        t: &Target,
    ) -> Result<(), PostError> {
        self.pressure = t.pressure;
        self.segment_line = t.line;
        if let Some(last) = &mut self.last
            && last.pressure.to_bits() != t.pressure.to_bits()
        {
            // The wheel moves with the pressure (seed 001): the last block's
            // axes put the contact point elsewhere now. Before a feed move,
            // the axes bring it back onto the last point first, in a block
            // of its own with the new pressure word; otherwise (a rapid
            // follows, or the point cannot be reached at the new pressure)
            // the move starts where the contact point went.
            let near = Near {
                joints: &last.node.joints,
                hold: last.node.hold,
                branch: Some(last.node.branch),
            };
            let back = match t.motion {
                Motion::Feed => solve_near(
                    kin,
                    &last.node.pose,
                    &near,
                    &self.rotary,
                    &mut self.solutions,
                ),
                Motion::Rapid => None,
            };
            if let Some((pose, sol)) = back {
                let node = Node::solved(pose, &sol, last.node.hold);
                self.inserted(machine, kin, &node, Motion::Feed, t)?;
            } else {
                let here = kin.fk(&last.node.joints[..self.n]);
                last.node.pose = Pose {
                    reference: last.node.pose.reference.and(here.reference),
                    ..here
                };
                last.lever = f64::INFINITY;
            }
        }
        if let Some(last) = &self.last
            && t.motion == Motion::Feed
        {
            let linearize = self.settings.lintol > 0.0 && self.settings.tcp.is_none();
            if t.cut && !t.continuous {
                let last = *last;
                for node in &self.reconfigure(machine, kin, &last, t)? {
                    self.inserted(machine, kin, node, Motion::Feed, t)?;
                }
            } else if linearize
                && let Some(bound) =
                    chord_settles(kin, &last.node, t.node, last.lever, self.settings.lintol)
            {
                let p = &mut self.planning;
                p.max_linearization_error_mm = p.max_linearization_error_mm.max(bound);
            } else if linearize {
                let (from, lever, from_line) = (last.node, last.lever, last.line);
                self.inserted.clear();
                let mut inserted = std::mem::take(&mut self.inserted);
                let result = self.split(kin, &from, t.node, lever, 0, &mut inserted);
                match result {
                    Ok(()) => {}
                    // A move that starts a segment may be a repositioning
                    // the CL asks for at feed: it is written as it is.
                    Err(_) if !t.cut => inserted.clear(),
                    Err(e) => {
                        let to = &t.node.pose;
                        // Leaving the band explains a midpoint the machine
                        // cannot reach and halving that does not converge.
                        let band = match e {
                            SplitError::LinearPlane => None,
                            _ => outside_the_band(kin, &from.pose, to),
                        };
                        return Err((t.at)(match band {
                            Some(band) => format!(
                                "the tool axis interpolated between CL line {from_line} and this point, {}, {band}",
                                describe(to)
                            ),
                            None => format!(
                                "{} between CL line {from_line} and this point, {}",
                                e.message(),
                                describe(to)
                            ),
                        }));
                    }
                }
                for node in &inserted {
                    self.inserted(machine, kin, node, Motion::Feed, t)?;
                }
                self.inserted = inserted;
            }
        }
        if t.motion == Motion::Rapid
            && let Some(last) = &self.last
        {
            // An axis that unwinds at the start of a segment does so where
            // the rapid ends, not while the tool leaves the cut: the rapid
            // keeps the turn it has, and a block of its own then unwinds
            // the whole turns (the same pose).
            let mut kept = *t.node;
            for &i in &self.unwind {
                let turns = ((last.node.joints[i] - kept.joints[i]) / 360.0).round();
                kept.joints[i] += 360.0 * turns;
            }
            if kept.joints != t.node.joints && kept.joints != last.node.joints {
                self.inserted(machine, kin, &kept, Motion::Rapid, t)?;
            }
        }
        self.block(
            machine,
            kin,
            t.node,
            t.motion,
            Some(t.line),
            t.line,
            t.feed,
            t.at,
        )
    }

    /// A block the post inserts before CL point `t` (it has no CL line of
    /// its own).
    fn inserted(
        &mut self,
        machine: &Machine,
        kin: &Kinematics,
        node: &Node,
        motion: Motion,
        t: &Target,
    ) -> Result<(), PostError> {
        self.block(machine, kin, node, motion, None, t.line, t.feed, t.at)?;
        self.planning.inserted_blocks += 1;
        Ok(())
    }

    /// Halves the CL segment `a`–`b` until the contact point at the
    /// joint-space midpoint of every piece lies within the tolerance of the
    /// straight segment; the inserted nodes go to `out` in path order.
    /// `lever`: a bound of the lever at `a` (infinite when unknown).
    fn linearize(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        b: &Node,
        lever: f64,
        depth: u32,
        out: &mut Vec<Node>,
    ) -> Result<(), SplitError> {
        if let Some(bound) = chord_settles(kin, a, b, lever, self.settings.lintol) {
            let p = &mut self.planning;
            p.max_linearization_error_mm = p.max_linearization_error_mm.max(bound);
            return Ok(());
        }
        self.split(kin, a, b, lever, depth, out)
    }

    /// [`Emitter::linearize`] for a segment the chord bound did not settle:
    /// the midpoint's forward kinematics decides, and the pieces recurse.
    fn split(
        &mut self,
        kin: &Kinematics,
        a: &Node,
        b: &Node,
        lever: f64,
        depth: u32,
        out: &mut Vec<Node>,
    ) -> Result<(), SplitError> {
        let n = self.n;
        let mid = joints_at(a, b, 0.5, n);
        let reached = kin.fk(&mid[..n]).point;
        let deviation = distance_to_segment(&reached, &a.pose.point, &b.pose.point);
        let lintol = self.settings.lintol;
        if deviation <= lintol {
            let p = &mut self.planning;
            p.max_linearization_error_mm = p.max_linearization_error_mm.max(deviation);
            return Ok(());
        }
        let turn = angle_between(&a.pose.axis, &b.pose.axis);
        let span = (a.pose.point - b.pose.point).norm();
        if depth >= MAX_DEPTH || (span < 1e-7 && turn < 1e-9) {
            // The axes move while the pose hardly does: not a continuous
            // motion of the tool. Where the volume the linear axes span
            // (1 for axes at right angles) is nearly zero or changes sign,
            // their directions (turned by rotary axes between them in the
            // chain) become coplanar there, and their travel grows like
            // the inverse of the distance to that place.
            let volume = |q: &Joints| linear_volume(kin, q, self.n, &self.linear);
            let coplanar = match (volume(&a.joints), volume(&b.joints)) {
                (Some(va), Some(vb)) => va * vb <= 0.0 || va.abs().min(vb.abs()) < 0.02,
                _ => false,
            };
            return Err(if coplanar {
                SplitError::LinearPlane
            } else {
                SplitError::NoConvergence
            });
        }
        // The deviation of a piece shrinks like the square of its length: a
        // CL segment that strays too far for two halves (a long move with a
        // large turn) is cut at once into as many equal pieces as that says
        // it needs, instead of being halved down to a power of two of them.
        // Each piece is then checked like any segment, and halved where it
        // still strays. (Not where the interpolated tool axis leaves the
        // directions the machine can point: the deviation is uneven along
        // such a segment, and halving puts its nodes where it is.)
        let pieces = ((deviation / lintol).sqrt() * PIECES_MARGIN).ceil();
        if depth == 0
            && deviation > 4.0 * lintol
            && kin
                .folds()
                .is_none_or(|f| f.arc_outside(&a.pose.axis, &b.pose.axis).is_none())
        {
            let pieces = pieces.min(MAX_PIECES);
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
                    // An interpolated tool axis the machine cannot point, a
                    // node it cannot reach, or one in the singular cone
                    // between ends outside it (its angle held beside
                    // exact ones that swing round the pole): halving
                    // decides, as it does for shorter segments. (Halving
                    // holds the angle of every node of a half with a held
                    // end.)
                    _ => break,
                }
            }
            let all = nodes.len() + 1 == pieces as usize;
            let result = if all {
                self.axis_off(off);
                self.linearize_through(kin, a, &nodes, b, lever, depth, out)
            } else {
                Ok(())
            };
            self.pieces = nodes;
            if all {
                return result;
            }
        }
        let (m, _, off) = self.node_at(kin, a, b, 0.5)?;
        self.axis_off(off);
        self.linearize_through(kin, a, &[m], b, lever, depth, out)
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
    ) -> Result<(), SplitError> {
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
    ) -> Result<(Node, bool, f64), SplitError> {
        let guess = joints_at(a, b, t, self.n);
        let pose = interpolate(&a.pose, &b.pose, t);
        // Inside the singular cone the singular angle moves linearly in
        // joint space (held between the ends) instead of swinging.
        let hold = self.settings.singularity.and_then(|s| {
            let held = a.hold.is_some() || b.hold.is_some();
            (held || s.distance(&pose.axis) < self.settings.cone_rad).then_some(Hold {
                axis: s.axis,
                value: guess[s.axis],
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
            return Err(SplitError::OutsideTravel);
        };
        let off = angle_between(&solved.axis, &pose.axis);
        Ok((Node::solved(solved, &sol, hold), natural, off))
    }

    /// Counts an inserted node whose tool axis lies `off_rad` from the CL's
    /// interpolated one (held near the pole, or at the edge of what the
    /// machine can point).
    fn axis_off(&mut self, off_rad: f64) {
        let p = &mut self.planning;
        let deg = off_rad.to_degrees();
        if deg > p.max_inserted_axis_deviation_deg {
            p.max_inserted_axis_deviation_deg = deg;
            p.max_inserted_axis_deviation_line = Some(self.segment_line);
        }
    }

    /// Retract along the tool axis from the last block, turn the rotary axes
    /// to the new configuration above the point before `t` and re-approach
    /// it, so that the segment to `t` is cut in the new configuration: the
    /// rapid and approach blocks are written here, and the feed blocks
    /// that linearize the segment are returned for the caller to write
    /// before `t`. Where the new configuration cannot reach the point
    /// before, or not move on from it continuously, the re-approach is onto
    /// `t` itself and the segment is left uncut (reported).
    fn reconfigure(
        &mut self,
        machine: &Machine,
        kin: &Kinematics,
        last: &Last,
        t: &Target,
    ) -> Result<Vec<Node>, PostError> {
        let (from, to) = (&last.node, t.node);
        if !self.settings.reconfigure {
            return Err((t.at)(format!(
                "no continuous motion reaches this point from CL line {} inside the travel ({}); \
                 a retract and reconfiguration is needed, but --no-reconfigure forbids it",
                last.line,
                self.jump_text(&from.joints, &to.joints)
            )));
        }
        let d = self.settings.retract_mm;
        let lift = |node: &Node| Pose {
            point: node.pose.point + node.pose.axis * d,
            ..node.pose
        };
        // The point before, in the configuration of `t`.
        let resumed = self.resume(kin, from, to);
        let down = resumed.as_ref().map_or(to, |(node, _)| node);
        let (up, over) = (lift(from), lift(down));
        let mut nodes = [*from, *down];
        for (k, (pose, near)) in [(up, from), (over, down)].into_iter().enumerate() {
            let near = Near {
                joints: &near.joints,
                hold: near.hold,
                branch: Some(near.branch),
            };
            let Some((pose, sol)) =
                solve_near(kin, &pose, &near, &self.rotary, &mut self.solutions)
            else {
                return Err((t.at)(format!(
                    "the retract of {d} mm along the tool axis for a reconfiguration {} is outside the travel \
                     (set a smaller distance with --retract or [post] retract)",
                    if k == 0 {
                        "before this point"
                    } else {
                        "above this point"
                    }
                )));
            };
            nodes[k] = Node::solved(pose, &sol, near.hold);
        }
        let (axis, a, b) = self.largest_jump(&from.joints, &to.joints);
        let uncut_mm = match resumed {
            Some(_) => 0.0,
            None => (to.pose.point - from.pose.point).norm(),
        };
        if uncut_mm > 0.0
            && let PostError::Input(mut warning) = (t.at)(format!(
                "the segment from CL line {} to this point ({uncut_mm:.3} mm) is not cut: no setting \
                 of the rotary axes inside the travel moves along it continuously, and after the \
                 retract and reconfiguration ({} {a:.3}° to {b:.3}°) the tool re-approaches this point",
                last.line, self.names[axis]
            ))
        {
            warning.severity = Severity::Warning;
            self.warnings.push(*warning);
        }
        self.planning.reconfigurations.push(Reconfiguration {
            line: t.line,
            previous_line: Some(last.line),
            axis: self.names[axis].clone(),
            from_deg: a,
            to_deg: b,
            retract_mm: d,
            uncut_mm,
        });
        for node in &nodes {
            self.inserted(machine, kin, node, Motion::Rapid, t)?;
        }
        Ok(match resumed {
            // The approach onto the point before, then the segment.
            Some((node, between)) => std::iter::once(node).chain(between).collect(),
            None => Vec::new(),
        })
    }

    /// The point before a reconfiguration (`from`) in the configuration of
    /// the point after it (`to`), and the nodes that linearize the segment
    /// between them: `None` when that configuration cannot reach `from`, or
    /// the segment needs a jump of a rotary axis (beyond the planner's
    /// ceiling of a continuous step) or does not converge to the straight
    /// segment.
    fn resume(&mut self, kin: &Kinematics, from: &Node, to: &Node) -> Option<(Node, Vec<Node>)> {
        let near = Near {
            joints: &to.joints,
            hold: to.hold,
            branch: Some(to.branch),
        };
        let (pose, sol) = solve_near(kin, &from.pose, &near, &self.rotary, &mut self.solutions)?;
        let node = Node::solved(pose, &sol, to.hold);
        let step = self
            .rotary
            .iter()
            .map(|&i| (to.joints[i] - node.joints[i]).abs())
            .fold(0.0, f64::max);
        if node.branch != to.branch || step > STEP_CEILING_DEG {
            return None;
        }
        let mut between = Vec::new();
        if self.settings.lintol > 0.0 && self.settings.tcp.is_none() {
            // (A segment that is then not cut does not count.)
            let error_before = self.planning.max_linearization_error_mm;
            if self
                .linearize(kin, &node, to, f64::INFINITY, 0, &mut between)
                .is_err()
            {
                self.planning.max_linearization_error_mm = error_before;
                return None;
            }
        }
        Some((node, between))
    }

    fn largest_jump(&self, a: &Joints, b: &Joints) -> (usize, f64, f64) {
        let i = self
            .rotary
            .iter()
            .copied()
            .max_by(|&i, &j| (b[i] - a[i]).abs().total_cmp(&(b[j] - a[j]).abs()))
            .unwrap_or(0);
        (i, a[i], b[i])
    }

    fn jump_text(&self, a: &Joints, b: &Joints) -> String {
        let (i, x, y) = self.largest_jump(a, b);
        format!(
            "{} would have to jump from {x:.3}° to {y:.3}°",
            self.names[i]
        )
    }

    /// Rounds, checks and writes one block.
    #[allow(clippy::too_many_arguments)]
    fn block(
        &mut self,
        machine: &Machine,
        kin: &Kinematics,
        node: &Node,
        motion: Motion,
        cl_line: Option<usize>,
        line: usize,
        feed: Option<f64>,
        at: &dyn Fn(String) -> PostError,
    ) -> Result<(), PostError> {
        let n = self.n;
        let pose = &node.pose;
        // Joint output writes the axis values; tool-centre-point output
        // writes the tool point on X, Y, Z and the rotary axis values.
        let mut values = node.joints;
        if let Some([x, y, z]) = self.settings.tcp {
            values[x] = pose.point.x;
            values[y] = pose.point.y;
            values[z] = pose.point.z;
        }
        self.writer
            .quantize_axes(&values[..n], &mut self.written[..n]);
        let (mut reached, written_lever) = kin.fk_lever(
            &self.written[..n],
            &mut self.sin_cos,
            pose.reference.is_some(),
        );
        // The lever at the exact values, from that at the written ones.
        let (w, v) = self.rounding_travel;
        let mut lever = lever_over(written_lever, w, v);
        if let Some([x, y, z]) = self.settings.tcp {
            // The controller puts the tool point where the words say; the
            // orientation comes from the rotary words alone.
            reached.point = Vector3::new(self.written[x], self.written[y], self.written[z]);
            lever = f64::INFINITY;
        }
        if !self
            .stats
            .record(pose, &reached, line, &self.settings.tolerance)
            && !self.within_cl_rounding(kin, pose, &reached, line)
            && !self.within_block_bound(machine, kin, pose, &reached)
        {
            let (p, a) = pose_error(pose, &reached);
            let s = &self.settings;
            return Err(at(format!(
                "closed-loop check failed: the block as written puts the tool {p:.6} mm and {a:.3e} rad \
                 from the CL pose (tolerance {:.6} mm, {:.3e} rad); {}",
                s.tolerance.position_mm,
                s.tolerance.axis_rad,
                describe(pose)
            )));
        }
        let feed = match motion {
            Motion::Rapid => None,
            Motion::Feed => {
                let Some(f) = feed else {
                    return Err(at(
                        "feed move before any FEDRAT: the controller has no feed rate for it"
                            .into(),
                    ));
                };
                // Inverse time says how long a block takes, which a block
                // from an unknown start does not know: it is written at the
                // CL feed rate per minute (G94), inverse time resumes after.
                if self.settings.feed_mode == FeedMode::InverseTime
                    && self.inverse_time_on == self.start_unknown
                {
                    self.inverse_time_on = !self.start_unknown;
                    self.writer.inverse_time(self.inverse_time_on)?;
                }
                let word = self.feed_word(f, node, &values, line);
                if let Some((i, speed, turned, time)) = self.fast_turn.take()
                    && let PostError::Input(mut warning) = at(format!(
                        "this feed block turns {} by {turned:.3}° in {:.1e} s ({speed:.0}°/min): \
                         the machine file gives {} no max_velocity to hold it to",
                        self.names[i],
                        time * 60.0,
                        self.names[i]
                    ))
                {
                    warning.severity = Severity::Warning;
                    self.warnings.push(*warning);
                }
                if word < 1.0 && self.writer.feed_rounds_to_zero(word) {
                    return Err(at(format!(
                        "the feed word {word} rounds to 0 with the dialect's feed decimals (CL feed rate {f} mm/min): \
                         the controller would not move; check the FEDRAT"
                    )));
                }
                Some(word)
            }
        };
        if motion == Motion::Feed
            && let Some(last) = &self.last
        {
            for &i in &self.rotary {
                let step = (node.joints[i] - last.node.joints[i]).abs();
                if step > self.planning.max_rotary_step_deg {
                    self.planning.max_rotary_step_deg = step;
                    self.planning.max_rotary_step_line = Some(line);
                }
            }
        }
        self.last = Some(Last {
            node: *node,
            pressure: self.pressure,
            line,
            values,
            lever,
        });
        // The pressure column, if any, follows the axes (a copy of fixed
        // length: no call to memcpy).
        let mut row = [f64::NAN; MAX_AXES + 1];
        row[..MAX_AXES].copy_from_slice(&values);
        row[n] = self.pressure;
        self.writer
            .block(&Block {
                cl_line,
                motion,
                axes: &row[..n + usize::from(self.has_pressure)],
                feed,
            })
            .map_err(|e| match e.kind() {
                // A value the dialect cannot write: the CL point's fault.
                std::io::ErrorKind::InvalidInput => at(e.to_string()),
                _ => PostError::Io(e),
            })?;
        self.start_unknown = false;
        Ok(())
    }

    /// The feed word of a feed block reaching `node` from the last block:
    /// the block time is the CL segment length over the CL feed rate (a
    /// block that only turns rotary axes takes its largest rotary change in
    /// degrees over the feed rate), slowed down where an axis would exceed
    /// its maximum velocity; the word says that time in the feed mode's
    /// terms.
    fn feed_word(&mut self, feed: f64, node: &Node, values: &Joints, line: usize) -> f64 {
        // At the tool point, only a maximum velocity can make a block
        // slower than the CL feed rate.
        if self.settings.feed_mode == FeedMode::Tip && self.vmax.is_empty() {
            return feed;
        }
        let Some(last) = self.last.as_ref().filter(|_| !self.start_unknown) else {
            return feed;
        };
        let length = (node.pose.point - last.node.pose.point).norm();
        let turn = self
            .rotary
            .iter()
            .map(|&i| (node.joints[i] - last.node.joints[i]).abs())
            .fold(0.0, f64::max);
        // A tool point that moves less than 1 µm (for every dialect alike)
        // does not move: the block only turns, and takes its largest rotary
        // change in degrees over the feed rate taken as degrees per minute.
        // (Its length instead would make the block an instant: F without
        // bound where F is the block time.)
        let distance = if length >= PURE_TURN_MM { length } else { turn };
        if distance <= 1e-9 || feed <= 0.0 {
            return feed;
        }
        let programmed = distance / feed;
        let mut time = programmed;
        let mut limiting = None;
        for &(i, v) in &self.vmax {
            let need = (values[i] - last.values[i]).abs() / v;
            if need > time * (1.0 + 1e-9) {
                time = need;
                limiting = Some(i);
            }
        }
        if let Some(i) = limiting {
            let p = &mut self.planning;
            p.feed_clamp_count += 1;
            if p.feed_clamps.len() < MAX_CLAMPS_LISTED {
                p.feed_clamps.push(FeedClamp {
                    line,
                    axis: self.names[i].clone(),
                    programmed_min: programmed,
                    written_min: time,
                });
            }
        }
        if self.settings.feed_mode != FeedMode::Tip {
            // The block time is what the program says: a rotary axis with no
            // maximum velocity to hold it to may be asked to turn faster
            // than any machine does (a reorientation about the tool point
            // while it hardly moves).
            for &i in &self.rotary {
                let turned = (values[i] - last.values[i]).abs();
                let speed = turned / time;
                if speed > FAST_TURN_DEG_PER_MIN
                    && !self.vmax.iter().any(|&(j, _)| j == i)
                    && !self.fast_warned.contains(&i)
                {
                    self.fast_warned.push(i);
                    self.fast_turn = Some((i, speed, turned, time));
                }
            }
        }
        match self.settings.feed_mode {
            FeedMode::Tip => feed * programmed / time,
            FeedMode::InverseTime => 1.0 / time,
            FeedMode::Dpm => {
                // The controller moves the vector of every axis (mm and
                // degrees together) at F: F = its length / block time.
                let d2: f64 = (0..self.n)
                    .map(|i| (values[i] - last.values[i]).powi(2))
                    .sum();
                if d2 > 0.0 { d2.sqrt() / time } else { feed }
            }
        }
    }

    /// A CL tool axis just outside the directions the machine can point (CL
    /// rounding, see [`Kinematics::axis_rounding`]) is solved at the nearest one it
    /// can point: the block is right if it is within the tolerance of that
    /// direction. The axis tolerance in force (and reported) grows to the
    /// block's error (at most that distance more), and the block is counted
    /// in the summary.
    fn within_cl_rounding(
        &mut self,
        kin: &Kinematics,
        want: &Pose,
        got: &Pose,
        line: usize,
    ) -> bool {
        let (gap, nearest) = kin.axis_reach(&want.axis);
        let t = &mut self.settings.tolerance;
        if gap == 0.0
            || gap > kin.axis_rounding()
            || (want.point - got.point).norm() > t.position_mm
            || angle_between(&nearest, &got.axis) > t.axis_rad
            || reference_error(want, got) > t.axis_rad
        {
            return false;
        }
        t.axis_rad = t.axis_rad.max(pose_error(want, got).1);
        let p = &mut self.planning;
        p.beyond_reach_blocks += 1;
        p.max_beyond_reach_rad = p.max_beyond_reach_rad.max(gap);
        p.first_beyond_reach_line.get_or_insert(line);
        true
    }

    /// With the derived tolerance, a block beyond the machine-wide bound is
    /// still right if its error is what rounding causes at its own levers; the
    /// tolerance in force (and reported) grows to it.
    fn within_block_bound(
        &mut self,
        machine: &Machine,
        kin: &Kinematics,
        want: &Pose,
        got: &Pose,
    ) -> bool {
        let s = &mut self.settings;
        if s.tolerance_given || s.tcp.is_some() {
            return false;
        }
        let resolution = &s.resolution;
        let block = Tolerance::at_block(machine, kin, &self.written[..self.n], |i| resolution[i]);
        let (p, a) = pose_error(want, got);
        if p > block.position_mm || a > block.axis_rad {
            return false;
        }
        s.tolerance.position_mm = s.tolerance.position_mm.max(p);
        s.tolerance.axis_rad = s.tolerance.axis_rad.max(a);
        true
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

/// Distance from `p` to the segment `a`–`b`.
/// The joints at `t` (0..1) of the straight joint motion from `a` to `b`
/// (at 0.5 the exact midpoint).
fn joints_at(a: &Node, b: &Node, t: f64, n: usize) -> Joints {
    let mut q = a.joints;
    for (q, v) in q.iter_mut().zip(&b.joints).take(n) {
        *q = (1.0 - t) * *q + t * v;
    }
    q
}

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

/// Why a CL segment cannot be linearized.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum SplitError {
    /// The directions of the three linear axes become coplanar along it.
    LinearPlane,
    /// The halving reached its depth while the pose hardly moved.
    NoConvergence,
    /// No solution inside the travel at a midpoint.
    OutsideTravel,
}

impl SplitError {
    fn message(self) -> &'static str {
        match self {
            SplitError::LinearPlane => {
                "the linear axes cannot follow the straight CL segment (rotary axes between them in the chain turn their directions into a plane along it, where their travel grows without bound; --lintol 0 writes the segment as one joint move)"
            }
            SplitError::NoConvergence => {
                "the rotary axes cannot follow the path continuously (the joint motion does not converge to the straight CL segment)"
            }
            SplitError::OutsideTravel => {
                "an intermediate pose of the linearization is outside the travel"
            }
        }
    }
}

/// Why no motion follows the CL segment from `a` to `b` when the tool axis
/// interpolated along it (the great circle the linearization follows)
/// leaves the band of directions the machine can point (see
/// [`kinpost_machine::Folds`]), as the end of a sentence on that axis;
/// `None` when it stays inside.
fn outside_the_band(kin: &Kinematics, a: &Pose, b: &Pose) -> Option<String> {
    let e = kin.folds()?.arc_outside(&a.axis, &b.axis)?;
    // Below this the linearization's own rounding, not the machine, decides.
    (e.depth > 1e-9).then(|| {
        // (+ 0.0: no "-0.0000000".)
        let c = e.cone_axis.map(|v| v + 0.0);
        format!(
            "passes {:.4}° into the cone of directions within {:.4}° of ({:.7}, {:.7}, {:.7}) that the machine cannot point: add CL points outside that cone, or --lintol 0 writes the segment as one joint move",
            e.depth.to_degrees(),
            e.half_angle.to_degrees(),
            c.x,
            c.y,
            c.z
        )
    })
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
