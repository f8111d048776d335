//! The integration tests of kinpost-machine, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-machine --test all MODULE::`).

mod folds;
mod kinematics;
mod li_eq30;
#[path = "../li_paper/mod.rs"]
mod li_paper;
mod linuxcnc_trt;
mod malformed;
mod never_panics;
mod zhang_eq5;
