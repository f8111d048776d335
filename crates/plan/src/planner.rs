//! The planner stage: CL points (with their candidate configurations in
//! the [`Trellis`]) and the commands between them wait, in order, until the
//! planner decides (every `lag` points and at the end); then every point
//! goes to the [`PlanSink`] as a decided [`Node`], the commands in their
//! places among them.
//!
//! Points whose tool axis lies within the singular cone are not planned by
//! the trellis. Between the decided points around them, they are solved
//! exactly where no rotary axis then moves faster than a cut allows
//! (see [`PathPlan::exact_run`]); elsewhere their singular angle is
//! interpolated between those points in the same segment (held at the one
//! there is, if only one), and the other axes are solved for it exactly.

use std::ops::Range;

use kinpost_diag::{Located, Site};
use kinpost_machine::angle::atan2_deg;
use kinpost_machine::tolerance::{ARC_SUM_SLACK_DEG, FOLD_SLACK_RAD, NO_LENGTH_MM, POLE_SLACK_RAD};
use kinpost_machine::{
    Folds, IkFailure, Joints, Kinematics, KinematicsAtPressure, MAX_AXES, Machine, Mm, Pose,
    Singularity, Solution, angle_between,
};
use kinpost_nc::Motion;
use nalgebra::Vector3;
use serde::Serialize;

use crate::node::Node;
use crate::pole::Pole;
use crate::solve::{Hold, Near, solve_near};
use crate::{Choice, Link, Rejection, Trellis, rejection};

/// Settled points (see [`PathPlan::is_full`]) written at once: enough that
/// a decision costs next to nothing, few enough that the points, their
/// candidates and their CL text stay in the cache until written.
const SETTLED_BATCH: usize = 256;

/// A CL point as the program hands it to the planner.
#[derive(Debug, Clone, Copy)]
pub struct PathPoint {
    /// The pose in the part frame, mm.
    pub pose: Pose,
    /// Rapid or feed.
    pub motion: Motion,
    /// Its 1-based CL line.
    pub line: usize,
    /// The CL feed rate in force, mm/min.
    pub feed: Option<f64>,
    /// The pressure as written (NaN: none).
    pub pressure: f64,
}

/// A decided point, as the planner hands it to its [`PlanSink`].
#[derive(Debug, Clone, Copy)]
pub struct Planned<'a> {
    /// The configuration decided and the pose it reaches.
    pub node: &'a Node,
    /// Rapid or feed.
    pub motion: Motion,
    /// The CL feed rate in force, mm/min.
    pub feed: Option<f64>,
    /// The pressure as written (NaN: none); the kinematics handed over with
    /// the point is that of this pressure.
    pub pressure: f64,
    /// The move into it is continuous (else: retract and reconfigure).
    pub continuous: bool,
    /// The move into it is part of a cut (not the start of a segment).
    pub cut: bool,
    /// Its CL statement: file, line and text.
    pub site: Site<'a>,
}

/// Where the planner's decisions go: the next stage of the post (the
/// motion stage), or a `Vec` in a test.
pub trait PlanSink<C> {
    /// The sink's error; a planner error at a point becomes one.
    type Error: From<Located<PlanError>>;

    /// A decided point; `kin` is the machine at the point's pressure.
    fn point(&mut self, kin: &Kinematics, point: &Planned<'_>) -> Result<(), Self::Error>;

    /// A command that stood between the points, in its place.
    fn command(&mut self, command: C) -> Result<(), Self::Error>;
}

/// Why a point cannot be planned.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PlanError {
    /// The kinematics has no solution for the pose.
    #[error("{failure}: {pose}")]
    Ik {
        /// Why.
        failure: IkFailure,
        /// The pose.
        pose: Box<Pose>,
    },
    /// Every solution lies outside the travel; the violation of the first
    /// branch is given.
    #[error(
        "no solution inside the travel: {axis} would be {} (limits {} .. {}) for {pose}",
        Mm(*.value),
        .limits[0],
        .limits[1]
    )]
    OutsideTravel {
        /// The axis outside its travel.
        axis: String,
        /// The value it would take.
        value: f64,
        /// Its limits.
        limits: [f64; 2],
        /// The pose.
        pose: Box<Pose>,
    },
    /// The kinematics found no solution at all.
    #[error("no solution for {pose}")]
    NoSolution {
        /// The pose.
        pose: Box<Pose>,
    },
    /// A point in the singular cone cannot be reached with the free angle
    /// held where the points around it say, nor exactly.
    #[error(
        "no solution inside the travel for this singular point with {axis} held at {held_deg:.4}°"
    )]
    HeldOutOfReach {
        /// The axis held (`the free axis` when the machine has none).
        axis: String,
        /// The angle held, degrees.
        held_deg: f64,
    },
}

