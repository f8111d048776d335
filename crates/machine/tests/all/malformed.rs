//! The malformed machine-file corpus: every `tests/malformed/NAME.toml` has
//! one mistake (its first line says which) and must give exactly the
//! diagnostics rendered in `NAME.expected`.
//!
//! To regenerate the expected files after a deliberate change of wording, run
//! `KINPOST_BLESS=1 cargo test -p kinpost-machine --test all malformed::` and review
//! the diff.

use std::fs;
use std::path::{Path, PathBuf};

use kinpost_testkit::{Goldens, assert_no_orphans, files_with_extension};

use kinpost_machine::machine_from_toml;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed")
}

#[test]
fn malformed_corpus() {
    let files = files_with_extension(&corpus(), "toml");
    assert!(files.len() >= 20, "corpus too small: {}", files.len());

    let mut goldens = Goldens::from_env();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let source = fs::read_to_string(path).unwrap();
        let diags = match machine_from_toml(&source, &name) {
            Ok(m) => {
                goldens.fail(format!("{name}: loaded machine `{}`", m.name));
                continue;
            }
            Err(d) => d,
        };

        // Every diagnostic is an error that names a line and a column of
        // this file and shows that line.
        assert!(!diags.0.is_empty(), "{name}");
        let lines: Vec<&str> = source.lines().collect();
        for d in &diags.0 {
            assert!(d.is_error(), "{name}: {d:?}");
            assert_eq!(d.file, name);
            assert!(
                d.line >= 1 && d.line <= lines.len() + 1 && d.column >= 1 && d.width >= 1,
                "{name}: {d:?}"
            );
            assert_eq!(
                d.source_line,
                lines.get(d.line - 1).copied().unwrap_or(""),
                "{name}"
            );
        }

        goldens.check(&path.with_extension("expected"), &format!("{diags}\n"));
    }
    goldens.finish();
}

/// Every expected output has its input file.
#[test]
fn no_orphan_expected_files() {
    assert_no_orphans(&corpus(), "expected", "toml");
}
