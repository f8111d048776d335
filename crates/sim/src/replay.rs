//! The replay: every step of the interpreter through the machine.

use kinpost_machine::{Kinematics, KinematicsAtPressure, Machine, Singularity};
use kinpost_nc::interp::{Event, FeedMode, MAX_AXES, MotionKind, Move, Step};

use crate::cl::ClPath;
use crate::collide::Worlds;
use crate::path::{ArcPath, BlockPath, Joints, Shape, plane_axes};
use crate::removal::{BlockConditions, Cutting};
use crate::report::{At, ClComparison, Deviation, Overtravel, SimReport, SingularPassage};
use crate::{SimError, SimOptions, tolerance};

mod tcp;

/// What the replay knows of one axis.
#[derive(Debug, Clone)]
struct AxisInfo {
    name: String,
    /// Travel in joint values (NC values with the work offset): the
    /// limits, or the fixed value of a locked axis; `None`: unlimited.
    travel: Option<[f64; 2]>,
    machine_offset: f64,
    /// Turns without end: its value follows the interpreter's travel.
    endless: bool,
    rotary: bool,
    /// Rapid rate, mm/min or degrees/min.
    rapid_per_min: f64,
    max_velocity: Option<f64>,
}

/// A program's replay on a machine, one [`Step`] at a time
/// ([`Replay::step`]), then [`Replay::finish`].
pub struct Replay {
    axes: Vec<AxisInfo>,
    n: usize,
    xyz: [Option<usize>; 3],
    kin: KinematicsAtPressure,
    q: Joints,
    offset: Joints,
    /// Axes whose position is known (bit i): locked axes, and axes a block
    /// has programmed. The others stand where the program found them,
    /// which a program excerpt does not say.
    known: u32,
    /// All of the machine's axes (bit i for i < n).
    all: u32,
    /// Line of the first block after which every axis is known.
    complete_at: Option<usize>,
    pressure: f64,
    report: SimReport,
    cl: Option<(ClPath, ClComparison)>,
    worlds: Option<Worlds>,
    cutting: Option<Cutting>,
    /// The machine's singular tool-axis direction and the cone around it
    /// (radians) within which a passage is reported.
    singular: Option<(Singularity, f64)>,
    /// Joints and a lower bound of the tool axis's distance from the
    /// singular direction there (radians): a block's start is the previous
    /// block's end, and a block that turns the rotary axes by T moves the
    /// tool axis by at most T, so most blocks need no forward kinematics.
    last_pole: Option<(Joints, f64)>,
    scratch: Vec<f64>,
    untimed_blocks: u64,
    error: Option<SimError>,
}

/// The machine the replay moves: axes locked only without a reference
/// direction are free (a program may turn them, as 6-axis output does).
pub(crate) fn sim_machine(machine: &Machine) -> Machine {
    if machine.unlocks_with_reference() {
        machine.with_reference_axes_free()
    } else {
        machine.clone()
    }
}

