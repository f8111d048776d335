//! The integration tests of kinpost-collide, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-collide --test all MODULE::`).

#[path = "../common/mod.rs"]
mod common;
mod mesh_distance;
mod never_panics;
mod sweep;
mod world;
