//! The closed-loop check: every block, with its values exactly as written,
//! is run back through the forward kinematics and compared with the CL
//! pose it was made from. The [`Check`] stage wraps any [`BlockSink`] (the
//! NC writer): it asks the sink how it rounds the values, checks them, and
//! hands the block on only when it passes.

use kinpost_machine::angle::SinCosMemo;
pub use kinpost_machine::angle_between;
use kinpost_machine::tolerance::{
    CHECK_SLACK_MM, CHECK_SLACK_RAD, LEVER_PROBE_DEG, REFERENCE_NORMAL_MIN, SECOND_ORDER_MARGIN,
};
use kinpost_machine::{Joints, Kinematics, MAX_AXES, Machine, Pose, lever_over};
use kinpost_nc::{ArcMotion, Block, BlockError};
use nalgebra::Vector3;

use crate::command::{Command, Pending};
use crate::error::{CheckError, PostError};
use crate::motion::{MotionBlock, MotionSink};
use crate::native_arc::{self, ProgramAxes};
use crate::native_cycle;
use kinpost_diag::{Diagnostic, Located};
use kinpost_machine::tolerance::NATIVE_ARC_MIN_SAMPLES;

/// Where the blocks of a program go, once checked: the NC writer, or a
/// test's list ([`Recorded`](crate::Recorded)).
pub trait BlockSink {
    /// `values` (the first `values.len()` machine axes) as this sink writes
    /// them, into `written`: the closed-loop check runs on these.
    fn round(&mut self, values: &[f64], written: &mut [f64]);

    /// A motion block: the machine's axis values (and its pressure, if it
    /// has a pressure axis) exactly as they were checked; a circular block
    /// (with an arc) only to a sink that [writes arcs](BlockSink::writes_arcs).
    fn block(&mut self, block: &Block<&[f64]>) -> Result<(), BlockError>;

    /// A command, in its place among the blocks.
    fn command(&mut self, pending: Pending) -> Result<(), PostError>;

    /// Inverse-time feed on (`G93`) or off (`G94`).
    fn inverse_time(&mut self, on: bool) -> Result<(), PostError>;

    /// Whether a feed word of `word` writes as 0.
    fn feed_rounds_to_zero(&self, word: f64) -> bool;

    /// Whether this sink writes circular blocks; without, the check hands
    /// every arc on as its lines.
    fn writes_arcs(&self) -> bool {
        false
    }

    /// Whether this sink writes an arc in `plane` (a helix when `helix`)
    /// as a circular block; the others go on as lines.
    fn writes_arc(&self, plane: kinpost_nc::ArcPlane, helix: bool) -> bool {
        let _ = (plane, helix);
        self.writes_arcs()
    }

    /// An arc block's centre offset (program X, Y, Z) as this sink writes
    /// it.
    fn round_centre(&self, offset: [f64; 3]) -> [f64; 3] {
        offset
    }

    /// Whether this sink may write canned cycles; without, the check hands
    /// every hole on as its moves.
    fn writes_cycles(&self) -> bool {
        false
    }

    /// One hole as a canned cycle: `Ok(false)`, with nothing written, when
    /// the sink cannot write it as one (the check then hands on its moves).
    fn hole(&mut self, hole: &kinpost_nc::Hole) -> Result<bool, kinpost_nc::NcError> {
        let _ = hole;
        Ok(false)
    }
}

/// How far a block may put the tool from its CL pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Largest distance between the tool point of a block and its CL point, mm.
    pub position_mm: f64,
    /// Largest angle between the tool axis of a block and its CL axis, rad.
    pub axis_rad: f64,
}

impl Tolerance {
    /// The error that rounding to the output decimals can cause: half a unit
    /// of the last decimal on every free linear axis, plus half a unit on
    /// every free rotary axis times the machine's largest pivot distance
    /// ([`Machine::largest_pivot_distance`]). `resolution(i)` is the value of
    /// one unit in the last written decimal of axis `i` (0.001 for 3
    /// decimals).
    pub fn from_resolution(machine: &Machine, resolution: impl Fn(usize) -> f64) -> Tolerance {
        let lever = machine.largest_pivot_distance();
        Self::with_levers(machine, resolution, |_| lever)
    }