impl Replay {
    /// A replay on `machine` (validated), compared with `cl` when given.
    pub fn new(
        machine: &Machine,
        options: &SimOptions,
        cl: Option<ClPath>,
    ) -> Result<Replay, SimError> {
        let sim = sim_machine(machine);
        let n = sim.axes.len();
        if n > MAX_AXES {
            return Err(SimError::TooManyAxes(n));
        }
        let mut report = SimReport::default();
        let mut assumed_rapid = Vec::new();
        let axes: Vec<AxisInfo> = sim
            .axes
            .iter()
            .map(|a| {
                let rapid_per_min = a.max_velocity.unwrap_or_else(|| {
                    assumed_rapid.push(a.name.clone());
                    if a.is_rotary() {
                        tolerance::ASSUMED_RAPID_DEG_PER_MIN
                    } else {
                        tolerance::ASSUMED_RAPID_MM_PER_MIN
                    }
                });
                AxisInfo {
                    name: a.name.clone(),
                    travel: a.fixed.map(|f| [f, f]).or(a.travel()),
                    machine_offset: a.machine_offset,
                    endless: a.is_endless(),
                    rotary: a.is_rotary(),
                    rapid_per_min,
                    max_velocity: a.max_velocity,
                }
            })
            .collect();
        if !assumed_rapid.is_empty() {
            report.assumed.push(format!(
                "rapid rates of {} mm/min (linear) and {} degrees/min (rotary) for axes without `max_velocity` in the machine file ({}); rapids move each axis at its own rate; no acceleration is modelled, so the run time is a lower bound",
                tolerance::ASSUMED_RAPID_MM_PER_MIN,
                tolerance::ASSUMED_RAPID_DEG_PER_MIN,
                assumed_rapid.join(" ")
            ));
        }
        let xyz = ["X", "Y", "Z"].map(|l| sim.axis_index(l).filter(|&i| !axes[i].rotary));
        let kin = KinematicsAtPressure::new(&sim, Kinematics::new(&sim), options.pressure_offset);
        let cone_deg = machine
            .post
            .singular_cone_deg
            .unwrap_or(kinpost_machine::tolerance::DEFAULT_SINGULAR_CONE_DEG);
        let singular = kin.singularity().map(|s| (s, cone_deg.to_radians()));
        let mut q = [0.0; MAX_AXES];
        let start = start_joints(machine, options);
        q[..n].copy_from_slice(&start[..n]);
        // (The machine file's locked axes: a program need not write them.)
        let known = machine
            .axes
            .iter()
            .enumerate()
            .filter(|(_, a)| a.fixed.is_some())
            .fold(0u32, |k, (i, _)| k | 1 << i);
        let worlds = if options.collisions && !sim.solids.is_empty() {
            Some(Worlds::new(&sim, options.pressure_offset)?)
        } else {
            None
        };
        let cl = cl.map(|c| {
            let cmp = ClComparison {
                cl_points: c.len(),
                ..ClComparison::default()
            };
            (c, cmp)
        });
        Ok(Replay {
            axes,
            n,
            xyz,
            kin,
            q,
            offset: [0.0; MAX_AXES],
            known,
            all: if n == 32 { u32::MAX } else { (1u32 << n) - 1 },
            complete_at: None,
            pressure: f64::NAN,
            report,
            cl,
            worlds,
            cutting: None,
            singular,
            last_pole: None,
            scratch: Vec::new(),
            untimed_blocks: 0,
            error: None,
        })
    }

    /// The replay also removes material: the tool's poses of every block
    /// are cut from `cutting`'s stock ([`Replay::finish_cutting`] gives
    /// it back).
    pub fn with_cutting(mut self, cutting: Cutting) -> Replay {
        self.cutting = Some(cutting);
        self
    }

    /// A block that turns the tool axis through the cone around the
    /// machine's singular direction (where one rotary angle is free and
    /// swings): a singular passage, reported with the least angle and how
    /// far the free axis turns. The tool axis moves by at most the sum of
    /// the rotary turns, so a block whose ends are farther from the pole
    /// than half that sum plus the cone is passed without sampling; others
    /// are sampled as the CL comparison samples.
    fn singular_passage(&mut self, path: &BlockPath, at: &At) {
        let Some((pole, cone)) = self.singular else {
            return;
        };
        if !self.may_pass_pole(&path.from, &path.to, cone) {
            return;
        }
        let n = self.n;
        let pieces = self.pieces(path, &0.0);
        let mut q = [0.0; MAX_AXES];
        let mut least = f64::INFINITY;
        for k in 0..=pieces {
            path.at(k as f64 / pieces as f64, &mut q);
            least = least.min(pole.distance(&self.kin.fk(&q[..n]).axis));
        }
        let turn_deg = (path.to[pole.axis] - path.from[pole.axis]).abs();
        self.note_passage(at, least, turn_deg);
    }

    /// Whether a block from joints `from` to `to` that turns a rotary axis
    /// may bring the tool axis within `cone` (radians) of the singular
    /// direction: the axis moves by at most the sum of the rotary turns,
    /// so it cannot when its ends are farther from the pole than half that
    /// sum plus the cone.
    pub(crate) fn may_pass_pole(&mut self, from: &Joints, to: &Joints, cone: f64) -> bool {
        let Some((pole, _)) = self.singular else {
            return false;
        };
        let n = self.n;
        let turn_rad: f64 = (0..n)
            .filter(|&i| self.axes[i].rotary)
            .map(|i| (to[i] - from[i]).abs().to_radians())
            .sum();
        if turn_rad == 0.0 {
            return false;
        }
        let bound = match self.last_pole {
            Some((q, d)) if q[..n] == from[..n] => d,
            _ => f64::NEG_INFINITY,
        };
        if bound - turn_rad > cone {
            // Clear of the cone all along; the bound at the end.
            self.last_pole = Some((*to, bound - turn_rad));
            return false;
        }
        let d0 = pole.distance(&self.kin.fk(&from[..n]).axis);
        let d1 = pole.distance(&self.kin.fk(&to[..n]).axis);
        self.last_pole = Some((*to, d1));
        (d0 + d1 - turn_rad) / 2.0 <= cone
    }

