//! The integration tests of kinpost-machine, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-machine --test all MODULE::`).

#[path = "../li_paper/mod.rs"]
mod li_paper;
mod folds;
mod kinematics;
mod li_eq30;
mod linuxcnc_trt;
mod malformed;
mod never_panics;
mod zhang_eq5;