    /// The rounding error of tool-centre-point output: the tool point is
    /// written directly (half a unit per linear word), the tool axis through
    /// the rotary words.
    pub fn for_tcp(machine: &Machine, resolution: impl Fn(usize) -> f64) -> Tolerance {
        Self::with_levers(machine, resolution, |_| 0.0)
    }

    /// The rounding error bound of one block at joint values `q`, with the
    /// actual lever of every rotary axis (how far the tool point moves per
    /// radian of that axis, by central differences through `kin`). Used where
    /// a block lies beyond the machine-wide bound, e.g. on a machine without
    /// travel limits whose linear axes run far out; 1.5 times the first-order
    /// bound covers the second-order terms of half a unit.
    pub fn at_block(
        machine: &Machine,
        kin: &Kinematics,
        q: &[f64],
        resolution: impl Fn(usize) -> f64,
    ) -> Tolerance {
        let mut probe = q.to_vec();
        let h = LEVER_PROBE_DEG;
        let t = Self::with_levers(machine, resolution, |i| {
            probe[i] = q[i] + h;
            let plus = kin.fk(&probe).point;
            probe[i] = q[i] - h;
            let minus = kin.fk(&probe).point;
            probe[i] = q[i];
            (plus - minus).norm() / (2.0 * h).to_radians()
        });
        Tolerance {
            position_mm: SECOND_ORDER_MARGIN * t.position_mm,
            axis_rad: t.axis_rad,
        }
    }

    fn with_levers(
        machine: &Machine,
        resolution: impl Fn(usize) -> f64,
        mut lever: impl FnMut(usize) -> f64,
    ) -> Tolerance {
        let mut position = 0.0;
        let mut axis = 0.0;
        for (i, a) in machine.axes.iter().enumerate() {
            if !a.is_free() {
                continue;
            }
            let half = 0.5 * resolution(i);
            if a.is_rotary() {
                let rad = half.to_radians();
                axis += rad;
                position += rad * lever(i);
            } else {
                position += half;
            }
        }
        // Slack for the arithmetic itself.
        Tolerance {
            position_mm: position + CHECK_SLACK_MM,
            axis_rad: axis + CHECK_SLACK_RAD,
        }
    }
}

/// Position and orientation error of `got` against `want`: the angle
/// between the tool axes, or between the reference directions if that is
/// larger (both poses with one: 6-axis output).
pub fn pose_error(want: &Pose, got: &Pose) -> (f64, f64) {
    (
        (want.point - got.point).norm(),
        angle_between(&want.axis, &got.axis).max(reference_error(want, got)),
    )
}

/// The angle between the reference directions of `want` and `got`, each
/// taken normal to its tool axis (the part of a CL reference along the tool
/// axis says nothing: the inverse kinematics leaves it out too); 0 unless
/// both have one.
pub fn reference_error(want: &Pose, got: &Pose) -> f64 {
    let (Some(a), Some(b)) = (&want.reference, &got.reference) else {
        return 0.0;
    };
    let normal = |r: &Vector3<f64>, axis: &Vector3<f64>| r - axis * r.dot(axis);
    let (a, b) = (normal(a, &want.axis), normal(b, &got.axis));
    match (
        a.try_normalize(REFERENCE_NORMAL_MIN),
        b.try_normalize(REFERENCE_NORMAL_MIN),
    ) {
        (Some(a), Some(b)) => angle_between(&a, &b),
        // A reference along the tool axis gives no direction to compare.
        _ => 0.0,
    }
}

/// Running maxima of the check.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CheckStats {
    /// Largest distance of a block's tool point from its CL point, mm.
    pub max_position_error_mm: f64,
    /// Largest angle of a block's tool axis (or reference) from its CL
    /// one, radians.
    pub max_axis_error_rad: f64,
    /// CL line of the block with the largest position error.
    pub worst_line: Option<usize>,
    /// sin of `max_axis_error_rad`, to skip the `atan2` of smaller errors.
    sin_max_axis: f64,
}

