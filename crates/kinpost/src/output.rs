//! All-or-nothing output files: written to a temporary file beside the
//! target and renamed over it only when the whole program succeeded.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use tempfile::NamedTempFile;

/// An output file being written.
pub struct AtomicFile {
    temp: BufWriter<NamedTempFile>,
    target: PathBuf,
}

impl AtomicFile {
    /// Creates the temporary file in the target's directory (so that the
    /// final rename does not cross file systems).
    pub fn create(target: &Path) -> io::Result<AtomicFile> {
        let dir = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        let temp = tempfile::Builder::new()
            .prefix(".kinpost-")
            .suffix(".tmp")
            .tempfile_in(dir)?;
        Ok(AtomicFile {
            temp: BufWriter::with_capacity(1 << 16, temp),
            target: target.to_path_buf(),
        })
    }

    /// Flushes and renames the file into place.
    pub fn commit(self) -> io::Result<()> {
        self.finish()?.persist()
    }

    /// Flushes the file to disk, ready to be renamed into place: what can
    /// fail for want of space happens here, so that several outputs can be
    /// finished first and renamed together.
    pub fn finish(self) -> io::Result<Finished> {
        let temp = self.temp.into_inner().map_err(|e| e.into_error())?;
        // The temporary file is private (0600); the result gets the mode of
        // the file it replaces, or an ordinary file's 0644.
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&self.target)
                .map(|m| m.permissions().mode() & 0o7777)
                .unwrap_or(0o644);
            temp.as_file()
                .set_permissions(std::fs::Permissions::from_mode(mode))?;
        }
        temp.as_file().sync_all()?;
        Ok(Finished {
            temp,
            target: self.target,
        })
    }
}

/// An output file written to disk, not yet in place (dropped: removed).
pub struct Finished {
    temp: NamedTempFile,
    target: PathBuf,
}

impl Finished {
    /// Renames the file into place.
    pub fn persist(self) -> io::Result<()> {
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
