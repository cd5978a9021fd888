//! Writes that never lose a file: the output goes to a temporary file in the destination's folder,
//! is flushed and synced, and is renamed over the destination only once complete. A write that
//! fails part-way (disk full, file size limit, an error from the producer) removes the temporary
//! file and leaves any previous file at the destination untouched.
//!
//! Only a regular file is replaced: a symbolic link's target is written (the link stays), and a
//! path that is a device or a pipe (`/dev/null`, a fifo) is written in place, never replaced by a
//! file. A temporary file left by a killed run is removed by the next write to the same path
//! (its name holds the process id, and that process is gone). [`same_file`] tells a command that
//! an output names one of its inputs, before it writes anything.

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `path` atomically: `body` writes the content to a buffered temporary file in the same
/// folder, which is then flushed, synced to disk and renamed into place.
pub fn write_atomically(
    path: impl AsRef<Path>,
    body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>,
) -> io::Result<()> {
    let path = &resolve_links(path.as_ref())?;
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => return Err(io::Error::other("it is a folder")),
        Ok(m) if !m.is_file() => return write_in_place(path, body),
        _ => {}
    }
    let (tmp, file) = create_temp(path)?;
    let result = (|| {
        let mut w = BufWriter::new(file);
        body(&mut w)?;
        w.flush()?;
        let file = w.into_inner().map_err(io::IntoInnerError::into_error)?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&tmp, path)
    })();
    match result {
        Ok(()) => {
            sync_folder(path);
            Ok(())
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Writes a path that is not a regular file (a device, a fifo) as it is: opened for writing,
/// never created, truncated or renamed over.
fn write_in_place(path: &Path, body: impl FnOnce(&mut BufWriter<File>) -> io::Result<()>) -> io::Result<()> {
    let mut w = BufWriter::new(OpenOptions::new().write(true).open(path)?);
    body(&mut w)?;
    w.flush()
}

/// Links followed to what they name: the path to write (a link to nothing yet names the file
/// the write creates). More than 40 links in a row is an error, as for the system's own lookup.
fn resolve_links(path: &Path) -> io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let target = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// Whether `a` and `b` name one file (the same device and inode, so a hard link, a symbolic link
/// or another spelling of the path is caught); false when either does not exist.
pub fn same_file(a: impl AsRef<Path>, b: impl AsRef<Path>) -> bool {
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(a), Ok(b)) => identity(&a) == identity(&b),
        _ => false,
    }
}

#[cfg(unix)]
fn identity(m: &std::fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((m.dev(), m.ino()))
}

// Without inode numbers, no two files are known to be one.
#[cfg(not(unix))]
fn identity(_: &std::fs::Metadata) -> Option<(u64, u64)> {
    None
}

/// A new file next to `path`, named `.NAME.tmp-PID-N`, created exclusively, after removing the
/// temporary files of `path` whose process is gone.
fn create_temp(path: &Path) -> io::Result<(PathBuf, File)> {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "the path names no file"))?
        .to_string_lossy()
        .into_owned();
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    remove_stale_temps(dir, &name);
    loop {
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let tmp = dir.join(format!(".{name}.tmp-{}-{n}", std::process::id()));
        match OpenOptions::new().write(true).create_new(true).open(&tmp) {
            Ok(f) => return Ok((tmp, f)),
            Err(e) if e.kind() == io::ErrorKind::AlreadyExists => continue,
            Err(e) => return Err(e),
        }
    }
}

/// Removes `.NAME.tmp-PID-N` files in `dir` left by processes that no longer run (a run killed
/// in the middle of its write). Best effort: a file that cannot be removed stays.
fn remove_stale_temps(dir: &Path, name: &str) {
    let prefix = format!(".{name}.tmp-");
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)) else { continue };
        let pid = rest.split('-').next().and_then(|p| p.parse::<u32>().ok());
        if pid.is_some_and(|pid| pid != std::process::id() && !process_runs(pid)) {
            let _ = std::fs::remove_file(entry.path());
        }
    }
}

/// Whether process `pid` exists (signal 0 checks without sending; a process of another user
/// answers "not permitted", and counts as running).
#[cfg(unix)]
fn process_runs(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return true };
    // SAFETY: kill with signal 0 sends nothing; it only reports whether the process exists.
    unsafe { libc::kill(pid, 0) == 0 || io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH) }
}