    /// A block whose tool axis came `least` (radians) from the singular
    /// direction while the free axis turned `turn_deg`: a singular passage
    /// when inside the cone.
    pub(crate) fn note_passage(&mut self, at: &At, least: f64, turn_deg: f64) {
        let Some((pole, cone)) = self.singular else {
            return;
        };
        if least > cone {
            return;
        }
        let passages = &mut self.report.singular_passages;
        if let Some(last) = passages.last_mut()
            && last.last_block + 1 == at.block
        {
            last.last_block = at.block;
            last.angle_deg = last.angle_deg.min(least.to_degrees());
            last.turn_deg += turn_deg;
            return;
        }
        passages.push(SingularPassage {
            at: at.clone(),
            last_block: at.block,
            axis: self.axes[pole.axis].name.clone(),
            angle_deg: least.to_degrees(),
            cone_deg: cone.to_degrees(),
            turn_deg,
        });
    }

    /// A block's conditions for the grinding process model: the pressure
    /// word in force, the spindle speed when it turns, the block's time.
    pub(crate) fn conditions(&self, m: &Move, seconds: f64) -> BlockConditions {
        let turning = m.state.spindle != kinpost_nc::interp::SpindleDir::Off;
        BlockConditions {
            pressure: self.pressure,
            spindle_rpm: if turning { m.state.spindle_speed } else { 0.0 },
            seconds,
        }
    }

    /// The tool's poses along a block for material removal: its end alone
    /// when its start is not known; else its start, the points where a
    /// straight sweep ends (none inside a feed block that turns no rotary
    /// axis, the arrival of each axis in a rapid that turns none), or
    /// samples as fine as the CL comparison's along a block that turns a
    /// rotary axis or an arc, and its end.
    fn block_poses(&self, path: &BlockPath, started: bool) -> Vec<kinpost_machine::Pose> {
        let n = self.n;
        let end = self.kin.fk(&path.to[..n]);
        if !started {
            return vec![end];
        }
        let start = self.kin.fk(&path.from[..n]);
        let turns = (0..n).any(|i| self.axes[i].rotary && path.to[i] != path.from[i]);
        let mut ts: Vec<f64> = match &path.shape {
            Shape::Joint if !turns => Vec::new(),
            Shape::Rapid { reach } if !turns => {
                let mut t: Vec<f64> = reach[..n]
                    .iter()
                    .copied()
                    .filter(|&t| t > 0.0 && t < 1.0)
                    .collect();
                t.sort_by(f64::total_cmp);
                t.dedup();
                t
            }
            _ => {
                let pieces = self.pieces(path, &(end.point - start.point).norm());
                (1..pieces).map(|k| k as f64 / pieces as f64).collect()
            }
        };
        let mut q = [0.0; MAX_AXES];
        let mut poses = Vec::with_capacity(ts.len() + 2);
        poses.push(start);
        for t in ts.drain(..) {
            path.at(t, &mut q);
            poses.push(self.kin.fk(&q[..n]));
        }
        poses.push(end);
        poses
    }

    /// One step of the interpreter.
    pub fn step(&mut self, step: &Step) {
        if self.error.is_some() {
            return;
        }
        match &step.event {
            Event::Move(m) => self.motion(step, m),
            Event::Pressure { value, .. } => {
                self.pressure = *value;
                self.kin.select(*value);
                self.last_pole = None;
            }
            Event::Dwell { seconds } => self.report.duration_s += seconds,
            _ => {}
        }
    }

    /// The report, with what the interpreter reported (`interp`).
    pub fn finish(self, interp: &kinpost_nc::interp::Report) -> Result<SimReport, SimError> {
        self.finish_cutting(interp).map(|(r, _)| r)
    }