impl CheckStats {
    /// Records one block; returns whether it is within `tolerance`. Only
    /// errors that may be new maxima or failures are measured exactly (one
    /// `sqrt`/`atan2` saved per block on the hot path).
    pub fn record(&mut self, want: &Pose, got: &Pose, line: usize, tolerance: &Tolerance) -> bool {
        let d2 = (want.point - got.point).norm_squared();
        let max = self.max_position_error_mm;
        if d2 > max * max {
            self.max_position_error_mm = d2.sqrt();
            self.worst_line = Some(line);
        }
        let sin = want.axis.cross(&got.axis).norm();
        let cos = want.axis.dot(&got.axis);
        if cos <= 0.0 || sin > self.sin_max_axis || want.reference.is_some() {
            let a = sin.atan2(cos).max(reference_error(want, got));
            if a > self.max_axis_error_rad {
                self.max_axis_error_rad = a;
                self.sin_max_axis = if a < std::f64::consts::FRAC_PI_2 {
                    a.sin()
                } else {
                    1.0
                };
            }
        }
        self.max_position_error_mm <= tolerance.position_mm
            && self.max_axis_error_rad <= tolerance.axis_rad
    }
}

/// What the check found, for the summary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CheckReport {
    /// The largest errors and where.
    pub stats: CheckStats,
    /// The tolerance in force at the end (it grows for blocks whose CL
    /// tool axis lies just beyond reach, and, with the derived tolerance,
    /// for blocks checked at their own levers).
    pub tolerance: Tolerance,
    /// Blocks whose CL tool axis lies just outside the directions the
    /// machine can point, checked against the nearest direction it can.
    pub beyond_reach_blocks: u64,
    /// The largest distance of such a CL axis from that direction, radians.
    pub max_beyond_reach_rad: f64,
    /// The CL line of the first.
    pub first_beyond_reach_line: Option<usize>,
    /// CL arcs written as circular blocks (pieces of a full circle or
    /// helix counted one by one).
    pub native_arcs: u64,
    /// Holes of CL canned cycles written as the dialect's cycles.
    pub native_cycles: u64,
}

/// How the check is set up.
#[derive(Debug, Clone)]
pub struct CheckSettings {
    /// The tolerance (derived from the output decimals, or given).
    pub tolerance: Tolerance,
    /// The position tolerance was given: it does not grow.
    pub tolerance_given: bool,
    /// Tool-centre-point output: indices of X, Y, Z.
    pub tcp: Option<[usize; 3]>,
    /// One unit of the last written decimal, per axis.
    pub resolution: Vec<f64>,
}

/// The check stage (see the module's documentation), writing to `S`.
pub struct Check<S> {
    sink: S,
    machine: Machine,
    settings: CheckSettings,
    n: usize,
    has_pressure: bool,
    /// How far rounding can move the axes, as [`Kinematics::joint_travel`]
    /// measures it: one unit of the last decimal of every free axis.
    rounding_travel: (f64, f64),
    written: Joints,
    /// The sines and cosines of the written rotary values, for the next
    /// block's check.
    sin_cos: SinCosMemo,
    /// A block has been checked (`written` holds its values).
    started: bool,
    /// The program's X, Y, Z axes, when the sink writes arcs and the
    /// machine has them.
    program_axes: Option<ProgramAxes>,
    /// The blocks of an arc being gathered (see [`Command::ArcBegin`]).
    arc: Option<Box<Gathered>>,
    /// The program's X, Y, Z axes, when the sink writes canned cycles and
    /// the machine has them (and no pressure axis).
    cycle_axes: Option<ProgramAxes>,
    /// The blocks and commands of a hole being gathered (see
    /// [`Command::HoleBegin`]).
    hole: Option<Box<GatheredHole>>,
    report: CheckReport,
}

/// The moves of a hole of a canned cycle, checked and held back until its
/// end.
struct GatheredHole {
    cycle: Box<crate::cycle::HoleCycle>,
    rpm: Option<f64>,
    ccw: bool,
    /// The values written before the hole.
    start: Joints,
    items: Vec<HeldItem>,
}