/// A run of CL points inside the singular cone: solved exactly where that
/// needs no swing of the free axis, else with its angle held.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SingularStretch {
    /// CL line of the first point of the run.
    pub first_line: usize,
    /// CL line of its last point.
    pub last_line: usize,
    /// The free (singular) axis.
    pub axis: String,
    /// Its angle at the first and the last point, degrees.
    pub from_deg: f64,
    /// See `from_deg`.
    pub to_deg: f64,
    /// The largest angle between a point's tool axis and its CL tool axis,
    /// degrees.
    pub max_axis_deviation_deg: f64,
}

/// One CL point waiting for the plan.
#[derive(Debug, Clone)]
struct PlanPoint {
    pose: Pose,
    line: usize,
    motion: Motion,
    feed: Option<f64>,
    /// Its CL line's text in `Planner::source`.
    source: Range<usize>,
    /// In the singular cone: not in the trellis.
    singular: bool,
    /// The pressure as written (NaN: none).
    pressure: f64,
    /// Segment number (a new one at every rapid and break).
    segment: u64,
    /// First point of its segment.
    starts_segment: bool,
}

/// What was decided for a point.
#[derive(Clone, Copy)]
struct Decided {
    node: Node,
    continuous: bool,
}

/// The planner: every decision about which configuration of the machine
/// reaches each CL point (branches, turns, singular runs, folds). `C`: the
/// commands that stand between the points (comments, tool changes, …),
/// passed on in their places.
pub struct Planner<C> {
    trellis: Trellis,
    singularity: Option<Singularity>,
    /// Singular cone half-angle, rad (0: only exactly singular points).
    cone_rad: f64,
    rotary: Vec<usize>,
    /// Free rotary axes with `wrap = "unwind"`.
    unwind: Vec<usize>,
    names: Vec<String>,
    /// The travel of each axis (NaN: none), for errors.
    limits: Vec<[f64; 2]>,
    file: String,
    /// The waiting points, in path order. The buffers of the plan keep their
    /// room from one decision to the next: a decision every `lag` points
    /// must not cost fresh pages.
    points: Vec<PlanPoint>,
    /// Commands among the waiting points, each with the number of waiting
    /// points before it.
    outputs: Vec<(usize, C)>,
    /// CL line texts of the waiting points, back to back.
    source: Vec<u8>,
    /// Since the last point in the trellis: tool-axis turn (degrees), the
    /// tool axis near the singular direction (at a singular point, or
    /// interpolated from point to point), a segment start.
    turn: f64,
    across: bool,
    free: bool,
    /// Tool axis and reference of the last point. (Two fields, not an
    /// option of a pair: that was written in pieces and read back whole,
    /// which stalls the processor.)
    previous_axis: Option<Vector3<f64>>,
    previous_reference: Option<Vector3<f64>>,
    /// Distance from the tool axis of the last point to the singular
    /// direction (`None`: no singularity, or no point yet).
    previous_pole: Option<Pole>,
    /// The folds of the machine (see [`Folds`]), if it has any.
    folds: Option<Folds>,
    /// The separation of the branches of the last point in the trellis (see
    /// [`separation`]), on a machine with folds.
    planned_fold: Option<f64>,
    /// Since the last point in the trellis: the tool axis, interpolated
    /// from point to point, reached a fold.
    fold_reached: bool,
    segment: u64,
    break_pending: bool,
    /// The last point written: its node and segment.
    last: Option<(Node, u64)>,
    choices: Vec<Choice>,
    /// The decided nodes of one run of singular points.
    run: Vec<Decided>,
    solutions: Vec<Solution>,
    stretches: Vec<SingularStretch>,
}