    /// [`Replay::finish`], with the stock as cut when the replay removed
    /// material ([`Replay::with_cutting`]).
    pub fn finish_cutting(
        mut self,
        interp: &kinpost_nc::interp::Report,
    ) -> Result<(SimReport, Option<Cutting>), SimError> {
        if let Some(e) = self.error {
            return Err(e);
        }
        if let Some(c) = &mut self.cutting {
            c.flush()?;
        }
        let r = &mut self.report;
        r.executed_blocks = interp.executed_blocks;
        let mut assumed = interp.assumed.clone();
        assumed.append(&mut r.assumed);
        r.assumed = assumed;
        r.assumed.push(match self.complete_at {
            Some(line) => format!(
                "an axis is where the program puts it from its first word on: before that its position is unknown and not checked; collisions and the CL comparison start once every axis is known (line {line})"
            ),
            None => "an axis is where the program puts it from its first word on; not every axis was ever programmed, so no pose was checked for collisions or against the CL".to_string(),
        });
        if self.untimed_blocks > 0 {
            r.assumed.push(format!(
                "{} feed blocks without a feed rate (F0, or G95 without a spindle speed) take the time their axes' velocity limits give (0 without limits)",
                self.untimed_blocks
            ));
        }
        r.warnings = interp.warnings.iter().map(|w| w.to_string()).collect();
        if let Some((_, cmp)) = self.cl.take() {
            r.max_position_error_mm = cmp.position.as_ref().map(|d| d.value);
            r.max_axis_error_rad = cmp.axis.as_ref().map(|d| d.value);
            r.cl = Some(cmp);
        }
        if let Some(w) = self.worlds.take() {
            let (collisions, near) = w.into_contacts();
            r.collisions = collisions;
            r.near_misses = near;
        }
        r.rapid_into_stock = r
            .collisions
            .iter()
            .filter(|c| c.kind == "rapid_into_stock")
            .map(|c| c.at.clone())
            .chain(
                self.cutting
                    .iter()
                    .flat_map(|c| c.rapid_cuts().iter().cloned()),
            )
            .collect();
        r.rapid_into_stock.sort_by_key(|a| a.block);
        r.rapid_into_stock.dedup_by_key(|a| a.block);
        Ok((self.report, self.cutting))
    }

    /// A motion block.
    fn motion(&mut self, step: &Step, m: &Move) {
        self.report.blocks += 1;
        let at = At {
            block: self.report.blocks,
            line: step.line,
            number: step.number,
        };
        if m.state.tcp {
            if let Err(e) = self.tcp_motion(step, m, &at) {
                self.error = Some(e);
            }
            return;
        }
        let from = self.q;
        let path = match self.block_path(m, step.line, &from) {
            Ok(p) => p,
            Err(e) => {
                self.error = Some(e);
                return;
            }
        };
        let known_before = self.known;
        self.known |= m.programmed & self.all;
        self.check_travel(&path, &at, known_before);
        let seconds = self.block_time_s(m, &path, &path);
        self.report.duration_s += seconds;
        let rapid = m.kind == MotionKind::Rapid;
        let started = known_before == self.all;
        if self.known == self.all {
            self.complete_at.get_or_insert(step.line);
            if self.cl.is_some() && !rapid {
                self.compare(&path, &at, started);
            }
            if started {
                self.singular_passage(&path, &at);
            }
            if let Some(w) = &mut self.worlds
                && let Err(e) = w.check(&path, &at, rapid, started, self.pressure)
            {
                self.error = Some(e);
                return;
            }
            if self.cutting.is_some() {
                let poses = self.block_poses(&path, started);
                let conditions = self.conditions(m, seconds);
                if let Some(c) = &mut self.cutting
                    && let Err(e) = c.cut(&poses, &at, rapid, Some(conditions))
                {
                    self.error = Some(e);
                    return;
                }
            }
        }
        self.q = path.to;
        self.offset[..self.n].copy_from_slice(&m.state.offset.as_slice()[..self.n]);
    }

    /// The values the block ends at and how it gets there from `from` (the
    /// joints; under TCP the tool point in place of X Y Z).
    fn block_path(&self, m: &Move, line: usize, from: &Joints) -> Result<BlockPath, SimError> {
        let n = self.n;
        let mut to = *from;
        let (end, travel, off) = (
            m.end.as_slice(),
            m.travel.as_slice(),
            m.state.offset.as_slice(),
        );
        for i in 0..n {
            to[i] = if self.axes[i].endless {
                from[i] + travel[i] + (off[i] - self.offset[i])
            } else {
                end[i] + off[i]
            };
        }
        let shape = match &m.kind {
            MotionKind::Linear => Shape::Joint,
            MotionKind::Rapid => {
                let mut reach = [0.0; MAX_AXES];
                let mut longest: f64 = 0.0;
                for i in 0..n {
                    reach[i] = (to[i] - from[i]).abs() / self.axes[i].rapid_per_min;
                    longest = longest.max(reach[i]);
                }
                if longest > 0.0 {
                    reach.iter_mut().for_each(|r| *r /= longest);
                }
                Shape::Rapid { reach }
            }
            MotionKind::Arc(a) => {
                let axes = plane_axes(a.plane, self.xyz).ok_or(SimError::ArcPlane { line })?;
                // The centre's plane coordinates, in joint values.
                let xyz_of = |axis: usize| {
                    let k = self.xyz.iter().position(|x| *x == Some(axis)).unwrap_or(0);
                    a.centre_mm[k] + off[axis]
                };
                let centre = [xyz_of(axes[0]), xyz_of(axes[1])];
                Shape::Arc(ArcPath::new(
                    axes,
                    centre,
                    from,
                    &to,
                    a.sweep_deg,
                    a.clockwise,
                ))
            }
        };
        Ok(BlockPath {
            n,
            from: *from,
            to,
            shape,
        })
    }

