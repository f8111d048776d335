//! What the command's tests share: the repository root, running the built
//! command in a folder, a fresh scratch folder.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `kinpost ARGS` run in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kinpost"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run kinpost")
}

/// A fresh folder for one test (`prefix` and the process id in its name).
pub fn temp_dir(prefix: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("kinpost-{prefix}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}