/// What a hole holds back, in order.
enum HeldItem {
    Block(HeldBlock),
    Command(Pending),
    InverseTime(bool),
}

/// The blocks of a CL arc, checked and held back until its end.
struct Gathered {
    arc: Box<kinpost_cl::Arc>,
    /// The values written before the arc (its start).
    start: Joints,
    /// Each block: values handed over (pressure last), values as written,
    /// motion, CL line, feed.
    blocks: Vec<HeldBlock>,
    /// The kinematics of the first block (the machine at its pressure).
    kin: Option<Kinematics>,
    /// Only an XY block may be written (see [`Command::ArcBegin`]).
    xy_only: bool,
}

struct HeldBlock {
    row: [f64; MAX_AXES + 1],
    written: Joints,
    motion: kinpost_nc::Motion,
    cl_line: Option<usize>,
    feed: Option<f64>,
}

impl<S: BlockSink> Check<S> {
    /// The check of `machine`'s blocks (as the program drives it) with
    /// `settings`, handing them to `sink`.
    pub fn new(machine: &Machine, settings: CheckSettings, sink: S) -> Self {
        let axes = &machine.axes;
        let free = |rotary: bool| {
            (0..axes.len())
                .filter(|&i| axes[i].is_free() && axes[i].is_rotary() == rotary)
                .map(|i| settings.resolution[i])
                .sum::<f64>()
        };
        Check {
            rounding_travel: (free(true).to_radians(), free(false)),
            n: axes.len(),
            has_pressure: machine.pressure.is_some(),
            machine: machine.clone(),
            report: CheckReport {
                stats: CheckStats::default(),
                tolerance: settings.tolerance,
                beyond_reach_blocks: 0,
                max_beyond_reach_rad: 0.0,
                first_beyond_reach_line: None,
                native_arcs: 0,
                native_cycles: 0,
            },
            cycle_axes: if sink.writes_cycles() && machine.pressure.is_none() {
                ProgramAxes::of(machine)
            } else {
                None
            },
            hole: None,
            program_axes: if sink.writes_arcs() && settings.tcp.is_none() {
                ProgramAxes::of(machine)
            } else {
                None
            },
            sink,
            settings,
            written: [0.0; MAX_AXES],
            sin_cos: SinCosMemo::default(),
            started: false,
            arc: None,
        }
    }

    /// The sink, and what the check found.
    pub fn finish(self) -> (S, CheckReport) {
        (self.sink, self.report)
    }

    /// Whether the block `b`, written as `self.written` and reaching
    /// `reached`, is within the tolerance (growing it where the rules
    /// allow).
    fn passes(&mut self, kin: &Kinematics, b: &MotionBlock<'_>, reached: &Pose) -> bool {
        let tolerance = self.report.tolerance;
        self.report
            .stats
            .record(b.target, reached, b.site.line, &tolerance)
            || self.within_cl_rounding(kin, b.target, reached, b.site.line)
            || self.within_block_bound(kin, b.target, reached)
    }

    /// A CL tool axis just outside the directions the machine can point (CL
    /// rounding, see [`Kinematics::axis_rounding`]) is solved at the nearest
    /// one it can point: the block is right if it is within the tolerance
    /// of that direction. The axis tolerance in force (and reported) grows
    /// to the block's error (at most that distance more), and the block is
    /// counted in the report.
    fn within_cl_rounding(
        &mut self,
        kin: &Kinematics,
        want: &Pose,
        got: &Pose,
        line: usize,
    ) -> bool {
        let (gap, nearest) = kin.axis_reach(&want.axis);
        let r = &mut self.report;
        let t = &mut r.tolerance;
        if gap == 0.0
            || gap > kin.axis_rounding()
            || (want.point - got.point).norm() > t.position_mm
            || angle_between(&nearest, &got.axis) > t.axis_rad
            || reference_error(want, got) > t.axis_rad
        {
            return false;
        }
        t.axis_rad = t.axis_rad.max(pose_error(want, got).1);
        r.beyond_reach_blocks += 1;
        r.max_beyond_reach_rad = r.max_beyond_reach_rad.max(gap);
        r.first_beyond_reach_line.get_or_insert(line);
        true
    }

