//! Where the results of a command go (`kinpost post`: the program and the
//! JSON summary; `kinpost path`: the CL file, its plot and report; …), each
//! to a file (all or nothing) or to standard output (`-`).

use std::io::{self, Write};
use std::path::{Path, PathBuf};

use crate::output::{AtomicFile, Finished};
use anyhow::{Context, Result};

use crate::usage;

/// One result of a run, held until the whole run succeeded.
pub enum Sink {
    /// Standard output, held in memory so that a failed run prints nothing.
    Stdout(Vec<u8>),
    /// A file, written beside its target and renamed over it at the end.
    File(AtomicFile, PathBuf),
}

impl Sink {
    /// Standard output, or the file at `path` (its temporary file created
    /// now, so that a file that cannot be created fails the run early).
    pub fn open(path: Option<&Path>) -> Result<Sink> {
        match path {
            None => Ok(Sink::Stdout(Vec::new())),
            // (The rename at the end would fail, after all the work.)
            Some(path) if path.is_dir() => Err(usage(format!(
                "{} is a directory: the output must be a file",
                path.display()
            ))),
            Some(path) => {
                let file = AtomicFile::create(path)
                    .with_context(|| format!("cannot create {}", path.display()))?;
                Ok(Sink::File(file, path.to_path_buf()))
            }
        }
    }
}

impl Write for Sink {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match self {
            Sink::Stdout(v) => v.write(buf),
            Sink::File(f, _) => f.write(buf),
        }
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        match self {
            Sink::Stdout(v) => v.write_all(buf),
            Sink::File(f, _) => f.write_all(buf),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self {
            Sink::Stdout(_) => Ok(()),
            Sink::File(f, _) => f.flush(),
        }
    }
}

/// Delivers the results of a successful run as nearly together as files
/// allow: every file is written to disk first (where a full disk fails),
/// then standard output, and only then are the files renamed into place.
pub fn deliver(sinks: Vec<Sink>) -> Result<()> {
    let mut stdout = Vec::new();
    let mut finished: Vec<(Finished, PathBuf)> = Vec::new();
    for sink in sinks {
        match sink {
            Sink::Stdout(bytes) => stdout.extend_from_slice(&bytes),
            Sink::File(file, path) => {
                let done = file
                    .finish()
                    .with_context(|| format!("cannot write {}", path.display()))?;
                finished.push((done, path));
            }
        }
    }
    if !stdout.is_empty() {
        let mut out = io::stdout().lock();
        out.write_all(&stdout)?;
        out.flush()?;
    }
    for (done, path) in finished {
        done.persist()
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The sinks of a command's outputs, in the order given: each is named as
/// on the command line and goes to its path, or to standard output for `-`.
/// Refuses (usage errors) two outputs on standard output, and outputs that
/// name an input or each other (see [`refuse_same_files`]). Every file's
/// temporary file exists when this returns (see [`Sink::open`]).
pub fn open_outputs(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<Vec<Sink>> {
    let stdout = |p: &&Path| *p == Path::new("-");
    let on_stdout: Vec<&str> = outputs
        .iter()
        .filter(|(_, p)| stdout(p))
        .map(|(name, _)| *name)
        .collect();
    if let [first, second, ..] = on_stdout[..] {
        return Err(usage(format!(
            "{second} - would write to standard output, where {first} goes: give one of them a file"
        )));
    }
    let files: Vec<(&str, &Path)> = outputs
        .iter()
        .copied()
        .filter(|(_, p)| !stdout(p))
        .collect();
    refuse_same_files(inputs, &files)?;
    outputs
        .iter()
        .map(|&(_, p)| Sink::open((!stdout(&p)).then_some(p)))
        .collect()
}

/// Refuses (a usage error) an output that names an input or another
/// output: renaming it into place would destroy the file it names.
/// Each path comes with how the command line named it.
pub fn refuse_same_files(inputs: &[(&str, &Path)], outputs: &[(&str, &Path)]) -> Result<()> {
    for (k, (out_name, out)) in outputs.iter().enumerate() {
        for (in_name, input) in inputs {
            if same_file(out, input) {
                return Err(usage(format!(
                    "{out_name} {} is the {in_name} {}: it would be overwritten",
                    out.display(),
                    input.display()
                )));
            }
        }
        for (other_name, other) in &outputs[..k] {
            if same_file(out, other) {
                return Err(usage(format!(
                    "{other_name} {} and {out_name} {} are the same file",
                    other.display(),
                    out.display()
                )));
            }
        }
    }
    Ok(())
}

/// Whether two paths name the same file: the same inode when both exist
/// (hard links, symbolic links), else the same canonical place.
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        use std::os::unix::fs::MetadataExt;
        return (ma.dev(), ma.ino()) == (mb.dev(), mb.ino());
    }
    place(a) == place(b)
}

/// A path's place for comparison: canonical when it exists, else its
/// directory's canonical path joined with its name (a file not yet
/// written), else the path as given.
fn place(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (dir.canonicalize(), path.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => path.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_file_sees_links_and_files_not_yet_written() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.cls");
        std::fs::write(&a, "x").unwrap();
        let hard = dir.path().join("hard.cls");
        std::fs::hard_link(&a, &hard).unwrap();
        assert!(same_file(&a, &hard));
        assert!(same_file(&a, &dir.path().join(".").join("a.cls")));
        let new = dir.path().join("new.nc");
        assert!(same_file(&new, &dir.path().join(".").join("new.nc")));
        assert!(!same_file(&new, &a));
        assert!(!same_file(&new, &dir.path().join("other.nc")));
    }
}
