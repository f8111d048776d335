//! The integration tests of kinpost-cl, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-cl --test all MODULE::`).

mod corpus;
mod data_files;
mod limits;
mod malformed;
mod never_panics;
mod statements;