    /// Holds block `b` (its values handed over in `row`, as written in
    /// `self.written`) back among the blocks of the arc being gathered.
    #[cold]
    #[inline(never)]
    fn hold(&mut self, kin: &Kinematics, b: &MotionBlock<'_>, row: &[f64; MAX_AXES + 1]) {
        if let Some(h) = &mut self.hole {
            h.items.push(HeldItem::Block(HeldBlock {
                row: *row,
                written: self.written,
                motion: b.motion,
                cl_line: b.cl_line,
                feed: b.feed,
            }));
            return;
        }
        if let Some(g) = &mut self.arc {
            if g.kin.is_none() {
                g.kin = Some(kin.clone());
            }
            g.blocks.push(HeldBlock {
                row: *row,
                written: self.written,
                motion: b.motion,
                cl_line: b.cl_line,
                feed: b.feed,
            });
        }
    }

    /// The end of a gathered arc: one circular block when the machine can
    /// write it and it passes the check (see [`crate::native_arc`]),
    /// otherwise its blocks as they are (each passed the check already).
    /// `at`: the CL statement, for an error of the writer.
    fn end_arc(&mut self, at: &Diagnostic) -> Result<(), PostError> {
        let Some(g) = self.arc.take() else {
            return Ok(());
        };
        if let Some((block, deviation)) = self.native_block(&g) {
            let held = g.blocks.last().expect("a native arc has blocks");
            self.write_held(held, Some(block), at)?;
            let stats = &mut self.report.stats;
            if deviation > stats.max_position_error_mm {
                stats.max_position_error_mm = deviation;
                stats.worst_line = held.cl_line;
            }
            self.report.native_arcs += 1;
            return Ok(());
        }
        for held in &g.blocks {
            self.write_held(held, None, at)?;
        }
        Ok(())
    }

    /// The end of a gathered hole: the dialect's cycle when the hole's
    /// moves are exactly the cycle's (see [`crate::native_cycle`]) and the
    /// sink writes it, otherwise its blocks and commands as they are (each
    /// block passed the check already). `at`: the CL statement, for an
    /// error of the writer.
    fn end_hole(&mut self, at: &Diagnostic) -> Result<(), PostError> {
        let Some(g) = self.hole.take() else {
            return Ok(());
        };
        let mut items = g.items.into_iter();
        if let Some((prefix, hole)) =
            self.native_hole(&g.cycle, (g.rpm, g.ccw), &g.start, items.as_slice())
        {
            for item in items.by_ref().take(prefix) {
                self.release(item, at)?;
            }
            let written = self
                .sink
                .hole(&hole)
                .map_err(|e| PostError::from(at_statement(at, e)))?;
            if written {
                self.report.native_cycles += 1;
                return Ok(());
            }
        }
        for item in items {
            self.release(item, at)?;
        }
        Ok(())
    }

    /// The hole of a gathered hole's items and how many blocks come before
    /// it, if the sink may write it as a cycle: only blocks, dwells and
    /// spindle changes, and the blocks exactly the cycle's moves.
    fn native_hole(
        &mut self,
        cycle: &crate::cycle::HoleCycle,
        spindle: (Option<f64>, bool),
        start: &Joints,
        items: &[HeldItem],
    ) -> Option<(usize, kinpost_nc::Hole)> {
        let axes = self.cycle_axes.as_ref()?;
        let n = self.n;
        let mut blocks = Vec::with_capacity(items.len());
        for item in items {
            match item {
                HeldItem::Block(b) => blocks.push(native_cycle::HoleBlock {
                    exact: &b.row[..n],
                    written: &b.written[..n],
                    motion: b.motion,
                    feed: b.feed,
                }),
                HeldItem::Command(Pending {
                    command: Command::Dwell(_) | Command::Spindle(_),
                    ..
                }) => {}
                _ => return None,
            }
        }
        let sink = &mut self.sink;
        native_cycle::fit(cycle, axes, &start[..n], &blocks, spindle, |v, w| {
            sink.round(v, w)
        })
    }

