//! The motion stage: from the planner's decided points to the blocks of the
//! program. Between two feed blocks it inserts blocks until the contact
//! point, moved linearly in joint space, stays on the straight CL segment
//! ([`linearize`]); where the planner found no continuous motion it
//! retracts along the tool axis, reconfigures and re-approaches
//! ([`reconfigure`]); where the pressure changes it brings the wheel back
//! onto the last point; every feed block gets its feed word ([`feed`]).
//! Blocks go to a [`MotionSink`]: the closed-loop check, or a test's list.

pub mod feed;
pub mod linearize;
mod reconfigure;

use kinpost_diag::{Diagnostic, Site};
use kinpost_machine::tolerance::BAND_DEPTH_RAD;
use kinpost_machine::{Joints, Kinematics, Machine, Pose};
use kinpost_nc::Motion;
use kinpost_plan::{Near, Node, PlanSink, Planned, solve_near};
use serde::Serialize;

use crate::command::Pending;
use crate::config::{Config, FeedMode};
use crate::error::{LinearizationFailure, MotionError, PostError};
use feed::{FeedClamp, FeedMove, Feeds};
use linearize::{LinearizationReport, Linearizer};

/// A block on its way to the program: what it must reach and the values
/// that should reach it.
#[derive(Debug, Clone, Copy)]
pub struct MotionBlock<'a> {
    /// The pose the block must reach (part frame).
    pub target: &'a Pose,
    /// The axis values to write, machine order (with tool-centre-point
    /// output, the tool point on X, Y, Z).
    pub values: &'a Joints,
    /// The pressure to write (NaN: none).
    pub pressure: f64,
    /// Rapid or feed.
    pub motion: Motion,
    /// Its CL line (`None`: a block the post inserted).
    pub cl_line: Option<usize>,
    /// The feed word of a feed block.
    pub feed: Option<f64>,
    /// The CL statement it belongs to (an inserted block: the point it
    /// leads to).
    pub site: Site<'a>,
}

/// Where the motion stage's blocks go: the closed-loop check, or a test's
/// list.
pub trait MotionSink {
    /// A block, through `kin` (the machine at the block's pressure). Returns
    /// an upper bound of the lever of the block's exact values (see
    /// [`kinpost_machine::midpoint_bound`]; infinite when unknown): the
    /// linearization of the next segment starts from it.
    fn block(&mut self, kin: &Kinematics, block: &MotionBlock<'_>) -> Result<f64, PostError>;

    /// A command, in its place among the blocks.
    fn command(&mut self, pending: Pending) -> Result<(), PostError>;

    /// Inverse-time feed on or off.
    fn inverse_time(&mut self, on: bool) -> Result<(), PostError>;

    /// Whether a feed word of `word` writes as 0.
    fn feed_rounds_to_zero(&self, word: f64) -> bool;
}

/// What the motion stage did, for the summary.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MotionReport {
    /// Retract-and-reconfigure events.
    pub reconfigurations: Vec<Reconfiguration>,
    /// Blocks the stage inserted: linearization, retracts, re-approaches.
    pub inserted_blocks: u64,
    /// The linearization's figures.
    pub linearization: LinearizationReport,
    /// Largest change of one rotary axis between two consecutive feed
    /// blocks, degrees, and the CL line of the block.
    pub max_rotary_step_deg: f64,
    /// See `max_rotary_step_deg`.
    pub max_rotary_step_line: Option<usize>,
    /// Feed blocks slowed down to the axes' maximum velocities (the first
    /// 1000), and how many there were.
    pub feed_clamps: Vec<FeedClamp>,
    /// See `feed_clamps`.
    pub feed_clamp_count: u64,
    /// What could not be done quite as the CL asks, at its CL lines.
    pub warnings: Vec<Diagnostic>,
}

/// A retract and reconfiguration between two CL points of a cut.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reconfiguration {
    /// The CL line reached after the reconfiguration.
    pub line: usize,
    /// The CL line before it.
    pub previous_line: Option<usize>,
    /// The rotary axis with the largest jump.
    pub axis: String,
    /// Its value before, degrees.
    pub from_deg: f64,
    /// Its value after, degrees.
    pub to_deg: f64,
    /// Retract distance along the tool axis, mm.
    pub retract_mm: f64,
    /// Length of the CL segment from `previous_line` to `line` that is not
    /// cut, mm: 0 where the tool re-approaches the previous point in the
    /// new setting and cuts the segment from there (the usual case); the
    /// whole segment where the new setting cannot reach the previous point
    /// or move on from it continuously (the re-approach is then onto
    /// `line`).
    pub uncut_mm: f64,
}

