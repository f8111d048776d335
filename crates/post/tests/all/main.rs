//! The integration tests of kinpost-post, one test binary (each file of
//! this folder is a module: `cargo test -p kinpost-post --test all MODULE::`).
//! Test machines are in `tests/machines` and `tests/folds`; insta snapshots
//! in `tests/all/snapshots`; proptest regressions in
//! `tests/proptest-regressions/MODULE.txt`.

mod cl_events;
mod cl_events_never_panics;
mod common;
mod corpus;
mod golden;
mod native_arcs;
mod native_cycles;
mod nc_output;
mod planning;
mod pressure;
mod qiao_figure28;
mod random_machines;
mod readback;
mod rng;
mod rs274;
mod six_axis;
mod stages;
mod tcp;
