//! The integration tests of kinpost-stock, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-stock --test all MODULE::`).

mod compare;
mod cuts;
mod determinism;
mod fast_removal;
mod kernels;
mod never_panics;
mod outputs;
mod process;
