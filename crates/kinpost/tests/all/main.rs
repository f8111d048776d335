//! The integration tests of the `kinpost` command, one test binary (each
//! file of this folder is a module: `cargo test -p kinpost --test all
//! MODULE::`). They run the built command as a user would.

// The formulas of Li et al.'s paper, shared with kinpost-machine's tests.
#[path = "../../../machine/tests/li_paper/mod.rs"]
mod li_paper;

mod architecture;
mod calibrate_cli;
mod cli;
mod common;
mod data_manifest;
mod experiments;
mod hostile;
mod li_grinding_path;
mod rotor37;
mod sim_cli;
