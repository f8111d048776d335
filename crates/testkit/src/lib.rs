//! Test helpers shared by kinpost's crates (a dev-dependency only).
//!
//! **Golden files.** A test renders what the code under test gives (the
//! diagnostics of a malformed file, the events of a CL file) and compares it
//! with a file kept beside the inputs. [`Goldens`] collects every mismatch
//! of a run and reports them all at once; with `KINPOST_BLESS=1` in the
//! environment it writes the files anew instead, for a deliberate change
//! whose diff is then reviewed in git.
//!
//! ```
//! use kinpost_testkit::Goldens;
//! let dir = std::env::temp_dir().join("kinpost-testkit-doc");
//! std::fs::create_dir_all(&dir).unwrap();
//! let path = dir.join("case.expected");
//! std::fs::write(&path, "one error\n").unwrap();
//! let mut goldens = Goldens::from_env();
//! goldens.check(&path, "one error\n");
//! goldens.finish();
//! ```

#![deny(missing_docs)]

use std::fs;
use std::path::{Path, PathBuf};

/// The environment variable that makes [`Goldens`] write instead of compare.
pub const BLESS_VAR: &str = "KINPOST_BLESS";

/// Golden-file comparisons of one test, mismatches collected.
#[derive(Debug)]
pub struct Goldens {
    bless: bool,
    failures: Vec<String>,
}

impl Goldens {
    /// Compares, or writes when `KINPOST_BLESS` is set.
    pub fn from_env() -> Self {
        Goldens {
            bless: std::env::var_os(BLESS_VAR).is_some(),
            failures: Vec::new(),
        }
    }

    /// Whether this run writes the golden files.
    pub fn blessing(&self) -> bool {
        self.bless
    }

    /// `actual` against the golden file `path` (written, with its folder,
    /// when blessing). A missing or different file is a failure, shown with
    /// both texts.
    pub fn check(&mut self, path: &Path, actual: &str) {
        if self.bless {
            if let Some(dir) = path.parent() {
                fs::create_dir_all(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
            }
            fs::write(path, actual).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            return;
        }
        match fs::read_to_string(path) {
            Ok(expected) if expected == actual => {}
            Ok(expected) => self.failures.push(format!(
                "{}:\n--- expected\n{expected}--- got\n{actual}",
                path.display()
            )),
            Err(e) => self.failures.push(format!("{}: {e}", path.display())),
        }
    }

    /// Records a failure of the test's own (an input that should have
    /// failed and did not, …), reported with the mismatches.
    pub fn fail(&mut self, message: String) {
        self.failures.push(message);
    }

    /// Panics with every failure, if any.
    pub fn finish(self) {
        assert!(
            self.failures.is_empty(),
            "{} golden mismatch(es) ({BLESS_VAR}=1 writes them anew; review the diff):\n{}",
            self.failures.len(),
            self.failures.join("\n")
        );
    }
}

/// The files of `dir` whose extension is `ext`, sorted.
pub fn files_with_extension(dir: &Path, ext: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == ext))
        .collect();
    files.sort();
    files
}

/// Panics if a golden file (`golden_ext`) of `dir` has no input beside it
/// (`input_ext`, same stem): a golden left over from a removed case.
pub fn assert_no_orphans(dir: &Path, golden_ext: &str, input_ext: &str) {
    for golden in files_with_extension(dir, golden_ext) {
        assert!(
            golden.with_extension(input_ext).is_file(),
            "{} has no .{input_ext}",
            golden.display()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("kinpost-testkit-{name}-{}", std::process::id()));
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn a_different_text_is_a_failure_with_both_texts() {
        let dir = scratch("diff");
        let path = dir.join("a.expected");
        fs::write(&path, "old\n").unwrap();
        let mut g = Goldens {
            bless: false,
            failures: Vec::new(),
        };
        g.check(&path, "new\n");
        g.check(&dir.join("missing.expected"), "x");
        assert_eq!(g.failures.len(), 2);
        assert!(g.failures[0].contains("--- expected\nold\n--- got\nnew\n"));
        let caught = std::panic::catch_unwind(|| g.finish());
        assert!(caught.is_err());
    }

    #[test]
    fn blessing_writes_the_file_and_its_folder() {
        let dir = scratch("bless");
        let path = dir.join("sub/b.expected");
        let mut g = Goldens {
            bless: true,
            failures: Vec::new(),
        };
        g.check(&path, "text\n");
        g.finish();
        assert_eq!(fs::read_to_string(&path).unwrap(), "text\n");
    }

    #[test]
    fn orphans_and_sorted_listing() {
        let dir = scratch("orphans");
        for f in ["b.toml", "a.toml", "a.expected", "c.expected"] {
            fs::write(dir.join(f), "").unwrap();
        }
        let names: Vec<_> = files_with_extension(&dir, "toml")
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["a.toml", "b.toml"]);
        let caught = std::panic::catch_unwind(|| assert_no_orphans(&dir, "expected", "toml"));
        assert!(caught.is_err(), "c.expected has no c.toml");
        fs::remove_file(dir.join("c.expected")).unwrap();
        assert_no_orphans(&dir, "expected", "toml");
    }
}
