//! Material removal on a tri-dexel stock, a belt-grinding process model,
//! and comparison of the simulated part with the design.
//!
//! kinpost's virtual machine replays an NC program through the machine's
//! kinematics and hands this crate the tool's poses in the part frame; the
//! crate removes what the tool sweeps from a stock and compares the result
//! with the design, as VERICUT's AUTO-DIFF does: the deepest gouge and the
//! largest residual with where they are and which block made them, regions
//! beyond tolerance, a histogram, a watertight STL of the part, a PLY
//! coloured by deviation and an SVG map.
//!
//! **Conventions.** Everything is in the part frame (the workpiece frame of
//! the machine file), in mm. A [`ToolPose`] is a tool point, a unit tool
//! axis and an optional reference direction:
//! * end mills and drills: the tip centre, the axis from the tip towards
//!   the spindle (APT);
//! * the belt's contact wheel: the contact point on the rim, the axis from
//!   the contact point towards the wheel centre, the reference the feed
//!   direction; the wheel's rotation axis is reference × tool axis (the
//!   `[tool]` convention of `mts1600.toml` and of `kinpost path`);
//! * the disc wheel of the A/C grinder (Li (B-spline grinding), §5, eq. 27
//!   to 29): the contact point on the rim of the grinding face, the axis the
//!   face normal pointing from the part into the wheel, the reference the
//!   direction in the face from the contact point to the face centre.
//!
//! **Stock.** Three grids of rays along X, Y and Z (cell centres of a
//! lattice of spacing h, the resolution), each ray a sorted list of solid
//! intervals whose ends are exact along the ray and remember the move that
//! last cut them ([`Stock`]). One interval per ray is stored inline (32
//! bytes a ray). Stocks come from a box, a closed STL mesh (ray parity with
//! exact predicates, [`mesh`]) or a design grown by an allowance
//! ([`Stock::from_mesh_offset`]; for a design known by one surface, the
//! closed shell of [`Design::shell_of_surface`]); [`default_resolution`]
//! picks h for about 16 million rays.
//!
//! **Cutting.** [`Stock::cut_move`] removes what the tool sweeps between two
//! poses: exactly for translations of cylinders and spheres ([`kernel`]),
//! sampled otherwise with no tool point moving more than one ray spacing
//! between samples ([`tolerance::SAMPLE_STEP_FRACTION`]). Only the rays
//! within the tool's bounds clipped to the stock's box are visited
//! ([`clip`]); rows of rays run in parallel, each ray alone, so the result
//! is the same bytes for any thread count. [`Stock::cut_moves`] cuts a
//! batch of moves in one visit of their rays (up to 32 moves a visit), the
//! stock of its moves one by one bit for bit: `kinpost sim` hands its
//! blocks' moves over that way.
//!
//! **Speed.** Most of a move's spans change nothing: a wheel's or a ball's
//! surface behind its contact, or a sample of a move above a deeper one.
//! The default [`Removal::Fast`] visits a batch's solids in an order that
//! meets each ray's deepest early, skips them where a test with products
//! and sums only (no root, no quotient, every rounding bounded) proves that
//! the span the kernel would compute starts at or above the ray's level,
//! ray by ray or a whole segment of eight rows at once, and computes the
//! others four rays at a time ([`Stock::set_removal`]; AVX2 chosen at run
//! time). It gives the stock of [`Removal::Reference`], the
//! straightforward evaluation of every span, bit for bit, on every
//! processor and for any thread count.
//!
//! **Grinding process.** [`ProcessModel`]: the pressure axis's force table,
//! a Winkler contact and Preston's removal law, read from a TOML process
//! file; [`Stock::grind_move`] grinds with it; [`calibrate`] fits Preston's
//! coefficient and the wheel's stiffness to measured traces ([`process`]).
//!
//! **Comparison and output.** [`compare`] measures the design (a closed
//! mesh, or a B-spline surface over a parameter region) along the rays
//! ([`design`]), keeping the samples beyond tolerance, a histogram, the
//! range of all deviations and a [`DeviationMap`] of every ray seen along
//! each axis; [`contour`] meshes the part (marching tetrahedra on the ray
//! lattice); [`write_stl`], [`write_ply`], [`write_svg`] and [`Report`]
//! give the files and the report.
//!
//! ```
//! use kinpost_stock::{Design, Mesh, Stock, Tool, ToolPose, compare};
//! use nalgebra::{Point3, Vector3};
//!
//! let (lo, hi) = (Point3::new(0.0, 0.0, 0.0), Point3::new(40.0, 20.0, 10.0));
//! let mut stock = Stock::from_box(lo, hi, 0.25).unwrap();
//! // A 4 mm flat end mill cuts a slot 0.3 mm deep, as move 7.
//! let tool = Tool::FlatEnd { diameter: 4.0, flute_length: 20.0, shank: None };
//! let a = ToolPose::new(Point3::new(10.0, 10.0, 9.7), Vector3::z());
//! let b = ToolPose::new(Point3::new(30.0, 10.0, 9.7), Vector3::z());
//! stock.cut_move(&tool, &a, &b, 7).unwrap();
//! // Against the uncut box as the design: one gouge of 0.3 mm, by move 7.
//! let design = Design::from_mesh(Mesh::cuboid(lo, hi)).unwrap();
//! let cmp = compare(&stock, &design, 0.01).unwrap();
//! let deepest = cmp.gouge_max().unwrap();
//! assert!((deepest.deviation_mm + 0.3).abs() < 1e-9);
//! assert_eq!(deepest.move_id, Some(7));
//! ```

#![deny(missing_docs)]
// `!(a < b)` on floats is deliberate here: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Ray-grid arithmetic reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

mod build;
pub mod clip;
pub mod contour;
pub mod design;
pub mod dexel;
pub mod kernel;
mod lanes;
pub mod mesh;
pub mod output;
pub mod process;
pub mod report;
mod row;
pub mod stock;
pub mod tolerance;
pub mod tool;

pub use contour::{PartMesh, contour};
pub use design::{Comparison, Design, DesignError, DeviationMap, Region, Sample, compare};
pub use mesh::{Mesh, MeshError};
pub use output::{map_colour, write_ply, write_stl, write_svg};
pub use process::{
    Calibration, Conditions, Contact, GrindStats, ProcessError, ProcessModel, Trace, TraceFile,
    belt_speed_mm_s, calibrate,
};
pub use report::{BlockRef, GrindBlock, GrindingSummary, Report, ReportRegion};
pub use stock::{
    BatchError, CutError, Family, Move, MoveCut, Removal, Stock, StockError, default_resolution,
};
pub use tool::{Piece, PlacedTool, Shank, Tool, ToolError, ToolPose};