    /// Every axis against its travel along the block (an axis whose start
    /// is not known, bit clear in `known_before`: at its end only, once
    /// programmed). A block is charged with an excess only where it goes
    /// beyond where it started: a block that starts outside (the previous
    /// block took it there) and comes back is not.
    fn check_travel(&mut self, path: &BlockPath, at: &At, known_before: u32) {
        for i in 0..self.n {
            let range = if known_before & (1 << i) != 0 {
                path.range(i, &mut self.scratch)
            } else {
                [path.to[i], path.to[i]]
            };
            self.charge_travel(i, range, [path.from[i], path.to[i]], at, known_before);
        }
    }

    /// Axis `i`, which takes the values `range` in a block from `ends[0]`
    /// to `ends[1]`, against its travel (see [`Replay::check_travel`]).
    fn charge_travel(
        &mut self,
        i: usize,
        range: [f64; 2],
        ends: [f64; 2],
        at: &At,
        known_before: u32,
    ) {
        {
            let Some([lo, hi]) = self.axes[i].travel else {
                return;
            };
            let started = known_before & (1 << i) != 0;
            if !started && self.known & (1 << i) == 0 {
                return;
            }
            let [min, max] = range;
            // Each side on its own, less what the start already exceeded
            // it by (0 for a start not known).
            let from = ends[0];
            let (start_below, start_above) = if started {
                ((lo - from).max(0.0), (from - hi).max(0.0))
            } else {
                (0.0, 0.0)
            };
            let t = tolerance::TRAVEL_MM_OR_DEG;
            let below = (lo - min > t && lo - min > start_below + t).then_some(lo - min);
            let above = (max - hi > t && max - hi > start_above + t).then_some(max - hi);
            let (value, excess) = match (below, above) {
                (None, None) => return,
                (Some(b), Some(a)) if b >= a => (min, b),
                (Some(b), None) => (min, b),
                (_, Some(a)) => (max, a),
            };
            let a = &self.axes[i];
            self.report.overtravel.push(Overtravel {
                at: at.clone(),
                axis: a.name.clone(),
                value: value + a.machine_offset,
                limits: [lo + a.machine_offset, hi + a.machine_offset],
                excess,
                between_ends: (value - ends[1]).abs() > tolerance::TRAVEL_MM_OR_DEG,
            });
        }
    }

    /// The block's time, seconds: the feed's along `programmed` (the
    /// tool point's path under TCP), or each axis at its rapid rate, and
    /// never faster than an axis' `max_velocity` allows for the joints'
    /// change in `joints`.
    fn block_time_s(&mut self, m: &Move, programmed: &BlockPath, joints: &BlockPath) -> f64 {
        let mut slowest_min: f64 = 0.0;
        for i in 0..self.n {
            let d = (joints.to[i] - joints.from[i]).abs();
            let rate = match m.kind {
                MotionKind::Rapid => Some(self.axes[i].rapid_per_min),
                _ => self.axes[i].max_velocity,
            };
            if let Some(v) = rate {
                slowest_min = slowest_min.max(d / v);
            }
        }
        if m.kind == MotionKind::Rapid {
            return slowest_min * 60.0;
        }
        let length = self.feed_length(m, programmed);
        let feed_min = match m.feed_mode {
            FeedMode::PerMinute => (m.feed > 0.0).then(|| length / m.feed),
            FeedMode::InverseTime => (m.feed > 0.0).then(|| 1.0 / m.feed),
            FeedMode::PerRevolution => {
                let v = m.feed * m.state.spindle_speed;
                (v > 0.0).then(|| length / v)
            }
        };
        let feed_min = feed_min.unwrap_or_else(|| {
            if length > 0.0 {
                self.untimed_blocks += 1;
            }
            0.0
        });
        feed_min.max(slowest_min) * 60.0
    }

