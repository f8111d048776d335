//! Why a post run fails, and what it warns about: typed errors and warnings
//! of every stage, in one place. An error about a CL statement is located
//! once, by the stage that knows the statement ([`Located`]); the messages
//! are the errors' texts.

use kinpost_diag::{Diagnostic, Located};
use kinpost_machine::Pose;
use kinpost_nc::{BlockError, NcError};
use kinpost_plan::PlanError;

/// Why a post run failed.
#[derive(Debug, thiserror::Error)]
pub enum PostError {
    /// The CL reader's own error (a malformed statement).
    #[error("{0}")]
    Cl(Box<Diagnostic>),
    /// A CL statement the program cannot follow.
    #[error("{0}")]
    Program(Box<Located<ProgramError>>),
    /// A CL point no configuration of the machine reaches.
    #[error("{0}")]
    Plan(Box<Located<PlanError>>),
    /// A move between CL points the machine cannot make as asked.
    #[error("{0}")]
    Motion(Box<Located<MotionError>>),
    /// A block that fails the closed-loop check.
    #[error("{0}")]
    Check(Box<Located<CheckError>>),
    /// A block value the dialect cannot write.
    #[error("{0}")]
    Block(Box<Located<BlockError>>),
    /// A command template failing on a CL statement.
    #[error("{0}")]
    Command(Box<Located<NcError>>),
    /// A header or footer template failing.
    #[error("{0}")]
    Template(Box<NcError>),
    /// The machine and dialect cannot write this kind of program.
    #[error(transparent)]
    Setup(#[from] SetupError),
    /// An option value out of range.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The output could not be written.
    #[error("cannot write the NC program: {0}")]
    Io(#[from] std::io::Error),
}

impl PostError {
    /// The place in the CL file the error is about, for the user, if it is
    /// about one.
    pub fn diagnostic(&self) -> Option<&Diagnostic> {
        match self {
            PostError::Cl(d) => Some(d),
            PostError::Program(e) => Some(&e.diagnostic),
            PostError::Plan(e) => Some(&e.diagnostic),
            PostError::Motion(e) => Some(&e.diagnostic),
            PostError::Check(e) => Some(&e.diagnostic),
            PostError::Block(e) => Some(&e.diagnostic),
            PostError::Command(e) => Some(&e.diagnostic),
            PostError::Template(_)
            | PostError::Setup(_)
            | PostError::Config(_)
            | PostError::Io(_) => None,
        }
    }
}

impl From<Diagnostic> for PostError {
    fn from(d: Diagnostic) -> Self {
        PostError::Cl(Box::new(d))
    }
}

impl From<Located<ProgramError>> for PostError {
    fn from(e: Located<ProgramError>) -> Self {
        PostError::Program(Box::new(e))
    }
}

impl From<Located<PlanError>> for PostError {
    fn from(e: Located<PlanError>) -> Self {
        PostError::Plan(Box::new(e))
    }
}

impl From<Located<MotionError>> for PostError {
    fn from(e: Located<MotionError>) -> Self {
        PostError::Motion(Box::new(e))
    }
}

impl From<Located<CheckError>> for PostError {
    fn from(e: Located<CheckError>) -> Self {
        PostError::Check(Box::new(e))
    }
}

impl From<Located<BlockError>> for PostError {
    fn from(e: Located<BlockError>) -> Self {
        match e.error {
            BlockError::Io(io) => PostError::Io(io),
            _ => PostError::Block(Box::new(e)),
        }
    }
}

impl From<Located<NcError>> for PostError {
    fn from(e: Located<NcError>) -> Self {
        match e.error {
            NcError::Io(io) => PostError::Io(io),
            _ => PostError::Command(Box::new(e)),
        }
    }
}

impl From<NcError> for PostError {
    fn from(e: NcError) -> Self {
        match e {
            NcError::Io(io) => PostError::Io(io),
            other => PostError::Template(Box::new(other)),
        }
    }
}

/// Why a point handed to the planner failed: the point itself (no
/// configuration of the machine reaches it; the caller locates it at its
/// statement), or a later stage, located already.
#[derive(Debug)]
pub enum PointError {
    /// No configuration reaches the point.
    Point(PlanError),
    /// A stage after the planner failed.
    Post(PostError),
}

impl From<PostError> for PointError {
    fn from(e: PostError) -> Self {
        PointError::Post(e)
    }
}

/// A CL statement the program stage cannot follow.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProgramError {
    /// `FEDRAT/MMPR|IPR` before any spindle speed.
    #[error("a feed per revolution needs the spindle speed: give SPINDL/rpm before it")]
    FeedPerRevWithoutSpindle,
    /// A feed move while the feed is per revolution and the spindle is off.
    #[error(
        "feed move at a feed per revolution with the spindle off (SPINDL/OFF): give SPINDL/rpm before it"
    )]
    SpindleOffForFeedPerRev,
    /// A feed move before any `FEDRAT`.
    #[error("feed move before any FEDRAT: the controller has no feed rate for it")]
    NoFeedRate,
    /// `PRESSURE` names another word than the machine's pressure axis.
    #[error("PRESSURE names `{word}`, but the pressure word of machine `{machine}` is `{axis}`")]
    PressureWord {
        /// The word the CL names.
        word: String,
        /// The machine.
        machine: String,
        /// Its pressure word.
        axis: String,
    },
    /// A pressure the machine, dialect or output mode cannot program.
    #[error(transparent)]
    Pressure(#[from] PressureError),
    /// A CL point with a reference direction in a program that began
    /// without (`false`), or the other way round (`true`).
    #[error("{}", if *.0 {
        "this CL point has no reference direction, but the program began with them \
         (6-axis output): give every GOTO nine values, or none"
    } else {
        "this CL point has a reference direction, but the program began without \
         (5-axis output, locked axes stay locked): give every GOTO nine values, or none"
    })]
    ReferenceMismatch(bool),
    /// A later `MSYS` changes the machine coordinate system of the first.
    #[error(
        "MSYS changes the machine coordinate system of line {first_line}: with --frame mcs (the \
         default) every point is posted in the MCS as written; post the operations of each \
         coordinate system as a program of their own, or give --frame absolute to post them all \
         in the absolute frame"
    )]
    MachineSystemChanged {
        /// The line of the first `MSYS`.
        first_line: usize,
    },
    /// An `MSYS` with an axis but not both, under `--frame absolute`: its
    /// points cannot be placed in the absolute frame.
    #[error(
        "MSYS gives no complete frame (origin, X and Y axes): --frame absolute cannot place the \
         points that follow"
    )]
    MachineSystemIncomplete,
    /// A statement the reader understands and the post does not act on yet.
    #[error("{what}: kinpost reads it but does not post it yet")]
    NotPosted {
        /// What the statement asks for.
        what: &'static str,
    },
    /// A `CIRCLE` whose arc cannot be built from the current point to the
    /// next `GOTO`.
    #[error("CIRCLE: {0}")]
    Arc(#[from] kinpost_cl::ArcError),
    /// A curve that cannot be linearized within the tolerance.
    #[error("the curve cannot be followed within the tolerance: {0}")]
    Sample(#[from] kinpost_cl::SampleError),
    /// A canned cycle that cannot be expanded.
    #[error(transparent)]
    Cycle(#[from] crate::cycle::CycleError),
    /// A `CIRCLE` while a canned cycle is on: its `GOTO` is a hole.
    #[error(
        "CIRCLE while a CYCLE is on: the next GOTO is a hole, not the end of an arc; give CYCLE/OFF first"
    )]
    CircleInCycle,
    /// `GOHOME` with no point to go to.
    #[error(
        "GOHOME with no home point: the CL gives no point and no FROM, and the machine file has no `[post] home`; give GOHOME/x,y,z, a FROM before it, or the machine's home axis values"
    )]
    NoHome,
    /// A surface speed with no tool diameter to turn it into rpm.
    #[error(
        "SPINDL in surface speed (SMM/SFM) needs the tool diameter to give rpm: give TLDATA or CUTTER with the diameter before it"
    )]
    SurfaceSpeedWithoutDiameter,
    /// A dwell in spindle revolutions with the spindle off.
    #[error(
        "DELAY in spindle revolutions, but no spindle speed is in force: give SPINDL/rpm before it"
    )]
    DwellRevolutionsWithoutSpindle,
    /// Cutter compensation in another plane than XY.
    #[error(
        "CUTCOM in the {0} plane: kinpost writes cutter compensation in the XY plane (G17) only"
    )]
    CutcomPlane(&'static str),
    /// `ORIGIN` with an offset.
    #[error(
        "ORIGIN/{0:?} moves the program origin: kinpost posts every point in the machine file's part frame and does not shift it; set the work offset there, or remove the ORIGIN"
    )]
    OriginOffset([f64; 3]),
    /// A dwell that cannot be written.
    #[error("DELAY of {0} s: a dwell is a finite number of seconds, not below 0")]
    Dwell(f64),
}