/// The previous block written.
#[derive(Debug, Clone, Copy)]
struct Last {
    node: Node,
    /// The pressure it was written at (NaN: none).
    pressure: f64,
    line: usize,
    /// Values as handed over (tool point on X, Y, Z in TCP output).
    values: Joints,
    /// Upper bound of the lever of `node.joints` (see
    /// [`kinpost_machine::midpoint_bound`]); infinite when unknown.
    lever: f64,
}

/// The motion stage (see the module's documentation), writing to `S`.
pub struct MotionStage<S> {
    sink: S,
    n: usize,
    /// Free rotary axes.
    rotary: Vec<usize>,
    /// Free rotary axes with `wrap = "unwind"`.
    unwind: Vec<usize>,
    names: Vec<String>,
    /// Tool-centre-point output: indices of X, Y, Z.
    tcp: Option<[usize; 3]>,
    retract_mm: f64,
    reconfigure: bool,
    linearizer: Option<Linearizer>,
    feeds: Feeds,
    last: Option<Last>,
    /// Where the tool is before the next block is not known: at the start
    /// and after a tool change (the machine went to where it changes
    /// tools). A feed block from there has no length, hence no time.
    start_unknown: bool,
    /// Inverse-time feed is in force: switched on for the first feed block
    /// with a known start, off again for a feed block without one.
    inverse_time_on: bool,
    solutions: Vec<kinpost_machine::Solution>,
    inserted: Vec<Node>,
    report: MotionReport,
}

impl<S: MotionSink> MotionStage<S> {
    /// The motion stage of a program for `machine` (as the program drives
    /// it) through `kin`, with the settings of `config`; `tcp`: the indices
    /// of X, Y, Z in tool-centre-point output.
    pub fn new(
        machine: &Machine,
        kin: &Kinematics,
        config: &Config,
        tcp: Option<[usize; 3]>,
        sink: S,
    ) -> Self {
        let axes = &machine.axes;
        let rotary: Vec<usize> = machine.free_rotary_axes().collect();
        let linear = (0..axes.len())
            .filter(|&i| axes[i].is_free() && !axes[i].is_rotary())
            .collect();
        // Joint output only: with tool-centre-point output the controller
        // interpolates the tool point.
        let linearizer = (config.lintol_mm > 0.0 && tcp.is_none()).then(|| {
            Linearizer::new(
                config.lintol_mm,
                kin,
                config.singular_cone_deg.to_radians(),
                rotary.clone(),
                linear,
            )
        });
        MotionStage {
            sink,
            n: axes.len(),
            unwind: machine.unwinding_axes().collect(),
            names: axes.iter().map(|a| a.name.clone()).collect(),
            rotary,
            tcp,
            retract_mm: config.retract_mm,
            reconfigure: config.reconfigure,
            linearizer,
            feeds: Feeds::new(machine, config.feed_mode),
            last: None,
            start_unknown: true,
            inverse_time_on: false,
            solutions: Vec::with_capacity(16),
            inserted: Vec::new(),
            report: MotionReport::default(),
        }
    }

    /// Ends the program (inverse time off, if on): the sink and the report.
    pub fn finish(mut self) -> Result<(S, MotionReport), PostError> {
        if self.inverse_time_on {
            self.sink.inverse_time(false)?;
        }
        let mut report = self.report;
        if let Some(l) = &self.linearizer {
            report.linearization = l.report;
        }
        report.feed_clamps = self.feeds.clamps;
        report.feed_clamp_count = self.feeds.clamp_count;
        Ok((self.sink, report))
    }