// Without a way to ask, every process counts as running and nothing is removed.
#[cfg(not(unix))]
fn process_runs(_: u32) -> bool {
    true
}

/// Syncs the folder of `path` so that the rename itself survives a crash (best effort: not every
/// system can open a folder).
fn sync_folder(path: &Path) {
    #[cfg(unix)]
    if let Some(dir) = path.parent().map(|d| if d.as_os_str().is_empty() { Path::new(".") } else { d }) {
        if let Ok(d) = File::open(dir) {
            let _ = d.sync_all();
        }
    }
    #[cfg(not(unix))]
    let _ = path;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh folder of the test's own, removed when the test ends.
    fn folder(name: &str) -> tempfile::TempDir {
        tempfile::Builder::new().prefix(&format!("raytrail-cli-write-{name}-")).tempdir().unwrap()
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> =
            std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
        v.sort();
        v
    }

    #[test]
    fn a_complete_write_replaces_the_file() {
        let scratch = folder("ok");
        let dir = scratch.path();
        let path = dir.join("out.txt");
        std::fs::write(&path, b"old").unwrap();
        write_atomically(&path, |w| w.write_all(b"new content")).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new content");
        assert_eq!(entries(dir), ["out.txt"]);
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let scratch = folder("fail");
        let dir = scratch.path();
        let path = dir.join("out.txt");
        std::fs::write(&path, b"the good file").unwrap();
        let e = write_atomically(&path, |w| {
            // More than the buffer holds, so part of it reaches the temporary file first.
            w.write_all(&vec![b'x'; 1 << 20])?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(e.to_string(), "disk full");
        assert_eq!(std::fs::read(&path).unwrap(), b"the good file");
        assert_eq!(entries(dir), ["out.txt"]);
        // No folder: an error, nothing created.
        assert!(write_atomically(dir.join("no/such/out.txt"), |w| w.write_all(b"x")).is_err());
    }

    #[cfg(unix)]
    #[test]
    fn a_link_is_kept_and_its_target_written() {
        let scratch = folder("link");
        let dir = scratch.path();
        let (target, link) = (dir.join("target.txt"), dir.join("link.txt"));
        std::fs::write(&target, b"old").unwrap();
        std::os::unix::fs::symlink("target.txt", &link).unwrap();
        write_atomically(&link, |w| w.write_all(b"new")).unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert_eq!(entries(dir), ["link.txt", "target.txt"]);
        assert!(same_file(&link, &target));
        assert!(!same_file(&link, dir.join("absent")));
    }

    #[cfg(unix)]
    #[test]
    fn a_device_is_written_in_place_not_replaced() {
        use std::os::unix::fs::FileTypeExt;
        write_atomically("/dev/null", |w| w.write_all(b"gone")).unwrap();
        assert!(std::fs::metadata("/dev/null").unwrap().file_type().is_char_device());
        // A full device reports the error.
        if Path::new("/dev/full").exists() {
            assert!(write_atomically("/dev/full", |w| w.write_all(b"x")).is_err());
        }
        assert!(write_atomically(std::env::temp_dir(), |w| w.write_all(b"x")).is_err());
    }

    #[cfg(unix)]
    #[test]
    fn a_killed_runs_temporary_file_is_removed_by_the_next_write() {
        let scratch = folder("stale");
        let dir = scratch.path();
        let path = dir.join("out.txt");
        // A process id no process has (above the kernel's limit of 2^22), and this process's own.
        let stale = dir.join(".out.txt.tmp-4194999-0");
        let live = dir.join(format!(".out.txt.tmp-{}-999", std::process::id()));
        let other = dir.join(".other.txt.tmp-4194999-0");
        for f in [&stale, &live, &other] {
            std::fs::write(f, b"").unwrap();
        }
        write_atomically(&path, |w| w.write_all(b"x")).unwrap();
        let live_name = live.file_name().unwrap().to_string_lossy().into_owned();
        let mut want = vec![".other.txt.tmp-4194999-0".to_string(), live_name, "out.txt".to_string()];
        want.sort();
        assert_eq!(entries(dir), want);
    }
}
