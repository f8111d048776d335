//! The integration tests of kinpost-sim, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-sim --test all MODULE::`).

mod analytic;
mod collisions;
mod never_panics;
mod posted;
mod qiao_figure28;
mod rs274_time;