impl<C> Planner<C> {
    /// A planner for `machine` (as the program drives it) with kinematics
    /// `kin`, deciding with `trellis`, holding the free angle inside the
    /// singular cone of half-angle `cone_deg`; `file`: the CL file's name,
    /// for diagnostics.
    pub fn new(
        machine: &Machine,
        kin: &Kinematics,
        trellis: Trellis,
        cone_deg: f64,
        file: &str,
    ) -> Self {
        let axes = &machine.axes;
        Planner {
            trellis,
            singularity: kin.singularity(),
            cone_rad: cone_deg.to_radians(),
            rotary: machine.free_rotary_axes().collect(),
            unwind: machine.unwinding_axes().collect(),
            names: axes.iter().map(|a| a.name.clone()).collect(),
            limits: axes
                .iter()
                .map(|a| a.limits.unwrap_or([f64::NAN, f64::NAN]))
                .collect(),
            file: file.to_string(),
            points: Vec::new(),
            outputs: Vec::new(),
            source: Vec::new(),
            turn: 0.0,
            across: false,
            free: true,
            previous_axis: None,
            previous_reference: None,
            previous_pole: None,
            folds: kin.folds(),
            planned_fold: None,
            fold_reached: false,
            segment: 0,
            break_pending: true,
            last: None,
            choices: Vec::new(),
            run: Vec::new(),
            solutions: Vec::with_capacity(16),
            stretches: Vec::new(),
        }
    }

    /// The path is interrupted here (rapid, tool change, end of an
    /// operation): the next point starts a segment.
    pub fn break_segment(&mut self) {
        self.break_pending = true;
    }

    /// A command between points, passed on in its place.
    pub fn push_command(&mut self, command: C) {
        self.outputs.push((self.points.len(), command));
    }

    /// Whether nothing waits.
    pub fn is_idle(&self) -> bool {
        self.points.is_empty() && self.outputs.is_empty()
    }

    /// The singular runs decided so far.
    pub fn stretches(&self) -> &[SingularStretch] {
        &self.stretches
    }

    /// Adds a CL point, solved through `kin` at the point's pressure;
    /// `source_line`: the text of its CL line, for diagnostics made when it
    /// is decided. An error is returned for the point at once when it cannot
    /// be reached at all (the caller locates it).
    pub fn push_point(
        &mut self,
        kin: &mut KinematicsAtPressure,
        point: PathPoint,
        source_line: &[u8],
    ) -> Result<(), PlanError> {
        let PathPoint {
            pose,
            motion,
            line,
            feed,
            pressure,
        } = point;
        kin.select(pressure);
        if motion == Motion::Rapid {
            self.break_pending = true;
        }
        let starts_segment = std::mem::take(&mut self.break_pending);
        if starts_segment {
            self.segment += 1;
            self.free = true;
        }
        let pole = self.singularity.map(|s| Pole::new(&s, &pose.axis));
        if let Some(axis) = &self.previous_axis {
            let reference = &self.previous_reference;
            let axis_turn = angle_between_deg(axis, &pose.axis);
            let mut turn = axis_turn;
            if let (Some(a), Some(b)) = (reference, &pose.reference) {
                turn = turn.max(angle_between_deg(a, b));
            }
            self.turn += turn;
            // The tool axis, interpolated from point to point (as the
            // linearization moves it), passes through the singular cone:
            // the branches meet there, as at singular points. The arc comes
            // within the cone only if the distances of its ends add up to
            // at most its length and the cone's diameter (triangle
            // inequality): far from the pole that settles it.
            if let (Some(s), Some(a), Some(b)) = (&self.singularity, self.previous_pole, pole) {
                let cone = self.cone_rad + POLE_SLACK_RAD;
                if Pole::sum_within(
                    a,
                    b,
                    axis_turn + 2.0 * cone.to_degrees() + ARC_SUM_SLACK_DEG,
                ) && s.arc_distance(axis, &pose.axis) <= cone
                {
                    self.across = true;
                }
            }
            if let Some(f) = &self.folds {
                self.fold_reached |= f.reached(axis, &pose.axis, FOLD_SLACK_RAD);
            }
        }
        self.previous_axis = Some(pose.axis);
        self.previous_reference = pose.reference;
        self.previous_pole = pole;
        // The hint picks the turn of axes without limits: near the cheapest
        // configuration of the previous point; at the start of a segment,
        // near zero for the axes that unwind there (the turn nearest zero
        // is then among the candidates however far the last cut turned).
        let mut hint: Joints = self.trellis.best_last().copied().unwrap_or([0.0; MAX_AXES]);
        if starts_segment {
            for &i in &self.unwind {
                hint[i] = 0.0;
            }
        }
        let n = kin.axis_count();
        kin.ik(&pose, Some(&hint[..n]), &mut self.solutions)
            .map_err(|e| PlanError::Ik {
                failure: kin.ik_failure(e, &pose.axis),
                pose: Box::new(pose),
            })?;
        let in_cone = pole.is_some_and(|p| p.within(self.cone_rad));
        let singular = in_cone || self.solutions.iter().all(|s| s.singular);
        if singular {
            if !self.solutions.iter().any(Solution::is_valid) {
                return Err(self.rejected(&pose));
            }
            self.across = true;
        } else {
            // Near a fold the branches lie apart by a separation that
            // grows like the square root of the distance to it. Where the
            // tool axis, interpolated from point to point (as the
            // linearization moves it), reaches the fold, the branches meet:
            // a branch may switch, and the angles may move by as much as
            // the branches lie apart at the two points. Otherwise each
            // branch moves by its half of the change of the separation
            // (the branches are its mean ± half of it, the mean as smooth
            // as elsewhere) besides what the turn allows.
            let fold = self
                .folds
                .map(|_| separation(&self.solutions, &self.rotary));
            let (mut fold_deg, mut across_fold) = (0.0, false);
            if let (Some(s0), Some(s1)) = (self.planned_fold, fold)
                && (s0 + s1).is_finite()
            {
                across_fold = self.fold_reached;
                fold_deg = if across_fold {
                    s0 + s1
                } else {
                    0.5 * (s0 - s1).abs()
                };
            }
            self.planned_fold = fold;
            let link = if self.free {
                Link::Free
            } else {
                Link::Cut {
                    turn_deg: self.turn,
                    across_singular: self.across,
                    fold_deg,
                    across_fold,
                }
            };
            if !self.trellis.push(&self.solutions, link) {
                return Err(self.rejected(&pose));
            }
            self.turn = 0.0;
            self.across = false;
            self.fold_reached = false;
            self.free = false;
        }
        let start = self.source.len();
        self.source.extend_from_slice(source_line);
        self.points.push(PlanPoint {
            pose,
            line,
            motion,
            feed,
            pressure,
            source: start..self.source.len(),
            singular,
            segment: self.segment,
            starts_segment,
        });
        Ok(())
    }