/// Why a pressure cannot be programmed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PressureError {
    /// The machine has no `[pressure]` section.
    #[error("machine `{0}` has no pressure axis (no [pressure] section)")]
    NoPressureAxis(String),
    /// The dialect has no `[pressure]` table.
    #[error(
        "dialect `{dialect}` cannot write the pressure word `{word}`: it has no [pressure] table \
         (copy it and add one, see docs/dialects.md)"
    )]
    NoPressureWord {
        /// The dialect.
        dialect: String,
        /// The machine's pressure word.
        word: String,
    },
    /// Tool-centre-point output cannot move the tool point by the wheel
    /// offset.
    #[error(
        "tool-centre-point output cannot compensate the wheel offset at {word} = {value} ({offset_mm:.3} mm): \
         the controller puts the tool point where its own tool data says; use joint output \
         (--output joint), or --no-pressure-compensation"
    )]
    TcpCannotCompensate {
        /// The pressure word.
        word: String,
        /// The pressure, as a user writes it.
        value: String,
        /// How far the wheel moves, mm.
        offset_mm: f64,
    },
}

/// What programming a pressure means that the user should know.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PressureWarning {
    /// The pressure lies outside the calibration: the wheel sits on a stop.
    #[error(
        "{word} = {value} is {} the machine's calibration ({} .. {}): the wheel sits on its stop, \
         where it is at {word} = {stop}",
        if *.above { "above" } else { "below" },
        .range[0],
        .range[1]
    )]
    OnStop {
        /// The pressure word.
        word: String,
        /// The pressure, as a user writes it.
        value: String,
        /// Above the calibration (else below).
        above: bool,
        /// The calibration's ends.
        range: [String; 2],
        /// The end it is clamped to.
        stop: String,
    },
    /// `--no-pressure-compensation`: the wheel is off where it would be.
    #[error(
        "not compensated (--no-pressure-compensation): at {word} = {value} the wheel is {offset_mm:.3} mm from \
         where it is at the reference {word} = {reference} ({:.3} mm along {}, {:.3} mm along {}), and so \
         is every contact point",
        .along[0].0,
        .along[0].1,
        .along[1].0,
        .along[1].1
    )]
    NotCompensated {
        /// The pressure word.
        word: String,
        /// The pressure, as a user writes it.
        value: String,
        /// How far the wheel is off, mm.
        offset_mm: f64,
        /// The reference pressure.
        reference: String,
        /// The offset along the two plane axes, mm, and their names.
        along: [(f64, String); 2],
    },
}

