//! All-or-nothing output files: written to a temporary file beside the
//! target and renamed over it only when the whole program succeeded. A
//! symbolic link is followed (the file it names is replaced, the link
//! stays); a device or pipe (`/dev/null`, a FIFO) is not replaced but written
//! into, from a temporary file, once the whole program succeeded.
//!
//! Every temporary file is staged: listed while it exists, so that an
//! interrupted run (SIGINT, SIGTERM, SIGHUP; see
//! [`remove_staged_files_on_signals`]) removes them all before it exits. A
//! new file gets the mode the umask gives (`0666 & !umask`); a replaced
//! file keeps its mode, less the set-user-ID and set-group-ID bits.

use std::fs::{self, File, OpenOptions};
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

use tempfile::NamedTempFile;

/// The temporary files of this process that are not in place yet.
static STAGED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// The staged list, locked. Held while the outputs of a run are put in
/// place, so that a signal's clean-up waits until they all are.
pub fn staged() -> MutexGuard<'static, Vec<PathBuf>> {
    STAGED.lock().unwrap_or_else(PoisonError::into_inner)
}

fn stage(path: &Path) {
    staged().push(path.to_path_buf());
}

fn unstage(list: &mut Vec<PathBuf>, path: &Path) {
    if let Some(i) = list.iter().position(|p| p == path) {
        list.swap_remove(i);
    }
}

/// Removes every staged temporary file when the process gets SIGINT,
/// SIGTERM or SIGHUP, then exits with 128 + the signal's number, as a shell
/// reports a process the signal ended. A signal that comes while a run puts
/// its outputs in place waits until all are (they are then complete);
/// the exit code still says the run was interrupted. Call once, early in
/// `main`; on other systems than Unix it does nothing.
pub fn remove_staged_files_on_signals() -> io::Result<()> {
    #[cfg(unix)]
    {
        use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
        let mut signals = signal_hook::iterator::Signals::new([SIGINT, SIGTERM, SIGHUP])?;
        std::thread::Builder::new()
            .name("kinpost-signals".into())
            .spawn(move || {
                if let Some(signal) = signals.forever().next() {
                    let mut list = staged();
                    for path in list.drain(..) {
                        let _ = fs::remove_file(path);
                    }
                    let _ = io::stderr().write_all(b"kinpost: interrupted; no output written\n");
                    std::process::exit(128 + signal);
                }
            })?;
    }
    Ok(())
}

/// A temporary file in the staged list while it lives (removed and taken
/// off the list when dropped).
struct StagedTemp(Option<NamedTempFile>);

impl StagedTemp {
    fn new(temp: NamedTempFile) -> StagedTemp {
        stage(temp.path());
        StagedTemp(Some(temp))
    }

    fn get(&self) -> &NamedTempFile {
        self.0.as_ref().expect("present until dropped or persisted")
    }

    fn get_mut(&mut self) -> &mut NamedTempFile {
        self.0.as_mut().expect("present until dropped or persisted")
    }

    /// Renames the file to `target` (the staged list is held by the
    /// caller, `list`).
    fn persist(mut self, list: &mut Vec<PathBuf>, target: &Path) -> io::Result<()> {
        let temp = self.0.take().expect("present until dropped or persisted");
        let path = temp.path().to_path_buf();
        match temp.persist(target) {
            Ok(_) => {
                unstage(list, &path);
                Ok(())
            }
            Err(e) => {
                // Dropping it removes it.
                self.0 = Some(e.file);
                Err(e.error)
            }
        }
    }
}

impl Drop for StagedTemp {
    fn drop(&mut self) {
        if let Some(temp) = self.0.take() {
            let path = temp.path().to_path_buf();
            drop(temp);
            // (Not waiting for the list: its holder may be this thread,
            // putting outputs in place. A path left on it names no file;
            // removing it again at a signal does nothing.)
            if let Ok(mut list) = STAGED.try_lock() {
                unstage(&mut list, &path);
            }
        }
    }
}

impl Write for StagedTemp {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.get_mut().write(buf)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.get_mut().flush()
    }
}

/// An output file being written.
pub struct AtomicFile {
    temp: BufWriter<StagedTemp>,
    target: PathBuf,
    into_special: bool,
}

