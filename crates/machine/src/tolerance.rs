//! Every tolerance of the post's pipeline, in one place, each with its
//! reason. Lengths are in mm (`_MM`), angles in degrees (`_DEG`) or radians
//! (`_RAD`); a bare number is a ratio.
//!
//! The kinematics solves poses to about 1e-9 mm and 1e-12 rad (closed
//! forms in `f64`); the NC output rounds to 1e-3 or 1e-4 mm. The slacks
//! below sit between the two: far above the arithmetic's round-off, far
//! below anything the output can show.

pub use crate::kinematics::{AXIS_ROUNDING_RAD, MAX_AXIS_ROUNDING_RAD};

/// Default linearization tolerance: how far the contact point, moved
/// linearly in joint space between two blocks, may stray from the straight
/// CL segment, mm. A fifth of a typical finishing tolerance of 0.01 mm.
pub const DEFAULT_LINTOL_MM: f64 = 0.002;

/// Default half-angle of the singular cone, degrees: inside it a machine's
/// free angle moves faster than a cut allows for small turns of the tool
/// axis (its rate grows like 1 / sin of the distance to the pole), so the
/// angle is held there where the exact one would swing.
pub const DEFAULT_SINGULAR_CONE_DEG: f64 = 0.5;

/// Default retract distance of a reconfiguration, mm: clear of the part
/// for the turn of the rotary axes on most jobs.
pub const DEFAULT_RETRACT_MM: f64 = 50.0;

/// How close to a fold the interpolated tool axis counts as reaching it,
/// radians: the rounding of CL tool axes; the branches lie within ≈ √(1e-9)
/// of each other there.
pub const FOLD_SLACK_RAD: f64 = 1e-9;

/// How far outside the singular cone an interpolated tool axis may pass
/// the singular direction and still count as entering it, radians: the
/// round-off of the arc's least distance.
pub const POLE_SLACK_RAD: f64 = 1e-9;

/// Slack of the triangle-inequality test that an arc of tool axes may come
/// within the singular cone (two distances and a turn added), degrees.
pub const ARC_SUM_SLACK_DEG: f64 = 1e-9;

/// Relative slack of the lower bound of a tool axis's distance from the
/// singular direction: far above the rounding of the bound and of `atan2`
/// (a few ulp each).
pub const POLE_BOUND_SLACK: f64 = 1e-12;

/// A run of CL points shorter than this does not move, mm: its singular
/// angle is interpolated by count, not by length.
pub const NO_LENGTH_MM: f64 = 1e-9;

/// How far a solution's held angle may lie from the value held, degrees.
/// The tool axis solved is one the machine points with that value, so the
/// solution has it up to rounding; where that axis lies on a fold (the two
/// branches meet there, as beside the small hole of a C axis out of
/// square), the angle is found through a square root of a near-zero term,
/// and lies up to about 1e-4° off.
pub const HELD_SLACK_DEG: f64 = 1e-3;

/// What the chord bound of the linearization adds for the ends of a joint
/// motion not being exactly on their CL points (the inverse kinematics is
/// exact to 1e-9 mm), mm.
pub const CHORD_SLACK_MM: f64 = 1e-6;

/// Deepest halving of one CL segment by the linearization (2^16 blocks).
pub const MAX_HALVING_DEPTH: u32 = 16;

/// Most equal pieces a CL segment is cut into at once by the linearization
/// (each may still be halved).
pub const MAX_PIECES: f64 = 4096.0;

/// How many more pieces than the midpoint's deviation says are cut at once,
/// so that a segment of even curvature needs no halving after.
pub const PIECES_MARGIN: f64 = 1.05;

/// A piece of a CL segment this short, mm, that turns the tool axis by
/// less than [`STALL_TURN_RAD`] and still strays from its chord: the axes
/// move while the pose hardly does, and halving it further cannot help.
pub const STALL_SPAN_MM: f64 = 1e-7;

/// See [`STALL_SPAN_MM`], radians.
pub const STALL_TURN_RAD: f64 = 1e-9;

/// The signed volume the directions of three linear axes span (1 for axes
/// at right angles) below which they count as nearly coplanar: their travel
/// grows like its inverse.
pub const COPLANAR_VOLUME: f64 = 0.02;

/// How far an interpolated tool axis must pass into a cone of directions
/// the machine cannot point to be that cone's fault, radians; below it the
/// linearization's own rounding decides.
pub const BAND_DEPTH_RAD: f64 = 1e-9;

/// A block whose tool point moves less than this only turns, mm: it takes
/// its largest rotary change in degrees over the feed rate (the same for
/// every dialect).
pub const PURE_TURN_MM: f64 = 1e-3;

/// A block that moves less than this (mm, or degrees when it only turns)
/// has no block time: its feed word is the CL feed rate.
pub const NO_MOVE: f64 = 1e-9;

/// Relative slack before an axis's maximum velocity slows a block down
/// (the division that gives its time rounds).
pub const VMAX_SLACK: f64 = 1e-9;

/// A rotary axis without a maximum velocity that a feed block turns faster
/// than this, degrees per minute (100 turns a minute), is warned about once.
pub const FAST_TURN_DEG_PER_MIN: f64 = 36_000.0;

/// Slack of the closed-loop tolerance for the check's own arithmetic
/// (forward kinematics of rounded values), mm.
pub const CHECK_SLACK_MM: f64 = 1e-9;

/// See [`CHECK_SLACK_MM`], radians.
pub const CHECK_SLACK_RAD: f64 = 1e-9;

/// The step of the central differences that measure a rotary axis's lever
/// at one block, degrees.
pub const LEVER_PROBE_DEG: f64 = 1e-3;

/// What the first-order rounding bound of one block is multiplied by to
/// cover the second-order terms of half a unit.
pub const SECOND_ORDER_MARGIN: f64 = 1.5;

/// A reference direction whose part normal to the tool axis is shorter
/// than this gives no direction to compare.
pub const REFERENCE_NORMAL_MIN: f64 = 1e-12;

/// A CL reference direction off perpendicular to the tool axis by more than
/// this is remarked on (its part along the axis is left out), degrees.
pub const REFERENCE_SKEW_DEG: f64 = 0.1;

/// How far the linear axes of a machine may be from a rigid map of the
/// part frame (|MᵀM − I| of the tool point's motion per mm of X, Y, Z at
/// fixed rotary values) for its arcs to be written as circular blocks:
/// arithmetic only; every kinematic chain of rigid axes is exact to it.
pub const NATIVE_ARC_RIGID: f64 = 1e-9;

/// How far an arc's normal, mapped into the program's X, Y, Z, may be
/// from a coordinate axis (1 − |cos|) for the arc to lie in G17, G18 or
/// G19: arithmetic only (a CL arc axis is written with 6 or more
/// decimals; 1e-9 of the cosine is 4.5e-5 rad, far below them, so an
/// arc in a tilted plane is never taken for one in a machine plane).
pub const NATIVE_ARC_PLANE_COS: f64 = 1e-9;

/// Largest difference of the radii to the start and the end of a written
/// circular block, mm: controllers refuse an arc whose end is off its
/// circle by more (LinuxCNC's default for G2/G3 with I J K is 0.0005 inch
/// absolute with 0.1 % relative; this stays below it).
pub const NATIVE_ARC_RADIUS_MISMATCH_MM: f64 = 0.002;

/// Points of a written circular block compared with the CL arc by the
/// closed-loop check, at least, besides one between every two of its
/// linearized points.
pub const NATIVE_ARC_MIN_SAMPLES: usize = 16;
