//! Writing output files so that a failure is never silent and nothing is
//! left half-written.
//!
//! - A regular file is written to a temporary sibling (`<name>.tmp-<pid>-<n>`)
//!   and renamed over the destination only when every write, the flush and
//!   the sync succeeded ([`AtomicFile::commit`]); dropped uncommitted, the
//!   temporary file is removed.
//! - A destination that exists and is not a regular file (a character device
//!   such as `/dev/null` or `/dev/full`, a FIFO) is written in place: there
//!   is nothing to replace atomically, and renaming over a device would
//!   destroy it. Every write and the final flush are still checked.
//! - A directory, a missing parent directory or an unwritable place is an
//!   error naming the path, reported before any computation when the caller
//!   creates the file first (as the commands do).

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;

/// A file could not be written.
#[derive(Debug, thiserror::Error)]
#[error("cannot write {}: {cause}", path.display())]
pub struct OutputError {
    /// The file that could not be written.
    pub path: PathBuf,
    /// Why.
    pub cause: std::io::Error,
}

impl OutputError {
    /// `cause` writing `path`.
    pub fn new(path: &Path, cause: std::io::Error) -> Self {
        Self {
            path: path.to_path_buf(),
            cause,
        }
    }

    /// An error with a message of ours.
    pub fn other(path: &Path, message: impl std::fmt::Display) -> Self {
        Self::new(path, std::io::Error::other(message.to_string()))
    }
}

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// Every temporary sibling handed out and not yet moved into place or
/// removed: what [`remove_temporaries`] removes when the process must end
/// at once (a second SIGINT/SIGTERM).
static TEMPORARIES: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn temporaries() -> std::sync::MutexGuard<'static, Vec<PathBuf>> {
    TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner())
}

/// The temporary `tmp` was moved into place or removed: forget it.
pub fn forget_temporary(tmp: &Path) {
    let mut t = temporaries();
    if let Some(i) = t.iter().rposition(|p| p == tmp) {
        t.swap_remove(i);
    }
}

/// Remove every temporary sibling still registered (the names are unique
/// to this process, so nothing else is touched); how many were removed.
pub fn remove_temporaries() -> usize {
    let mut t = temporaries();
    let removed = t
        .drain(..)
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count();
    removed
}

/// A temporary sibling of `path`, unique within this process, registered
/// until [`forget_temporary`] (so that [`remove_temporaries`] finds it).
pub fn tmp_sibling(path: &Path) -> PathBuf {
    let mut name = path
        .file_name()
        .map(|n| n.to_os_string())
        .unwrap_or_default();
    name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        COUNTER.fetch_add(1, Ordering::Relaxed)
    ));
    let tmp = path.with_file_name(name);
    temporaries().push(tmp.clone());
    tmp
}

/// Whether `path` exists and is something other than a regular file or a
/// directory (a device, a FIFO, a socket): written in place.
pub fn is_special(path: &Path) -> bool {
    std::fs::metadata(path).is_ok_and(|m| !m.is_file() && !m.is_dir())
}

/// A file written atomically (see the module documentation).
pub struct AtomicFile {
    path: PathBuf,
    /// None when writing in place.
    tmp: Option<PathBuf>,
    out: Option<BufWriter<File>>,
}

