//! The file-system layer below everything that writes: atomic writes and spill folders.
//!
//! Writing output files atomically: into a temporary file in the same directory, then renamed over the
//! target, so a crash or a full disk never leaves a half-written file where a good one was.
//!
//! **Temporary files.** The temporary file of a write to `dir/NAME` is `dir/.NAME.XXXXXX.PID.ktree-tmp`
//! (hidden, random `XXXXXX`, `PID` the writing process). An error removes it; a process killed mid-write
//! cannot, so the next write to the same target removes the temporary files of `NAME` whose process no
//! longer runs (where `/proc` tells; elsewhere they stay, recognisable by the suffix).

use std::io::Write;
use std::path::{Path, PathBuf};

/// The suffix of temporary files.
const TEMP_SUFFIX: &str = ".ktree-tmp";

/// Writes `bytes` to `path` atomically, creating the parent directory if needed. A new file gets the mode
/// `File::create` would give it (0666 less the umask); a file replaced keeps its mode.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("sub/out.txt");
/// ktree::fs::write_atomic(&path, b"hello").unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// ```
///
/// # Errors
/// A [`FileOpError`] naming the path, its source the I/O error as the system gave it.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), FileOpError> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Like [`write_atomic`], with the content produced by `fill` into a buffered writer (through an
/// [`AtomicFile`]).
///
/// # Errors
/// A [`FileOpError`] naming the path, its source the I/O error from `fill` or the file system as it was
/// given (its kind and `raw_os_error` kept); the target is untouched.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// std::fs::write(dir.path().join("plain"), b"").unwrap();
/// let e = ktree::fs::write_atomic(&dir.path().join("plain/out.txt"), b"x").unwrap_err();
/// assert_eq!(e.path(), dir.path().join("plain/out.txt"));
/// # #[cfg(target_os = "linux")]
/// assert_eq!(e.io().raw_os_error(), Some(20)); // ENOTDIR
/// ```
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), FileOpError> {
    let with_path = |e| FileOpError::new(FileOp::Write, path, e);
    let mut file = AtomicFile::create(path).map_err(with_path)?;
    {
        let mut w = std::io::BufWriter::new(&mut file);
        fill(&mut w).map_err(with_path)?;
        w.flush().map_err(with_path)?;
    }
    file.commit().map_err(with_path)
}

/// A file written atomically: written as a temporary file beside its target, which
/// [`commit`](Self::commit) renames over the target; dropped without a commit, it is removed and the
/// target is untouched. Unbuffered: wrap it in a [`std::io::BufWriter`] for small writes.
///
/// ```
/// use std::io::Write;
/// let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("out.txt");
/// let mut file = ktree::fs::AtomicFile::create(&path).unwrap();
/// file.write_all(b"hello").unwrap();
/// assert!(!path.exists());
/// file.commit().unwrap();
/// assert_eq!(std::fs::read(&path).unwrap(), b"hello");
/// ```
#[derive(Debug)]
pub struct AtomicFile {
    tmp: tempfile::NamedTempFile,
    path: PathBuf,
}

