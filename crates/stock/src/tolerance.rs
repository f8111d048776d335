//! Every tolerance of the crate, in one place, with its reason.

/// Largest distance, as a fraction of the resolution, that any point of a
/// tool within reach of the stock moves between two consecutive sampled
/// poses of a move that is not a pure translation (or of a piece without an
/// analytic sweep). Across the rays, one spacing is what the stock
/// resolves. Along a ray, the spans of consecutive samples overlap and are
/// united, so what a sampled move leaves is the cusp between two positions
/// of the tool's surface, δ²/(8ρ) for δ ≤ h and a surface of radius ρ:
/// 6·10⁻⁶ mm for a 50 mm wheel and 1·10⁻⁴ mm for a 6 mm ball at h =
/// 0.05 mm, far below a comparison tolerance (0.01 mm). Only at a sharp
/// edge (a wheel's side) may the uncut sliver reach one ray spacing.
pub const SAMPLE_STEP_FRACTION: f64 = 1.0;

/// Two tool axes (unit vectors) whose difference is below this are the same
/// axis: the move is a pure translation and is swept analytically. 1e-12 is
/// a thousand times the rounding of a unit vector's components.
pub const SAME_AXIS: f64 = 1e-12;

/// Solid intervals shorter than this (mm) are dropped after a cut: a sliver
/// of a nanometre is rounding between a tool's entry and exit, not material.
pub const SLIVER_MM: f64 = 1e-9;

/// Numerical convergence of the iterative ray intersections (the rounded
/// disc of a bull-nose corner or a wheel edge), in mm along the ray: a
/// thousand times below the 1e-6 mm the tests ask of exact cuts.
pub const ROOT_MM: f64 = 1e-9;

/// Default comparison tolerance (mm): deviations within ±0.01 mm count as
/// "within tolerance" (the brief's default, VERICUT's usual AUTO-DIFF
/// setting for finishing).
pub const DEFAULT_DIFF_TOL_MM: f64 = 0.01;

/// The ray count the default resolution aims at: about 16 million rays,
/// about 0.5 GiB of intervals (32 bytes a ray).
pub const DEFAULT_RAY_BUDGET: f64 = 16.0e6;

/// Default resolutions are rounded up to one of these "nice" spacings (mm).
pub const NICE_RESOLUTIONS_MM: [f64; 12] = [
    0.005, 0.01, 0.02, 0.025, 0.05, 0.1, 0.2, 0.25, 0.5, 1.0, 2.0, 5.0,
];

/// The largest number of rays a stock may have: 100 million rays hold
/// about 3 GiB of intervals, six times the brief's largest stock (the
/// 250 × 80 × 40 mm block at 0.05 mm: 13 million); a finer lattice on a
/// shared 24 GiB machine is an error to report, not an allocation to try.
pub const MAX_RAYS: u64 = 100_000_000;
