//! Shared by the surface tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use kinpost_surface::grid::{Grid, read_grid};

/// The repository root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The 35 measured points of Li (B-spline grinding) (Tables 1–5).
pub fn li_points_path() -> PathBuf {
    root().join("data/li-bspline/points.csv")
}

pub fn li_points() -> Grid {
    let path = li_points_path();
    let text = std::fs::read_to_string(&path).expect("data/li-bspline/points.csv");
    read_grid(&text, &path.to_string_lossy()).expect("valid grid")
}