    /// Hands one held item of a hole on to the sink.
    fn release(&mut self, item: HeldItem, at: &Diagnostic) -> Result<(), PostError> {
        match item {
            HeldItem::Block(held) => self.write_held(&held, None, at),
            HeldItem::Command(p) => self.sink.command(p),
            HeldItem::InverseTime(on) => self.sink.inverse_time(on),
        }
    }

    /// A held block (of an arc or a hole) as checked, straight or along
    /// `arc`.
    fn write_held(
        &mut self,
        held: &HeldBlock,
        arc: Option<ArcMotion>,
        at: &Diagnostic,
    ) -> Result<(), PostError> {
        let n = self.n + usize::from(self.has_pressure);
        self.sink
            .block(&Block {
                cl_line: held.cl_line,
                line: None,
                number: None,
                motion: held.motion,
                axes: &held.row[..n],
                feed: held.feed,
                arc,
            })
            .map_err(|e| PostError::from(at_statement(at, e)))
    }

    /// The circular block of a gathered arc and its largest distance from
    /// the CL arc, if it can be written: every block a feed block at one
    /// feed, no pressure axis, every free axis but X, Y, Z as at the start, the
    /// arc in a program plane there, and the block as written within the
    /// tolerance of the CL arc at its sampled points.
    fn native_block(&self, g: &Gathered) -> Option<(ArcMotion, f64)> {
        // (A machine with a pressure word writes it on a line of its own
        // before the block that changes it: its arcs stay lines.)
        if self.has_pressure {
            return None;
        }
        let axes = self.program_axes.as_ref()?;
        let kin = g.kin.as_ref()?;
        let last = g.blocks.last()?;
        let n = self.n;
        let steady = g.blocks.iter().all(|b| {
            b.motion == kinpost_nc::Motion::Feed
                && b.feed == last.feed
                && b.row[n].to_bits() == last.row[n].to_bits()
                && axes
                    .others
                    .iter()
                    .all(|&i| b.written[i].to_bits() == g.start[i].to_bits())
        });
        if !steady {
            return None;
        }
        let start = &g.start[..n];
        let mut native = native_arc::fit(kin, axes, &g.arc, start)?;
        if g.xy_only && native.plane != kinpost_nc::ArcPlane::Xy {
            return None;
        }
        let normal = axes.xyz[native.plane.axes()[2]];
        let helix = last.written[normal].to_bits() != g.start[normal].to_bits();
        if !self.sink.writes_arc(native.plane, helix) {
            return None;
        }
        native.centre_offset = self.sink.round_centre(native.centre_offset);
        let samples = (2 * g.blocks.len()).max(NATIVE_ARC_MIN_SAMPLES);
        let deviation = native_arc::deviation_mm(
            kin,
            axes,
            &g.arc,
            start,
            &last.written[..n],
            &native,
            samples,
        );
        (deviation <= self.report.tolerance.position_mm).then_some((native, deviation))
    }

    /// With the derived tolerance, a block beyond the machine-wide bound is
    /// still right if its error is what rounding causes at its own levers;
    /// the tolerance in force (and reported) grows to it.
    fn within_block_bound(&mut self, kin: &Kinematics, want: &Pose, got: &Pose) -> bool {
        let s = &self.settings;
        if s.tolerance_given || s.tcp.is_some() {
            return false;
        }
        let resolution = &s.resolution;
        let block = Tolerance::at_block(&self.machine, kin, &self.written[..self.n], |i| {
            resolution[i]
        });
        let (p, a) = pose_error(want, got);
        if p > block.position_mm || a > block.axis_rad {
            return false;
        }
        let t = &mut self.report.tolerance;
        t.position_mm = t.position_mm.max(p);
        t.axis_rad = t.axis_rad.max(a);
        true
    }
}

/// `error` of writing what the CL statement `at` asked for, located there.
fn at_statement<E: std::fmt::Display>(at: &Diagnostic, error: E) -> Located<E> {
    Located {
        diagnostic: Box::new(Diagnostic {
            message: error.to_string(),
            ..at.clone()
        }),
        error,
    }
}