    /// Whether the planner should decide now: the trellis is full, or
    /// [`SETTLED_BATCH`] points or more wait in a settled trellis
    /// ([`Trellis::is_settled`]: deciding them changes nothing, and the
    /// waiting points stay in the cache).
    pub fn is_full(&self) -> bool {
        self.trellis.is_full() || (self.trellis.len() >= SETTLED_BATCH && self.trellis.is_settled())
    }

    /// Why no solution of `pose` in `self.solutions` can be used.
    fn rejected(&self, pose: &Pose) -> PlanError {
        match rejection(&self.solutions) {
            Rejection::OutsideLimits(v) => PlanError::OutsideTravel {
                axis: self.names[v.axis].clone(),
                value: v.value,
                limits: self.limits[v.axis],
                pose: Box::new(*pose),
            },
            Rejection::NoSolution => PlanError::NoSolution {
                pose: Box::new(*pose),
            },
        }
    }

    /// Decides the waiting points and hands them to `sink`, with the
    /// commands among them, in path order. Unless `all`, singular points
    /// after the last planned one (and commands after it) keep waiting for
    /// their next neighbour.
    pub fn flush<S: PlanSink<C>>(
        &mut self,
        kin: &mut KinematicsAtPressure,
        sink: &mut S,
        all: bool,
    ) -> Result<(), S::Error> {
        self.choices.clear();
        if all || self.trellis.is_full() {
            self.trellis.decide(&mut self.choices);
        } else {
            self.trellis.decide_settled(&mut self.choices);
        }
        let end = if all {
            self.points.len()
        } else {
            self.points
                .iter()
                .rposition(|p| !p.singular)
                .map_or(0, |k| k + 1)
        };
        let written = if all {
            self.outputs.len()
        } else {
            self.outputs.partition_point(|(at, _)| *at < end)
        };
        let mut outputs = std::mem::take(&mut self.outputs);
        let mut pending = outputs.drain(..written).peekable();
        // Planned points take the trellis's choices, in order; a run of
        // singular points is decided when it comes, between its neighbours.
        let mut c = 0;
        let mut k = 0;
        while k < end {
            if !self.points[k].singular {
                while let Some((_, p)) = pending.next_if(|(at, _)| *at <= k) {
                    sink.command(p)?;
                }
                let choice = self.choices[c];
                c += 1;
                let decided = Decided {
                    node: Node {
                        pose: self.points[k].pose,
                        joints: choice.joints,
                        hold: None,
                        branch: choice.branch,
                    },
                    continuous: choice.continuous,
                };
                self.write_point(kin, sink, k, decided)?;
                k += 1;
                continue;
            }
            let segment = self.points[k].segment;
            let mut e = k;
            while e < end && self.points[e].singular && self.points[e].segment == segment {
                e += 1;
            }
            let next = self.choices.get(c).copied();
            self.fill_run(kin, k..e, next)?;
            for j in k..e {
                while let Some((_, p)) = pending.next_if(|(at, _)| *at <= j) {
                    sink.command(p)?;
                }
                let decided = self.run[j - k];
                self.write_point(kin, sink, j, decided)?;
            }
            k = e;
        }
        for (_, p) in pending {
            sink.command(p)?;
        }
        for o in &mut outputs {
            o.0 -= end;
        }
        self.outputs = outputs;
        self.points.drain(..end);
        // Keep the text of the points still waiting only.
        match self.points.first().map(|p| p.source.start) {
            None => self.source.clear(),
            Some(from) => {
                self.source.drain(..from);
                for p in &mut self.points {
                    p.source = p.source.start - from..p.source.end - from;
                }
            }
        }
        // The last point written is the trellis's anchor already unless it
        // was decided outside it (a singular point at the end).
        if all && let Some((node, _)) = &self.last {
            self.trellis.set_anchor(node.joints, node.branch);
        }
        Ok(())
    }