/// The machine and the dialect cannot write this kind of program.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetupError {
    /// Tool-centre-point output needs free linear axes X, Y and Z.
    #[error(
        "tool-centre-point output needs free linear axes named X, Y and Z; machine `{machine}` has no {axis}"
    )]
    TcpAxes {
        /// The machine.
        machine: String,
        /// The axis missing.
        axis: &'static str,
    },
    /// The dialect lacks a template the program needs.
    #[error("dialect `{dialect}` has no `{template}` template: it cannot {what}")]
    MissingTemplate {
        /// The dialect.
        dialect: String,
        /// The template's key.
        template: &'static str,
        /// What it would do.
        what: &'static str,
    },
    /// `--pressure` cannot be programmed.
    #[error(transparent)]
    Pressure(#[from] PressureError),
}

/// An option value out of range (a usage error of the command).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// A value outside its range: the option and what it must be.
    #[error("{option} must be {must}")]
    OutOfRange {
        /// The option, as the command spells it (`--lintol`).
        option: &'static str,
        /// What it must be.
        must: &'static str,
    },
    /// An axis rounding outside 0 ..= `max_rad`.
    #[error(
        "--axis-rounding must be an angle from 0 to {max_rad:e} rad (the rounding of a CL tool axis; 1e-4 for 4 decimals)"
    )]
    AxisRounding {
        /// The largest axis rounding, radians.
        max_rad: f64,
    },
}