impl AtomicFile {
    /// Starts writing `path`: creates its folder if needed, removes the temporary files of killed writes
    /// to it, and creates its temporary file `.NAME.XXXXXX.PID.ktree-tmp`, with the mode `File::create`
    /// would give a new file (0666 less the umask) or the mode of the file it replaces.
    ///
    /// # Errors
    /// The folder or the temporary file cannot be created (the error as the system gave it).
    pub fn create(path: &Path) -> std::io::Result<Self> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        if let Err(e) = std::fs::create_dir_all(dir) {
            // A plain file where the folder should be: say "not a directory" as the system does, not
            // "file exists".
            return Err(match std::fs::read_dir(dir) {
                Err(not_dir) if dir.exists() => not_dir,
                _ => e,
            });
        }
        let name = path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        remove_stale(dir, &name, TEMP_SUFFIX);
        let (prefix, suffix) = (
            format!(".{name}."),
            format!(".{}{TEMP_SUFFIX}", std::process::id()),
        );
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(&suffix);
        // The mode a plain `File::create` gives (0666 less the umask), not the temporary file's 0600.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let tmp = builder.tempfile_in(dir)?;
        // A file replaced keeps its mode.
        if let Ok(old) = std::fs::metadata(path) {
            tmp.as_file().set_permissions(old.permissions())?;
        }
        Ok(Self {
            tmp,
            path: path.to_path_buf(),
        })
    }

    /// Ends the write: the bytes written are synced to the disk, then the file is renamed over its target.
    ///
    /// # Errors
    /// The sync or the rename failed (the error as the system gave it); the temporary file is removed and
    /// the target untouched.
    pub fn commit(self) -> std::io::Result<()> {
        self.tmp.as_file().sync_all()?;
        self.tmp.persist(&self.path).map_err(|e| e.error)?;
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        self.tmp.as_file_mut().write(bytes)
    }

    fn write_all(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.tmp.as_file_mut().write_all(bytes)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.tmp.as_file_mut().flush()
    }
}

/// The suffix of spill folders: `.NAME.XXXXXX.PID.ktree-spill`.
pub(crate) const SPILL_SUFFIX: &str = ".ktree-spill";

/// Creates the hidden spill folder `.NAME.XXXXXX.PID.ktree-spill` of a build or operation writing `out`, in
/// `temp_dir` (default: the output's folder, created if needed), after removing the folders of killed
/// processes ([`remove_stale`]). The folder is removed when the returned guard is dropped.
///
/// # Errors
/// The folder that cannot be used, and why.
pub(crate) fn spill_folder(
    out: &Path,
    temp_dir: Option<&Path>,
) -> Result<tempfile::TempDir, (PathBuf, std::io::Error)> {
    let dir = match temp_dir {
        Some(d) => d.to_path_buf(),
        None => match out.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        },
    };
    if temp_dir.is_none() {
        std::fs::create_dir_all(&dir).map_err(|e| (dir.clone(), e))?;
    }
    let name = out
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    remove_stale(&dir, &name, SPILL_SUFFIX);
    tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(&format!(".{}{SPILL_SUFFIX}", std::process::id()))
        .tempdir_in(&dir)
        .map_err(|e| (dir, e))
}

/// Removes `dir/.NAME.*.PID{suffix}` files and folders left by processes that were killed (their `PID` no
/// longer runs): the temporary files of atomic writes (`.ktree-tmp`) and the spill folders of out-of-core
/// builds (`.ktree-spill`). Best effort: errors are ignored, and nothing is removed where `/proc` does not
/// list processes.
pub(crate) fn remove_stale(dir: &Path, name: &str, suffix: &str) {
    let proc = Path::new("/proc");
    if !proc.join("self").exists() {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let prefix = format!(".{name}.");
    for entry in entries.flatten() {
        let file = entry.file_name();
        let file = file.to_string_lossy();
        let Some(rest) = file
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(suffix))
        else {
            continue;
        };
        let Some(pid) = rest.rsplit('.').next().and_then(|p| p.parse::<u32>().ok()) else {
            continue;
        };
        if !proc.join(pid.to_string()).exists() {
            let path = entry.path();
            let _ = if path.is_dir() {
                std::fs::remove_dir_all(path)
            } else {
                std::fs::remove_file(path)
            };
        }
    }
}