    /// Hands waiting point `k` to `sink` as decided.
    fn write_point<S: PlanSink<C>>(
        &mut self,
        kin: &mut KinematicsAtPressure,
        sink: &mut S,
        k: usize,
        d: Decided,
    ) -> Result<(), S::Error> {
        let p = &self.points[k];
        kin.select(p.pressure);
        sink.point(
            kin,
            &Planned {
                node: &d.node,
                motion: p.motion,
                feed: p.feed,
                pressure: p.pressure,
                continuous: d.continuous,
                cut: !p.starts_segment,
                site: self.site(p),
            },
        )?;
        self.last = Some((d.node, p.segment));
        Ok(())
    }

    /// Solves the waiting points `run` of the singular cone, into
    /// `self.run`: exactly if that needs no swing ([`PathPlan::exact_run`]),
    /// else with the singular angle held. The point before is the last one
    /// written; `next` is the choice of the planned point after the run, if
    /// any.
    fn fill_run(
        &mut self,
        kin: &mut KinematicsAtPressure,
        run: Range<usize>,
        next: Option<Choice>,
    ) -> Result<(), Located<PlanError>> {
        let points = &self.points;
        let seg = points[run.start].segment;
        // The decided neighbours in the same segment.
        let before: Option<Node> = self.last.filter(|(_, s)| *s == seg).map(|(n, _)| n);
        let after: Option<Node> = points
            .get(run.end)
            .filter(|p| p.segment == seg && !p.singular)
            .zip(next)
            .filter(|(_, c)| c.continuous)
            .map(|(p, c)| Node {
                pose: p.pose,
                joints: c.joints,
                hold: None,
                branch: c.branch,
            });
        let anchor = self
            .last
            .map(|(n, _)| n.joints)
            .or_else(|| self.trellis.anchor().copied())
            .unwrap_or([0.0; MAX_AXES]);
        let axis = self.singularity.map(|s| s.axis);
        let value_of = |node: &Node| axis.map_or(0.0, |i| node.joints[i]);
        let (from, to) = match (before, after) {
            (Some(b), Some(a)) => (value_of(&b), value_of(&a)),
            (Some(b), None) => (value_of(&b), value_of(&b)),
            (None, Some(a)) => (value_of(&a), value_of(&a)),
            (None, None) => {
                let v = axis.map_or(0.0, |i| anchor[i]);
                (v, v)
            }
        };
        // (At the start of a segment, from the last point written: a
        // rapid need not swing the free angle for a tool axis that CL
        // rounding put a hair beside the pole.)
        let written = before.or(self.last.map(|(n, _)| n));
        if self.exact_run(kin, run.clone(), written.as_ref(), after.as_ref(), &anchor) {
            return Ok(());
        }
        // Interpolate by distance along the CL path from the point before
        // to the point after (by count where it does not move).
        let mut lengths = Vec::with_capacity(run.len() + 1);
        let mut total = 0.0;
        let mut previous = before.map(|b| b.pose.point);
        for p in &self.points[run.clone()] {
            let p = p.pose.point;
            total += previous.map_or(0.0, |q| (p - q).norm());
            lengths.push(total);
            previous = Some(p);
        }
        if let Some(a) = after {
            total += previous.map_or(0.0, |q| (a.pose.point - q).norm());
        }
        let count = run.len() + usize::from(after.is_some());
        let mut guess = before.map_or(anchor, |b| b.joints);
        self.run.clear();
        for (j, k) in run.clone().enumerate() {
            let p = &self.points[k];
            let t = if total > NO_LENGTH_MM {
                lengths[j] / total
            } else {
                (j + usize::from(before.is_some())) as f64 / count.max(1) as f64
            };
            let hold = axis.map(|i| Hold {
                axis: i,
                value_deg: from + (to - from) * t,
            });
            kin.select(p.pressure);
            let kin: &Kinematics = kin;
            // (The branches meet at the pole: any branch.)
            let near = |hold| Near {
                joints: &guess,
                hold,
                branch: None,
            };
            let solved = solve_near(kin, &p.pose, &near(hold), &self.rotary, &mut self.solutions)
                .map(|(pose, s)| (pose, s, hold))
                .or_else(|| {
                    // The held angle is out of reach here: the exact
                    // solution nearest the previous point.
                    solve_near(kin, &p.pose, &near(None), &self.rotary, &mut self.solutions)
                        .map(|(pose, s)| (pose, s, None))
                });
            let Some((pose, sol, hold)) = solved else {
                return Err(self.site(p).locate(PlanError::HeldOutOfReach {
                    axis: axis
                        .map_or("the free axis", |i| self.names[i].as_str())
                        .into(),
                    held_deg: hold.map_or(f64::NAN, |h| h.value_deg),
                }));
            };
            guess = sol.joints;
            self.run.push(Decided {
                node: Node::solved(pose, &sol, hold),
                continuous: true,
            });
        }
        self.record_stretch(run);
        Ok(())
    }