    /// The length the feed applies to: the X Y Z path (the arc's, helix
    /// included), or where those stand still, the rotary axes' degrees (as
    /// rs274 and the Sinumerik take it).
    fn feed_length(&self, m: &Move, path: &BlockPath) -> f64 {
        let d = |i: usize| path.to[i] - path.from[i];
        let linear: f64 = match (&m.kind, &path.shape) {
            (MotionKind::Arc(a), Shape::Arc(arc)) => {
                let r = 0.5 * (arc.radius[0] + arc.radius[1]);
                (r * arc.sweep_rad).hypot(a.helix_mm)
            }
            _ => self
                .xyz
                .iter()
                .flatten()
                .map(|&i| d(i) * d(i))
                .sum::<f64>()
                .sqrt(),
        };
        if linear > tolerance::STANDSTILL_MM {
            return linear;
        }
        (0..self.n)
            .filter(|&i| self.axes[i].rotary)
            .map(|i| d(i) * d(i))
            .sum::<f64>()
            .sqrt()
    }

    /// The replayed tool point and axis of a feed block against the CL: at
    /// the block's end, and inside it when its start is known (`started`).
    fn compare(&mut self, path: &BlockPath, at: &At, started: bool) {
        let end = self.kin.fk(&path.to[..self.n]);
        let pieces = if started {
            let start = self.kin.fk(&path.from[..self.n]);
            self.pieces(path, &(end.point - start.point).norm())
        } else {
            1
        };
        let mut q = [0.0; MAX_AXES];
        for k in 1..=pieces {
            let pose = if k == pieces {
                end
            } else {
                path.at(k as f64 / pieces as f64, &mut q);
                self.kin.fk(&q[..self.n])
            };
            self.measure(&pose, at, k == pieces);
        }
    }

    /// One replayed pose against the CL (`end`: a block's end).
    fn measure(&mut self, pose: &kinpost_machine::Pose, at: &At, end: bool) {
        let Some((cl, cmp)) = &mut self.cl else {
            return;
        };
        let m = cl.measure(&pose.point, &pose.axis);
        cmp.samples += 1;
        let dev = |value: f64| Deviation {
            at: at.clone(),
            cl_line: m.cl_line,
            value,
        };
        raise(&mut cmp.position, m.position_mm, &dev);
        raise(&mut cmp.axis, m.axis_rad, &dev);
        if end {
            raise(&mut cmp.position_at_block_ends, m.position_mm, &dev);
            raise(&mut cmp.axis_at_block_ends, m.axis_rad, &dev);
        }
    }

    /// How many pieces a feed block is sampled in for the CL comparison:
    /// steps of at most [`tolerance::SAMPLE_STEP_MM`] of the tool point
    /// and [`tolerance::SAMPLE_STEP_DEG`] of any rotary axis, and arcs to a
    /// chord error of [`tolerance::SAMPLE_CHORD_MM`].
    fn pieces(&self, path: &BlockPath, tool_travel_mm: &f64) -> usize {
        let mut k = (tool_travel_mm / tolerance::SAMPLE_STEP_MM).ceil();
        for i in (0..self.n).filter(|&i| self.axes[i].rotary) {
            k = k.max(((path.to[i] - path.from[i]).abs() / tolerance::SAMPLE_STEP_DEG).ceil());
        }
        if let Shape::Arc(arc) = &path.shape {
            k = k.max(arc.pieces(tolerance::SAMPLE_CHORD_MM) as f64);
        }
        (k as usize).clamp(1, tolerance::MAX_SAMPLES_PER_BLOCK)
    }
}

/// `slot` raised to `value` when that is larger.
fn raise(slot: &mut Option<Deviation>, value: f64, dev: &impl Fn(f64) -> Deviation) {
    if slot.as_ref().is_none_or(|d| value > d.value) {
        *slot = Some(dev(value));
    }
}

/// Where the machine starts: the interpreter's start (`Options::start`)
/// or the machine's home (locked axes at their value, the others at 0).
pub(crate) fn start_joints(machine: &Machine, options: &SimOptions) -> Vec<f64> {
    match &options.interp.start {
        Some(s) => s.clone(),
        None => machine.home_joints(),
    }
}