impl AtomicFile {
    /// Create the temporary file (or open the special file); errors name `path`.
    pub fn create(path: &Path) -> Result<Self, OutputError> {
        let err = |source| OutputError::new(path, source);
        if path.is_dir() {
            return Err(err(std::io::Error::new(
                std::io::ErrorKind::IsADirectory,
                "the output path is a directory",
            )));
        }
        if path.file_name().is_none() {
            return Err(err(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "the output path has no file name",
            )));
        }
        if is_special(path) {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(err)?;
            return Ok(Self {
                path: path.to_path_buf(),
                tmp: None,
                out: Some(BufWriter::new(file)),
            });
        }
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            if !dir.is_dir() {
                return Err(err(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!("the directory {} does not exist", dir.display()),
                )));
            }
        }
        let tmp = tmp_sibling(path);
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)
            .map_err(err)?;
        Ok(Self {
            path: path.to_path_buf(),
            tmp: Some(tmp),
            out: Some(BufWriter::new(file)),
        })
    }

    /// The destination (not the temporary sibling).
    pub fn path(&self) -> &Path {
        &self.path
    }

    fn writer(&mut self) -> Result<&mut BufWriter<File>, OutputError> {
        let path = self.path.clone();
        self.out
            .as_mut()
            .ok_or_else(|| OutputError::other(&path, "the file was already committed"))
    }

    /// Write a line (the newline is added).
    pub fn line(&mut self, args: std::fmt::Arguments<'_>) -> Result<(), OutputError> {
        let path = self.path.clone();
        writeln!(self.writer()?, "{args}").map_err(|e| OutputError::new(&path, e))
    }

    /// Write bytes.
    pub fn bytes(&mut self, data: &[u8]) -> Result<(), OutputError> {
        let path = self.path.clone();
        self.writer()?
            .write_all(data)
            .map_err(|e| OutputError::new(&path, e))
    }

    /// Flush, sync and move into place; the destination changes only now.
    pub fn commit(mut self) -> Result<PathBuf, OutputError> {
        let path = self.path.clone();
        let err = |source| OutputError::new(&path, source);
        let out = self.out.take().expect("commit once");
        let file = out.into_inner().map_err(|e| err(e.into_error()))?;
        match &self.tmp {
            Some(tmp) => {
                file.sync_all().map_err(err)?;
                drop(file);
                std::fs::rename(tmp, &path).map_err(err)?;
                forget_temporary(tmp);
                self.tmp = None;
            }
            None => {
                // Devices may not support fsync (EINVAL); the flush above
                // already reported a failed write (ENOSPC on /dev/full).
                let _ = file.sync_all();
            }
        }
        Ok(path)
    }
}

impl Drop for AtomicFile {
    fn drop(&mut self) {
        if let Some(tmp) = self.tmp.take() {
            self.out = None;
            let _ = std::fs::remove_file(&tmp);
            forget_temporary(&tmp);
        }
    }
}

/// Write a whole file atomically.
pub fn write_file(path: &Path, data: &[u8]) -> Result<PathBuf, OutputError> {
    let mut f = AtomicFile::create(path)?;
    f.bytes(data)?;
    f.commit()
}

/// Bytes free for an unprivileged writer on the filesystem that holds
/// `path` (its directory when `path` does not exist yet); None when it
/// cannot be asked (not Unix, or the path has no existing ancestor).
pub fn free_bytes(path: &Path) -> Option<u64> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        let mut at = path;
        while !at.exists() {
            at = match at.parent() {
                Some(p) if p.as_os_str().is_empty() => Path::new("."),
                p => p?,
            };
        }
        let c = std::ffi::CString::new(at.as_os_str().as_bytes()).ok()?;
        // SAFETY: a valid NUL-terminated path and a zeroed struct to fill.
        let mut st: libc::statvfs = unsafe { std::mem::zeroed() };
        if unsafe { libc::statvfs(c.as_ptr(), &mut st) } != 0 {
            return None;
        }
        Some((st.f_bavail as u64).saturating_mul(st.f_frsize as u64))
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// A size in bytes as people read it (kB, MB, GB, TB, PB; powers of 1000).
pub fn human_bytes(b: f64) -> String {
    let units = ["B", "kB", "MB", "GB", "TB", "PB", "EB"];
    let mut v = b;
    let mut k = 0;
    while v >= 1000.0 && k + 1 < units.len() {
        v /= 1000.0;
        k += 1;
    }
    if k == 0 {
        format!("{v:.0} B")
    } else {
        format!("{v:.1} {}", units[k])
    }
}

/// Above this an output is worth a warning with its estimated size.
pub const LARGE_OUTPUT_BYTES: f64 = 1e9;

/// Check that an output of about `estimated` bytes fits on the filesystem
/// of `path` before anything is computed: an error naming both sizes when
/// it does not (a device such as `/dev/null` always fits); `Ok(Some(..))`
/// with a warning to print when it is large ([`LARGE_OUTPUT_BYTES`]).
pub fn check_room(path: &Path, estimated: f64, what: &str) -> Result<Option<String>, OutputError> {
    if is_special(path) {
        return Ok(None);
    }
    if let Some(free) = free_bytes(path) {
        if estimated > free as f64 {
            return Err(OutputError::other(
                path,
                format!(
                    "{what} would take about {}, and {} are free there",
                    human_bytes(estimated),
                    human_bytes(free as f64)
                ),
            ));
        }
    }
    Ok((estimated > LARGE_OUTPUT_BYTES)
        .then(|| format!("{what} will take about {}", human_bytes(estimated))))
}

