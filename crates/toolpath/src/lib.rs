//! Belt-grinding paths on B-spline surfaces (Li (B-spline grinding), §5).
//!
//! A contact wheel of radius R and width W rolls along iso-parametric
//! passes of a [`Surface`], zig-zag: its axis lies in the tangent plane
//! across the pass, so a pass grinds a strip about W wide. The CL tool
//! axis is the surface normal on the chosen side (from the contact point
//! towards the wheel: Li (B-spline grinding) eq. 29 puts the wheel's grinding-face normal
//! on it), the CL point the contact point, and the tool reference the feed
//! direction of the passes (for 6-axis machines).
//!
//! * Point spacing along a pass: the chord between two CL points deviates
//!   from the surface by at most the chord tolerance (estimated from the
//!   curve's curvature, √(8·tol/κ), then checked at quarter points), and the
//!   tool axis turns by at most a given angle.
//! * Spacing between passes: a step-over (largest distance between the
//!   contact points of neighbouring passes), by default W·(1 − overlap);
//!   with a scallop limit, the largest step whose scallop stays under it.
//! * Scallop height: the material left between two passes, measured from
//!   the wheels themselves (see [`scallop`]): for a point X of the surface
//!   between the passes, its clearance to each wheel (the distance from X
//!   along the surface normal to the wheel's cylinder, within the wheel's
//!   width); the scallop is the largest over X of the smaller clearance. A negative clearance is
//!   the wheel's edge cutting under the design surface (a concave section
//!   across the pass, where a rigid straight wheel would gouge; real contact
//!   wheels yield), reported as the wheel-edge interference, looked for
//!   over each wheel's whole width (out to its edges, beyond the
//!   neighbouring pass when the step is smaller than half the width).
//!
//! Passes start and end with a lead along the normal and are joined by
//! rapids. [`cl::write_cl`] writes the NX-style CL file, [`plot::plot_path`]
//! an SVG of the passes.

#![deny(missing_docs)]
// `!(a < b)` on floats is deliberate here: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Band and basis arithmetic reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

pub mod cl;
mod path;
pub mod plot;
pub mod scallop;

pub use kinpost_surface::Surface;
pub use path::{
    ContactPoint, Direction, MAX_PASSES, MAX_PATH_POINTS, MIN_CHORD_TOLERANCE_MM, Pass, PathError,
    PathOptions, Report, Side, Spacing, Toolpath, Wheel, plan,
};