    /// One planned CL point and whatever must come before it.
    fn point(&mut self, kin: &Kinematics, t: &Planned<'_>) -> Result<(), PostError> {
        if let Some(l) = &mut self.linearizer {
            l.segment_line = t.site.line;
        }
        self.pressure_change(kin, t)?;
        if t.motion == Motion::Feed
            && let Some(last) = &self.last
        {
            if t.cut && !t.continuous {
                let last = *last;
                for node in &self.reconfigure(kin, &last, t)? {
                    self.inserted(kin, node, Motion::Feed, t)?;
                }
            } else {
                self.linearize(kin, t)?;
            }
        }
        if t.motion == Motion::Rapid {
            self.unwind_where_the_rapid_ends(kin, t)?;
        }
        self.block(kin, t.node, t.motion, Some(t.site.line), t)
    }

    /// The wheel moves with the pressure (Qi, thesis, ch. 3): the last
    /// block's axes put the contact point elsewhere now. Before a feed move,
    /// the axes bring it back onto the last point first, in a block of its
    /// own with the new pressure word; otherwise (a rapid follows, or the
    /// point cannot be reached at the new pressure) the move starts where
    /// the contact point went.
    fn pressure_change(&mut self, kin: &Kinematics, t: &Planned<'_>) -> Result<(), PostError> {
        let Some(last) = &mut self.last else {
            return Ok(());
        };
        if last.pressure.to_bits() == t.pressure.to_bits() {
            return Ok(());
        }
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
            self.inserted(kin, &node, Motion::Feed, t)?;
        } else {
            let here = kin.fk(&last.node.joints[..self.n]);
            last.node.pose = Pose {
                reference: last.node.pose.reference.and(here.reference),
                ..here
            };
            last.lever = f64::INFINITY;
        }
        Ok(())
    }

    /// The blocks that linearize the feed move from the last block into
    /// `t`.
    fn linearize(&mut self, kin: &Kinematics, t: &Planned<'_>) -> Result<(), PostError> {
        let (Some(l), Some(last)) = (&mut self.linearizer, &self.last) else {
            return Ok(());
        };
        if l.settles(kin, &last.node, t.node, last.lever) {
            return Ok(());
        }
        let mut inserted = std::mem::take(&mut self.inserted);
        inserted.clear();
        match l.split(kin, &last.node, t.node, last.lever, 0, &mut inserted) {
            Ok(()) => {}
            // A move that starts a segment may be a repositioning the CL
            // asks for at feed: it is written as it is.
            Err(_) if !t.cut => inserted.clear(),
            Err(e) => return Err(t.site.locate(segment_error(kin, e, last, t)).into()),
        }
        for node in &inserted {
            self.inserted(kin, node, Motion::Feed, t)?;
        }
        self.inserted = inserted;
        Ok(())
    }

    /// An axis that unwinds at the start of a segment does so where the
    /// rapid ends, not while the tool leaves the cut: the rapid keeps the
    /// turn it has, and a block of its own then unwinds the whole turns
    /// (the same pose).
    fn unwind_where_the_rapid_ends(
        &mut self,
        kin: &Kinematics,
        t: &Planned<'_>,
    ) -> Result<(), PostError> {
        let Some(last) = &self.last else {
            return Ok(());
        };
        let mut kept = *t.node;
        for &i in &self.unwind {
            let turns = ((last.node.joints[i] - kept.joints[i]) / 360.0).round();
            kept.joints[i] += 360.0 * turns;
        }
        if kept.joints != t.node.joints && kept.joints != last.node.joints {
            self.inserted(kin, &kept, Motion::Rapid, t)?;
        }
        Ok(())
    }

    /// A block the stage inserts before CL point `t` (it has no CL line of
    /// its own).
    fn inserted(
        &mut self,
        kin: &Kinematics,
        node: &Node,
        motion: Motion,
        t: &Planned<'_>,
    ) -> Result<(), PostError> {
        self.block(kin, node, motion, None, t)?;
        self.report.inserted_blocks += 1;
        Ok(())
    }

    /// Gives a block its values and feed word and hands it on.
    fn block(
        &mut self,
        kin: &Kinematics,
        node: &Node,
        motion: Motion,
        cl_line: Option<usize>,
        t: &Planned<'_>,
    ) -> Result<(), PostError> {
        let line = t.site.line;
        // Joint output writes the axis values; tool-centre-point output
        // writes the tool point on X, Y, Z and the rotary axis values.
        let mut values = node.joints;
        if let Some([x, y, z]) = self.tcp {
            values[x] = node.pose.point.x;
            values[y] = node.pose.point.y;
            values[z] = node.pose.point.z;
        }
        let feed = match motion {
            Motion::Rapid => None,
            Motion::Feed => Some(self.feed_word(node, &values, t)?),
        };
        if motion == Motion::Feed
            && let Some(last) = &self.last
        {
            let r = &mut self.report;
            for &i in &self.rotary {
                let step = (node.joints[i] - last.node.joints[i]).abs();
                if step > r.max_rotary_step_deg {
                    r.max_rotary_step_deg = step;
                    r.max_rotary_step_line = Some(line);
                }
            }
        }
        let lever = self.sink.block(
            kin,
            &MotionBlock {
                target: &node.pose,
                values: &values,
                pressure: t.pressure,
                motion,
                cl_line,
                feed,
                site: t.site,
            },
        )?;
        self.last = Some(Last {
            node: *node,
            pressure: t.pressure,
            line,
            values,
            lever,
        });
        self.start_unknown = false;
        Ok(())
    }

    /// The feed word of a feed block into `node` (values `values`) at the
    /// CL feed rate of `t`. Inverse time says how long a block takes, which
    /// a block from an unknown start does not know: it is written at the CL
    /// feed rate per minute (G94), inverse time resumes after.
    fn feed_word(
        &mut self,
        node: &Node,
        values: &Joints,
        t: &Planned<'_>,
    ) -> Result<f64, PostError> {
        let Some(f) = t.feed else {
            return Err(t.site.locate(MotionError::NoFeedRate).into());
        };
        if self.feeds.mode == FeedMode::InverseTime && self.inverse_time_on == self.start_unknown {
            self.inverse_time_on = !self.start_unknown;
            self.sink.inverse_time(self.inverse_time_on)?;
        }
        let mut word = f;
        if !self.feeds.is_cl_feed()
            && let Some(last) = self.last.as_ref().filter(|_| !self.start_unknown)
        {
            let (w, warning) = self.feeds.word(
                f,
                &FeedMove {
                    node,
                    values,
                    from: &last.node,
                    from_values: &last.values,
                    line: t.site.line,
                },
            );
            word = w;
            if let Some(w) = warning {
                self.report.warnings.push(t.site.warning(w));
            }
        }
        if word < 1.0 && self.sink.feed_rounds_to_zero(word) {
            return Err(t
                .site
                .locate(MotionError::FeedRoundsToZero { word, feed: f })
                .into());
        }
        Ok(word)
    }
}

