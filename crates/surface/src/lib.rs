//! Cubic B-spline surfaces from measured points (Li (B-spline grinding)).
//!
//! * [`grid`]: grids of points from CSV files, whitespace tables and NASA
//!   blade tables, with located diagnostics.
//! * [`Surface::fit`]: interpolation through an m × n grid (open uniform
//!   knots, uniform or chord-length parameters, natural, not-a-knot or
//!   clamped-tangent ends: an (m+2) × (n+2) control net) or least-squares
//!   approximation with a chosen net; a band solver per direction, so a
//!   200 × 200 grid fits in milliseconds.
//! * [`Surface::derivatives`], [`Surface::geometry`]: point, first and
//!   second derivatives, unit normal, Gaussian and mean curvature,
//!   principal curvatures and directions.
//! * [`json`]: surface files that load back bit-identically.
//! * [`svg`]: pictures of the surface coloured by curvature.
//!
//! ```
//! use kinpost_surface::{FitOptions, Surface, grid::read_grid};
//! let csv = "row,col,x,y,z\n0,0,0,0,0\n0,1,0,1,0\n1,0,1,0,0\n1,1,1,1,0.5\n";
//! let grid = read_grid(csv, "g.csv").unwrap();
//! let s = Surface::fit(&grid, &FitOptions::default()).unwrap();
//! assert_eq!(s.net_size(), (4, 4));
//! assert!(s.residual().unwrap().max < 1e-12);
//! let g = s.geometry(0.5, 0.5).unwrap();
//! assert!((g.normal.norm() - 1.0).abs() < 1e-12);
//! ```

#![deny(missing_docs)]
// `!(a < b)` on floats is deliberate here: it also rejects NaN.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
// Band and basis arithmetic reads best with explicit indices.
#![allow(clippy::needless_range_loop)]

pub mod banded;
pub mod basis;
pub mod fit1d;
pub mod geometry;
pub mod grid;
pub mod json;
mod surface;
pub mod svg;

pub use fit1d::{Ends, FitError};
pub use geometry::{Degenerate, Derivatives, LocalGeometry};
pub use surface::{
    FitData, FitOptions, Method, Parameterisation, Residual, Surface, SurfaceFitError,
};
