//! The malformed machine-file corpus: every `tests/malformed/NAME.toml` has
//! one mistake (its first line says which) and must give exactly the
//! diagnostics rendered in `NAME.expected`.
//!
//! To regenerate the expected files after a deliberate change of wording, run
//! `KINPOST_BLESS=1 cargo test -p kinpost-machine --test all malformed::` and review
//! the diff.

use std::fs;
use std::path::{Path, PathBuf};

use kinpost_machine::machine_from_toml;

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed")
}

#[test]
fn malformed_corpus() {
    let bless = std::env::var_os("KINPOST_BLESS").is_some();
    let mut files: Vec<PathBuf> = fs::read_dir(corpus())
        .expect("tests/malformed")
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "corpus too small: {}", files.len());

    let mut failures = Vec::new();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let source = fs::read_to_string(path).unwrap();
        let diags = match machine_from_toml(&source, &name) {
            Ok(m) => {
                failures.push(format!("{name}: loaded machine `{}`", m.name));
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

        let rendered = format!("{diags}\n");
        let expected_path = path.with_extension("expected");
        if bless {
            fs::write(&expected_path, &rendered).unwrap();
            continue;
        }
        match fs::read_to_string(&expected_path) {
            Ok(expected) if expected == rendered => {}
            Ok(expected) => failures.push(format!(
                "{name}:\n--- expected\n{expected}--- got\n{rendered}"
            )),
            Err(e) => failures.push(format!("{}: {e}", expected_path.display())),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every file in the corpus has an expected output and vice versa.
#[test]
fn no_orphan_expected_files() {
    for entry in fs::read_dir(corpus()).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "expected") {
            assert!(
                path.with_extension("toml").is_file(),
                "{} has no .toml",
                path.display()
            );
        }
    }
}