    /// The run solved exactly, into `self.run`, when that needs no swing:
    /// each point at the solution nearest the one before (at the start of
    /// the program, nearest the one after, backwards), every rotary axis
    /// moving from point to point (from `from`, the point written before
    /// the run, and into `after`, the point after it) by no more than a
    /// cut allows for the turn of the tool axis ([`Costs::step_bound`], the
    /// rate at the edge of the singular cone). A path that comes into the
    /// cone without passing close by the pole is then written as the CL
    /// has it, with no tool axis held off. `false` (nothing solved) where
    /// the exact angle would swing: there the angle is held (see
    /// [`PathPlan::fill_run`]). A point exactly on the singular direction
    /// takes the angle of its neighbour (free there), and its run is
    /// reported as a stretch held at that angle.
    fn exact_run(
        &mut self,
        kin: &mut KinematicsAtPressure,
        run: Range<usize>,
        from: Option<&Node>,
        after: Option<&Node>,
        anchor: &Joints,
    ) -> bool {
        let costs = self.trellis.costs();
        let rotary = &self.rotary;
        let within = |a: &Joints, a_pose: &Pose, b: &Joints, b_pose: &Pose| {
            let mut turn = angle_between(&a_pose.axis, &b_pose.axis);
            if let (Some(ra), Some(rb)) = (&a_pose.reference, &b_pose.reference) {
                turn = turn.max(angle_between(ra, rb));
            }
            let bound = costs.step_bound(turn.to_degrees());
            rotary.iter().all(|&i| (b[i] - a[i]).abs() <= bound)
        };
        self.run.clear();
        // Backwards from the point after when nothing was written before.
        let backwards = from.is_none();
        let (first, end) = if backwards {
            (after, None)
        } else {
            (from, after)
        };
        let mut last: Option<(Joints, Pose)> = first.map(|b| (b.joints, b.pose));
        let mut singular = false;
        for j in 0..run.len() {
            let k = if backwards {
                run.end - 1 - j
            } else {
                run.start + j
            };
            let p = &self.points[k];
            kin.select(p.pressure);
            let near = Near {
                joints: last.as_ref().map_or(anchor, |(j, _)| j),
                hold: None,
                branch: None,
            };
            let Some((pose, sol)) = solve_near(kin, &p.pose, &near, rotary, &mut self.solutions)
            else {
                self.run.clear();
                return false;
            };
            if sol.nearest_axis
                || last
                    .as_ref()
                    .is_some_and(|(j, q)| !within(j, q, &sol.joints, &p.pose))
            {
                self.run.clear();
                return false;
            }
            singular |= sol.singular;
            last = Some((sol.joints, p.pose));
            self.run.push(Decided {
                node: Node::solved(pose, &sol, None),
                continuous: true,
            });
        }
        if let (Some(a), Some((j, q))) = (end, &last)
            && !within(j, q, &a.joints, &a.pose)
        {
            self.run.clear();
            return false;
        }
        if backwards {
            self.run.reverse();
        }
        if singular {
            self.record_stretch(run);
        }
        true
    }