/// Why the linearization of the segment from `last` into `t` failed, as
/// the user reads it: leaving the band of directions the machine can point
/// explains a midpoint it cannot reach and halving that does not converge.
fn segment_error(
    kin: &Kinematics,
    e: LinearizationFailure,
    last: &Last,
    t: &Planned<'_>,
) -> MotionError {
    let (from_line, to) = (last.line, t.node.pose);
    let band = match e {
        LinearizationFailure::LinearPlane => None,
        _ => kin
            .folds()
            .and_then(|f| f.arc_outside(&last.node.pose.axis, &to.axis))
            .filter(|e| e.depth > BAND_DEPTH_RAD),
    };
    match band {
        Some(e) => MotionError::LeavesBand {
            from_line,
            to,
            depth_deg: e.depth.to_degrees(),
            half_angle_deg: e.half_angle.to_degrees(),
            // (+ 0.0: no "-0.0000000".)
            cone_axis: [
                e.cone_axis.x + 0.0,
                e.cone_axis.y + 0.0,
                e.cone_axis.z + 0.0,
            ],
        },
        None => MotionError::Linearization {
            kind: e,
            from_line,
            to,
        },
    }
}

impl<S: MotionSink> PlanSink<Pending> for MotionStage<S> {
    type Error = PostError;

    #[inline]
    fn point(&mut self, kin: &Kinematics, point: &Planned<'_>) -> Result<(), PostError> {
        MotionStage::point(self, kin, point)
    }

    fn command(&mut self, pending: Pending) -> Result<(), PostError> {
        if pending.changes_tool() {
            self.start_unknown = true;
        }
        self.sink.command(pending)
    }
}
