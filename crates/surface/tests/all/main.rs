//! The integration tests of kinpost-surface, one test binary (each file of
//! this folder is a module: `cargo test -p kinpost-surface --test all MODULE::`).

mod common;
mod never_panics;
mod scipy;
mod surfaces;
