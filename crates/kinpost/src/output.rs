//! All-or-nothing output files: written to a temporary file beside the
//! target and renamed over it only when the whole program succeeded. A
//! symbolic link is followed (the file it names is replaced, the link
//! stays); a device or pipe (`/dev/null`, a FIFO) is not replaced but written
//! into, from a temporary file, once the whole program succeeded.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

/// An output file being written.
pub struct AtomicFile {
    temp: BufWriter<NamedTempFile>,
    target: PathBuf,
    into_special: bool,
}

/// `path` with its symbolic links followed (the link's target, which need
/// not exist yet).
fn resolve_links(path: &Path) -> io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    // As many links as the system follows itself.
    for _ in 0..40 {
        match fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let link = fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if link.is_relative() => dir.join(link),
                    _ => link,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(io::Error::other(format!(
        "{}: too many levels of symbolic links",
        path.display()
    )))
}

impl AtomicFile {
    /// Creates the temporary file in the target's directory (so that the
    /// final rename does not cross file systems), or, for a device or pipe,
    /// in the system's temporary directory.
    pub fn create(target: &Path) -> io::Result<AtomicFile> {
        let target = resolve_links(target)?;
        let into_special = fs::metadata(&target).is_ok_and(|m| !m.is_file() && !m.is_dir());
        let dir = match target.parent() {
            _ if into_special => std::env::temp_dir(),
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let temp = tempfile::Builder::new()
            .prefix(".kinpost-")
            .suffix(".tmp")
            .tempfile_in(dir)?;
        Ok(AtomicFile {
            temp: BufWriter::with_capacity(1 << 16, temp),
            target,
            into_special,
        })
    }

    /// Flushes and renames the file into place.
    #[cfg(test)]
    pub fn commit(self) -> io::Result<()> {
        self.finish()?.persist()
    }

    /// Flushes the file to disk, ready to be renamed into place: what can
    /// fail for want of space happens here, so that several outputs can be
    /// finished first and renamed together.
    pub fn finish(self) -> io::Result<Finished> {
        let temp = self.temp.into_inner().map_err(|e| e.into_error())?;
        if !self.into_special {
            // The temporary file is private (0600); the result gets the mode
            // of the file it replaces, or an ordinary file's 0644.
            #[cfg(unix)]
            {
                use std::os::unix::fs::PermissionsExt;
                let mode = fs::metadata(&self.target)
                    .map(|m| m.permissions().mode() & 0o7777)
                    .unwrap_or(0o644);
                temp.as_file()
                    .set_permissions(fs::Permissions::from_mode(mode))?;
            }
            temp.as_file().sync_all()?;
        }
        Ok(Finished {
            temp,
            target: self.target,
            into_special: self.into_special,
        })
    }
}

/// An output file written to disk, not yet in place (dropped: removed).
pub struct Finished {
    temp: NamedTempFile,
    target: PathBuf,
    into_special: bool,
}

impl Finished {
    /// Renames the file into place, or writes it into the device or pipe.
    pub fn persist(mut self) -> io::Result<()> {
        if self.into_special {
            let file: &mut File = self.temp.as_file_mut();
            file.seek(SeekFrom::Start(0))?;
            let mut out = OpenOptions::new().write(true).open(&self.target)?;
            io::copy(file, &mut out)?;
            return out.flush();
        }
        self.temp.persist(&self.target).map_err(|e| e.error)?;
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.temp.write(buf)
    }

    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        self.temp.write_all(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.temp.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dropped_file_leaves_the_old_one_alone() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.mpf");
        std::fs::write(&target, "good").unwrap();
        {
            let mut f = AtomicFile::create(&target).unwrap();
            f.write_all(b"partial").unwrap();
            // dropped without commit: a failed run
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "good");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        let mut f = AtomicFile::create(&target).unwrap();
        f.write_all(b"new").unwrap();
        f.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new");
    }

    #[test]
    fn finished_file_appears_only_when_persisted() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.json");
        let mut f = AtomicFile::create(&target).unwrap();
        f.write_all(b"{}").unwrap();
        let finished = f.finish().unwrap();
        assert!(!target.exists());
        finished.persist().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "{}");
        let mut f = AtomicFile::create(&target).unwrap();
        f.write_all(b"[]").unwrap();
        drop(f.finish().unwrap());
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "{}");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_followed_and_a_pipe_is_written_into() {
        let dir = tempfile::tempdir().unwrap();
        // A link to a file: the file gets the program, the link stays.
        let file = dir.path().join("program.nc");
        std::fs::write(&file, "old").unwrap();
        let link = dir.path().join("link.nc");
        std::os::unix::fs::symlink("program.nc", &link).unwrap();
        let mut f = AtomicFile::create(&link).unwrap();
        f.write_all(b"new").unwrap();
        f.commit().unwrap();
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert_eq!(std::fs::read_to_string(&file).unwrap(), "new");
        // A link to a file that does not exist yet: it is made.
        let dangling = dir.path().join("later.nc");
        std::os::unix::fs::symlink("made.nc", &dangling).unwrap();
        let mut f = AtomicFile::create(&dangling).unwrap();
        f.write_all(b"made").unwrap();
        f.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.path().join("made.nc")).unwrap(),
            "made"
        );
        // /dev/null stays the device.
        let mut f = AtomicFile::create(Path::new("/dev/null")).unwrap();
        f.write_all(b"gone").unwrap();
        f.commit().unwrap();
        use std::os::unix::fs::FileTypeExt;
        assert!(
            std::fs::metadata("/dev/null")
                .unwrap()
                .file_type()
                .is_char_device()
        );
        // A FIFO gets the program when the run succeeds, and stays a FIFO.
        let fifo = dir.path().join("pipe.nc");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let reader = {
                let fifo = fifo.clone();
                std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
            };
            let mut f = AtomicFile::create(&fifo).unwrap();
            f.write_all(b"through the pipe").unwrap();
            f.commit().unwrap();
            assert_eq!(reader.join().unwrap(), "through the pipe");
            assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
        }
        // Nothing left behind in the folder but what was made.
        let mut names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert!(
            names.iter().all(|n| !n.starts_with(".kinpost-")),
            "{names:?}"
        );
    }

    #[cfg(unix)]
    #[test]
    fn new_files_are_0644_and_replaced_files_keep_their_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("new.mpf");
        let write = |bytes: &[u8]| {
            let mut f = AtomicFile::create(&target).unwrap();
            f.write_all(bytes).unwrap();
            f.commit().unwrap();
        };
        write(b"x");
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&target), 0o644);
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        write(b"y");
        assert_eq!(mode(&target), 0o640);
    }
}
