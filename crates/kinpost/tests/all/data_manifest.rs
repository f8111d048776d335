//! Every file in the repository's `data/` folder has a row in
//! `data/MANIFEST.md` (origin and license), and every path the manifest
//! names exists: data written by others keeps its license only if we say
//! which it is.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data")
}

/// The files under `dir`, as paths relative to `root` with `/` separators.
fn files(root: &Path, dir: &Path, out: &mut BTreeSet<String>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(root, &path, out);
        } else {
            let rel = path.strip_prefix(root).unwrap();
            let parts: Vec<_> = rel.iter().map(|p| p.to_string_lossy()).collect();
            out.insert(parts.join("/"));
        }
    }
}

/// The paths of the manifest's table: the backquoted words of each row's
/// first column.
fn named_in_manifest(manifest: &str) -> BTreeSet<String> {
    let mut named = BTreeSet::new();
    for row in manifest.lines().filter(|l| l.starts_with("| `")) {
        let first_column = row.split(" | ").next().unwrap();
        for (i, piece) in first_column.split('`').enumerate() {
            if i % 2 == 1 {
                named.insert(piece.to_string());
            }
        }
    }
    named
}

#[test]
fn every_data_file_has_a_manifest_row_and_every_row_a_file() {
    let root = data_dir();
    let manifest = std::fs::read_to_string(root.join("MANIFEST.md")).unwrap();
    let mut present = BTreeSet::new();
    files(&root, &root, &mut present);
    present.remove("MANIFEST.md");
    let named = named_in_manifest(&manifest);
    let unlisted: Vec<_> = present.difference(&named).collect();
    assert!(
        unlisted.is_empty(),
        "data files without a row in data/MANIFEST.md: {unlisted:?}"
    );
    let missing: Vec<_> = named.difference(&present).collect();
    assert!(
        missing.is_empty(),
        "data/MANIFEST.md names files that are not there: {missing:?}"
    );
}

#[test]
fn every_row_names_a_license() {
    let manifest = std::fs::read_to_string(data_dir().join("MANIFEST.md")).unwrap();
    for row in manifest.lines().filter(|l| l.starts_with("| `")) {
        let columns: Vec<_> = row.split(" | ").collect();
        assert!(
            columns.len() >= 4 && !columns[2].trim().is_empty(),
            "a manifest row without a license column: {row}"
        );
    }
}