impl<S: BlockSink> MotionSink for Check<S> {
    /// Rounds the block as the sink writes it, runs it through the forward
    /// kinematics, compares it with its target and hands it on.
    fn block(&mut self, kin: &Kinematics, b: &MotionBlock<'_>) -> Result<f64, PostError> {
        let n = self.n;
        self.sink.round(&b.values[..n], &mut self.written[..n]);
        let (mut reached, written_lever) = kin.fk_lever(
            &self.written[..n],
            &mut self.sin_cos,
            b.target.reference.is_some(),
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
        if !self.passes(kin, b, &reached) {
            let (position_mm, axis_rad) = pose_error(b.target, &reached);
            let t = &self.report.tolerance;
            return Err(b
                .site
                .locate(CheckError {
                    position_mm,
                    axis_rad,
                    tolerance_mm: t.position_mm,
                    tolerance_rad: t.axis_rad,
                    target: *b.target,
                })
                .into());
        }
        // The pressure column, if any, follows the axes (a copy of fixed
        // length: no call to memcpy).
        let mut row = [f64::NAN; MAX_AXES + 1];
        row[..MAX_AXES].copy_from_slice(b.values);
        row[n] = b.pressure;
        self.started = true;
        if self.arc.is_some() || self.hole.is_some() {
            self.hold(kin, b, &row);
            return Ok(lever);
        }
        self.sink
            .block(&Block {
                cl_line: b.cl_line,
                line: None,
                number: None,
                motion: b.motion,
                axes: &row[..n + usize::from(self.has_pressure)],
                feed: b.feed,
                arc: None,
            })
            .map_err(|e| PostError::from(b.site.locate(e)))?;
        Ok(lever)
    }

    fn command(&mut self, pending: Pending) -> Result<(), PostError> {
        match pending.command {
            Command::ArcBegin { arc, xy_only } => {
                self.end_arc(&pending.at)?;
                if self.program_axes.is_some() && self.started {
                    self.arc = Some(Box::new(Gathered {
                        arc,
                        start: self.written,
                        blocks: Vec::new(),
                        kin: None,
                        xy_only,
                    }));
                }
                Ok(())
            }
            Command::ArcEnd => self.end_arc(&pending.at),
            Command::HoleBegin { cycle, rpm, ccw } => {
                self.end_arc(&pending.at)?;
                self.end_hole(&pending.at)?;
                if self.cycle_axes.is_some() && self.started {
                    self.hole = Some(Box::new(GatheredHole {
                        cycle,
                        rpm,
                        ccw,
                        start: self.written,
                        items: Vec::new(),
                    }));
                }
                Ok(())
            }
            Command::HoleEnd => self.end_hole(&pending.at),
            _ => {
                if let Some(h) = &mut self.hole {
                    h.items.push(HeldItem::Command(pending));
                    return Ok(());
                }
                self.end_arc(&pending.at)?;
                self.sink.command(pending)
            }
        }
    }

    fn inverse_time(&mut self, on: bool) -> Result<(), PostError> {
        if let Some(h) = &mut self.hole {
            h.items.push(HeldItem::InverseTime(on));
            return Ok(());
        }
        self.sink.inverse_time(on)
    }

    fn feed_rounds_to_zero(&self, word: f64) -> bool {
        self.sink.feed_rounds_to_zero(word)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn tolerance_of_mts1600_at_3_decimals() {
        let m = kinpost_machine::builtin::load("mts1600").unwrap().unwrap();
        let t = Tolerance::from_resolution(&m, |_| 0.001);
        // 3 linear axes × 0.0005 mm + 2 free rotaries × 0.0005° × lever.
        let lever = m.largest_pivot_distance();
        let want = 3.0 * 0.0005 + 2.0 * 0.0005f64.to_radians() * lever + 1e-9;
        assert!((t.position_mm - want).abs() < 1e-15);
        // The A line (the X axis) is farthest from the home contact point
        // (43, 79.2, −350); the travel box is 1750.5 × 501 × 501.3 mm.
        let want_lever = (79.2f64.powi(2) + 350.0f64.powi(2)).sqrt()
            + (1750.5f64.powi(2) + 501.0f64.powi(2) + 501.3f64.powi(2)).sqrt();
        assert!((lever - want_lever).abs() < 1e-9, "{lever} vs {want_lever}");
        assert!((t.axis_rad - (2.0 * 0.0005f64.to_radians() + 1e-9)).abs() < 1e-15);
    }

    #[test]
    fn a_head_no_linear_axis_follows_keeps_its_pivot_as_lever() {
        // head-head-bc: X Y Z carry the C fork, which carries the B spindle
        // with its line 250 mm above the tool tip; the linear travel does
        // not move the tool tip away from either line.
        let m = kinpost_machine::builtin::load("head-head-bc")
            .unwrap()
            .unwrap();
        assert!((m.largest_pivot_distance() - 250.0).abs() < 1e-9);
        let t = Tolerance::from_resolution(&m, |_| 0.001);
        let want = 3.0 * 0.0005 + 2.0 * 0.0005f64.to_radians() * 250.0 + 1e-9;
        assert!((t.position_mm - want).abs() < 1e-15, "{}", t.position_mm);
    }

    #[test]
    fn stats_keep_exact_maxima() {
        let pose = |x: f64, ax: f64| Pose {
            point: Vector3::new(x, 0.0, 0.0),
            axis: Vector3::new(ax.sin(), 0.0, ax.cos()),
            reference: None,
        };
        let tol = Tolerance {
            position_mm: 0.5,
            axis_rad: 0.25,
        };
        let mut s = CheckStats::default();
        assert!(s.record(&pose(0.0, 0.0), &pose(0.3, 0.2), 7, &tol));
        assert!(s.record(&pose(0.0, 0.0), &pose(0.1, 0.1), 8, &tol));
        assert!((s.max_position_error_mm - 0.3).abs() < 1e-15);
        assert!((s.max_axis_error_rad - 0.2).abs() < 1e-15);
        assert_eq!(s.worst_line, Some(7));
        assert!(!s.record(&pose(0.0, 0.0), &pose(0.0, 2.5), 9, &tol));
        assert!((s.max_axis_error_rad - 2.5).abs() < 1e-12);
    }

    #[test]
    fn six_axis_blocks_are_checked_on_their_reference_too() {
        // The same point and tool axis, the reference turned 0.1 rad about
        // the axis: an orientation error of 0.1 rad.
        let pose = |r: Vector3<f64>| Pose {
            point: Vector3::zeros(),
            axis: Vector3::z(),
            reference: Some(r),
        };
        let tol = Tolerance {
            position_mm: 0.01,
            axis_rad: 1e-3,
        };
        let turned = Vector3::new(0.1f64.cos(), 0.1f64.sin(), 0.0);
        let mut s = CheckStats::default();
        assert!(!s.record(&pose(Vector3::x()), &pose(turned), 3, &tol));
        assert!((s.max_axis_error_rad - 0.1).abs() < 1e-12);
        assert!((pose_error(&pose(Vector3::x()), &pose(turned)).1 - 0.1).abs() < 1e-12);
        // A CL reference with a part along the tool axis points the same
        // way once that part is left out, as the inverse kinematics has it.
        let mut s = CheckStats::default();
        let leaning = Vector3::new(1.0, 0.0, 0.3).normalize();
        assert!(s.record(&pose(leaning), &pose(Vector3::x()), 4, &tol));
        assert_eq!(s.max_axis_error_rad, 0.0);
        // Without a reference on both sides there is nothing to compare.
        let mut none = pose(Vector3::x());
        none.reference = None;
        assert_eq!(reference_error(&pose(turned), &none), 0.0);
    }

    #[test]
    fn small_angles_are_accurate() {
        let a = Vector3::z();
        let b = Vector3::new(1e-10, 0.0, 1.0).normalize();
        assert!((angle_between(&a, &b) - 1e-10).abs() < 1e-20);
    }
}