/// Why the temporary files of a job that spills to disk (an out-of-core build, a streamed Boolean) or its
/// output could not be written. The target is then untouched and the spill files are removed.
#[derive(Debug, thiserror::Error)]
pub enum SpillError {
    /// The folder for the spill files cannot be used.
    #[error("cannot create spill files in the temporary folder {}", path.display())]
    TempDir {
        /// The folder.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// A spill file cannot be written or read back.
    #[error("spill file {}", path.display())]
    Spill {
        /// The spill file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
    /// The output cannot be written.
    #[error("cannot write {}", path.display())]
    Output {
        /// The output file.
        path: PathBuf,
        /// The error.
        source: std::io::Error,
    },
}

impl SpillError {
    /// The kind of the I/O error behind it.
    pub fn kind(&self) -> std::io::ErrorKind {
        match self {
            Self::TempDir { source, .. }
            | Self::Spill { source, .. }
            | Self::Output { source, .. } => source.kind(),
        }
    }
}

impl From<SpillError> for std::io::Error {
    /// The error as an I/O error of the same kind, its message naming the file.
    fn from(e: SpillError) -> Self {
        std::io::Error::new(e.kind(), e)
    }
}

/// What was being done to a file when it failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum FileOp {
    /// Opening or reading it.
    Read,
    /// Creating or writing it (for an atomic write: its folder, its temporary file, the rename).
    Write,
    /// Creating a folder.
    CreateFolder,
}

/// An error and its causes in one line, `A: B: C`: each error's message says its own part only, its
/// cause is its [`source`](std::error::Error::source). A message that already ends with its cause's, as
/// some errors of other crates write theirs, is not repeated.
///
/// ```
/// let dir = tempfile::tempdir().unwrap();
/// let plain = dir.path().join("plain");
/// std::fs::write(&plain, b"").unwrap();
/// let e = ktree::fs::write_atomic(&plain.join("x"), b"").unwrap_err(); // below a plain file
/// // The operation and path, then the system's reason.
/// let text = ktree::fs::error_chain(&e);
/// assert!(text.starts_with(&e.to_string()) && text.len() > e.to_string().len(), "{text}");
/// ```
pub fn error_chain(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let next = c.to_string();
        if !next.is_empty() && !text.ends_with(&next) {
            text.push_str(": ");
            text.push_str(&next);
        }
        cause = c.source();
    }
    text
}

/// A file operation that failed: the path and the [`std::io::Error`] as the system gave it, kept whole as
/// the [`source`](std::error::Error::source) (its [`kind`](std::io::Error::kind) and
/// [`raw_os_error`](std::io::Error::raw_os_error) intact). Its message names the operation and the path
/// only; the cause is its source (print the chain: `cannot write out.ktree: No space left on device`).
#[derive(Debug, thiserror::Error)]
#[error("cannot {} {}", match .op { FileOp::Read => "read", FileOp::Write => "write", FileOp::CreateFolder => "create the folder" }, .path.display())]
pub struct FileOpError {
    op: FileOp,
    path: PathBuf,
    #[source]
    source: std::io::Error,
}

impl FileOpError {
    /// The failure `source` of `op` on `path`.
    pub fn new(op: FileOp, path: &Path, source: std::io::Error) -> Self {
        Self {
            op,
            path: path.to_path_buf(),
            source,
        }
    }

    /// What was being done.
    pub fn op(&self) -> FileOp {
        self.op
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The I/O error as the system gave it.
    pub fn io(&self) -> &std::io::Error {
        &self.source
    }

    /// The I/O error as the system gave it, taken out.
    pub fn into_io(self) -> std::io::Error {
        self.source
    }

    /// The kind of the I/O error.
    pub fn kind(&self) -> std::io::ErrorKind {
        self.source.kind()
    }
}

impl From<FileOpError> for std::io::Error {
    /// The error as an I/O error of the same kind, its message naming the file (its source is the
    /// original error).
    fn from(e: FileOpError) -> Self {
        std::io::Error::new(e.kind(), e)
    }
}

/// An I/O failure kept whole inside a file error, so that its [`source`](std::error::Error::source) is the
/// [`std::io::Error`] and a caller can act on its [`kind`](IoCause::kind) (Python raises `FileNotFoundError`,
/// `PermissionError`, …). Cloneable, and equal when kind and message are.
///
/// ```
/// use std::error::Error;
/// let e = ktree::io::read_ktree_file(std::path::Path::new("no/such.ktree")).unwrap_err();
/// let io = e.source().and_then(|s| s.downcast_ref::<std::io::Error>()).unwrap();
/// assert_eq!(io.kind(), std::io::ErrorKind::NotFound);
/// ```
#[derive(Debug, Clone)]
pub struct IoCause(std::sync::Arc<std::io::Error>);

impl IoCause {
    /// What kind of failure it was.
    pub fn kind(&self) -> std::io::ErrorKind {
        self.0.kind()
    }

