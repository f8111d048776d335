//! Where the results of a command go (`kinpost post`: the program and the
//! JSON summary; `kinpost path`: the CL file, its plot and report; …), each
//! to a file (all or nothing) or to standard output (`-`).

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::output::{self, AtomicFile, Finished};

use crate::usage;

/// One result of a run, held until the whole run succeeded.
pub enum Sink {
    /// Standard output, spooled to an unnamed temporary file (bounded
    /// memory; removed by the system whatever happens to the process) and
    /// copied out only when the whole run succeeded: a failed run prints
    /// nothing.
    Stdout(BufWriter<File>),
    /// A file, written beside its target and renamed over it at the end.
    File(AtomicFile, PathBuf),
}

impl Sink {
    /// Standard output, or the file at `path` (its temporary file created
    /// now, so that a file that cannot be created fails the run early).
    pub fn open(path: Option<&Path>) -> Result<Sink> {
        match path {
            None => {
                let spool = tempfile::tempfile()
                    .context("cannot create a temporary file to hold standard output")?;
                Ok(Sink::Stdout(BufWriter::with_capacity(1 << 16, spool)))
            }
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
            Sink::Stdout(v) => v.flush(),
            Sink::File(f, _) => f.flush(),
        }
    }
}

/// Delivers the results of a successful run, all or none: every file is
/// written to disk first (where a full disk fails), then what goes into a
/// device or pipe (`/dev/full` fails here) and standard output, and only
/// when all of that succeeded are the files renamed into place. Any failure
/// before the renames removes every staged file. (A reader of standard
/// output that stopped early, `| head`, has the files put in place all the
/// same: the run was complete; its broken pipe is returned after.)
pub fn deliver(sinks: Vec<Sink>) -> Result<()> {
    let mut spool = None;
    let mut finished: Vec<(Finished, PathBuf)> = Vec::new();
    for sink in sinks {
        match sink {
            Sink::Stdout(bytes) => spool = Some(bytes),
            Sink::File(file, path) => {
                let done = file
                    .finish()
                    .with_context(|| format!("cannot write {}", path.display()))?;
                finished.push((done, path));
            }
        }
    }
    for (done, path) in &mut finished {
        done.write_special()
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    let mut stdout_error = None;
    if let Some(spool) = spool
        && let Err(e) = copy_spool(spool)
    {
        if e.kind() == io::ErrorKind::BrokenPipe {
            stdout_error = Some(e);
        } else {
            return Err(anyhow::Error::new(e).context("cannot write to standard output"));
        }
    }
    let mut list = output::staged();
    let mut failed = None;
    let mut placed = Vec::new();
    for (done, path) in finished {
        if failed.is_some() {
            // (Dropped: removed.)
            drop(done);
            continue;
        }
        match done.persist(&mut list) {
            Ok(()) => placed.push(path),
            Err(e) => failed = Some((e, path)),
        }
    }
    drop(list);
    if let Some((e, path)) = failed {
        let placed = if placed.is_empty() {
            String::new()
        } else {
            format!(
                " (already in place: {})",
                placed
                    .iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        return Err(
            anyhow::Error::new(e).context(format!("cannot write {}{placed}", path.display()))
        );
    }
    match stdout_error {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

/// Copies the spooled standard output out.
fn copy_spool(spool: BufWriter<File>) -> io::Result<()> {
    let mut file = spool.into_inner().map_err(|e| e.into_error())?;
    file.seek(SeekFrom::Start(0))?;
    let mut out = io::stdout().lock();
    io::copy(&mut file, &mut out)?;
    out.flush()
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
    refuse_stdin_as_output(&files)?;
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

/// Whether two paths name the same file: the same device and inode when
/// both exist (hard links, symbolic links), else the same place once every
/// symbolic link is followed (two links to one file not yet written).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    if let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) {
        use std::os::unix::fs::MetadataExt;
        return (ma.dev(), ma.ino()) == (mb.dev(), mb.ino());
    }
    place(a) == place(b)
}

/// A path's place for comparison: its symbolic links followed (a dangling
/// link: the file it would make), then canonical when it exists, else its
/// directory's canonical path joined with its name (a file not yet
/// written), else the path as given.
fn place(path: &Path) -> PathBuf {
    let path = output::resolve_links(path).unwrap_or_else(|_| path.to_path_buf());
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    match (dir.canonicalize(), path.file_name()) {
        (Ok(d), Some(name)) => d.join(name),
        _ => path.clone(),
    }
}

/// Refuses (a usage error) an output that is the file standard input reads
/// (`post - -o f.cls < f.cls`): the run would replace what it reads.
pub fn refuse_stdin_as_output(outputs: &[(&str, &Path)]) -> Result<()> {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        use std::os::unix::fs::MetadataExt;
        let stdin = io::stdin();
        let Ok(fd) = stdin.as_fd().try_clone_to_owned() else {
            return Ok(());
        };
        let Ok(m) = File::from(fd).metadata() else {
            return Ok(());
        };
        if !m.is_file() {
            return Ok(());
        }
        for (name, path) in outputs {
            if let Ok(o) = std::fs::metadata(path)
                && (o.dev(), o.ino()) == (m.dev(), m.ino())
            {
                return Err(usage(format!(
                    "{name} {} is the file standard input reads: it would be overwritten",
                    path.display()
                )));
            }
        }
    }
    let _ = outputs;
    Ok(())
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

    #[cfg(unix)]
    #[test]
    fn two_dangling_links_to_one_new_file_are_the_same_file() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.lnk");
        let b = dir.path().join("b.lnk");
        std::os::unix::fs::symlink("new.mpf", &a).unwrap();
        std::os::unix::fs::symlink(dir.path().join("new.mpf"), &b).unwrap();
        assert!(same_file(&a, &b));
        assert!(same_file(&a, &dir.path().join("new.mpf")));
        let c = dir.path().join("c.lnk");
        std::os::unix::fs::symlink("other.mpf", &c).unwrap();
        assert!(!same_file(&a, &c));
    }
}