/// A move between CL points the machine cannot make as the CL asks.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    /// The linearization of a CL segment fails.
    #[error("{kind} between CL line {from_line} and this point, {to}")]
    Linearization {
        /// Why.
        kind: LinearizationFailure,
        /// The CL line the segment starts at.
        from_line: usize,
        /// The pose it ends at.
        to: Pose,
    },
    /// The tool axis interpolated along a segment leaves the band of
    /// directions the machine can point.
    #[error(
        "the tool axis interpolated between CL line {from_line} and this point, {to}, passes {depth_deg:.4}° into the cone of directions within {half_angle_deg:.4}° of ({:.7}, {:.7}, {:.7}) that the machine cannot point: add CL points outside that cone, or --lintol 0 writes the segment as one joint move",
        .cone_axis[0],
        .cone_axis[1],
        .cone_axis[2]
    )]
    LeavesBand {
        /// The CL line the segment starts at.
        from_line: usize,
        /// The pose it ends at.
        to: Pose,
        /// How deep the interpolated axis passes into the cone, degrees.
        depth_deg: f64,
        /// The cone's half-angle, degrees.
        half_angle_deg: f64,
        /// The cone's axis.
        cone_axis: [f64; 3],
    },
    /// A reconfiguration is needed, and the options forbid it.
    #[error(
        "no continuous motion reaches this point from CL line {from_line} inside the travel ({axis} would have to jump from {from_deg:.3}° to {to_deg:.3}°); \
         a retract and reconfiguration is needed, but --no-reconfigure forbids it"
    )]
    ReconfigurationForbidden {
        /// The CL line before.
        from_line: usize,
        /// The rotary axis with the largest jump.
        axis: String,
        /// Its value before, degrees.
        from_deg: f64,
        /// Its value after, degrees.
        to_deg: f64,
    },
    /// The retract of a reconfiguration leaves the travel.
    #[error(
        "the retract of {retract_mm} mm along the tool axis for a reconfiguration {} is outside the travel \
         (set a smaller distance with --retract or [post] retract)",
        if *.above { "above this point" } else { "before this point" }
    )]
    RetractOutsideTravel {
        /// The retract distance, mm.
        retract_mm: f64,
        /// Above the point after (else: above the point before).
        above: bool,
    },
    /// A feed block without a feed rate.
    #[error("feed move before any FEDRAT: the controller has no feed rate for it")]
    NoFeedRate,
    /// A feed word that the dialect's decimals write as 0.
    #[error(
        "the feed word {word} rounds to 0 with the dialect's feed decimals (CL feed rate {feed} mm/min): \
         the controller would not move; check the FEDRAT"
    )]
    FeedRoundsToZero {
        /// The feed word.
        word: f64,
        /// The CL feed rate, mm/min.
        feed: f64,
    },
}

/// Why a CL segment cannot be linearized.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum LinearizationFailure {
    /// The directions of the three linear axes become coplanar along it.
    #[error(
        "the linear axes cannot follow the straight CL segment (rotary axes between them in the chain turn their directions into a plane along it, where their travel grows without bound; --lintol 0 writes the segment as one joint move)"
    )]
    LinearPlane,
    /// The halving reached its depth while the pose hardly moved.
    #[error(
        "the rotary axes cannot follow the path continuously (the joint motion does not converge to the straight CL segment)"
    )]
    NoConvergence,
    /// No solution inside the travel at a midpoint.
    #[error("an intermediate pose of the linearization is outside the travel")]
    OutsideTravel,
}

/// What the post could not do quite as the CL asks, at a CL point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionWarning {
    /// A segment left uncut by a reconfiguration.
    #[error(
        "the segment from CL line {from_line} to this point ({uncut_mm:.3} mm) is not cut: no setting \
         of the rotary axes inside the travel moves along it continuously, and after the \
         retract and reconfiguration ({axis} {from_deg:.3}° to {to_deg:.3}°) the tool re-approaches this point"
    )]
    Uncut {
        /// The CL line the segment starts at.
        from_line: usize,
        /// Its length, mm.
        uncut_mm: f64,
        /// The rotary axis with the largest jump.
        axis: String,
        /// Its value before, degrees.
        from_deg: f64,
        /// Its value after, degrees.
        to_deg: f64,
    },
    /// A rotary axis without a maximum velocity turned implausibly fast.
    #[error(
        "this feed block turns {axis} by {turned_deg:.3}° in {:.1e} s ({speed_deg_per_min:.0}°/min): \
         the machine file gives {axis} no max_velocity to hold it to",
        .minutes * 60.0
    )]
    FastTurn {
        /// The axis.
        axis: String,
        /// How far it turns, degrees.
        turned_deg: f64,
        /// In how long, minutes.
        minutes: f64,
        /// At what speed, degrees per minute.
        speed_deg_per_min: f64,
    },
}

/// A block that fails the closed-loop check.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "closed-loop check failed: the block as written puts the tool {position_mm:.6} mm and {axis_rad:.3e} rad \
     from the CL pose (tolerance {tolerance_mm:.6} mm, {tolerance_rad:.3e} rad); {target}"
)]
pub struct CheckError {
    /// Distance of the tool point from the CL point, mm.
    pub position_mm: f64,
    /// Angle of the tool axis (or reference) from the CL's, radians.
    pub axis_rad: f64,
    /// The position tolerance in force, mm.
    pub tolerance_mm: f64,
    /// The axis tolerance in force, radians.
    pub tolerance_rad: f64,
    /// The pose the block must reach.
    pub target: Pose,
}
