//! The integration tests of kinpost-plan, one test binary (each file of
//! this folder is a module: `cargo test -p kinpost-plan --test all MODULE::`).

mod oracle;
mod planner;