    /// The error itself.
    pub fn error(&self) -> &std::io::Error {
        &self.0
    }
}

impl From<std::io::Error> for IoCause {
    fn from(e: std::io::Error) -> Self {
        Self(std::sync::Arc::new(e))
    }
}

impl std::fmt::Display for IoCause {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl PartialEq for IoCause {
    fn eq(&self, other: &Self) -> bool {
        self.kind() == other.kind() && self.0.to_string() == other.0.to_string()
    }
}

impl Eq for IoCause {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stale_temporaries_of_dead_writers_are_removed_on_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.ktree");
        // PIDs above the kernel's maximum (4194304) never run.
        let stale = dir.path().join(".out.ktree.abc123.4294967295.ktree-tmp");
        let live = dir.path().join(format!(
            ".out.ktree.abc123.{}.ktree-tmp",
            std::process::id()
        ));
        let other = dir.path().join(".other.ktree.abc123.4294967295.ktree-tmp");
        for f in [&stale, &live, &other] {
            std::fs::write(f, b"partial").unwrap();
        }
        write_atomic(&target, b"new").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"new");
        assert!(!stale.exists(), "a dead writer's temporary file stays");
        assert!(
            live.exists(),
            "a running writer's temporary file was removed"
        );
        assert!(
            other.exists(),
            "another target's temporary file was removed"
        );
    }

    #[cfg(unix)]
    #[test]
    fn outputs_get_the_mode_of_a_plain_create_and_a_replaced_file_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt;
        let mode = |p: &Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        let dir = tempfile::tempdir().unwrap();
        let plain = dir.path().join("plain");
        std::fs::File::create(&plain).unwrap();
        let new = dir.path().join("new.ktree");
        write_atomic(&new, b"x").unwrap();
        assert_eq!(mode(&new), mode(&plain), "a new output's mode");
        let kept = dir.path().join("kept.ktree");
        std::fs::write(&kept, b"old").unwrap();
        std::fs::set_permissions(&kept, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_atomic(&kept, b"new").unwrap();
        assert_eq!(mode(&kept), 0o640, "a replaced file's mode");
        assert_eq!(std::fs::read(&kept).unwrap(), b"new");
    }

    /// The cause of a failed write is the system's error itself: its kind and errno survive.
    #[cfg(target_os = "linux")]
    #[test]
    fn writing_below_a_plain_file_keeps_the_system_error() {
        use std::error::Error as _;
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("plain"), b"").unwrap();
        for target in ["plain/out.ktree", "plain/sub/out.ktree"] {
            let e = write_atomic(&dir.path().join(target), b"x").unwrap_err();
            let io = e
                .source()
                .unwrap()
                .downcast_ref::<std::io::Error>()
                .unwrap();
            assert_eq!(io.raw_os_error(), Some(20), "{target}: ENOTDIR, got {io}");
            assert_eq!(io.kind(), std::io::ErrorKind::NotADirectory);
            assert!(e.to_string().ends_with(target), "{e}");
            assert!(!e.to_string().contains(&io.to_string()), "{e}");
        }
    }

    #[test]
    fn a_failed_write_leaves_the_old_file_and_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("keep.txt");
        write_atomic(&target, b"old").unwrap();
        let e = write_atomic_with(&target, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        })
        .unwrap_err();
        assert!(e.to_string().contains("keep.txt"), "{e}");
        assert_eq!(e.io().to_string(), "disk full");
        assert_eq!(std::fs::read(&target).unwrap(), b"old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
