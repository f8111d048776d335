//! The malformed-input corpus: every `tests/malformed/NAME.cls` must give
//! exactly the diagnostics rendered in `NAME.expected` (warnings in order, then
//! the first error), joined by blank lines.
//!
//! To regenerate the expected files after a deliberate change of wording, run
//! `KINPOST_BLESS=1 cargo test -p kinpost-cl --test all malformed::` and review the
//! diff.

use std::fs;
use std::path::{Path, PathBuf};

use kinpost_testkit::{Goldens, assert_no_orphans, files_with_extension};

use kinpost_cl::{ClReader, Diagnostic, Severity};

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/malformed")
}

/// Every diagnostic of `bytes` up to and including the first error.
fn diagnostics(name: &str, bytes: &[u8]) -> Vec<Diagnostic> {
    let mut reader = ClReader::new(bytes, format!("malformed/{name}"));
    let mut out = Vec::new();
    loop {
        let result = reader.next_statement();
        out.extend(reader.take_warnings());
        match result {
            Ok(Some(_)) => {}
            Ok(None) => return out,
            Err(e) => {
                out.push(e);
                return out;
            }
        }
    }
}

#[test]
fn malformed_corpus() {
    let files = files_with_extension(&corpus(), "cls");
    assert!(files.len() >= 30, "corpus too small: {}", files.len());

    let mut goldens = Goldens::from_env();
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let bytes = fs::read(path).unwrap();
        let diags = diagnostics(&name, &bytes);

        // Every input here is malformed: it ends in exactly one error, and
        // every diagnostic names a line and a column and shows the line.
        assert_eq!(
            diags
                .iter()
                .filter(|d| d.severity == Severity::Error)
                .count(),
            1,
            "{name}: {diags:#?}"
        );
        assert!(diags.last().unwrap().is_error(), "{name}");
        for d in &diags {
            assert!(
                d.line >= 1 && d.column >= 1 && d.width >= 1,
                "{name}: {d:?}"
            );
            assert!(!d.source_line.is_empty(), "{name}: {d:?}");
            assert_eq!(d.file, format!("malformed/{name}"));
        }

        let rendered: String = diags
            .iter()
            .map(|d| format!("{d}\n"))
            .collect::<Vec<_>>()
            .join("\n");
        goldens.check(&path.with_extension("expected"), &rendered);
    }
    goldens.finish();
}

/// Every expected output has its input file.
#[test]
fn no_orphan_expected_files() {
    assert_no_orphans(&corpus(), "expected", "cls");
}
