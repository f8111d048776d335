//! Material removal on a tri-dexel stock, a belt-grinding process model,
//! and comparison of the simulated part with the design.
//!
//! (Crate doc completed below.)

// `!(a < b)` on floats is deliberate here: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

mod build;
pub mod clip;
pub mod dexel;
pub mod contour;
pub mod design;
pub mod kernel;
pub mod mesh;
pub mod output;
pub mod process;
pub mod report;
pub mod stock;
pub mod tolerance;
pub mod tool;

pub use stock::{CutError, Family, MoveCut, Stock, StockError, default_resolution};
pub use contour::{PartMesh, contour};
pub use output::{write_ply, write_stl, write_svg};
pub use report::{BlockRef, Report, ReportRegion};
pub use design::{Comparison, Design, DesignError, Region, Sample, compare};
pub use process::{
    Calibration, Conditions, Contact, GrindStats, ProcessError, ProcessModel, Trace, belt_speed_mm_s, calibrate,
};
pub use mesh::{Mesh, MeshError};
pub use tool::{Piece, PlacedTool, Shank, Tool, ToolError, ToolPose};
