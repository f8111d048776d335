//! The integration tests of kinpost-nc, one test binary (each file
//! of this folder is a module: `cargo test -p kinpost-nc --test all MODULE::`).

mod diagnostics;
mod dialects_builtin;
mod hostile;
mod interp_fanuc;
mod interp_heidenhain;
mod interp_never_panics;
mod interp_roundtrip;
mod interp_rs274;
mod interp_sinumerik;
mod never_panics;
mod program_commands;
mod props;
mod writer;
