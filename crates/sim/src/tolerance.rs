//! The replay's tolerances and assumptions, in one place with their reasons.

/// How far beyond its travel an axis may go unreported, mm or degrees: the
/// slack of `Axis::accepts` for values computed exactly at a limit. A value
/// a program writes past its limit by the smallest output unit (0.001) is
/// reported.
pub const TRAVEL_MM_OR_DEG: f64 = 1e-9;

/// Rapid rate assumed for a linear axis whose machine file gives no
/// `max_velocity`, mm/min: a common rapid traverse of machining centres
/// (10 m/min). Said in the report's `assumed` when used.
pub const ASSUMED_RAPID_MM_PER_MIN: f64 = 10_000.0;

/// Rapid rate assumed for a rotary axis without `max_velocity`,
/// degrees/min: 10 revolutions per minute, a common rotary-table rapid.
pub const ASSUMED_RAPID_DEG_PER_MIN: f64 = 3_600.0;

/// Below this X Y Z travel a feed block is a rotary-only move whose feed
/// applies to degrees, mm.
pub const STANDSTILL_MM: f64 = 1e-9;

/// Longest step of the tool point between two points compared with the
/// CL inside a feed block, mm. Near its largest value the deviation from a
/// CL curve of radius R changes with the square of the distance from the
/// sample, so the largest deviation along a block is found to within
/// about (step / 2)² / (2 R): 1.3e-4 mm against a CL arc of 10 mm radius,
/// less against straight CL segments.
pub const SAMPLE_STEP_MM: f64 = 0.1;

/// Largest step of a rotary axis between two compared points, degrees.
pub const SAMPLE_STEP_DEG: f64 = 0.25;

/// Chord error of the samples of an arc, mm.
pub const SAMPLE_CHORD_MM: f64 = 1e-3;

/// Most points compared inside one block (a block of several metres or
/// full turns is still sampled every few millimetres or less).
pub const MAX_SAMPLES_PER_BLOCK: usize = 100_000;

/// Largest change of a rotary axis over one chord of a block under
/// tool-centre-point control in the collision check, degrees: the
/// joint-linear chord leaves the controller's path by about L·θ²/8, under
/// 0.02 mm for a lever L of half a metre.
pub const TCP_CHORD_DEG: f64 = 1.0;

/// Largest travel of a linear axis over one chord of a block under
/// tool-centre-point control in the collision check, mm.
pub const TCP_CHORD_MM: f64 = 10.0;

/// Poses sampled after a contact's first pose to find how near the pair
/// comes in the rest of the piece (`collide.rs`): the sweep stops at the
/// first pose within the clearance, and the report gives the nearest.
pub const NEAREST_SAMPLES: usize = 16;

/// The golden-section search for the nearest pose of a contact stops
/// when its bracket is this fraction of the piece.
pub const NEAREST_FRACTION: f64 = 1e-4;