    /// Reports the run solved in `self.run` as a singular stretch: the
    /// singular angle at its ends, and how far its tool axes lie from the
    /// CL's.
    fn record_stretch(&mut self, run: Range<usize>) {
        let Some(i) = self.singularity.map(|s| s.axis) else {
            return;
        };
        let value = |d: &Decided| d.node.joints[i];
        let deviation = self
            .run
            .iter()
            .zip(&self.points[run.clone()])
            .map(|(d, p)| angle_between(&d.node.pose.axis, &p.pose.axis))
            .fold(0.0, f64::max);
        self.stretches.push(SingularStretch {
            first_line: self.points[run.start].line,
            last_line: self.points[run.end - 1].line,
            axis: self.names[i].clone(),
            from_deg: self.run.first().map_or(f64::NAN, value),
            to_deg: self.run.last().map_or(f64::NAN, value),
            max_axis_deviation_deg: deviation.to_degrees(),
        });
    }

    /// A waiting point's CL statement.
    fn site<'a>(&'a self, p: &PlanPoint) -> Site<'a> {
        Site {
            file: &self.file,
            line: p.line,
            text: &self.source[p.source.clone()],
        }
    }
}

/// How far apart the branches of a point lie: over the pairs of candidates
/// of different branches, the smallest largest difference of a rotary axis
/// (degrees); infinite when the candidates are of one branch.
fn separation(solutions: &[Solution], rotary: &[usize]) -> f64 {
    let mut closest = f64::INFINITY;
    for (k, a) in solutions.iter().enumerate() {
        for b in solutions[k + 1..].iter().filter(|b| b.branch != a.branch) {
            let apart = rotary
                .iter()
                .map(|&i| (a.joints[i] - b.joints[i]).abs())
                .fold(0.0, f64::max);
            closest = closest.min(apart);
        }
    }
    closest
}

/// Angle between unit vectors, degrees (the turn of the tool axis between
/// two points). Small turns, as between the points of a CL path, are
/// `2·asin(|a − b| / 2)` by the series of asin (relative error below 1e-13
/// for chords under 0.1, turns under 5.7°: one square root and a
/// polynomial); larger ones atan2 of sine and cosine.
#[inline]
fn angle_between_deg(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let chord2 = (a - b).norm_squared();
    if chord2 < 0.01 {
        // x = chord/2; asin x = x·(1 + x²/6 + 3x⁴/40 + 5x⁶/112 + 35x⁸/1152 + …),
        // the next term below 63/2816·x¹⁰ < 3e-15 relative.
        let x2 = 0.25 * chord2;
        let series =
            1.0 + x2 * (1.0 / 6.0 + x2 * (3.0 / 40.0 + x2 * (5.0 / 112.0 + x2 * (35.0 / 1152.0))));
        (2.0 * x2.sqrt() * series).to_degrees()
    } else {
        atan2_deg(a.cross(b).norm(), a.dot(b))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_and_large_turns_agree_with_atan2() {
        let a = Vector3::new(0.3, -0.2, 0.9).normalize();
        for deg in [0.0, 1e-9, 1e-4, 0.04, 1.0, 5.0, 5.8, 30.0, 179.0] {
            let turn = nalgebra::Rotation3::from_axis_angle(
                &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, -0.5).cross(&a)),
                f64::to_radians(deg),
            );
            let b = turn * a;
            let want = a.cross(&b).norm().atan2(a.dot(&b)).to_degrees();
            let got = angle_between_deg(&a, &b);
            // The chord loses relative accuracy at tiny turns, not absolute.
            assert!(
                (got - want).abs() <= 1e-12 * want + 1e-13,
                "{deg}: {got} vs {want}"
            );
        }
    }
}