/// Make sure `dir` exists and is writable (before any computation).
pub fn prepare_dir(dir: &Path) -> Result<(), OutputError> {
    prepare_output_dir(dir).map(OutputDir::keep)
}

/// Make sure `dir` exists and is writable, and remove it again if this
/// call created it and nothing was written into it: the returned guard
/// removes the directory when dropped while it is still empty, unless
/// [`OutputDir::keep`] was called (work that failed or was interrupted
/// leaves no empty folder behind).
pub fn prepare_output_dir(dir: &Path) -> Result<OutputDir, OutputError> {
    let err = |source| OutputError::new(dir, source);
    if dir.exists() && !dir.is_dir() {
        return Err(err(std::io::Error::new(
            std::io::ErrorKind::NotADirectory,
            "exists and is not a directory",
        )));
    }
    let created = !dir.exists();
    std::fs::create_dir_all(dir).map_err(err)?;
    let guard = OutputDir {
        path: created.then(|| dir.to_path_buf()),
    };
    let probe = tmp_sibling(&dir.join(".write-test"));
    std::fs::write(&probe, b"").map_err(err)?;
    std::fs::remove_file(&probe).map_err(err)?;
    forget_temporary(&probe);
    Ok(guard)
}

/// An output directory made by [`prepare_output_dir`].
#[derive(Debug)]
pub struct OutputDir {
    /// The directory when this process created it (removed when dropped empty).
    path: Option<PathBuf>,
}

impl OutputDir {
    /// Keep the directory whatever it holds.
    pub fn keep(mut self) {
        self.path = None;
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if let Some(p) = &self.path {
            // remove_dir fails on a directory that is not empty: then it stays.
            let _ = std::fs::remove_dir(p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An empty directory that goes when the guard drops.
    fn dir() -> tempfile::TempDir {
        tempfile::tempdir().unwrap()
    }

    #[test]
    fn a_committed_file_replaces_the_old_one_and_an_abandoned_one_leaves_nothing() {
        let d = dir();
        let p = d.path().join("out.csv");
        std::fs::write(&p, "old\n").unwrap();
        let mut f = AtomicFile::create(&p).unwrap();
        f.line(format_args!("new")).unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "old\n");
        f.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new\n");
        let mut f = AtomicFile::create(&p).unwrap();
        f.line(format_args!("half")).unwrap();
        drop(f);
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "new\n");
        assert_eq!(
            std::fs::read_dir(d.path()).unwrap().count(),
            1,
            "no temporary left"
        );
    }

    #[test]
    fn a_full_device_is_an_error_and_a_null_device_is_not_replaced() {
        if Path::new("/dev/full").exists() {
            let mut f = AtomicFile::create(Path::new("/dev/full")).unwrap();
            let big = vec![b'x'; 1 << 16];
            let r = f.bytes(&big).and_then(|_| f.commit().map(|_| ()));
            let e = r.unwrap_err();
            assert!(e.to_string().contains("/dev/full"), "{e}");
        }
        if Path::new("/dev/null").exists() {
            write_file(Path::new("/dev/null"), b"x").unwrap();
            assert!(is_special(Path::new("/dev/null")), "still a device");
        }
    }

    #[test]
    fn an_output_larger_than_the_free_space_is_refused_with_both_sizes() {
        let d = dir();
        let p = d.path().join("big.csv");
        let free = free_bytes(&p).expect("statvfs works here") as f64;
        let e = check_room(&p, 2.0 * free + 1e15, "the CSV")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("would take about") && e.contains("are free"),
            "{e}"
        );
        assert_eq!(check_room(&p, 10.0, "the CSV").unwrap(), None);
        if free > 2e9 {
            let w = check_room(&p, 1.5e9, "the CSV").unwrap().unwrap();
            assert!(w.contains("1.5 GB"), "{w}");
        }
        assert_eq!(human_bytes(3.2e15), "3.2 PB");
        assert_eq!(human_bytes(512.0), "512 B");
    }

    #[test]
    fn a_missing_directory_or_a_directory_path_is_named() {
        let e = AtomicFile::create(Path::new("/nonexistent-dir-xyz/out.csv"))
            .err()
            .unwrap();
        assert!(e.to_string().contains("does not exist"), "{e}");
        let d = dir();
        let e = AtomicFile::create(d.path()).err().unwrap();
        assert!(e.to_string().contains("is a directory"), "{e}");
    }
}