/// `path` with its symbolic links followed (the link's target, which need
/// not exist yet).
pub fn resolve_links(path: &Path) -> io::Result<PathBuf> {
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
    /// in the system's temporary directory. It is created with mode 0666
    /// less the umask: the mode a new file gets.
    pub fn create(target: &Path) -> io::Result<AtomicFile> {
        let target = resolve_links(target)?;
        let into_special = fs::metadata(&target).is_ok_and(|m| !m.is_file() && !m.is_dir());
        let dir = match target.parent() {
            _ if into_special => std::env::temp_dir(),
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let mut builder = tempfile::Builder::new();
        builder.prefix(".kinpost-").suffix(".tmp");
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            builder.permissions(fs::Permissions::from_mode(0o666));
        }
        let temp = builder.tempfile_in(dir)?;
        Ok(AtomicFile {
            temp: BufWriter::with_capacity(1 << 16, StagedTemp::new(temp)),
            target,
            into_special,
        })
    }

    /// Flushes and puts the file in place.
    #[cfg(test)]
    pub fn commit(self) -> io::Result<()> {
        let done = self.finish()?;
        let mut list = staged();
        done.persist(&mut list)
    }

    /// Flushes the file to disk, ready to be renamed into place: what can
    /// fail for want of space happens here, so that several outputs can be
    /// finished first and renamed together.
    pub fn finish(self) -> io::Result<Finished> {
        let temp = self.temp.into_inner().map_err(|e| e.into_error())?;
        if !self.into_special {
            // A file replaced keeps its mode, without set-user-ID and
            // set-group-ID (a program is no program to run with another's
            // rights); a new file keeps the mode it was created with.
            #[cfg(unix)]
            if let Ok(m) = fs::metadata(&self.target) {
                use std::os::unix::fs::PermissionsExt;
                let mode = m.permissions().mode() & 0o1777;
                temp.get()
                    .as_file()
                    .set_permissions(fs::Permissions::from_mode(mode))?;
            }
            temp.get().as_file().sync_all()?;
        }
        Ok(Finished {
            temp,
            target: self.target,
            into_special: self.into_special,
            written: false,
        })
    }
}

/// An output file written to disk, not yet in place (dropped: removed).
pub struct Finished {
    temp: StagedTemp,
    target: PathBuf,
    into_special: bool,
    /// The device or pipe has been written into.
    written: bool,
}

impl Finished {
    /// Writes the file into the device or pipe it goes to (nothing for a
    /// file: see [`Finished::persist`]).
    pub fn write_special(&mut self) -> io::Result<()> {
        if !self.into_special || self.written {
            return Ok(());
        }
        self.written = true;
        let file: &mut File = self.temp.get_mut().as_file_mut();
        file.seek(SeekFrom::Start(0))?;
        let mut out = OpenOptions::new().write(true).open(&self.target)?;
        io::copy(file, &mut out)?;
        out.flush()?;
        // (A full device such as /dev/full fails at the write or here.)
        out.sync_all().or_else(|e| match e.kind() {
            io::ErrorKind::InvalidInput | io::ErrorKind::Unsupported => Ok(()),
            _ if e.raw_os_error() == Some(22) => Ok(()),
            _ => Err(e),
        })
    }

    /// Renames the file into place (a device or pipe: writes into it, if
    /// [`Finished::write_special`] has not). `list` is the staged list,
    /// held by the caller ([`staged`]).
    pub fn persist(mut self, list: &mut Vec<PathBuf>) -> io::Result<()> {
        if self.into_special {
            return self.write_special();
        }
        self.temp.persist(list, &self.target)
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
        finished.persist(&mut staged()).unwrap();
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

    /// The process's umask, from /proc (Linux); `None` elsewhere.
    #[cfg(unix)]
    fn umask() -> Option<u32> {
        let status = std::fs::read_to_string("/proc/self/status").ok()?;
        let line = status.lines().find(|l| l.starts_with("Umask:"))?;
        u32::from_str_radix(line["Umask:".len()..].trim(), 8).ok()
    }

    #[cfg(unix)]
    #[test]
    fn new_files_honour_the_umask_and_replaced_files_keep_their_mode_less_setuid() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("new.mpf");
        let write = |bytes: &[u8]| {
            let mut f = AtomicFile::create(&target).unwrap();
            f.write_all(bytes).unwrap();
            f.commit().unwrap();
        };
        write(b"x");
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o7777;
        if let Some(umask) = umask() {
            assert_eq!(mode(&target), 0o666 & !umask);
        }
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        write(b"y");
        assert_eq!(mode(&target), 0o640);
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o6755)).unwrap();
        write(b"z");
        assert_eq!(mode(&target), 0o755);
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o1644)).unwrap();
        write(b"w");
        assert_eq!(mode(&target), 0o1644);
    }

    #[test]
    fn staged_files_are_listed_until_they_are_in_place_or_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let listed = |p: &Path| staged().iter().any(|s| s.starts_with(p));
        let f = AtomicFile::create(&dir.path().join("a.nc")).unwrap();
        assert!(listed(dir.path()));
        drop(f);
        assert!(!listed(dir.path()));
        let mut f = AtomicFile::create(&dir.path().join("b.nc")).unwrap();
        f.write_all(b"b").unwrap();
        assert!(listed(dir.path()));
        f.commit().unwrap();
        assert!(!listed(dir.path()));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
